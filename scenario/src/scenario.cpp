#include <strata/scenario/scenario.hpp>

#include <toml++/toml.h>

#include <algorithm>
#include <cctype>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <limits>
#include <map>
#include <set>
#include <sstream>

#include <strata/core/files.hpp>
#include <strata/core/progress.hpp>
#include <strata/core/toml_screen.hpp>

namespace strata::scenario {
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
    {"cm/s", "speed", 1e-2},
    {"mm/s", "speed", 1e-3},
    {"Pa", "stress", 1.0},
    {"kPa", "stress", 1e3},
    {"MPa", "stress", 1e6},
};

std::string unitsOf(std::string_view dimension) {
  std::string out;
  for (const auto& u : kUnits) {
    if (dimension == u.dimension) out += (out.empty() ? "" : ", ") + std::string(u.name);
  }
  return out;
}

// What a number may be: [lo, hi] (lo excluded when loOpen), `hiText` the upper bound as a user
// writes it ("10 km"). Every number is also checked finite (TOML has nan and inf literals).
struct Range {
  double lo = -std::numeric_limits<double>::infinity();
  double hi = std::numeric_limits<double>::infinity();
  bool loOpen = false;
  const char* hiText = "";
};
constexpr Range kAny{};
constexpr Range kPositive{0, std::numeric_limits<double>::infinity(), true, ""};

// What `v` (outside `r`) violates: "must be positive", "must not be negative", "must be at most 10 km".
std::string rangeText(const Range& r, double v) {
  if (v > r.hi) return std::string("must be at most ") + r.hiText;
  if (r.lo == 0) return r.loOpen ? "must be positive" : "must not be negative";
  return std::string("must be at least -") + r.hiText;
}

bool inRange(double v, const Range& r) { return (r.loOpen ? v > r.lo : v >= r.lo) && v <= r.hi; }

// "nan", "inf", "-inf" as TOML writes them.
std::string nonFinite(double v) { return std::isnan(v) ? "nan" : (v > 0 ? "inf" : "-inf"); }

// Levenshtein distance, for "did you mean".
size_t editDistance(const std::string& a, const std::string& b) {
  std::vector<size_t> row(b.size() + 1);
  for (size_t j = 0; j <= b.size(); ++j) row[j] = j;
  for (size_t i = 1; i <= a.size(); ++i) {
    size_t diagonal = row[0];
    row[0] = i;
    for (size_t j = 1; j <= b.size(); ++j) {
      const size_t up = row[j];
      row[j] = std::min({row[j] + 1, row[j - 1] + 1, diagonal + (a[i - 1] == b[j - 1] ? 0 : 1)});
      diagonal = up;
    }
  }
  return row[b.size()];
}

// Errors carry "file:line: key 'path': message". Every key read is recorded with its line
// (Scenario::keyLines) for checks that come later.
struct Reader {
  std::string file;
  std::filesystem::path baseDir;
  std::map<std::string, int>* lines = nullptr;

  void note(const toml::node& node, const std::string& key) const {
    if (lines) lines->emplace(key, int(node.source().begin.line));
  }
  Error error(const toml::node& node, const std::string& key, const std::string& message) const {
    return errorAt(int(node.source().begin.line), key, message);
  }
  Error errorAt(int line, const std::string& key, const std::string& message) const {
    return fail(file + ":" + std::to_string(line) + ": key '" + oneLine(key) + "': " + oneLine(message));
  }

  // Refuses keys outside `allowed` (catches typos such as "duraton").
  Status onlyKeys(const toml::table& table, const std::string& prefix,
                  std::initializer_list<const char*> allowed) const {
    if (!prefix.empty()) note(table, prefix);
    for (auto&& [k, v] : table) {
      const std::string key(k.str());
      if (std::none_of(allowed.begin(), allowed.end(), [&](const char* a) { return key == a; })) {
        std::string list, nearest;
        size_t nearestDistance = 3;  // a near miss: at most 2 edits from an allowed key the table lacks
        for (const char* a : allowed) {
          list += (list.empty() ? "" : ", ") + std::string(a);
          const size_t d = editDistance(key, a);
          if (d < nearestDistance && !table.contains(a)) nearest = a, nearestDistance = d;
        }
        return error(v, prefix.empty() ? key : prefix + "." + key,
                     "unknown key (expected one of: " + list + ")" +
                         (nearest.empty() ? std::string() : "; did you mean '" + nearest + "'?"));
      }
    }
    return {};
  }

  // A finite value within `range`.
  Status check(const toml::node& node, const std::string& key, double v, const Range& range) const {
    if (!std::isfinite(v)) return error(node, key, "not a finite number (" + nonFinite(v) + ")");
    if (!inRange(v, range)) return error(node, key, rangeText(range, v));
    return {};
  }

  Result<double> quantity(const toml::node& node, const std::string& key, std::string_view dimension,
                          const Range& range = kAny) const {
    note(node, key);
    double v = 0;
    if (auto n = node.value<double>(); n && (node.is_integer() || node.is_floating_point())) {
      v = *n;
    } else if (auto s = node.value<std::string>()) {
      auto q = parseQuantity(*s, dimension);
      if (!q) return error(node, key, q.message());
      v = *q;
    } else {
      return error(node, key,
                   "expected a " + std::string(dimension) + " such as \"10 " +
                       std::string(unitsOf(dimension).substr(0, unitsOf(dimension).find(','))) + "\"");
    }
    STRATA_TRY_STATUS(check(node, key, v, range));
    return v;
  }

  Result<double> number(const toml::node& node, const std::string& key, const Range& range = kAny) const {
    note(node, key);
    auto n = node.value<double>();
    if (!n || !(node.is_integer() || node.is_floating_point())) return error(node, key, "expected a number");
    STRATA_TRY_STATUS(check(node, key, *n, range));
    return *n;
  }

  Result<std::string> string(const toml::node& node, const std::string& key) const {
    note(node, key);
    if (auto s = node.value<std::string>()) return *s;
    return error(node, key, "expected a string");
  }

  Result<bool> boolean(const toml::node& node, const std::string& key) const {
    note(node, key);
    if (auto b = node.value<bool>()) return *b;
    return error(node, key, "expected true or false");
  }

  std::string path(const std::string& p) const {
    const std::filesystem::path fp(p);
    return (fp.is_absolute() ? fp : (baseDir / fp)).lexically_normal().string();
  }

