#include <strata/terrain/scenario.hpp>

#include <toml++/toml.h>

#include <algorithm>
#include <charconv>
#include <cmath>
#include <fstream>
#include <map>
#include <set>
#include <sstream>

namespace strata::terrain {
namespace {

struct Unit {
  const char* name;
  const char* dimension;
  double toSi;
};

// Units a scenario may use, by dimension. "rate" is a depth per time (rain, evaporation).
constexpr Unit kUnits[] = {
    {"s", "time", 1.0},
    {"min", "time", 60.0},
    {"h", "time", 3600.0},
    {"d", "time", 86400.0},
    {"m", "length", 1.0},
    {"km", "length", 1000.0},
    {"mm", "length", 1e-3},
    {"cm", "length", 1e-2},
    {"m/s", "rate", 1.0},
    {"mm/h", "rate", 1e-3 / 3600},
    {"mm/d", "rate", 1e-3 / 86400},
    {"m/h", "rate", 1.0 / 3600},
    {"m3/s", "discharge", 1.0},
    {"m^3/s", "discharge", 1.0},
    {"m/s", "speed", 1.0},
    {"km/h", "speed", 1.0 / 3.6},
};

std::string unitsOf(std::string_view dimension) {
  std::string out;
  for (const auto& u : kUnits) {
    if (dimension == u.dimension) out += (out.empty() ? "" : ", ") + std::string(u.name);
  }
  return out;
}

// Errors carry "file:line: key 'path': message".
struct Reader {
  std::string file;
  std::filesystem::path baseDir;

  Error error(const toml::node& node, const std::string& key, const std::string& message) const {
    return fail(file + ":" + std::to_string(node.source().begin.line) + ": key '" + key + "': " + message);
  }
  Error errorAt(int line, const std::string& key, const std::string& message) const {
    return fail(file + ":" + std::to_string(line) + ": key '" + key + "': " + message);
  }

  // Refuses keys outside `allowed` (catches typos such as "duraton").
  Status onlyKeys(const toml::table& table, const std::string& prefix,
                  std::initializer_list<const char*> allowed) const {
    for (auto&& [k, v] : table) {
      const std::string key(k.str());
      if (std::none_of(allowed.begin(), allowed.end(), [&](const char* a) { return key == a; })) {
        std::string list;
        for (const char* a : allowed) list += (list.empty() ? "" : ", ") + std::string(a);
        return error(v, prefix.empty() ? key : prefix + "." + key, "unknown key (expected one of: " + list + ")");
      }
    }
    return {};
  }

  Result<double> quantity(const toml::node& node, const std::string& key, std::string_view dimension) const {
    if (auto n = node.value<double>(); n && (node.is_integer() || node.is_floating_point())) return *n;
    if (auto s = node.value<std::string>()) {
      auto q = parseQuantity(*s, dimension);
      if (!q) return error(node, key, q.message());
      return *q;
    }
    return error(node, key,
                 "expected a " + std::string(dimension) + " such as \"10 " +
                     std::string(unitsOf(dimension).substr(0, unitsOf(dimension).find(','))) + "\"");
  }

  Result<double> number(const toml::node& node, const std::string& key) const {
    if (auto n = node.value<double>(); n && (node.is_integer() || node.is_floating_point())) return *n;
    return error(node, key, "expected a number");
  }

  Result<std::string> string(const toml::node& node, const std::string& key) const {
    if (auto s = node.value<std::string>()) return *s;
    return error(node, key, "expected a string");
  }

  Result<bool> boolean(const toml::node& node, const std::string& key) const {
    if (auto b = node.value<bool>()) return *b;
    return error(node, key, "expected true or false");
  }

  std::string path(const std::string& p) const {
    const std::filesystem::path fp(p);
    return (fp.is_absolute() ? fp : (baseDir / fp)).lexically_normal().string();
  }

