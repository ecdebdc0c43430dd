#include "manifest.hpp"

#include <cctype>
#include <charconv>
#include <cmath>
#include <cstdlib>
#include <sstream>

#include <toml++/toml.h>

namespace strata::terrain::detail {
namespace {

const char* layoutName(TileLayout l) { return l == TileLayout::Global ? "global" : "planar"; }

bool validFieldName(const std::string& n) {
  if (n.empty()) return false;
  for (char c : n) {
    if (!(std::isalnum(static_cast<unsigned char>(c)) || c == '_' || c == '-')) return false;
  }
  return true;
}

// The double whose shortest decimal form is the float's: 0.45f is written "0.45", not
// "0.44999998807907104", and still reads back as exactly 0.45f.
double readable(float f) {
  if (!std::isfinite(f)) return double(f);
  char buf[32];
  const auto end = std::to_chars(buf, buf + sizeof buf, f).ptr;
  return std::strtod(std::string(buf, end).c_str(), nullptr);
}

toml::array floats(const std::vector<float>& v) {
  toml::array a;
  for (float f : v) a.push_back(readable(f));
  return a;
}

// Typed access with messages naming the file and the key.
class Reader {
 public:
  explicit Reader(std::string path) : path_(std::move(path)) {}

  template <class T>
  Result<T> get(const toml::node_view<const toml::node>& node, const std::string& key) const {
    if (!node) return fail(path_ + ": missing '" + key + "'");
    if constexpr (std::is_same_v<T, double>) {
      if (auto v = node.value<double>()) return *v;  // also accepts integers
    } else if constexpr (std::is_same_v<T, int64_t>) {
      if (node.is_integer()) return *node.value<int64_t>();
    } else if constexpr (std::is_same_v<T, std::string>) {
      if (node.is_string()) return *node.value<std::string>();
    } else if constexpr (std::is_same_v<T, bool>) {
      if (node.is_boolean()) return *node.value<bool>();
    }
    return fail(path_ + ": '" + key + "' has the wrong type");
  }
  Result<int> getInt(const toml::node_view<const toml::node>& node, const std::string& key, int64_t lo,
                     int64_t hi) const {
    STRATA_TRY(int64_t v, get<int64_t>(node, key));
    if (v < lo || v > hi) {
      return fail(path_ + ": '" + key + "' = " + std::to_string(v) + " outside [" + std::to_string(lo) + ", " +
                  std::to_string(hi) + "]");
    }
    return int(v);
  }
  Result<std::vector<float>> getFloats(const toml::node_view<const toml::node>& node, const std::string& key,
                                       size_t n) const {
    const auto* a = node.as_array();
    if (!a) return fail(path_ + ": missing array '" + key + "'");
    if (a->size() != n) {
      return fail(path_ + ": '" + key + "' has " + std::to_string(a->size()) + " values, expected " +
                  std::to_string(n));
    }
    std::vector<float> out;
    for (const auto& e : *a) {
      auto v = e.value<double>();
      if (!v) return fail(path_ + ": '" + key + "' holds a non-number");
      out.push_back(float(*v));
    }
    return out;
  }
  const std::string& path() const { return path_; }

