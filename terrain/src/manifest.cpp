#include "manifest.hpp"

#include <cctype>
#include <charconv>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <sstream>

#include <toml++/toml.h>

#include <strata/core/toml_screen.hpp>

namespace strata::terrain::detail {
namespace {

const char* layoutName(TileLayout l) { return l == TileLayout::Global ? "global" : "planar"; }
const char* metricName(TileMetric m) { return m == TileMetric::Range ? "range" : "max_error"; }

bool validFieldName(const std::string& n) {
  if (n.empty() || n.size() > 64) return false;
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

// ---- Writing: a fixed subset of TOML, formatted by hand (deterministic, and none of toml++'s
// formatter, whose float printing has undefined behaviour on some values in 3.3.0).

std::string tomlFloat(double v) {
  if (std::isnan(v)) return "nan";
  if (std::isinf(v)) return v > 0 ? "inf" : "-inf";
  char buf[40];
  const auto end = std::to_chars(buf, buf + sizeof buf, v).ptr;
  std::string s(buf, end);
  if (s.find_first_of(".e") == std::string::npos) s += ".0";
  return s;
}

// Length of the valid UTF-8 sequence starting at s[i] (0: invalid). Overlong forms, surrogates
// and code points beyond U+10FFFF are invalid.
size_t utf8Length(std::string_view s, size_t i) {
  const auto c = static_cast<unsigned char>(s[i]);
  if (c < 0x80) return 1;
  size_t n = 0;
  uint32_t cp = 0;
  if ((c & 0xE0) == 0xC0) {
    n = 2;
    cp = c & 0x1F;
  } else if ((c & 0xF0) == 0xE0) {
    n = 3;
    cp = c & 0x0F;
  } else if ((c & 0xF8) == 0xF0) {
    n = 4;
    cp = c & 0x07;
  } else {
    return 0;
  }
  if (i + n > s.size()) return 0;
  for (size_t k = 1; k < n; ++k) {
    const auto d = static_cast<unsigned char>(s[i + k]);
    if ((d & 0xC0) != 0x80) return 0;
    cp = (cp << 6) | (d & 0x3F);
  }
  if ((n == 2 && cp < 0x80) || (n == 3 && cp < 0x800) || (n == 4 && cp < 0x10000) || cp > 0x10FFFF ||
      (cp >= 0xD800 && cp <= 0xDFFF)) {
    return 0;
  }
  return n;
}

// A TOML basic string in ASCII: quotes, backslashes and control characters escaped, every
// non-ASCII character written as a \uXXXX / \UXXXXXXXX escape (so the whole manifest is ASCII,
// which strata::screenToml's ASCII-only mode relies on); bytes that are not UTF-8 become U+FFFD (a manifest's strings
// come from GDAL, validated names and Strata's file names, which are UTF-8).
std::string tomlString(std::string_view s) {
  std::string out = "\"";
  char buf[16];
  for (size_t i = 0; i < s.size();) {
    const auto c = static_cast<unsigned char>(s[i]);
    if (c == '"' || c == '\\') {
      out += '\\';
      out += char(c);
      ++i;
    } else if (c < 0x20 || c == 0x7F) {
      std::snprintf(buf, sizeof buf, "\\u%04X", unsigned(c));
      out += buf;
      ++i;
    } else if (c < 0x80) {
      out += char(c);
      ++i;
    } else if (const size_t n = utf8Length(s, i); n > 0) {
      uint32_t cp = c & (n == 2 ? 0x1F : n == 3 ? 0x0F : 0x07);
      for (size_t k = 1; k < n; ++k) cp = (cp << 6) | (static_cast<unsigned char>(s[i + k]) & 0x3F);
      std::snprintf(buf, sizeof buf, cp > 0xFFFF ? "\\U%08X" : "\\u%04X", unsigned(cp));
      out += buf;
      i += n;
    } else {
      out += "\\uFFFD";
      ++i;
    }
  }
  return out + "\"";
}

template <class T, class F>
std::string tomlArray(const std::vector<T>& v, F&& item) {
  std::string s = "[";
  for (size_t i = 0; i < v.size(); ++i) s += (i ? ", " : "") + item(v[i]);
  return s + "]";
}

std::string floats(const std::vector<float>& v) {
  return tomlArray(v, [](float f) { return tomlFloat(readable(f)); });
}

// ---- Reading: typed access with messages naming the file, the line and the key.

class Reader {
 public:
  explicit Reader(std::string path) : path_(std::move(path)) {}

  // "path:line: key 'k': what" (the line of the node when it has one).
  Error error(const toml::node* node, const std::string& key, const std::string& what) const {
    std::string where = path_;
    if (node && node->source().begin.line > 0) where += ":" + std::to_string(node->source().begin.line);
    return fail(where + ": key '" + key + "': " + what);
  }
  Error error(const toml::node_view<const toml::node>& node, const std::string& key, const std::string& what) const {
    return error(node.node(), key, what);
  }

  Result<std::string> string(const toml::node_view<const toml::node>& node, const std::string& key,
                             size_t maxSize = 4096) const {
    if (!node) return error(node, key, "missing");
    if (!node.is_string()) return error(node, key, "is not a string");
    std::string v = *node.value<std::string>();
    if (v.size() > maxSize) return error(node, key, "longer than " + std::to_string(maxSize) + " bytes");
    return v;
  }
  Result<bool> boolean(const toml::node_view<const toml::node>& node, const std::string& key) const {
    if (!node) return error(node, key, "missing");
    if (!node.is_boolean()) return error(node, key, "is not true or false");
    return *node.value<bool>();
  }
  Result<int64_t> integer(const toml::node_view<const toml::node>& node, const std::string& key, int64_t lo,
                          int64_t hi) const {
    if (!node) return error(node, key, "missing");
    if (!node.is_integer()) return error(node, key, "is not an integer");
    const int64_t v = *node.value<int64_t>();
    if (v < lo || v > hi) {
      return error(node, key, std::to_string(v) + " outside [" + std::to_string(lo) + ", " + std::to_string(hi) + "]");
    }
    return v;
  }
  Result<int> getInt(const toml::node_view<const toml::node>& node, const std::string& key, int64_t lo,
                     int64_t hi) const {
    STRATA_TRY(int64_t v, integer(node, key, lo, hi));
    return int(v);
  }
  // A number (integers accepted) in [lo, hi]; NaN only when allowNaN; infinities never.
  Result<double> number(const toml::node* node, const std::string& key, double lo, double hi,
                        bool allowNaN = false) const {
    if (!node) return error(node, key, "missing");
    std::optional<double> v;
    if (node->is_floating_point()) v = *node->value<double>();
    if (node->is_integer()) v = double(*node->value<int64_t>());
    if (!v) return error(node, key, "is not a number");
    if (std::isnan(*v)) {
      if (allowNaN) return *v;
      return error(node, key, "is nan (not a number)");
    }
    if (!std::isfinite(*v)) return error(node, key, "is infinite");
    if (*v < lo || *v > hi) {
      std::ostringstream m;
      m << *v << " outside [" << lo << ", " << hi << "]";
      return error(node, key, m.str());
    }
    return *v;
  }
  Result<double> number(const toml::node_view<const toml::node>& node, const std::string& key, double lo, double hi,
                        bool allowNaN = false) const {
    return number(node.node(), key, lo, hi, allowNaN);
  }
  // An array of exactly n numbers, each as number() checks them.
  Result<std::vector<double>> numbers(const toml::node_view<const toml::node>& node, const std::string& key, size_t n,
                                      double lo, double hi, bool allowNaN = false) const {
    if (!node) return error(node, key, "missing");
    const auto* a = node.as_array();
    if (!a) return error(node, key, "is not an array");
    if (a->size() != n) {
      return error(node, key, "has " + std::to_string(a->size()) + " values, expected " + std::to_string(n));
    }
    std::vector<double> out;
    for (size_t i = 0; i < n; ++i) {
      STRATA_TRY(double v, number(a->get(i), key + "[" + std::to_string(i) + "]", lo, hi, allowNaN));
      out.push_back(v);
    }
    return out;
  }
  Result<std::vector<float>> floats(const toml::node_view<const toml::node>& node, const std::string& key, size_t n,
                                    double lo, double hi, bool allowNaN = false) const {
    STRATA_TRY(auto v, numbers(node, key, n, lo, hi, allowNaN));
    return std::vector<float>(v.begin(), v.end());
  }
  const std::string& path() const { return path_; }

 private:
  std::string path_;
};

// Elevations, thicknesses and depths any body has: beyond +-1e7 m is not terrain.
constexpr double kMaxAbsValueM = 1e7;

}  // namespace

Status validateDesc(const StoreDesc& d) {
  const auto& m = d.metric;
  if (m.minExp < 0 || m.maxExp > 14 || m.minExp > m.maxExp) {
    return fail("metric: min_exp " + std::to_string(m.minExp) + ", max_exp " + std::to_string(m.maxExp) +
                " (need 0 <= min_exp <= max_exp <= 14)");
  }
  if (!(std::isfinite(m.maxErrorM) && m.maxErrorM >= 0 && m.maxErrorM <= 1e6)) {
    return fail("metric: max_error_m " + std::to_string(m.maxErrorM) + " is not a finite number in [0, 1e6] m");
  }
  if (d.georef.width <= 0 || d.georef.height <= 0 || d.georef.width > (1 << 30) || d.georef.height > (1 << 30)) {
    return fail("georef: grid " + std::to_string(d.georef.width) + "x" + std::to_string(d.georef.height) +
                " (need 1..2^30 cells a side)");
  }
  const int footprint = 1 << m.maxExp;
  const int64_t tiles =
      int64_t(tilesAlong(d.georef.width, footprint)) * int64_t(tilesAlong(d.georef.height, footprint));
  if (tiles > (int64_t(1) << 24)) {
    return fail("georef: " + std::to_string(tiles) + " tiles of " + std::to_string(footprint) +
                " cells (more than 2^24); use a larger max_exp");
  }
  const auto& t = d.georef.transform.c;
  for (double c : t) {
    if (!std::isfinite(c)) return fail("georef: geotransform term is not finite");
  }
  if (t[1] * t[5] - t[2] * t[4] == 0) return fail("georef: degenerate geotransform (zero pixel size)");
  if (d.layout == TileLayout::Global) {
    if (!d.georef.geographic) return fail("layout: a global layout needs a geographic (lon/lat) CRS");
    const double spanX = std::abs(t[1]) * d.georef.width, spanY = std::abs(t[5]) * d.georef.height;
    // A global grid spans 360 x 180 degrees; 1e-6 degree slack absorbs the rounding of a pixel
    // size like 1/3 degree written in decimal.
    if (!d.georef.transform.isNorthUp() || std::abs(spanX - 360.0) > 1e-6 || std::abs(spanY - 180.0) > 1e-6) {
      return fail("layout: a global layout needs a north-up grid spanning 360 x 180 degrees");
    }
    if (d.georef.width % 2 != 0) return fail("layout: a global layout needs an even width (the polar fold)");
  }
  if (d.fields.empty()) return fail("fields: a store needs at least one field");
  if (d.fields.size() > 64) return fail("fields: at most 64 fields");
  for (size_t i = 0; i < d.fields.size(); ++i) {
    const auto& f = d.fields[i];
    if (!validFieldName(f.name)) return fail("field '" + f.name + "': names are 1..64 letters, digits, '_' or '-'");
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
  std::ostringstream o;
  auto kv = [&o](const char* key, const std::string& value) { o << key << " = " << value << "\n"; };
  auto num = [](auto v) { return std::to_string(v); };
  o << "# Strata tile store manifest: human-readable, rewritten atomically (temporary + rename).\n"
    << "# Tiles not listed are absent (no data). See docs/architecture.md, \"Terrain store\".\n";
  kv("format", tomlString(kFormatName));
  kv("version", num(kFormatVersion));
  kv("next_generation", num(m.nextGeneration));

  o << "\n[build]\n";
  kv("complete", m.state.complete ? "true" : "false");
  kv("pass", num(m.state.pass));
  kv("tiles_done", num(m.state.tilesDone));
  kv("sources", tomlArray(m.state.sources, [](const std::string& s) { return tomlString(s); }));

  const auto& g = d.georef;
  o << "\n[georef]\n";
  kv("crs_wkt", tomlString(g.crsWkt));
  if (g.epsg) kv("epsg", num(*g.epsg));
  kv("crs_name", tomlString(g.crsName));
  kv("geographic", g.geographic ? "true" : "false");
  kv("geotransform", tomlArray(std::vector<double>(g.transform.c, g.transform.c + 6), tomlFloat));
  kv("width", num(g.width));
  kv("height", num(g.height));
  kv("vertical_unit", tomlString(g.verticalUnit));
  kv("body", tomlString(g.body.name));
  kv("body_semi_major_m", tomlFloat(g.body.semiMajorM));
  kv("body_flattening", tomlFloat(g.body.flattening));

  o << "\n[layout]\n";
  kv("kind", tomlString(layoutName(d.layout)));
  kv("footprint_cells", num(1 << d.metric.maxExp));
  kv("tiles_x", num(m.tilesX));
  kv("tiles_y", num(m.tilesY));

  o << "\n[metric]\n";
  kv("kind", tomlString(metricName(d.metric.kind)));
  kv("min_exp", num(d.metric.minExp));
  kv("max_exp", num(d.metric.maxExp));
  kv("max_error_m", tomlFloat(d.metric.maxErrorM));

  for (size_t i = 0; i < d.fields.size(); ++i) {
    o << "\n[[fields]]\n";
    kv("name", tomlString(d.fields[i].name));
    kv("kind", tomlString(toString(d.fields[i].kind)));
    if (d.fields[i].kind == LayerKind::Material) kv("material", tomlString(d.fields[i].material));
    kv("range_min", tomlFloat(readable(m.rangeLo[i])));
    kv("range_max", tomlFloat(readable(m.rangeHi[i])));
    // The store's achieved error, from the tiles' records (informative: `strata check` verifies it).
    double maxE = 0, sumSq = 0;
    uint64_t cells = 0;
    for (const auto& r : m.tiles) {
      if (!r.present) continue;
      maxE = std::max(maxE, double(r.maxErrorM[i]));
      sumSq += double(r.rmsErrorM[i]) * double(r.rmsErrorM[i]) * double(r.validCells[i]);
      cells += r.validCells[i];
    }
    kv("cells", num(cells));
    kv("max_error_m", tomlFloat(readable(float(maxE))));
    kv("rms_error_m", tomlFloat(readable(float(cells ? std::sqrt(sumSq / double(cells)) : 0.0))));
  }

  for (const auto& mat : d.materials) {
    o << "\n[[materials]]\n";
    kv("name", tomlString(mat.name));
    kv("colour", floats({mat.colour[0], mat.colour[1], mat.colour[2]}));
    kv("erodibility", tomlFloat(readable(mat.erodibility)));
    kv("dissolution_rate", tomlFloat(readable(mat.dissolutionRate)));
    kv("talus_angle_deg", tomlFloat(readable(mat.talusAngleDeg)));
    kv("density_kg_m3", tomlFloat(readable(mat.densityKgM3)));
    kv("weathering_rate", tomlFloat(readable(mat.weatheringRatePerS)));
    kv("critical_shear_pa", tomlFloat(readable(mat.criticalShearPa)));
    kv("shear_erodibility", tomlFloat(readable(mat.shearErodibility)));
    kv("settling_velocity", tomlFloat(readable(mat.settlingVelocityMS)));
    kv("friction_angle_deg", tomlFloat(readable(mat.frictionAngleDeg)));
    kv("cohesion_pa", tomlFloat(readable(mat.cohesionPa)));
  }

  for (int ty = 0; ty < m.tilesY; ++ty) {
    for (int tx = 0; tx < m.tilesX; ++tx) {
      const auto& r = m.tiles[size_t(ty) * size_t(m.tilesX) + size_t(tx)];
      if (!r.present) continue;
      o << "\n[[tiles]]\n";
      kv("x", num(tx));
      kv("y", num(ty));
      kv("exp", num(r.exp));
      kv("generation", num(r.generation));
      kv("file", tomlString(r.file));
      kv("crc32", num(r.crc32));
      kv("bytes", num(r.bytes));
      kv("min", floats(r.minV));
      kv("max", floats(r.maxV));
      kv("valid", tomlArray(r.validCells, [](uint64_t v) { return std::to_string(v); }));
      kv("max_error", floats(r.maxErrorM));
      kv("rms_error", floats(r.rmsErrorM));
    }
  }
  return o.str();
}

std::string tileFileName(int tx, int ty, uint64_t generation) {
  return "tiles/x" + std::to_string(tx) + "_y" + std::to_string(ty) + "_g" + std::to_string(generation) + ".exr";
}

Result<Manifest> parseManifest(const std::string& text, const std::string& path) {
  TomlScreenOptions screen;
  screen.asciiOnly = true;  // the writer escapes every other character
  screen.kind = "manifest";
  STRATA_TRY_STATUS(screenToml(text, path, screen));
  toml::table root;
  try {
    root = toml::parse(text, path);
  } catch (const toml::parse_error& e) {
    return fail(path + ":" + std::to_string(e.source().begin.line) + ": " + std::string(e.description()));
  }
  const Reader r(path);
  const toml::node_view<const toml::node> top(static_cast<const toml::node&>(root));
  STRATA_TRY(std::string format, r.string(top["format"], "format"));
  if (format != kFormatName) return r.error(top["format"], "format", "'" + format + "' is not " + kFormatName);
  STRATA_TRY(int version, r.getInt(top["version"], "version", 1, 1000));
  if (version != kFormatVersion) {
    return r.error(top["version"], "version",
                   std::to_string(version) + " is not supported (this Strata reads version " +
                       std::to_string(kFormatVersion) + "; ingest the data again)");
  }
  Manifest m;
  STRATA_TRY(int64_t nextGen, r.integer(top["next_generation"], "next_generation", 1, int64_t(1) << 53));
  m.nextGeneration = uint64_t(nextGen);

  auto& d = m.desc;
  const auto g = top["georef"];
  STRATA_TRY(d.georef.crsWkt, r.string(g["crs_wkt"], "georef.crs_wkt", 1 << 16));
  if (g["epsg"]) {
    STRATA_TRY(int epsg, r.getInt(g["epsg"], "georef.epsg", 1, 1000000000));
    d.georef.epsg = epsg;
  }
  STRATA_TRY(d.georef.crsName, r.string(g["crs_name"], "georef.crs_name"));
  STRATA_TRY(d.georef.geographic, r.boolean(g["geographic"], "georef.geographic"));
  STRATA_TRY(auto gt, r.numbers(g["geotransform"], "georef.geotransform", 6, -1e300, 1e300));
  std::copy(gt.begin(), gt.end(), d.georef.transform.c);
  STRATA_TRY(d.georef.width, r.getInt(g["width"], "georef.width", 1, 1 << 30));
  STRATA_TRY(d.georef.height, r.getInt(g["height"], "georef.height", 1, 1 << 30));
  STRATA_TRY(d.georef.verticalUnit, r.string(g["vertical_unit"], "georef.vertical_unit"));
  if (d.georef.verticalUnit != "m") {
    return r.error(g["vertical_unit"], "georef.vertical_unit", "'" + d.georef.verticalUnit + "' (stores hold metres)");
  }
  STRATA_TRY(std::string bodyName, r.string(g["body"], "georef.body"));
  // From a 1 m body to 100 times Jupiter's radius; flattening below 1 (0: a sphere).
  STRATA_TRY(double a, r.number(g["body_semi_major_m"], "georef.body_semi_major_m", 1.0, 1e10));
  STRATA_TRY(double f, r.number(g["body_flattening"], "georef.body_flattening", 0.0, 0.999));
  d.georef.body = gis::Body::fromEllipsoid(a, f, bodyName);

  STRATA_TRY(std::string kind, r.string(top["layout"]["kind"], "layout.kind"));
  if (kind == "planar") {
    d.layout = TileLayout::Planar;
  } else if (kind == "global") {
    d.layout = TileLayout::Global;
  } else {
    return r.error(top["layout"]["kind"], "layout.kind", "'" + kind + "': expected planar or global");
  }
  STRATA_TRY(std::string metricKind, r.string(top["metric"]["kind"], "metric.kind"));
  if (metricKind == "max_error") {
    d.metric.kind = TileMetric::MaxError;
  } else if (metricKind == "range") {
    d.metric.kind = TileMetric::Range;
  } else {
    return r.error(top["metric"]["kind"], "metric.kind", "'" + metricKind + "': expected max_error or range");
  }
  STRATA_TRY(d.metric.minExp, r.getInt(top["metric"]["min_exp"], "metric.min_exp", 0, 14));
  STRATA_TRY(d.metric.maxExp, r.getInt(top["metric"]["max_exp"], "metric.max_exp", 0, 14));
  STRATA_TRY(d.metric.maxErrorM, r.number(top["metric"]["max_error_m"], "metric.max_error_m", 0.0, 1e6));
  STRATA_TRY(int footprint, r.getInt(top["layout"]["footprint_cells"], "layout.footprint_cells", 1, 1 << 14));
  if (footprint != 1 << d.metric.maxExp) {
    return r.error(top["layout"]["footprint_cells"], "layout.footprint_cells", "is not 2^metric.max_exp");
  }

  d.materials.clear();
  if (top["materials"] && !top["materials"].as_array())
    return r.error(top["materials"], "materials", "is not an array");
  if (const auto* mats = top["materials"].as_array()) {
    if (mats->size() > 256) return r.error(top["materials"], "materials", "more than 256 materials");
    for (size_t i = 0; i < mats->size(); ++i) {
      const toml::node_view<const toml::node> t((*mats)[i]);
      const std::string k = "materials[" + std::to_string(i) + "].";
      Material mat;
      STRATA_TRY(mat.name, r.string(t["name"], k + "name", 64));
      STRATA_TRY(auto colour, r.floats(t["colour"], k + "colour", 3, 0.0, 1.0));
      for (size_t c = 0; c < 3; ++c) mat.colour[c] = colour[c];
      STRATA_TRY(double e, r.number(t["erodibility"], k + "erodibility", 0.0, 1e6));
      STRATA_TRY(double dr, r.number(t["dissolution_rate"], k + "dissolution_rate", 0.0, 1e6));
      STRATA_TRY(double ta, r.number(t["talus_angle_deg"], k + "talus_angle_deg", 0.0, 90.0));
      STRATA_TRY(double rho, r.number(t["density_kg_m3"], k + "density_kg_m3", 0.0, 1e6));
      mat.erodibility = float(e);
      mat.dissolutionRate = float(dr);
      mat.talusAngleDeg = float(ta);
      mat.densityKgM3 = float(rho);
      // Keys newer than the store: the default material of that name, else the default.
      const auto defaults = defaultMaterials();
      const int known = findMaterial(defaults, mat.name);
      const Material fallback = known >= 0 ? defaults[size_t(known)] : Material{};
      const struct {
        const char* key;
        float Material::*field;
        double hi;
      } later[] = {{"weathering_rate", &Material::weatheringRatePerS, 1e3},
                   {"critical_shear_pa", &Material::criticalShearPa, 1e9},
                   {"shear_erodibility", &Material::shearErodibility, 1.0},
                   {"settling_velocity", &Material::settlingVelocityMS, 100.0},
                   {"friction_angle_deg", &Material::frictionAngleDeg, 90.0},
                   {"cohesion_pa", &Material::cohesionPa, 1e12}};
      for (const auto& key : later) {
        if (t[key.key].node()) {
          STRATA_TRY(double v, r.number(t[key.key], k + key.key, 0.0, key.hi));
          mat.*key.field = float(v);
        } else {
          mat.*key.field = fallback.*key.field;
        }
      }
      auto ok = validateMaterial(mat);
      if (!ok) return r.error(t.node(), k + "*", ok.message());
      d.materials.push_back(mat);
    }
  }

  const auto* fields = top["fields"].as_array();
  if (!fields) return r.error(top["fields"], "fields", "missing array");
  if (fields->size() > 64) return r.error(top["fields"], "fields", "more than 64 fields");
  for (size_t i = 0; i < fields->size(); ++i) {
    const toml::node_view<const toml::node> t((*fields)[i]);
    const std::string k = "fields[" + std::to_string(i) + "].";
    StoreField sf;
    STRATA_TRY(sf.name, r.string(t["name"], k + "name", 64));
    STRATA_TRY(std::string fk, r.string(t["kind"], k + "kind"));
    auto parsedKind = parseLayerKind(fk);
    if (!parsedKind) return r.error(t["kind"], k + "kind", parsedKind.message());
    sf.kind = *parsedKind;
    if (sf.kind == LayerKind::Material) {
      STRATA_TRY(sf.material, r.string(t["material"], k + "material", 64));
    }
    // NaN: the field has no data anywhere.
    STRATA_TRY(double lo, r.number(t["range_min"], k + "range_min", -kMaxAbsValueM, kMaxAbsValueM, true));
    STRATA_TRY(double hi, r.number(t["range_max"], k + "range_max", -kMaxAbsValueM, kMaxAbsValueM, true));
    if (std::isnan(lo) != std::isnan(hi) || lo > hi) {
      return r.error(t["range_min"], k + "range_min", "range_min/range_max are not a range (both nan, or min <= max)");
    }
    d.fields.push_back(sf);
    m.rangeLo.push_back(float(lo));
    m.rangeHi.push_back(float(hi));
  }
  auto valid = validateDesc(d);
  if (!valid) return fail(path + ": " + valid.message());
  const size_t nf = d.fields.size();

  const auto b = top["build"];
  STRATA_TRY(m.state.complete, r.boolean(b["complete"], "build.complete"));
  STRATA_TRY(m.state.pass, r.getInt(b["pass"], "build.pass", 0, 2));
  const int footprintCells = 1 << d.metric.maxExp;
  STRATA_TRY(m.tilesX, r.getInt(top["layout"]["tiles_x"], "layout.tiles_x", 1, 1 << 24));
  STRATA_TRY(m.tilesY, r.getInt(top["layout"]["tiles_y"], "layout.tiles_y", 1, 1 << 24));
  if (m.tilesX != tilesAlong(d.georef.width, footprintCells) ||
      m.tilesY != tilesAlong(d.georef.height, footprintCells)) {
    return r.error(top["layout"]["tiles_x"], "layout.tiles_x",
                   "tiles_x/tiles_y do not match the grid size and footprint");
  }
  const int64_t tileCount = int64_t(m.tilesX) * int64_t(m.tilesY);
  STRATA_TRY(m.state.tilesDone, r.integer(b["tiles_done"], "build.tiles_done", 0, tileCount));
  const auto* sources = b["sources"].as_array();
  if (!sources) return r.error(b["sources"], "build.sources", "missing array");
  if (!sources->empty() && sources->size() != nf) {
    return r.error(b["sources"], "build.sources",
                   "has " + std::to_string(sources->size()) + " entries for " + std::to_string(nf) + " fields");
  }
  for (size_t i = 0; i < sources->size(); ++i) {
    STRATA_TRY(std::string s, r.string(toml::node_view<const toml::node>((*sources)[i]),
                                       "build.sources[" + std::to_string(i) + "]", 1 << 16));
    m.state.sources.push_back(std::move(s));
  }

  m.tiles.assign(size_t(tileCount), TileRecord{});
  const auto* tiles = top["tiles"].as_array();
  if (top["tiles"] && !tiles) return r.error(top["tiles"], "tiles", "is not an array");
  const double cellsPerTile = double(footprintCells) * double(footprintCells);
  for (size_t i = 0; tiles && i < tiles->size(); ++i) {
    const toml::node_view<const toml::node> t((*tiles)[i]);
    const std::string k = "tiles[" + std::to_string(i) + "].";
    STRATA_TRY(int tx, r.getInt(t["x"], k + "x", 0, m.tilesX - 1));
    STRATA_TRY(int ty, r.getInt(t["y"], k + "y", 0, m.tilesY - 1));
    auto& rec = m.tiles[size_t(ty) * size_t(m.tilesX) + size_t(tx)];
    if (rec.present) {
      return r.error(t.node(), k + "x", "lists tile " + std::to_string(tx) + "," + std::to_string(ty) + " twice");
    }
    rec.present = true;
    STRATA_TRY(rec.exp, r.getInt(t["exp"], k + "exp", d.metric.minExp, d.metric.maxExp));
    STRATA_TRY(int64_t gen, r.integer(t["generation"], k + "generation", 1, int64_t(m.nextGeneration) - 1));
    rec.generation = uint64_t(gen);
    STRATA_TRY(rec.file, r.string(t["file"], k + "file"));
    // The name is fixed by the tile and generation: a manifest cannot point anywhere else.
    if (rec.file != tileFileName(tx, ty, rec.generation)) {
      return r.error(t["file"], k + "file",
                     "'" + rec.file + "' is not this tile's file name (" + tileFileName(tx, ty, rec.generation) + ")");
    }
    STRATA_TRY(int64_t crc, r.integer(t["crc32"], k + "crc32", 0, int64_t(UINT32_MAX)));
    rec.crc32 = uint32_t(crc);
    STRATA_TRY(int64_t bytes, r.integer(t["bytes"], k + "bytes", 1, int64_t(1) << 40));
    rec.bytes = uint64_t(bytes);
    STRATA_TRY(rec.minV, r.floats(t["min"], k + "min", nf, -kMaxAbsValueM, kMaxAbsValueM, true));
    STRATA_TRY(rec.maxV, r.floats(t["max"], k + "max", nf, -kMaxAbsValueM, kMaxAbsValueM, true));
    STRATA_TRY(auto cells, r.numbers(t["valid"], k + "valid", nf, 0, cellsPerTile));
    STRATA_TRY(rec.maxErrorM, r.floats(t["max_error"], k + "max_error", nf, 0.0, kMaxAbsValueM));
    STRATA_TRY(rec.rmsErrorM, r.floats(t["rms_error"], k + "rms_error", nf, 0.0, kMaxAbsValueM));
    bool any = false;
    for (size_t q = 0; q < nf; ++q) {
      if (cells[q] != std::floor(cells[q])) return r.error(t["valid"], k + "valid", "holds a non-integer");
      rec.validCells.push_back(uint64_t(cells[q]));
      const bool none = rec.validCells[q] == 0;
      any |= !none;
      if (std::isnan(rec.minV[q]) != none || std::isnan(rec.maxV[q]) != none || rec.minV[q] > rec.maxV[q]) {
        return r.error(t["min"], k + "min",
                       "min/max of field " + std::to_string(q) +
                           " are not a range (nan exactly where the tile has no valid cell)");
      }
      if (rec.rmsErrorM[q] > rec.maxErrorM[q] * (1 + 1e-6f)) {
        return r.error(t["rms_error"], k + "rms_error", "exceeds max_error for field " + std::to_string(q));
      }
    }
    if (!any) return r.error(t.node(), k + "valid", "a listed tile has no valid cell in any field");
  }
  if (!m.state.complete && m.state.pass == 0) {
    return r.error(b["pass"], "build.pass", "an incomplete store must be in pass 1 or 2");
  }
  return m;
}

}  // namespace strata::terrain::detail