  // [x, y] pairs: a single pair or an array of pairs.
  Result<Place> place(const toml::node& node, const std::string& key, CoordFrame frame, bool single) const {
    Place out;
    out.frame = frame;
    out.line = int(node.source().begin.line);
    out.key = key;
    const auto* arr = node.as_array();
    if (!arr) return error(node, key, single ? "expected [x, y]" : "expected [[x, y], ...]");
    auto pair = [&](const toml::node& n) -> Result<std::array<double, 2>> {
      const auto* p = n.as_array();
      if (!p || p->size() != 2 || !(*p)[0].is_number() || !(*p)[1].is_number()) {
        return error(n, key, "expected a coordinate pair [x, y] of numbers");
      }
      return std::array<double, 2>{(*p)[0].value<double>().value(), (*p)[1].value<double>().value()};
    };
    if (single) {
      STRATA_TRY(auto p, pair(node));
      out.points.push_back(p);
    } else {
      for (const auto& n : *arr) {
        STRATA_TRY(auto p, pair(n));
        out.points.push_back(p);
      }
    }
    if (frame == CoordFrame::LonLat) {
      for (const auto& p : out.points) {
        if (p[0] < -180 || p[0] > 360 || p[1] < -90 || p[1] > 90) {
          return error(node, key,
                       "longitude/latitude out of range: [" + std::to_string(p[0]) + ", " + std::to_string(p[1]) + "]");
        }
      }
    }
    return out;
  }