  // [x, y] pairs: a single pair or an array of pairs, finite; lon/lat in range.
  Result<Place> place(const toml::node& node, const std::string& key, CoordFrame frame, bool single) const {
    note(node, key);
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
      const std::array<double, 2> xy{(*p)[0].value<double>().value(), (*p)[1].value<double>().value()};
      for (double v : xy) {
        if (!std::isfinite(v)) return error(n, key, "not a finite number (" + nonFinite(v) + ")");
      }
      return xy;
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
// unit] (defaults "s" and `valueUnit`); times strictly increasing and not negative, values finite
// and within `range` (in SI units).
struct CurveSpec {
  const char* key;        // "hydrograph", "stage"
  const char* valueName;  // "discharge", "water surface elevation"
  const char* dimension;  // of the value, for parseQuantity
  const char* valueUnit;  // default unit of the value
  Range range;            // of the value in SI units
};

Result<TimeSeries> readCurve(const Reader& r, const toml::table& t, const std::string& prefix, const CurveSpec& c) {
  const std::string key = prefix + "." + c.key, unitsKey = key + "_units";
  const std::string pairText = std::string("[time, ") + c.valueName + "]";
  const auto* pts = t.get(c.key);
  if (!pts) return r.errorAt(int(t.source().begin.line), key, "missing (pairs " + pairText + ")");
  r.note(*pts, key);
  std::string timeUnit = "s", valueUnit = c.valueUnit;
  const auto* u = t.get(std::string(c.key) + "_units");
  if (u) {
    r.note(*u, unitsKey);
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
  std::vector<TimeSeries::Sample> out;
  for (const auto& n : *arr) {
    const auto* p = n.as_array();
    if (!p || p->size() != 2 || !(*p)[0].is_number() || !(*p)[1].is_number()) {
      return r.error(n, key, "expected a pair " + pairText + " of numbers");
    }
    const double rawT = (*p)[0].value<double>().value(), rawV = (*p)[1].value<double>().value();
    for (double raw : {rawT, rawV}) {
      if (!std::isfinite(raw)) return r.error(n, key, "not a finite number (" + nonFinite(raw) + ")");
    }
    const double ts = rawT * *tScale, v = rawV * *vScale;
    if (!std::isfinite(ts) || !std::isfinite(v)) return r.error(n, key, "not a finite number once in SI units");
    if (c.range.lo == 0 && v < 0) {
      return r.error(n, key, std::string("negative ") + c.valueName + " " + std::to_string(v) + " " + c.valueUnit);
    }
    if (!inRange(v, c.range)) return r.error(n, key, std::string("a ") + c.valueName + " " + rangeText(c.range, v));
    if (!out.empty() && ts <= out.back()[0]) return r.error(n, key, "times must increase strictly");
    if (ts < 0) return r.error(n, key, "negative time");
    out.push_back({ts, v});
  }
  return TimeSeries(std::move(out));
}

// Bounds of what a scenario may ask for (docs/scenario.md, "Ranges"): finite, physically
// meaningful, and small enough that every derived quantity (float depths, step counts) is too.
constexpr Range kThickness{0, 1e4, false, "10 km"};
constexpr Range kElevation{-1e5, 1e5, false, "100 km"};  // water surfaces: any body's relief is within
constexpr Range kDischarge{0, 1e8, false, "1e8 m3/s"};
constexpr Range kRate{0, 10.0 / 3600, false, "10 m/h"};  // rain, evaporation
constexpr Range kManning{0, 1, false, "1"};
constexpr Range kMaxStep{0, 86400, true, "1 d"};
constexpr Range kErosionConstant{0, 100, false, "100"};
constexpr Range kStress{0, 1e7, false, "10 MPa"};  // critical shear stress
constexpr Range kCohesion{0, 1e9, false, "1000 MPa"};
constexpr Range kShearErodibility{0, 1e-2, false, "0.01 m/(s Pa)"};
constexpr Range kSettling{0, 10, false, "10 m/s"};
constexpr Range kAngle{0, 89.9, true, "89.9 degrees"};
constexpr Range kPerSecond{0, 1e3, false, "1000 per second"};
constexpr Range kDuration{0, 3650 * 86400.0, true, "3650 d"};
constexpr Range kSpinUp{0, 365 * 86400.0, false, "365 d"};
constexpr Range kSpinUpTolerance{0, 0.5, true, "0.5"};
constexpr Range kWetThreshold{0, 100, true, "100 m"};

Result<TimeSeries> readHydrograph(const Reader& r, const toml::table& t, const std::string& prefix) {
  return readCurve(r, t, prefix, {"hydrograph", "discharge", "discharge", "m3/s", kDischarge});
}

Status readTerrain(const Reader& r, const toml::table& root, Scenario& s) {
  const auto* t = root["terrain"].as_table();
  if (!t) return fail(r.file + ": missing [terrain] (dem = \"file.tif\" or store = \"folder\")");
  STRATA_TRY_STATUS(r.onlyKeys(
      *t, "terrain",
      {"dem", "store", "layer", "breach_inflows", "fill_depressions", "voids", "assign_crs", "assign_geotransform"}));
  if (const auto* b = t->get("breach_inflows")) {
    STRATA_TRY(s.terrain.breachInflows, r.boolean(*b, "terrain.breach_inflows"));
  }
  if (const auto* f = t->get("fill_depressions")) {
    STRATA_TRY(s.terrain.fillDepressions, r.boolean(*f, "terrain.fill_depressions"));
  }
  if (const auto* v = t->get("voids")) {
    STRATA_TRY(auto mode, r.string(*v, "terrain.voids"));
    using V = decltype(s.terrain)::Voids;
    if (mode == "refuse")
      s.terrain.voids = V::kRefuse;
    else if (mode == "fill")
      s.terrain.voids = V::kFill;
    else if (mode == "walls")
      s.terrain.voids = V::kWalls;
    else if (mode == "holes")
      s.terrain.voids = V::kHoles;
    else
      return r.error(*v, "terrain.voids", "\"" + mode + "\": expected \"refuse\", \"fill\", \"walls\" or \"holes\"");
  }
  if (const auto* d = t->get("dem")) {
    if (d->is_string()) {
      STRATA_TRY(auto one, r.string(*d, "terrain.dem"));
      s.terrain.dems.push_back(r.path(one));
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
  if (const auto* c = t->get("assign_crs")) {
    if (!s.terrain.store.empty()) return r.error(*c, "terrain.assign_crs", "a tile store has its own CRS");
    STRATA_TRY(auto crs, r.string(*c, "terrain.assign_crs"));
    if (crs.empty()) return r.error(*c, "terrain.assign_crs", "empty (expected EPSG:n, WKT or PROJ text)");
    s.terrain.assignCrs = crs;
  }
  if (const auto* g = t->get("assign_geotransform")) {
    const std::string key = "terrain.assign_geotransform";
    if (!s.terrain.store.empty()) return r.error(*g, key, "a tile store has its own geotransform");
    const auto* a = g->as_array();
    if (!a || a->size() != 6) {
      return r.error(*g, key, "expected GDAL's six coefficients [x0, dx, rx, y0, ry, dy]");
    }
    std::array<double, 6> c{};
    for (size_t i = 0; i < 6; ++i) {
      STRATA_TRY(c[i], r.number((*a)[i], key));
    }
    if (c[1] * c[5] - c[2] * c[4] == 0) return r.error(*g, key, "the cell size is zero (dx * dy - rx * ry = 0)");
    s.terrain.assignGeotransform = c;
  }
  if (const auto* layers = t->get("layer")) {
    const auto* arr = layers->as_array();
    if (!arr) return r.error(*layers, "terrain.layer", "expected [[terrain.layer]] tables");
    for (size_t i = 0; i < arr->size(); ++i) {
      const std::string key = "terrain.layer[" + std::to_string(i) + "]";
      const auto* lt = (*arr)[i].as_table();
      if (!lt) return r.error((*arr)[i], key, "expected a table");
      STRATA_TRY_STATUS(r.onlyKeys(*lt, key, {"material", "thickness", "raster", "at_rest"}));
      LayerSpec l;
      if (!lt->get("material")) return r.error(*lt, key + ".material", "missing");
      STRATA_TRY(l.material, r.string(*lt->get("material"), key + ".material"));
      if (const auto* th = lt->get("thickness")) {
        STRATA_TRY(l.thicknessM, r.quantity(*th, key + ".thickness", "length"));
        if (l.thicknessM < 0) return r.error(*th, key + ".thickness", "negative thickness");
        STRATA_TRY_STATUS(r.check(*th, key + ".thickness", l.thicknessM, kThickness));
      }
      if (const auto* ar = lt->get("at_rest")) {
        STRATA_TRY(l.atRest, r.boolean(*ar, key + ".at_rest"));
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
    r.note(node, key);
    const double w = (*a)[0].value<double>().value(), so = (*a)[1].value<double>().value(),
                 e = (*a)[2].value<double>().value(), n = (*a)[3].value<double>().value();
    for (double v : {w, so, e, n}) {
      if (!std::isfinite(v)) return r.error(node, key, "not a finite number (" + nonFinite(v) + ")");
    }
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
    STRATA_TRY(s.region.cellSizeM, r.quantity(*c, "region.cell_size", "length", kPositive));
  }
  return {};
}

Status readModel(const Reader& r, const toml::table& root, Scenario& s) {
  const auto* t = root["model"].as_table();
  if (!t) return {};
  STRATA_TRY_STATUS(r.onlyKeys(*t, "model",
                               {"kind", "scheme", "local_steps", "manning_n", "manning_raster", "land_cover", "cfl",
                                "max_step", "slopes", "boundary", "backend"}));
  if (const auto* m = t->get("manning_raster")) {
    STRATA_TRY(auto path, r.string(*m, "model.manning_raster"));
    s.model.manningRaster = r.path(path);
  }
  if (const auto* lc = t->get("land_cover")) {
    const auto* lt = lc->as_table();
    if (!lt) return r.error(*lc, "model.land_cover", "expected a table (raster = \"landcover.tif\", manning = {...})");
    STRATA_TRY_STATUS(r.onlyKeys(*lt, "model.land_cover", {"raster", "manning"}));
    if (!lt->get("raster")) return r.errorAt(int(lt->source().begin.line), "model.land_cover.raster", "missing");
    STRATA_TRY(auto path, r.string(*lt->get("raster"), "model.land_cover.raster"));
    s.model.landCoverRaster = r.path(path);
    const auto* table = lt->get("manning") ? lt->get("manning")->as_table() : nullptr;
    if (!table || table->empty()) {
      return r.errorAt(int(lt->source().begin.line), "model.land_cover.manning",
                       "missing: Manning's n per class code, e.g. manning = { 10 = 0.1, 30 = 0.035, 80 = 0.03 }");
    }
    for (auto&& [k, v] : *table) {
      const std::string key = "model.land_cover.manning." + std::string(k.str());
      long long code = 0;
      const auto [end, ec] = std::from_chars(k.str().data(), k.str().data() + k.str().size(), code);
      if (ec != std::errc() || end != k.str().data() + k.str().size()) {
        return r.error(v, key,
                       "a class code is a whole number (the raster's value), got \"" + std::string(k.str()) + "\"");
      }
      STRATA_TRY(const double n, r.number(v, key, kManning));
      s.model.landCoverManning[code] = n;
    }
  }
  if (!s.model.manningRaster.empty() && !s.model.landCoverRaster.empty()) {
    return r.errorAt(s.keyLines.count("model.land_cover") ? s.keyLines.at("model.land_cover") : 0, "model.land_cover",
                     "give either manning_raster or land_cover, not both");
  }
  if (const auto* k = t->get("kind")) {
    STRATA_TRY(auto v, r.string(*k, "model.kind"));
    if (v == "flood") {
      s.model.kind = sim::WaterModel::kFiniteVolume;
    } else if (v == "pipe") {
      s.model.kind = sim::WaterModel::kVirtualPipes;
    } else {
      return r.error(*k, "model.kind", "expected \"flood\" or \"pipe\", got \"" + v + "\"");
    }
  }
  if (const auto* sc = t->get("scheme")) {
    STRATA_TRY(auto v, r.string(*sc, "model.scheme"));
    if (v != "finite_volume" && v != "inertial") {
      return r.error(*sc, "model.scheme", "expected \"finite_volume\" or \"inertial\", got \"" + v + "\"");
    }
    if (s.model.kind != sim::WaterModel::kFiniteVolume) {
      return r.error(*sc, "model.scheme", "is flood mode's choice; kind = \"pipe\" has no scheme");
    }
    s.model.inertial = v == "inertial";
    if (s.model.inertial) s.model.cfl = 0.7;  // Bates et al. (2010)'s alpha, unless cfl says otherwise
  }
  if (const auto* b = t->get("backend")) {
    STRATA_TRY(auto v, r.string(*b, "model.backend"));
    auto backend = parseBackend(v);
    if (!backend) return r.error(*b, "model.backend", backend.message());
    s.model.backend = *backend;
  }
  if (const auto* l = t->get("local_steps")) {
    STRATA_TRY(s.model.localSteps, r.boolean(*l, "model.local_steps"));
    if (s.model.localSteps && !s.model.inertial) {
      return r.error(*l, "model.local_steps", "local time steps need scheme = \"inertial\"");
    }
    if (s.model.localSteps && s.model.backend == Backend::kGpu) {
      return r.error(*l, "model.local_steps",
                     "local time steps run on the CPU backend; backend = \"gpu\" takes one step for the whole grid");
    }
  }
  if (const auto* n = t->get("manning_n")) {
    STRATA_TRY(s.model.manningN, r.number(*n, "model.manning_n"));
    if (!inRange(s.model.manningN, kManning)) {
      return r.error(*n, "model.manning_n", "Manning's n in s/m^(1/3) is between 0 and ~0.2 for natural channels");
    }
  }
  if (const auto* c = t->get("cfl")) {
    STRATA_TRY(s.model.cfl, r.number(*c, "model.cfl"));
    if (!(s.model.cfl > 0 && s.model.cfl <= 1)) return r.error(*c, "model.cfl", "must be in (0, 1]");
    if (s.model.kind == sim::WaterModel::kFiniteVolume && !s.model.inertial && s.model.cfl > 0.5) {
      return r.error(*c, "model.cfl", "flood mode needs cfl <= 0.5 (positivity of the finite-volume scheme)");
    }
  }
  if (const auto* m = t->get("max_step")) {
    STRATA_TRY(s.model.maxStepS, r.quantity(*m, "model.max_step", "time", kMaxStep));
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
      *t, "erosion", {"enabled", "law", "capacity", "erosion_rate", "deposition_rate", "dissolution_rate", "thermal"}));
  if (const auto* e = t->get("enabled")) {
    STRATA_TRY(s.erosion.enabled, r.boolean(*e, "erosion.enabled"));
  }
  if (const auto* e = t->get("thermal")) {
    STRATA_TRY(s.erosion.thermal, r.boolean(*e, "erosion.thermal"));
  }
  if (const auto* e = t->get("law")) {
    STRATA_TRY(auto law, r.string(*e, "erosion.law"));
    if (law == "shear") {
      s.erosion.law = sim::ErosionLaw::kShearStress;
    } else if (law == "force-based") {
      s.erosion.law = sim::ErosionLaw::kForceBased;
    } else {
      return r.error(*e, "erosion.law", "\"" + oneLine(law) + "\" is not \"shear\" or \"force-based\"");
    }
  }
  // Dissolution is a material's constant (E4), as every rate of the shear-stress law is.
  if (const auto* e = t->get("dissolution_rate")) {
    return r.error(*e, "erosion.dissolution_rate",
                   "dissolution is a material's constant: set dissolution_rate in [materials.NAME] "
                   "(docs/scenario.md)");
  }
  const std::pair<const char*, double*> numbers[] = {{"capacity", &s.erosion.capacity},
                                                     {"erosion_rate", &s.erosion.erosionRate},
                                                     {"deposition_rate", &s.erosion.depositionRate}};
  for (const auto& [name, out] : numbers) {
    if (const auto* n = t->get(name)) {
      const std::string key = std::string("erosion.") + name;
      if (s.erosion.law != sim::ErosionLaw::kForceBased) {
        return r.error(*n, key,
                       "belongs to law = \"force-based\"; the shear-stress law takes its constants from the "
                       "materials ([materials.NAME], docs/scenario.md)");
      }
      STRATA_TRY(*out, r.number(*n, key, kErosionConstant));
    }
  }
  return {};
}

// [materials.NAME]: a material's constants changed for this run.
Status readMaterials(const Reader& r, const toml::table& root, Scenario& s) {
  const auto* node = root.get("materials");
  if (!node) return {};
  const auto* t = node->as_table();
  if (!t) return r.error(*node, "materials", "expected tables [materials.NAME]");
  for (auto&& [name, v] : *t) {
    const std::string key = "materials." + std::string(name.str());
    const auto* mt = v.as_table();
    if (!mt) return r.error(v, key, "expected a table of the material's constants");
    STRATA_TRY_STATUS(r.onlyKeys(*mt, key,
                                 {"critical_shear", "shear_erodibility", "settling_velocity", "friction_angle",
                                  "cohesion", "talus_angle", "weathering_rate", "dissolution_rate", "erodibility"}));
    Scenario::MaterialChange c;
    c.name = std::string(name.str());
    struct Field {
      const char* key;
      std::optional<double> Scenario::MaterialChange::*out;
      const char* dimension;  // nullptr: a bare number
      Range range;
    };
    const Field fields[] = {
        {"critical_shear", &Scenario::MaterialChange::criticalShearPa, "stress", kStress},
        {"shear_erodibility", &Scenario::MaterialChange::shearErodibility, nullptr, kShearErodibility},
        {"settling_velocity", &Scenario::MaterialChange::settlingVelocityMS, "speed", kSettling},
        {"friction_angle", &Scenario::MaterialChange::frictionAngleDeg, nullptr, kAngle},
        {"cohesion", &Scenario::MaterialChange::cohesionPa, "stress", kCohesion},
        {"talus_angle", &Scenario::MaterialChange::talusAngleDeg, nullptr, kAngle},
        {"weathering_rate", &Scenario::MaterialChange::weatheringRatePerS, nullptr, kPerSecond},
        {"dissolution_rate", &Scenario::MaterialChange::dissolutionRate, nullptr, kPerSecond},
        {"erodibility", &Scenario::MaterialChange::erodibility, nullptr, kErosionConstant},
    };
    for (const auto& f : fields) {
      const auto* n = mt->get(f.key);
      if (!n) continue;
      const std::string k = key + "." + f.key;
      if (f.dimension) {
        STRATA_TRY(c.*f.out, r.quantity(*n, k, f.dimension, f.range));
      } else {
        STRATA_TRY(c.*f.out, r.number(*n, k, f.range));
      }
    }
    s.materials.push_back(std::move(c));
  }
  return {};
}

// [water.infiltration]: model = "constant" with rate, or "green_ampt" with conductivity, suction
// and moisture_deficit; raster (mm/h) optional for either.
Result<Scenario::Infiltration> readInfiltration(const Reader& r, const toml::node& node) {
  const std::string key = "water.infiltration";
  const auto* t = node.as_table();
  if (!t) return r.error(node, key, "expected a table (model = \"constant\", rate = \"5 mm/h\")");
  const auto* model = t->get("model");
  if (!model) return r.errorAt(int(t->source().begin.line), key + ".model", "missing: \"constant\" or \"green_ampt\"");
  STRATA_TRY(const std::string name, r.string(*model, key + ".model"));
  Scenario::Infiltration f;
  if (name == "constant") {
    STRATA_TRY_STATUS(r.onlyKeys(*t, key, {"model", "rate", "raster"}));
  } else if (name == "green_ampt") {
    f.greenAmpt = true;
    STRATA_TRY_STATUS(r.onlyKeys(*t, key, {"model", "conductivity", "suction", "moisture_deficit", "raster"}));
  } else {
    return r.error(*model, key + ".model", "\"" + name + "\": expected \"constant\" or \"green_ampt\"");
  }
  // A soil's Ks is under ~1 m/h (gravel); suction heads under ~10 m (clay's are ~0.3 m).
  constexpr Range kSoilRate{0, 1.0 / 3600, false, "1 m/h"};
  constexpr Range kSuction{0, 10, false, "10 m"};
  constexpr Range kDeficit{0, 1, false, "1"};
  auto need = [&](const char* k, const char* what) -> Result<const toml::node*> {
    if (const auto* n = t->get(k)) return n;
    return r.errorAt(int(t->source().begin.line), key + "." + k, std::string("missing: ") + what);
  };
  if (!f.greenAmpt) {
    STRATA_TRY(const auto* n, need("rate", "the loss rate, e.g. \"5 mm/h\""));
    STRATA_TRY(f.rateMPerS, r.quantity(*n, key + ".rate", "rate", kSoilRate));
  } else {
    STRATA_TRY(const auto* k, need("conductivity", "the saturated hydraulic conductivity Ks, e.g. \"10.9 mm/h\""));
    STRATA_TRY(f.rateMPerS, r.quantity(*k, key + ".conductivity", "rate", kSoilRate));
    STRATA_TRY(const auto* p, need("suction", "the wetting-front suction head, e.g. \"110 mm\""));
    STRATA_TRY(f.suctionM, r.quantity(*p, key + ".suction", "length", kSuction));
    STRATA_TRY(const auto* d, need("moisture_deficit", "porosity minus the initial water content, e.g. 0.3"));
    STRATA_TRY(f.moistureDeficit, r.number(*d, key + ".moisture_deficit", kDeficit));
  }
  if (const auto* ra = t->get("raster")) {
    STRATA_TRY(auto p, r.string(*ra, key + ".raster"));
    f.raster = r.path(p);
  }
  return f;
}

// [water.rain] frames = [["0 min", "radar_0000.tif"], ...]: times from 0, increasing, within the run.
Result<std::vector<Rain::Frame>> readRainFrames(const Reader& r, const toml::node& node, double durationS) {
  const std::string key = "water.rain.frames";
  r.note(node, key);
  const auto* arr = node.as_array();
  if (!arr || arr->empty()) return r.error(node, key, "expected [[time, \"raster.tif\"], ...] (rain in mm/h)");
  std::vector<Rain::Frame> out;
  for (size_t i = 0; i < arr->size(); ++i) {
    const std::string k = key + "[" + std::to_string(i) + "]";
    const auto* pair = (*arr)[i].as_array();
    if (!pair || pair->size() != 2) return r.error((*arr)[i], k, "expected [time, \"raster.tif\"]");
    Rain::Frame f;
    STRATA_TRY(f.timeS, r.quantity(*pair->get(0), k, "time"));
    STRATA_TRY(const std::string path, r.string(*pair->get(1), k));
    f.raster = r.path(path);
    if (f.timeS < 0) return r.error(*pair->get(0), k, "negative time");
    if (!out.empty() && f.timeS <= out.back().timeS) return r.error(*pair->get(0), k, "not after the frame before it");
    if (f.timeS >= durationS) {
      return r.error(*pair->get(0), k, "after the run ends (time.duration is " + formatDuration(durationS) + ")");
    }
    out.push_back(std::move(f));
  }
  return out;
}

Status readWater(const Reader& r, const toml::table& root, Scenario& s) {
  const auto* t = root["water"].as_table();
  if (!t) return {};
  STRATA_TRY_STATUS(r.onlyKeys(*t, "water", {"inflow", "rain", "dam_break", "level", "evaporation", "infiltration"}));
  if (const auto* e = t->get("evaporation")) {
    STRATA_TRY(s.water.evaporationMPerS, r.quantity(*e, "water.evaporation", "rate", kRate));
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
      f.name = "inflow " + std::to_string(i + 1);
      if (const auto* n = it->get("name")) {
        STRATA_TRY(f.name, r.string(*n, key + ".name"));
      }
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
    STRATA_TRY_STATUS(r.onlyKeys(*rt, "water.rain", {"rate", "raster", "start", "end", "frames"}));
    Rain rain;
    if (const auto* fr = rt->get("frames")) {
      STRATA_TRY(rain.frames, readRainFrames(r, *fr, s.durationS));
      for (const char* k : {"rate", "raster", "start"}) {
        if (const auto* n = rt->get(k)) {
          return r.error(*n, std::string("water.rain.") + k,
                         "the frames carry the rain: no rate, raster or start beside them");
        }
      }
    } else if (!rt->get("rate")) {
      return r.errorAt(int(rt->source().begin.line), "water.rain.rate", "missing (or give frames)");
    } else {
      STRATA_TRY(rain.rateMPerS, r.quantity(*rt->get("rate"), "water.rain.rate", "rate", kRate));
    }
    if (const auto* ra = rt->get("raster")) {
      STRATA_TRY(auto p, r.string(*ra, "water.rain.raster"));
      rain.raster = r.path(p);
    }
    if (const auto* st = rt->get("start")) {
      STRATA_TRY(rain.startS, r.quantity(*st, "water.rain.start", "time"));
      if (rain.startS < 0) return r.error(*st, "water.rain.start", "negative time");
      if (rain.startS >= s.durationS) {
        return r.error(*st, "water.rain.start",
                       "the rain starts after the run ends (time.duration is " + formatDuration(s.durationS) + ")");
      }
    }
    if (const auto* en = rt->get("end")) {
      STRATA_TRY(rain.endS, r.quantity(*en, "water.rain.end", "time"));
    }
    if (rt->get("end") && rain.endS <= rain.startS)
      return r.error(*rt->get("end"), "water.rain.end", "must be after start");
    if (rt->get("end") && !rain.frames.empty() && rain.endS <= rain.frames.back().timeS)
      return r.error(*rt->get("end"), "water.rain.end", "must be after the last frame's time");
    s.water.rain = rain;
  }
  if (const auto* in = t->get("infiltration")) {
    STRATA_TRY(s.water.infiltration, readInfiltration(r, *in));
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
      STRATA_TRY(d.surfaceElevationM, r.quantity(*dt->get("surface"), key + ".surface", "length", kElevation));
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
      l.name = "level " + std::to_string(i + 1);
      if (const auto* n = lt->get("name")) {
        STRATA_TRY(l.name, r.string(*n, key + ".name"));
      }
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
      STRATA_TRY(l.stage, readCurve(r, *lt, key, {"stage", "water surface elevation", "length", "m", kElevation}));
      l.stageLine = int(lt->get("stage")->source().begin.line);
      s.water.levels.push_back(std::move(l));
    }
  }
  return {};
}

Status readTime(const Reader& r, const toml::table& root, Scenario& s) {
  const auto* t = root["time"].as_table();
  if (!t) return fail(r.file + ": missing [time] (duration = \"6 h\", output_interval = \"30 min\")");
  STRATA_TRY_STATUS(r.onlyKeys(*t, "time", {"duration", "output_interval", "spin_up", "spin_up_tolerance"}));
  const auto* d = t->get("duration");
  if (!d) return r.errorAt(int(t->source().begin.line), "time.duration", "missing");
  STRATA_TRY(s.durationS, r.quantity(*d, "time.duration", "time", kDuration));
  if (const auto* u = t->get("spin_up")) {
    STRATA_TRY(s.spinUpS, r.quantity(*u, "time.spin_up", "time", kSpinUp));
  }
  if (const auto* u = t->get("spin_up_tolerance")) {
    STRATA_TRY(s.spinUpTolerance, r.number(*u, "time.spin_up_tolerance", kSpinUpTolerance));
    if (s.spinUpS <= 0) return r.error(*u, "time.spin_up_tolerance", "needs a spin_up (the longest it may run)");
  }
  s.outputIntervalS = s.durationS / 10;
  if (const auto* o = t->get("output_interval")) {
    STRATA_TRY(s.outputIntervalS, r.quantity(*o, "time.output_interval", "time", kPositive));
    if (s.outputIntervalS > s.durationS) return r.error(*o, "time.output_interval", "longer than the duration");
    // Every interval writes the maps, the series and a checkpoint.
    const double n = std::ceil(s.durationS / s.outputIntervalS - 1e-9);
    if (!(n <= double(kMaxOutputIntervals))) {
      char msg[160];
      std::snprintf(msg, sizeof msg, "gives %.3g output intervals over the duration (at most %lld)", n,
                    kMaxOutputIntervals);
      return r.error(*o, "time.output_interval", msg);
    }
  }
  return {};
}

Status readOutputs(const Reader& r, const toml::table& root, Scenario& s) {
  const auto* t = root["outputs"].as_table();
  if ((!t || !t->get("maps")) && s.erosion.enabled) {
    s.outputs.maps.insert(s.outputs.maps.end(), erosionOutputMaps().begin(), erosionOutputMaps().end());
  }
  if (!t) return {};
  STRATA_TRY_STATUS(r.onlyKeys(
      *t, "outputs",
      {"maps", "wet_threshold", "pictures", "plots", "gauge", "section", "probe_interval", "hazard_land_use"}));
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
    STRATA_TRY(s.outputs.wetThresholdM, r.quantity(*w, "outputs.wet_threshold", "length", kWetThreshold));
  }
  if (const auto* p = t->get("pictures")) {
    STRATA_TRY(s.outputs.pictures, r.boolean(*p, "outputs.pictures"));
  }
  if (const auto* p = t->get("plots")) {
    STRATA_TRY(s.outputs.plots, r.boolean(*p, "outputs.plots"));
  }
  if (const auto* p = t->get("hazard_land_use")) {
    STRATA_TRY(auto use, r.string(*p, "outputs.hazard_land_use"));
    if (use == "pasture") {
      s.outputs.hazardLandUse = HazardLandUse::kPasture;
    } else if (use == "woodland") {
      s.outputs.hazardLandUse = HazardLandUse::kWoodland;
    } else if (use == "urban") {
      s.outputs.hazardLandUse = HazardLandUse::kUrban;
    } else {
      return r.error(*p, "outputs.hazard_land_use",
                     "unknown land use \"" + oneLine(use) + "\" (pasture, woodland, urban: FD2321's debris factors)");
    }
  }
  if (const auto* p = t->get("probe_interval")) {
    STRATA_TRY(s.outputs.probeIntervalS, r.quantity(*p, "outputs.probe_interval", "time", kDuration));
  }
  // [[outputs.gauge]] (a point) and [[outputs.section]] (a line), each with an optional name.
  auto probes = [&](const char* table, const char* base, bool single, auto&& add) -> Status {
    const auto* node = t->get(table);
    if (!node) return {};
    const std::string outer = std::string("outputs.") + table;
    const auto* arr = node->as_array();
    if (!arr) return r.error(*node, outer, std::string("expected [[") + outer + "]] tables");
    for (size_t i = 0; i < arr->size(); ++i) {
      const std::string key = outer + "[" + std::to_string(i) + "]";
      const auto* it = (*arr)[i].as_table();
      if (!it) return r.error((*arr)[i], key, "expected a table");
      const std::string ll = std::string(base) + "_lonlat", xy = std::string(base) + "_xy";
      STRATA_TRY_STATUS(r.onlyKeys(*it, key, {"name", ll.c_str(), xy.c_str()}));
      std::string name = std::string(table) + " " + std::to_string(i + 1);
      if (const auto* n = it->get("name")) {
        STRATA_TRY(name, r.string(*n, key + ".name"));
      }
      STRATA_TRY(auto place, r.placeKey(*it, key, base, single));
      if (!place) return r.errorAt(int(it->source().begin.line), key, "missing " + ll + " or " + xy);
      if (!single && place->points.size() < 2)
        return r.errorAt(place->line, place->key, "a line needs at least 2 points");
      add(std::move(name), std::move(*place));
    }
    return {};
  };
  STRATA_TRY_STATUS(probes("gauge", "at", true, [&](std::string n, Place p) {
    s.outputs.gauges.push_back({std::move(n), std::move(p)});
  }));
  STRATA_TRY_STATUS(probes("section", "line", false, [&](std::string n, Place p) {
    s.outputs.sections.push_back({std::move(n), std::move(p)});
  }));
  return {};
}

}  // namespace

std::string oneLine(std::string_view text) {
  std::string out;
  for (char c : text) {
    const auto u = static_cast<unsigned char>(c);
    if (c == '\n') {
      out += "\\n";
    } else if (c == '\t') {
      out += "\\t";
    } else if (c == '\r') {
      out += "\\r";
    } else if (u < 0x20 || u == 0x7F) {
      char buf[8];
      std::snprintf(buf, sizeof buf, "\\x%02X", u);
      out += buf;
    } else {
      out += c;
    }
  }
  return out;
}

std::string Scenario::at(const std::string& key) const {
  const auto it = keyLines.find(key);
  return file.string() + (it == keyLines.end() ? "" : ":" + std::to_string(it->second)) + ": key '" + oneLine(key) +
         "': ";
}

const std::vector<std::string>& erosionOutputMaps() {
  static const std::vector<std::string> kMaps{"terrain_change", "exposed_material", "suspended_sediment",
                                              "layer_thickness"};
  return kMaps;
}

const std::vector<std::string>& knownOutputMaps() {
  static const std::vector<std::string> kMaps{
      "max_depth",     "max_speed",      "arrival_time",     "inundation_duration", "final_depth",    "hazard_rating",
      "flood_outline", "terrain_change", "exposed_material", "suspended_sediment",  "layer_thickness"};
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
    if (unit == u.name && dimension == u.dimension) {
      if (!std::isfinite(value * u.toSi)) return fail("\"" + std::string(text) + "\" is too large");
      return value * u.toSi;
    }
  }
  for (const auto& u : kUnits) {
    if (unit == u.name) {
      return fail("unit '" + std::string(unit) + "' is a " + u.dimension + ", not a " + std::string(dimension) +
                  " (use one of " + unitsOf(dimension) + ")");
    }
  }
  return fail("unknown unit '" + std::string(unit) + "' (use one of " + unitsOf(dimension) + ")");
}

Result<Backend> parseBackend(std::string_view name) {
  if (name == "auto") return Backend::kAuto;
  if (name == "cpu") return Backend::kCpu;
  if (name == "gpu") return Backend::kGpu;
  return fail("expected \"auto\", \"cpu\" or \"gpu\", got \"" + std::string(name) + "\"");
}

namespace {

// The scenario a parsed TOML table describes (everything parseScenario checks after the syntax).
Result<Scenario> readScenario(const toml::table& root, const std::filesystem::path& fileName) {
  Scenario s;
  Reader r{fileName.string(), fileName.parent_path(), &s.keyLines};
  STRATA_TRY_STATUS(r.onlyKeys(
      root, "",
      {"name", "description", "terrain", "region", "model", "erosion", "materials", "water", "time", "outputs"}));
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
  STRATA_TRY_STATUS(readMaterials(r, root, s));
  STRATA_TRY_STATUS(readTime(r, root, s));  // before [water]: rain must start within the run
  STRATA_TRY_STATUS(readWater(r, root, s));
  STRATA_TRY_STATUS(readOutputs(r, root, s));
  if (s.water.inflows.empty() && !s.water.rain && s.water.damBreaks.empty() && s.water.levels.empty()) {
    return fail(r.file + ": [water] has no source: add an inflow, rain, a dam_break or a level");
  }
  if (s.spinUpS > 0 && !s.water.damBreaks.empty()) {
    return fail(s.at("time.spin_up") +
                "a dam break releases its water at t = 0 and the spin-up runs before it: use one or the other");
  }
  if (s.spinUpTolerance > 0 && s.water.inflows.empty()) {
    return fail(s.at("time.spin_up_tolerance") +
                "is a fraction of the base flow (the inflows at t = 0), and [water] has no inflow");
  }
  // Rows land on steps (the step before each row is shortened to reach it): a million at most.
  if ((!s.outputs.gauges.empty() || !s.outputs.sections.empty()) && s.durationS / s.outputs.probeIntervalS > 1e6) {
    return fail(s.at("outputs.probe_interval") + "more than a million rows over the duration (" +
                std::to_string(s.durationS / s.outputs.probeIntervalS) + "): choose a longer interval");
  }
  if (s.model.inertial && s.erosion.enabled) {
    return fail(s.at("model.scheme") +
                "the local-inertial scheme moves water only; erosion needs scheme = \"finite_volume\" (the default)");
  }
  if (!s.outputs.sections.empty() && s.model.kind == sim::WaterModel::kVirtualPipes) {
    return fail(s.at("outputs.section") +
                "sections need the flood model's face fluxes; the pipe model has none (set [model] kind = \"flood\")");
  }
  for (const auto& m : erosionOutputMaps()) {
    if (std::find(s.outputs.maps.begin(), s.outputs.maps.end(), m) != s.outputs.maps.end() && !s.erosion.enabled) {
      return fail(r.file + ": outputs.maps asks for " + m + " but erosion is not enabled");
    }
  }
  return s;
}

// The TOML of a scenario: screened (toml++'s defects), then parsed; syntax errors name the line.
Result<toml::table> parseToml(std::string_view text, const std::string& file) {
  TomlScreenOptions screen;
  screen.kind = "scenario";
  screen.dateHint = "durations are quantities such as \"3 h\"";
  STRATA_TRY_STATUS(screenToml(text, file, screen));
  try {
    return toml::parse(text, file);
  } catch (const toml::parse_error& e) {
    return fail(file + ":" + std::to_string(e.source().begin.line) + ": " + oneLine(e.description()));
  }
}

// --- Every problem of a file in one pass (scenarioProblems) --------------------------------

// A message's line and key ("FILE:LINE: key 'KEY': ..."; 0 and "" when it names neither).
struct Located {
  int line = 0;
  std::string key;
};
Located locate(const std::string& message, const std::string& file) {
  Located l;
  if (!message.starts_with(file + ":")) return l;
  const size_t at = file.size() + 1;
  size_t end = at;
  while (end < message.size() && std::isdigit(static_cast<unsigned char>(message[end]))) ++end;
  if (end == at || message.compare(end, 7, ": key '") != 0) return l;
  l.line = std::stoi(message.substr(at, end - at));
  const size_t k0 = end + 7, k1 = message.find("': ", k0);
  if (k1 != std::string::npos) l.key = message.substr(k0, k1 - k0);
  return l;
}

// "water.inflow[0].hydrograph" -> {"water", "inflow", "[0]", "hydrograph"}.
std::vector<std::string> keyParts(const std::string& key) {
  std::vector<std::string> parts;
  std::string cur;
  for (char c : key) {
    if (c == '.' || c == '[') {
      if (!cur.empty()) parts.push_back(cur);
      cur = c == '[' ? "[" : "";
    } else if (c == ']') {
      parts.push_back(cur + "]");
      cur.clear();
    } else {
      cur += c;
    }
  }
  if (!cur.empty()) parts.push_back(cur);
  return parts;
}

// The node holding the last part of `parts` (a table or an array), or null.
toml::node* parentOf(toml::table& root, const std::vector<std::string>& parts) {
  toml::node* n = &root;
  for (size_t i = 0; i + 1 < parts.size() && n; ++i) {
    const auto& p = parts[i];
    if (p.starts_with("[")) {
      auto* a = n->as_array();
      const size_t k = size_t(std::strtoul(p.c_str() + 1, nullptr, 10));
      n = a && k < a->size() ? a->get(k) : nullptr;
    } else {
      auto* t = n->as_table();
      n = t ? t->get(p) : nullptr;
    }
  }
  return n;
}

bool erase(toml::table& root, const std::vector<std::string>& parts) {
  if (parts.empty()) return false;
  toml::node* parent = parentOf(root, parts);
  if (!parent) return false;
  const auto& last = parts.back();
  if (last.starts_with("[")) {
    auto* a = parent->as_array();
    const size_t k = size_t(std::strtoul(last.c_str() + 1, nullptr, 10));
    if (!a || k >= a->size()) return false;
    a->erase(a->begin() + std::ptrdiff_t(k));
    return true;
  }
  auto* t = parent->as_table();
  return t && t->erase(last) > 0;
}

// Values that stand in for a required key once its own is refused, so that the rest of its
// table is read too (each is valid wherever the key occurs). Only `strata check` reads with
// them: its scenario is never run.
bool standIn(toml::table& root, const std::vector<std::string>& parts) {
  toml::node* parent = parentOf(root, parts);
  auto* t = parent ? parent->as_table() : nullptr;
  if (!t || parts.empty()) return false;
  const std::string& leaf = parts.back();
  auto curve = [] {
    toml::array a;
    a.push_back(toml::array{0, 0});
    a.push_back(toml::array{1, 0});
    return a;
  };
  if (leaf == "duration") {
    t->insert_or_assign(leaf, "1 h");
  } else if (leaf == "dem") {
    t->insert_or_assign(leaf, "refused.tif");
  } else if (leaf == "rate" || leaf == "surface" || leaf == "thickness") {
    t->insert_or_assign(leaf, 0);
  } else if (leaf == "material") {
    t->insert_or_assign(leaf, "rock");
  } else if (leaf == "hydrograph" || leaf == "stage") {
    t->insert_or_assign(leaf, curve());
  } else {
    return false;
  }
  return true;
}

// An unknown key that is a near miss (at most 2 edits) of an allowed key its table lacks is
// renamed to it, as the user meant: its value is then read (and checked) under that name.
bool renameNearMiss(toml::table& root, const std::vector<std::string>& parts, const std::string& message) {
  const size_t a = message.find("expected one of: "), b = message.find(')', a);
  toml::node* parent = parentOf(root, parts);
  auto* t = parent ? parent->as_table() : nullptr;
  if (!t || a == std::string::npos || b == std::string::npos || b < a) return false;
  std::stringstream list(message.substr(a + 17, b - a - 17));
  std::string best, candidate;
  size_t bestDistance = 3;
  while (std::getline(list, candidate, ',')) {
    candidate.erase(0, candidate.find_first_not_of(' '));
    const size_t d = editDistance(parts.back(), candidate);
    if (d < bestDistance && !t->contains(candidate)) best = candidate, bestDistance = d;
  }
  if (best.empty()) return false;
  toml::node* node = t->get(parts.back());
  if (!node) return false;
  node->visit([&](auto& value) { t->insert_or_assign(best, value); });
  t->erase(parts.back());
  return true;
}

}  // namespace

Result<Scenario> parseScenario(std::string_view text, const std::filesystem::path& fileName) {
  STRATA_TRY(const auto root, parseToml(withoutBom(text), fileName.string()));
  STRATA_TRY(auto s, readScenario(root, fileName));
  s.text = std::string(text);
  return s;
}

ScenarioCheck checkScenarioText(std::string_view text, const std::filesystem::path& fileName) {
  ScenarioCheck check;
  const std::string file = fileName.string();
  auto parsed = parseToml(withoutBom(text), file);
  if (!parsed) {
    check.problems.push_back({0, "", parsed.message()});
    return check;
  }
  toml::table root = std::move(parsed).value();
  std::set<std::string> replaced;  // keys given a stand-in value (a problem of theirs again is a cascade)
  // Each pass reads the file up to its first problem; the key it names is then set aside (a
  // near-miss name renamed, a refused required value replaced by a valid one, anything else
  // removed) and the next pass reads on. A problem on a key already reported is its cascade.
  for (int pass = 0; pass < 200; ++pass) {
    auto s = readScenario(root, fileName);
    if (s) {
      check.scenario = std::move(s).value();
      break;
    }
    const std::string message = s.message();
    const Located at = locate(message, file);
    if (at.key.empty()) {  // a whole-file check (no key): only meaningful when nothing else is wrong
      if (check.problems.empty()) check.problems.push_back({0, "", message});
      break;
    }
    const bool cascade = check.hasProblem(at.key);
    if (!cascade) check.problems.push_back({at.line, at.key, message});
    const auto parts = keyParts(at.key);
    bool moved = false;
    if (!cascade && message.find("unknown key") != std::string::npos) moved = renameNearMiss(root, parts, message);
    if (!moved && !replaced.count(at.key)) {
      moved = standIn(root, parts);
      if (moved) replaced.insert(at.key);
    }
    if (!moved) moved = erase(root, parts);
    if (!moved && parts.size() > 1) moved = erase(root, {parts.begin(), parts.end() - 1});
    if (!moved) break;
  }
  return check;
}

bool ScenarioCheck::hasProblem(const std::string& key) const {
  return std::any_of(problems.begin(), problems.end(), [&](const Problem& p) { return p.key == key; });
}

Result<Scenario> loadScenario(const std::filesystem::path& file) {
  if (auto ok = requireRegularFile(file, "a scenario file"); !ok) {
    std::error_code ec;
    return fail(std::filesystem::exists(file, ec) ? ok.message() : file.string() + ": no such scenario file");
  }
  std::ifstream in(file);
  std::stringstream ss;
  ss << in.rdbuf();
  if (!in && !in.eof()) return fail(file.string() + ": cannot read");
  return parseScenario(ss.str(), file);
}

}  // namespace strata::scenario