 private:
  std::string path_;
};

}  // namespace

Status validateDesc(const StoreDesc& d) {
  const auto& m = d.metric;
  if (m.minExp < 0 || m.maxExp > 14 || m.minExp > m.maxExp) {
    return fail("metric: min_exp " + std::to_string(m.minExp) + ", max_exp " + std::to_string(m.maxExp) +
                " (need 0 <= min_exp <= max_exp <= 14)");
  }
  if (d.georef.width <= 0 || d.georef.height <= 0) {
    return fail("georef: grid " + std::to_string(d.georef.width) + "x" + std::to_string(d.georef.height) + " is empty");
  }
  if (d.layout == TileLayout::Global) {
    if (!d.georef.geographic) return fail("layout: a global layout needs a geographic (lon/lat) CRS");
    const auto& t = d.georef.transform.c;
    const double spanX = std::abs(t[1]) * d.georef.width, spanY = std::abs(t[5]) * d.georef.height;
    // A global grid spans 360 x 180 degrees; 1e-6 degree slack absorbs the rounding of a pixel
    // size like 1/3 degree written in decimal.
    if (!d.georef.transform.isNorthUp() || std::abs(spanX - 360.0) > 1e-6 || std::abs(spanY - 180.0) > 1e-6) {
      return fail("layout: a global layout needs a north-up grid spanning 360 x 180 degrees");
    }
    if (d.georef.width % 2 != 0) return fail("layout: a global layout needs an even width (the polar fold)");
  }
  if (d.fields.empty()) return fail("fields: a store needs at least one field");
  for (size_t i = 0; i < d.fields.size(); ++i) {
    const auto& f = d.fields[i];
    if (!validFieldName(f.name)) return fail("field '" + f.name + "': names are letters, digits, '_' or '-'");
    for (size_t j = 0; j < i; ++j) {
      if (d.fields[j].name == f.name) return fail("field '" + f.name + "': name used twice");
    }
    if (f.kind == LayerKind::Material && findMaterial(d.materials, f.material) < 0) {
      return fail("field '" + f.name + "': unknown material '" + f.material + "'");
    }
  }
  for (const auto& mat : d.materials) STRATA_TRY_STATUS(validateMaterial(mat));
  return {};
}

std::string manifestToToml(const Manifest& m) {
  const auto& d = m.desc;
  toml::table root;
  root.insert("format", kFormatName);
  root.insert("version", kFormatVersion);
  root.insert("next_generation", int64_t(m.nextGeneration));

  toml::table g;
  g.insert("crs_wkt", d.georef.crsWkt);
  if (d.georef.epsg) g.insert("epsg", *d.georef.epsg);
  g.insert("crs_name", d.georef.crsName);
  g.insert("geographic", d.georef.geographic);
  toml::array gt;
  for (double c : d.georef.transform.c) gt.push_back(c);
  g.insert("geotransform", gt);
  g.insert("width", d.georef.width);
  g.insert("height", d.georef.height);
  g.insert("vertical_unit", d.georef.verticalUnit);
  g.insert("body", d.georef.body.name);
  g.insert("body_semi_major_m", d.georef.body.semiMajorM);
  g.insert("body_flattening", d.georef.body.flattening);
  root.insert("georef", g);

  toml::table layout;
  layout.insert("kind", layoutName(d.layout));
  layout.insert("footprint_cells", 1 << d.metric.maxExp);
  layout.insert("tiles_x", m.tilesX);
  layout.insert("tiles_y", m.tilesY);
  root.insert("layout", layout);

  toml::table metric;
  metric.insert("kind", "range");
  metric.insert("min_exp", d.metric.minExp);
  metric.insert("max_exp", d.metric.maxExp);
  root.insert("metric", metric);

  toml::array fields;
  for (size_t i = 0; i < d.fields.size(); ++i) {
    toml::table f;
    f.insert("name", d.fields[i].name);
    f.insert("kind", toString(d.fields[i].kind));
    if (d.fields[i].kind == LayerKind::Material) f.insert("material", d.fields[i].material);
    f.insert("range_min", readable(m.rangeLo[i]));
    f.insert("range_max", readable(m.rangeHi[i]));
    fields.push_back(f);
  }
  root.insert("fields", fields);

  toml::array mats;
  for (const auto& mat : d.materials) {
    toml::table t;
    t.insert("name", mat.name);
    t.insert("colour", toml::array{readable(mat.colour[0]), readable(mat.colour[1]), readable(mat.colour[2])});
    t.insert("erodibility", readable(mat.erodibility));
    t.insert("dissolution_rate", readable(mat.dissolutionRate));
    t.insert("talus_angle_deg", readable(mat.talusAngleDeg));
    t.insert("density_kg_m3", readable(mat.densityKgM3));
    mats.push_back(t);
  }
  root.insert("materials", mats);

  toml::array tiles;
  for (int ty = 0; ty < m.tilesY; ++ty) {
    for (int tx = 0; tx < m.tilesX; ++tx) {
      const auto& r = m.tiles[size_t(ty) * size_t(m.tilesX) + size_t(tx)];
      if (!r.present) continue;
      toml::table t;
      t.insert("x", tx);
      t.insert("y", ty);
      t.insert("exp", r.exp);
      t.insert("generation", int64_t(r.generation));
      t.insert("file", r.file);
      t.insert("crc32", int64_t(r.crc32));
      t.insert("bytes", int64_t(r.bytes));
      t.insert("min", floats(r.minV));
      t.insert("max", floats(r.maxV));
      tiles.push_back(t);
    }
  }
  root.insert("tiles", tiles);

  std::ostringstream os;
  os << "# Strata tile store manifest: human-readable, rewritten atomically (temporary + rename).\n"
     << "# Tiles not listed are absent (no data). See docs/architecture.md, \"Terrain store\".\n"
     << root << "\n";
  return os.str();
}

Result<Manifest> parseManifest(const std::string& text, const std::string& path) {
  toml::table root;
  try {
    root = toml::parse(text, path);
  } catch (const toml::parse_error& e) {
    return fail(path + ":" + std::to_string(e.source().begin.line) + ": " + std::string(e.description()));
  }
  const Reader r(path);
  const toml::node_view<const toml::node> top(static_cast<const toml::node&>(root));
  STRATA_TRY(std::string format, r.get<std::string>(top["format"], "format"));
  if (format != kFormatName) return fail(path + ": format '" + format + "' is not " + kFormatName);
  STRATA_TRY(int version, r.getInt(top["version"], "version", 1, 1000));
  if (version != kFormatVersion) return fail(path + ": version " + std::to_string(version) + " is not supported");
  Manifest m;
  STRATA_TRY(int64_t nextGen, r.get<int64_t>(top["next_generation"], "next_generation"));
  m.nextGeneration = uint64_t(nextGen);

  auto& d = m.desc;
  const auto g = top["georef"];
  STRATA_TRY(d.georef.crsWkt, r.get<std::string>(g["crs_wkt"], "georef.crs_wkt"));
  if (g["epsg"]) {
    STRATA_TRY(int epsg, r.getInt(g["epsg"], "georef.epsg", 0, 1000000000));
    d.georef.epsg = epsg;
  }
  STRATA_TRY(d.georef.crsName, r.get<std::string>(g["crs_name"], "georef.crs_name"));
  STRATA_TRY(d.georef.geographic, r.get<bool>(g["geographic"], "georef.geographic"));
  const auto* gt = g["geotransform"].as_array();
  if (!gt || gt->size() != 6) return fail(path + ": 'georef.geotransform' must hold 6 numbers");
  for (size_t i = 0; i < 6; ++i) {
    auto v = (*gt)[i].value<double>();
    if (!v) return fail(path + ": 'georef.geotransform' holds a non-number");
    d.georef.transform.c[i] = *v;
  }
  STRATA_TRY(d.georef.width, r.getInt(g["width"], "georef.width", 1, 1 << 30));
  STRATA_TRY(d.georef.height, r.getInt(g["height"], "georef.height", 1, 1 << 30));
  STRATA_TRY(d.georef.verticalUnit, r.get<std::string>(g["vertical_unit"], "georef.vertical_unit"));
  STRATA_TRY(std::string bodyName, r.get<std::string>(g["body"], "georef.body"));
  STRATA_TRY(double a, r.get<double>(g["body_semi_major_m"], "georef.body_semi_major_m"));
  STRATA_TRY(double f, r.get<double>(g["body_flattening"], "georef.body_flattening"));
  d.georef.body = gis::Body::fromEllipsoid(a, f, bodyName);

  STRATA_TRY(std::string kind, r.get<std::string>(top["layout"]["kind"], "layout.kind"));
  if (kind == "planar") {
    d.layout = TileLayout::Planar;
  } else if (kind == "global") {
    d.layout = TileLayout::Global;
  } else {
    return fail(path + ": 'layout.kind' = '" + kind + "': expected planar or global");
  }
  STRATA_TRY(std::string metricKind, r.get<std::string>(top["metric"]["kind"], "metric.kind"));
  if (metricKind != "range") return fail(path + ": 'metric.kind' = '" + metricKind + "': expected range");
  STRATA_TRY(d.metric.minExp, r.getInt(top["metric"]["min_exp"], "metric.min_exp", 0, 14));
  STRATA_TRY(d.metric.maxExp, r.getInt(top["metric"]["max_exp"], "metric.max_exp", 0, 14));
  STRATA_TRY(int footprint, r.getInt(top["layout"]["footprint_cells"], "layout.footprint_cells", 1, 1 << 14));
  if (footprint != 1 << d.metric.maxExp) return fail(path + ": 'layout.footprint_cells' is not 2^metric.max_exp");

  d.materials.clear();
  if (const auto* mats = top["materials"].as_array()) {
    for (size_t i = 0; i < mats->size(); ++i) {
      const toml::node_view<const toml::node> t((*mats)[i]);
      const std::string k = "materials[" + std::to_string(i) + "].";
      Material mat;
      STRATA_TRY(mat.name, r.get<std::string>(t["name"], k + "name"));
      STRATA_TRY(auto colour, r.getFloats(t["colour"], k + "colour", 3));
      for (size_t c = 0; c < 3; ++c) mat.colour[c] = colour[c];
      STRATA_TRY(double e, r.get<double>(t["erodibility"], k + "erodibility"));
      STRATA_TRY(double dr, r.get<double>(t["dissolution_rate"], k + "dissolution_rate"));
      STRATA_TRY(double ta, r.get<double>(t["talus_angle_deg"], k + "talus_angle_deg"));
      STRATA_TRY(double rho, r.get<double>(t["density_kg_m3"], k + "density_kg_m3"));
      mat.erodibility = float(e);
      mat.dissolutionRate = float(dr);
      mat.talusAngleDeg = float(ta);
      mat.densityKgM3 = float(rho);
      auto ok = validateMaterial(mat);
      if (!ok) return fail(path + ": " + ok.message());
      d.materials.push_back(mat);
    }
  }

  const auto* fields = top["fields"].as_array();
  if (!fields) return fail(path + ": missing array 'fields'");
  for (size_t i = 0; i < fields->size(); ++i) {
    const toml::node_view<const toml::node> t((*fields)[i]);
    const std::string k = "fields[" + std::to_string(i) + "].";
    StoreField sf;
    STRATA_TRY(sf.name, r.get<std::string>(t["name"], k + "name"));
    STRATA_TRY(std::string fk, r.get<std::string>(t["kind"], k + "kind"));
    auto parsedKind = parseLayerKind(fk);
    if (!parsedKind) return fail(path + ": '" + k + "kind': " + parsedKind.message());
    sf.kind = *parsedKind;
    if (sf.kind == LayerKind::Material) {
      STRATA_TRY(sf.material, r.get<std::string>(t["material"], k + "material"));
    }
    STRATA_TRY(double lo, r.get<double>(t["range_min"], k + "range_min"));
    STRATA_TRY(double hi, r.get<double>(t["range_max"], k + "range_max"));
    d.fields.push_back(sf);
    m.rangeLo.push_back(float(lo));
    m.rangeHi.push_back(float(hi));
  }
  auto valid = validateDesc(d);
  if (!valid) return fail(path + ": " + valid.message());

  const int footprintCells = 1 << d.metric.maxExp;
  STRATA_TRY(m.tilesX, r.getInt(top["layout"]["tiles_x"], "layout.tiles_x", 1, 1 << 24));
  STRATA_TRY(m.tilesY, r.getInt(top["layout"]["tiles_y"], "layout.tiles_y", 1, 1 << 24));
  if (m.tilesX != tilesAlong(d.georef.width, footprintCells) ||
      m.tilesY != tilesAlong(d.georef.height, footprintCells)) {
    return fail(path + ": 'layout.tiles_x/tiles_y' do not match the grid size and footprint");
  }
  m.tiles.assign(size_t(m.tilesX) * size_t(m.tilesY), TileRecord{});
  const auto* tiles = top["tiles"].as_array();
  if (!tiles) return fail(path + ": missing array 'tiles'");
  const size_t nf = d.fields.size();
  for (size_t i = 0; i < tiles->size(); ++i) {
    const toml::node_view<const toml::node> t((*tiles)[i]);
    const std::string k = "tiles[" + std::to_string(i) + "].";
    STRATA_TRY(int tx, r.getInt(t["x"], k + "x", 0, m.tilesX - 1));
    STRATA_TRY(int ty, r.getInt(t["y"], k + "y", 0, m.tilesY - 1));
    auto& rec = m.tiles[size_t(ty) * size_t(m.tilesX) + size_t(tx)];
    if (rec.present)
      return fail(path + ": '" + k + "' lists tile " + std::to_string(tx) + "," + std::to_string(ty) + " twice");
    rec.present = true;
    STRATA_TRY(rec.exp, r.getInt(t["exp"], k + "exp", d.metric.minExp, d.metric.maxExp));
    STRATA_TRY(int64_t gen, r.get<int64_t>(t["generation"], k + "generation"));
    rec.generation = uint64_t(gen);
    STRATA_TRY(rec.file, r.get<std::string>(t["file"], k + "file"));
    if (rec.file.find("..") != std::string::npos || rec.file.empty() || rec.file[0] == '/') {
      return fail(path + ": '" + k + "file' = '" + rec.file + "' is not a path inside the store");
    }
    STRATA_TRY(int64_t crc, r.get<int64_t>(t["crc32"], k + "crc32"));
    if (crc < 0 || crc > int64_t(UINT32_MAX)) return fail(path + ": '" + k + "crc32' is not a 32-bit value");
    rec.crc32 = uint32_t(crc);
    STRATA_TRY(int64_t bytes, r.get<int64_t>(t["bytes"], k + "bytes"));
    rec.bytes = uint64_t(bytes);
    STRATA_TRY(rec.minV, r.getFloats(t["min"], k + "min", nf));
    STRATA_TRY(rec.maxV, r.getFloats(t["max"], k + "max", nf));
  }
  return m;
}

}  // namespace strata::terrain::detail