  // One of `<base>_lonlat` / `<base>_xy` from a table.
  Result<std::optional<Place>> placeKey(const toml::table& t, const std::string& prefix, const std::string& base,
                                        bool single) const {
    const auto* ll = t.get(base + "_lonlat");
    const auto* xy = t.get(base + "_xy");
    if (ll && xy)
      return error(*xy, prefix + "." + base + "_xy", "give either " + base + "_lonlat or " + base + "_xy, not both");
    if (!ll && !xy) return std::optional<Place>();
    STRATA_TRY(auto p, place(ll ? *ll : *xy, prefix + "." + base + (ll ? "_lonlat" : "_xy"),
                             ll ? CoordFrame::LonLat : CoordFrame::DemCrs, single));
    return std::optional<Place>(std::move(p));
  }
};

// A curve of [time, value] pairs under `key`, with optional `<key>_units` = [time unit, value
// unit] (defaults "s" and `valueUnit`); times strictly increasing and not negative.
struct CurveSpec {
  const char* key;           // "hydrograph", "stage"
  const char* valueName;     // "discharge", "water surface elevation"
  const char* dimension;     // of the value, for parseQuantity
  const char* valueUnit;     // default unit of the value
  bool nonNegative = false;  // refuse negative values
};

Result<std::vector<std::array<double, 2>>> readCurve(const Reader& r, const toml::table& t, const std::string& prefix,
                                                     const CurveSpec& c) {
  const std::string key = prefix + "." + c.key, unitsKey = key + "_units";
  const std::string pairText = std::string("[time, ") + c.valueName + "]";
  const auto* pts = t.get(c.key);
  if (!pts) return r.errorAt(int(t.source().begin.line), key, "missing (pairs " + pairText + ")");
  std::string timeUnit = "s", valueUnit = c.valueUnit;
  const auto* u = t.get(std::string(c.key) + "_units");
  if (u) {
    const auto* a = u->as_array();
    if (!a || a->size() != 2 || !(*a)[0].is_string() || !(*a)[1].is_string()) {
      return r.error(
          *u, unitsKey,
          std::string("expected [time unit, ") + c.dimension + " unit], e.g. [\"h\", \"" + c.valueUnit + "\"]");
    }
    timeUnit = (*a)[0].value<std::string>().value();
    valueUnit = (*a)[1].value<std::string>().value();
  }
  auto tScale = parseQuantity("1 " + timeUnit, "time");
  if (!tScale) return r.error(u ? *u : *pts, unitsKey, tScale.message());
  auto vScale = parseQuantity("1 " + valueUnit, c.dimension);
  if (!vScale) return r.error(u ? *u : *pts, unitsKey, vScale.message());
  const auto* arr = pts->as_array();
  if (!arr || arr->empty()) return r.error(*pts, key, "expected [" + pairText + ", ...]");
  std::vector<std::array<double, 2>> out;
  for (const auto& n : *arr) {
    const auto* p = n.as_array();
    if (!p || p->size() != 2 || !(*p)[0].is_number() || !(*p)[1].is_number()) {
      return r.error(n, key, "expected a pair " + pairText + " of numbers");
    }
    const double ts = (*p)[0].value<double>().value() * *tScale, v = (*p)[1].value<double>().value() * *vScale;
    if (c.nonNegative && v < 0) {
      return r.error(n, key, std::string("negative ") + c.valueName + " " + std::to_string(v) + " " + c.valueUnit);
    }
    if (!out.empty() && ts <= out.back()[0]) return r.error(n, key, "times must increase strictly");
    if (ts < 0) return r.error(n, key, "negative time");
    out.push_back({ts, v});
  }
  return out;
}

Result<Hydrograph> readHydrograph(const Reader& r, const toml::table& t, const std::string& prefix) {
  STRATA_TRY(auto points, readCurve(r, t, prefix, {"hydrograph", "discharge", "discharge", "m3/s", true}));
  return Hydrograph{std::move(points)};
}

Status readTerrain(const Reader& r, const toml::table& root, Scenario& s) {
  const auto* t = root["terrain"].as_table();
  if (!t) return fail(r.file + ": missing [terrain] (dem = \"file.tif\" or store = \"folder\")");
  STRATA_TRY_STATUS(r.onlyKeys(*t, "terrain", {"dem", "store", "layer"}));
  if (const auto* d = t->get("dem")) {
    if (auto one = d->value<std::string>()) {
      s.terrain.dems.push_back(r.path(*one));
    } else if (const auto* a = d->as_array()) {
      for (const auto& n : *a) {
        STRATA_TRY(auto p, r.string(n, "terrain.dem"));
        s.terrain.dems.push_back(r.path(p));
      }
    } else {
      return r.error(*d, "terrain.dem", "expected a file name or a list of file names");
    }
  }
  if (const auto* st = t->get("store")) {
    STRATA_TRY(auto p, r.string(*st, "terrain.store"));
    s.terrain.store = r.path(p);
  }
  if (s.terrain.dems.empty() == s.terrain.store.empty()) {
    return r.errorAt(int(t->source().begin.line), "terrain", "give exactly one of dem or store");
  }
  if (const auto* layers = t->get("layer")) {
    const auto* arr = layers->as_array();
    if (!arr) return r.error(*layers, "terrain.layer", "expected [[terrain.layer]] tables");
    for (size_t i = 0; i < arr->size(); ++i) {
      const std::string key = "terrain.layer[" + std::to_string(i) + "]";
      const auto* lt = (*arr)[i].as_table();
      if (!lt) return r.error((*arr)[i], key, "expected a table");
      STRATA_TRY_STATUS(r.onlyKeys(*lt, key, {"material", "thickness", "raster"}));
      LayerSpec l;
      if (!lt->get("material")) return r.error(*lt, key + ".material", "missing");
      STRATA_TRY(l.material, r.string(*lt->get("material"), key + ".material"));
      if (const auto* th = lt->get("thickness")) {
        STRATA_TRY(l.thicknessM, r.quantity(*th, key + ".thickness", "length"));
        if (l.thicknessM < 0) return r.error(*th, key + ".thickness", "negative thickness");
      }
      if (const auto* ra = lt->get("raster")) {
        STRATA_TRY(auto p, r.string(*ra, key + ".raster"));
        l.raster = r.path(p);
      }
      s.terrain.layers.push_back(std::move(l));
    }
  }
  return {};
}

Status readRegion(const Reader& r, const toml::table& root, Scenario& s) {
  const auto* t = root["region"].as_table();
  if (!t) return {};  // the whole DEM
  STRATA_TRY_STATUS(r.onlyKeys(*t, "region", {"bbox_lonlat", "bbox_xy", "polygon_lonlat", "polygon_xy", "cell_size"}));
  STRATA_TRY(auto poly, r.placeKey(*t, "region", "polygon", false));
  const auto* bll = t->get("bbox_lonlat");
  const auto* bxy = t->get("bbox_xy");
  if (bll && bxy) return r.error(*bxy, "region.bbox_xy", "give either bbox_lonlat or bbox_xy, not both");
  if ((bll || bxy) && poly) return r.errorAt(poly->line, poly->key, "give either a bbox or a polygon, not both");
  if (bll || bxy) {
    // Written [west, south, east, north].
    const toml::node& node = bll ? *bll : *bxy;
    const std::string key = bll ? "region.bbox_lonlat" : "region.bbox_xy";
    const auto* a = node.as_array();
    if (!a || a->size() != 4 || std::any_of(a->begin(), a->end(), [](const toml::node& n) { return !n.is_number(); })) {
      return r.error(node, key, "expected [west, south, east, north]");
    }
    const double w = (*a)[0].value<double>().value(), so = (*a)[1].value<double>().value(),
                 e = (*a)[2].value<double>().value(), n = (*a)[3].value<double>().value();
    if (!(w < e) || !(so < n)) return r.error(node, key, "west must be < east and south < north");
    if (bll && (w < -180 || e > 360 || so < -90 || n > 90)) {
      return r.error(node, key, "longitude/latitude out of range");
    }
    s.region.kind = decltype(s.region)::BBox;
    s.region.place =
        Place{bll ? CoordFrame::LonLat : CoordFrame::DemCrs, {{w, so}, {e, n}}, int(node.source().begin.line), key};
  }
  if (poly) {
    if (poly->points.size() < 3) return r.errorAt(poly->line, poly->key, "a polygon needs at least 3 points");
    s.region.kind = decltype(s.region)::Polygon;
    s.region.place = *poly;
  }
  if (const auto* c = t->get("cell_size")) {
    STRATA_TRY(s.region.cellSizeM, r.quantity(*c, "region.cell_size", "length"));
    if (s.region.cellSizeM <= 0) return r.error(*c, "region.cell_size", "must be positive");
  }
  return {};
}

Status readModel(const Reader& r, const toml::table& root, Scenario& s) {
  const auto* t = root["model"].as_table();
  if (!t) return {};
  STRATA_TRY_STATUS(r.onlyKeys(*t, "model", {"kind", "manning_n", "cfl", "max_step", "slopes", "boundary"}));
  if (const auto* k = t->get("kind")) {
    STRATA_TRY(auto v, r.string(*k, "model.kind"));
    if (v == "flood") {
      s.model.kind = WaterModel::Flood;
    } else if (v == "pipe") {
      s.model.kind = WaterModel::Pipe;
    } else {
      return r.error(*k, "model.kind", "expected \"flood\" or \"pipe\", got \"" + v + "\"");
    }
  }
  if (const auto* n = t->get("manning_n")) {
    STRATA_TRY(s.model.manningN, r.number(*n, "model.manning_n"));
    if (s.model.manningN < 0 || s.model.manningN > 1) {
      return r.error(*n, "model.manning_n", "Manning's n in s/m^(1/3) is between 0 and ~0.2 for natural channels");
    }
  }
  if (const auto* c = t->get("cfl")) {
    STRATA_TRY(s.model.cfl, r.number(*c, "model.cfl"));
    if (s.model.cfl <= 0 || s.model.cfl > 1) return r.error(*c, "model.cfl", "must be in (0, 1]");
    if (s.model.kind == WaterModel::Flood && s.model.cfl > 0.5) {
      return r.error(*c, "model.cfl", "flood mode needs cfl <= 0.5 (positivity of the finite-volume scheme)");
    }
  }
  if (const auto* m = t->get("max_step")) {
    STRATA_TRY(s.model.maxStepS, r.quantity(*m, "model.max_step", "time"));
    if (s.model.maxStepS <= 0) return r.error(*m, "model.max_step", "must be positive");
  }
  if (const auto* l = t->get("slopes")) {
    STRATA_TRY(auto v, r.string(*l, "model.slopes"));
    if (v != "minmod" && v != "mc")
      return r.error(*l, "model.slopes", "expected \"minmod\" or \"mc\", got \"" + v + "\"");
    s.model.sharpSlopes = v == "mc";
  }
  if (const auto* b = t->get("boundary")) {
    auto parse = [&](const toml::node& n, const std::string& key) -> Result<Boundary> {
      STRATA_TRY(auto v, r.string(n, key));
      if (v == "open") return Boundary::Open;
      if (v == "closed") return Boundary::Closed;
      return r.error(n, key, "expected \"open\" or \"closed\", got \"" + v + "\"");
    };
    if (b->is_string()) {
      STRATA_TRY(auto all, parse(*b, "model.boundary"));
      s.model.boundaries = {all, all, all, all};
    } else if (const auto* bt = b->as_table()) {
      STRATA_TRY_STATUS(r.onlyKeys(*bt, "model.boundary", {"west", "east", "south", "north"}));
      const char* names[4] = {"west", "east", "south", "north"};
      for (int i = 0; i < 4; ++i) {
        if (const auto* e = bt->get(names[i])) {
          STRATA_TRY(s.model.boundaries[size_t(i)], parse(*e, std::string("model.boundary.") + names[i]));
        }
      }
    } else {
      return r.error(*b, "model.boundary", "expected \"open\", \"closed\" or { west = ..., east = ... }");
    }
  }
  return {};
}

Status readErosion(const Reader& r, const toml::table& root, Scenario& s) {
  const auto* t = root["erosion"].as_table();
  if (!t) return {};
  STRATA_TRY_STATUS(r.onlyKeys(
      *t, "erosion", {"enabled", "capacity", "erosion_rate", "deposition_rate", "dissolution_rate", "thermal"}));
  if (const auto* e = t->get("enabled")) {
    STRATA_TRY(s.erosion.enabled, r.boolean(*e, "erosion.enabled"));
  }
  if (const auto* e = t->get("thermal")) {
    STRATA_TRY(s.erosion.thermal, r.boolean(*e, "erosion.thermal"));
  }
  const std::pair<const char*, double*> numbers[] = {{"capacity", &s.erosion.capacity},
                                                     {"erosion_rate", &s.erosion.erosionRate},
                                                     {"deposition_rate", &s.erosion.depositionRate},
                                                     {"dissolution_rate", &s.erosion.dissolutionRate}};
  for (const auto& [name, out] : numbers) {
    if (const auto* n = t->get(name)) {
      STRATA_TRY(*out, r.number(*n, std::string("erosion.") + name));
      if (*out < 0) return r.error(*n, std::string("erosion.") + name, "must not be negative");
    }
  }
  return {};
}

Status readWater(const Reader& r, const toml::table& root, Scenario& s) {
  const auto* t = root["water"].as_table();
  if (!t) return {};
  STRATA_TRY_STATUS(r.onlyKeys(*t, "water", {"inflow", "rain", "dam_break", "level", "evaporation"}));
  if (const auto* e = t->get("evaporation")) {
    STRATA_TRY(s.water.evaporationMPerS, r.quantity(*e, "water.evaporation", "rate"));
    if (s.water.evaporationMPerS < 0) return r.error(*e, "water.evaporation", "must not be negative");
  }
  if (const auto* in = t->get("inflow")) {
    const auto* arr = in->as_array();
    if (!arr) return r.error(*in, "water.inflow", "expected [[water.inflow]] tables");
    for (size_t i = 0; i < arr->size(); ++i) {
      const std::string key = "water.inflow[" + std::to_string(i) + "]";
      const auto* it = (*arr)[i].as_table();
      if (!it) return r.error((*arr)[i], key, "expected a table");
      STRATA_TRY_STATUS(r.onlyKeys(
          *it, key, {"name", "at_lonlat", "at_xy", "line_lonlat", "line_xy", "hydrograph", "hydrograph_units"}));
      Inflow f;
      f.name = it->get("name") ? it->get("name")->value_or(std::string()) : "inflow " + std::to_string(i + 1);
      STRATA_TRY(auto at, r.placeKey(*it, key, "at", true));
      STRATA_TRY(auto line, r.placeKey(*it, key, "line", false));
      if (at && line) return r.errorAt(line->line, line->key, "give a point (at_...) or a line (line_...), not both");
      if (!at && !line)
        return r.errorAt(int(it->source().begin.line), key, "missing at_lonlat / at_xy / line_lonlat / line_xy");
      f.place = at ? *at : *line;
      if (line && line->points.size() < 2) return r.errorAt(line->line, line->key, "a line needs at least 2 points");
      STRATA_TRY(f.hydrograph, readHydrograph(r, *it, key));
      s.water.inflows.push_back(std::move(f));
    }
  }
  if (const auto* rn = t->get("rain")) {
    const auto* rt = rn->as_table();
    if (!rt) return r.error(*rn, "water.rain", "expected a table");
    STRATA_TRY_STATUS(r.onlyKeys(*rt, "water.rain", {"rate", "raster", "start", "end"}));
    Rain rain;
    if (!rt->get("rate")) return r.errorAt(int(rt->source().begin.line), "water.rain.rate", "missing");
    STRATA_TRY(rain.rateMPerS, r.quantity(*rt->get("rate"), "water.rain.rate", "rate"));
    if (rain.rateMPerS < 0) return r.error(*rt->get("rate"), "water.rain.rate", "must not be negative");
    if (const auto* ra = rt->get("raster")) {
      STRATA_TRY(auto p, r.string(*ra, "water.rain.raster"));
      rain.raster = r.path(p);
    }
    if (const auto* st = rt->get("start")) {
      STRATA_TRY(rain.startS, r.quantity(*st, "water.rain.start", "time"));
    }
    if (const auto* en = rt->get("end")) {
      STRATA_TRY(rain.endS, r.quantity(*en, "water.rain.end", "time"));
    }
    if (rain.startS < 0) return r.error(*rt->get("start"), "water.rain.start", "negative time");
    if (rt->get("end") && rain.endS <= rain.startS)
      return r.error(*rt->get("end"), "water.rain.end", "must be after start");
    s.water.rain = rain;
  }
  if (const auto* db = t->get("dam_break")) {
    const auto* arr = db->as_array();
    if (!arr) return r.error(*db, "water.dam_break", "expected [[water.dam_break]] tables");
    for (size_t i = 0; i < arr->size(); ++i) {
      const std::string key = "water.dam_break[" + std::to_string(i) + "]";
      const auto* dt = (*arr)[i].as_table();
      if (!dt) return r.error((*arr)[i], key, "expected a table");
      STRATA_TRY_STATUS(r.onlyKeys(*dt, key, {"polygon_lonlat", "polygon_xy", "surface"}));
      DamBreak d;
      STRATA_TRY(auto poly, r.placeKey(*dt, key, "polygon", false));
      if (!poly || poly->points.size() < 3)
        return r.errorAt(int(dt->source().begin.line), key + ".polygon_lonlat",
                         "a polygon of at least 3 points is needed");
      d.polygon = *poly;
      if (!dt->get("surface"))
        return r.errorAt(int(dt->source().begin.line), key + ".surface", "missing (water surface elevation)");
      STRATA_TRY(d.surfaceElevationM, r.quantity(*dt->get("surface"), key + ".surface", "length"));
      s.water.damBreaks.push_back(std::move(d));
    }
  }
  if (const auto* lv = t->get("level")) {
    const auto* arr = lv->as_array();
    if (!arr) return r.error(*lv, "water.level", "expected [[water.level]] tables");
    for (size_t i = 0; i < arr->size(); ++i) {
      const std::string key = "water.level[" + std::to_string(i) + "]";
      const auto* lt = (*arr)[i].as_table();
      if (!lt) return r.error((*arr)[i], key, "expected a table");
      STRATA_TRY_STATUS(r.onlyKeys(
          *lt, key, {"name", "line_lonlat", "line_xy", "polygon_lonlat", "polygon_xy", "stage", "stage_units"}));
      Level l;
      l.name = lt->get("name") ? lt->get("name")->value_or(std::string()) : "level " + std::to_string(i + 1);
      STRATA_TRY(auto line, r.placeKey(*lt, key, "line", false));
      STRATA_TRY(auto poly, r.placeKey(*lt, key, "polygon", false));
      if (line && poly) return r.errorAt(poly->line, poly->key, "give a line (line_...) or a polygon, not both");
      if (!line && !poly) {
        return r.errorAt(int(lt->source().begin.line), key,
                         "missing line_lonlat / line_xy / polygon_lonlat / polygon_xy");
      }
      if (line && line->points.size() < 2) return r.errorAt(line->line, line->key, "a line needs at least 2 points");
      if (poly && poly->points.size() < 3) return r.errorAt(poly->line, poly->key, "a polygon needs at least 3 points");
      l.place = line ? *line : *poly;
      l.polygon = bool(poly);
      STRATA_TRY(l.stage, readCurve(r, *lt, key, {"stage", "water surface elevation", "length", "m", false}));
      l.stageLine = int(lt->get("stage")->source().begin.line);
      s.water.levels.push_back(std::move(l));
    }
  }
  return {};
}

Status readTime(const Reader& r, const toml::table& root, Scenario& s) {
  const auto* t = root["time"].as_table();
  if (!t) return fail(r.file + ": missing [time] (duration = \"6 h\", output_interval = \"30 min\")");
  STRATA_TRY_STATUS(r.onlyKeys(*t, "time", {"duration", "output_interval"}));
  const auto* d = t->get("duration");
  if (!d) return r.errorAt(int(t->source().begin.line), "time.duration", "missing");
  STRATA_TRY(s.durationS, r.quantity(*d, "time.duration", "time"));
  if (s.durationS <= 0) return r.error(*d, "time.duration", "must be positive");
  s.outputIntervalS = s.durationS / 10;
  if (const auto* o = t->get("output_interval")) {
    STRATA_TRY(s.outputIntervalS, r.quantity(*o, "time.output_interval", "time"));
    if (s.outputIntervalS <= 0) return r.error(*o, "time.output_interval", "must be positive");
    if (s.outputIntervalS > s.durationS) return r.error(*o, "time.output_interval", "longer than the duration");
  }
  return {};
}

Status readOutputs(const Reader& r, const toml::table& root, Scenario& s) {
  const auto* t = root["outputs"].as_table();
  if (!t) return {};
  STRATA_TRY_STATUS(r.onlyKeys(*t, "outputs", {"maps", "wet_threshold", "pictures", "plots"}));
  if (const auto* m = t->get("maps")) {
    const auto* arr = m->as_array();
    if (!arr) return r.error(*m, "outputs.maps", "expected a list of map names");
    s.outputs.maps.clear();
    for (const auto& n : *arr) {
      STRATA_TRY(auto name, r.string(n, "outputs.maps"));
      const auto& known = knownOutputMaps();
      if (std::find(known.begin(), known.end(), name) == known.end()) {
        std::string list;
        for (const auto& k : known) list += (list.empty() ? "" : ", ") + k;
        return r.error(n, "outputs.maps", "unknown map \"" + name + "\" (known: " + list + ")");
      }
      s.outputs.maps.push_back(name);
    }
  }
  if (const auto* w = t->get("wet_threshold")) {
    STRATA_TRY(s.outputs.wetThresholdM, r.quantity(*w, "outputs.wet_threshold", "length"));
    if (s.outputs.wetThresholdM <= 0) return r.error(*w, "outputs.wet_threshold", "must be positive");
  }
  if (const auto* p = t->get("pictures")) {
    STRATA_TRY(s.outputs.pictures, r.boolean(*p, "outputs.pictures"));
  }
  if (const auto* p = t->get("plots")) {
    STRATA_TRY(s.outputs.plots, r.boolean(*p, "outputs.plots"));
  }
  return {};
}

}  // namespace

const std::vector<std::string>& knownOutputMaps() {
  static const std::vector<std::string> kMaps{"max_depth",           "max_speed",   "arrival_time",
                                              "inundation_duration", "final_depth", "terrain_change"};
  return kMaps;
}

Result<double> parseQuantity(std::string_view text, std::string_view dimension) {
  const auto begin = text.find_first_not_of(" \t");
  if (begin == std::string_view::npos) return fail("empty value");
  text.remove_prefix(begin);
  double value = 0;
  const auto [end, ec] = std::from_chars(text.data(), text.data() + text.size(), value);
  if (ec != std::errc() || !std::isfinite(value))
    return fail("\"" + std::string(text) + "\" does not start with a number");
  std::string_view unit(end, size_t(text.data() + text.size() - end));
  while (!unit.empty() && (unit.front() == ' ' || unit.front() == '\t')) unit.remove_prefix(1);
  while (!unit.empty() && (unit.back() == ' ' || unit.back() == '\t')) unit.remove_suffix(1);
  if (unit.empty()) return fail("\"" + std::string(text) + "\" has no unit (use one of " + unitsOf(dimension) + ")");
  for (const auto& u : kUnits) {
    if (unit == u.name && dimension == u.dimension) return value * u.toSi;
  }
  for (const auto& u : kUnits) {
    if (unit == u.name) {
      return fail("unit '" + std::string(unit) + "' is a " + u.dimension + ", not a " + std::string(dimension) +
                  " (use one of " + unitsOf(dimension) + ")");
    }
  }
  return fail("unknown unit '" + std::string(unit) + "' (use one of " + unitsOf(dimension) + ")");
}

double Hydrograph::at(double t) const {
  if (points.empty() || t < points.front()[0] || t > points.back()[0]) return 0;
  for (size_t i = 1; i < points.size(); ++i) {
    if (t <= points[i][0]) {
      const double a = (t - points[i - 1][0]) / (points[i][0] - points[i - 1][0]);
      return points[i - 1][1] + a * (points[i][1] - points[i - 1][1]);
    }
  }
  return points.back()[1];
}

double Hydrograph::volume(double t0, double t1) const {
  if (points.size() < 2 || t1 <= t0) return 0;
  double v = 0;
  for (size_t i = 1; i < points.size(); ++i) {
    const double a = std::max(t0, points[i - 1][0]), b = std::min(t1, points[i][0]);
    if (b > a) v += 0.5 * (at(a) + at(b)) * (b - a);  // trapezoid is exact on a linear piece
  }
  return v;
}

Result<Scenario> parseScenario(std::string_view text, const std::filesystem::path& fileName) {
  Reader r{fileName.string(), fileName.parent_path()};
  toml::table root;
  try {
    root = toml::parse(text, fileName.string());
  } catch (const toml::parse_error& e) {
    return fail(r.file + ":" + std::to_string(e.source().begin.line) + ": " + std::string(e.description()));
  }
  STRATA_TRY_STATUS(r.onlyKeys(
      root, "", {"name", "description", "terrain", "region", "model", "erosion", "water", "time", "outputs"}));
  Scenario s;
  s.file = fileName;
  if (const auto* n = root.get("name")) {
    STRATA_TRY(s.name, r.string(*n, "name"));
  }
  if (const auto* d = root.get("description")) {
    STRATA_TRY(s.description, r.string(*d, "description"));
  }
  if (s.name.empty()) s.name = fileName.stem().string();
  STRATA_TRY_STATUS(readTerrain(r, root, s));
  STRATA_TRY_STATUS(readRegion(r, root, s));
  STRATA_TRY_STATUS(readModel(r, root, s));
  STRATA_TRY_STATUS(readErosion(r, root, s));
  STRATA_TRY_STATUS(readWater(r, root, s));
  STRATA_TRY_STATUS(readTime(r, root, s));
  STRATA_TRY_STATUS(readOutputs(r, root, s));
  if (s.water.inflows.empty() && !s.water.rain && s.water.damBreaks.empty() && s.water.levels.empty()) {
    return fail(r.file + ": [water] has no source: add an inflow, rain, a dam_break or a level");
  }
  if (std::find(s.outputs.maps.begin(), s.outputs.maps.end(), "terrain_change") != s.outputs.maps.end() &&
      !s.erosion.enabled) {
    return fail(r.file + ": outputs.maps asks for terrain_change but erosion is not enabled");
  }
  return s;
}

Result<Scenario> loadScenario(const std::filesystem::path& file) {
  std::error_code ec;
  if (!std::filesystem::is_regular_file(file, ec)) return fail(file.string() + ": no such scenario file");
  std::ifstream in(file);
  std::stringstream ss;
  ss << in.rdbuf();
  if (!in && !in.eof()) return fail(file.string() + ": cannot read");
  return parseScenario(ss.str(), file);
}

}  // namespace strata::terrain
