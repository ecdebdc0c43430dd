// TOML generation scripts: parsing and checks, GLSL line numbers kept for error messages.
#include <strata/procgen/script_file.hpp>

#include <filesystem>
#include <fstream>
#include <sstream>

#include <toml++/toml.h>

namespace strata::procgen {
namespace {

// The file line of the first character of a multi-line string whose opening quotes start on
// `line`: TOML drops a newline right after the opening quotes.
int firstContentLine(const std::vector<std::string>& lines, int line, int column) {
  if (line < 1 || line > int(lines.size())) return line;
  const std::string& text = lines[size_t(line - 1)];
  const size_t open = size_t(std::max(0, column - 1));
  const size_t quotes = text.find_first_of("\"'", open);
  if (quotes == std::string::npos || text.compare(quotes, 3, std::string(3, text[quotes])) != 0) return line;
  const bool restBlank = text.find_first_not_of(" \t\r", quotes + 3) == std::string::npos;
  return restBlank ? line + 1 : line;
}

}  // namespace

Result<ScriptFile> loadScriptFile(const std::string& path) {
  std::ifstream f(path, std::ios::binary);
  if (!f) return fail(path + ": cannot open the script file");
  std::stringstream buffer;
  buffer << f.rdbuf();
  const std::string text = buffer.str();
  std::vector<std::string> lines;
  {
    std::istringstream in(text);
    for (std::string l; std::getline(in, l);) lines.push_back(l);
  }
  toml::table root;
  try {
    root = toml::parse(text, path);
  } catch (const toml::parse_error& e) {
    return fail(path + ":" + std::to_string(e.source().begin.line) + ": " + std::string(e.description()));
  }
  const std::filesystem::path dir = std::filesystem::path(path).parent_path();
  ScriptFile out;

  if (auto* node = root.get("levels")) {
    auto v = node->value<int64_t>();
    if (!v || *v < 1 || *v > 14) return fail(path + ": 'levels' must be an integer in 1..14");
    out.levels = int(*v);
  }
  if (auto* node = root.get("wavelet")) {
    const auto v = node->value<std::string>();
    if (v == "cdf53") {
      out.wavelet = procgen::Wavelet::Cdf53;
    } else if (v == "cdf97") {
      out.wavelet = procgen::Wavelet::Cdf97;
    } else {
      return fail(path + ": 'wavelet' must be \"cdf53\" or \"cdf97\"");
    }
  }
  if (auto* node = root.get("dems")) {
    auto* arr = node->as_array();
    if (!arr || arr->size() > 2) return fail(path + ": 'dems' must be an array of at most 2 file paths");
    for (auto& e : *arr) {
      auto s = e.value<std::string>();
      if (!s) return fail(path + ": 'dems' entries must be strings");
      const std::filesystem::path p(*s);
      out.demPaths.push_back(p.is_absolute() ? p.string() : (dir / p).lexically_normal().string());
    }
  }
  if (auto* node = root.get("georef")) {
    auto* t = node->as_table();
    if (!t) return fail(path + ": 'georef' must be a table");
    OutputGeoref g;
    auto epsg = (*t)["epsg"].value<int64_t>();
    auto* origin = (*t)["origin"].as_array();
    auto cell = (*t)["cell_size"].value<double>();
    if (!epsg || *epsg <= 0) return fail(path + ": georef.epsg must be a positive integer EPSG code");
    if (!origin || origin->size() != 2 || !(*origin)[0].value<double>() || !(*origin)[1].value<double>()) {
      return fail(path + ": georef.origin must be [x, y], the top-left corner in CRS units");
    }
    if (!cell || !(*cell > 0)) return fail(path + ": georef.cell_size must be a number > 0");
    g.epsg = int(*epsg);
    g.originX = *(*origin)[0].value<double>();
    g.originY = *(*origin)[1].value<double>();
    g.cellSize = *cell;
    out.georef = g;
  }
  auto* layers = root["layer"].as_array();
  if (!layers || layers->empty()) return fail(path + ": no [[layer]] table (each layer needs name and glsl)");
  for (size_t i = 0; i < layers->size(); ++i) {
    auto* t = (*layers)[i].as_table();
    const std::string where = path + ": layer " + std::to_string(i + 1);
    if (!t) return fail(where + " is not a table");
    LayerScript layer;
    auto layerName = (*t)["name"].value<std::string>();
    if (!layerName || layerName->empty() ||
        layerName->find_first_not_of("abcdefghijklmnopqrstuvwxyzABCDEFGHIJKLMNOPQRSTUVWXYZ0123456789_-") !=
            std::string::npos) {
      return fail(where + ": 'name' must be a non-empty string of letters, digits, '_' or '-'");
    }
    layer.name = *layerName;
    auto* glsl = (*t).get("glsl");
    if (!glsl || !glsl->is_string()) return fail(where + " ('" + layer.name + "'): 'glsl' must be a string");
    layer.script.fileName = path;  // as the user gave it: compile errors say "path:line"
    layer.script.glsl = *glsl->value<std::string>();
    layer.script.firstLine = firstContentLine(lines, int(glsl->source().begin.line), int(glsl->source().begin.column));
    if (auto m = (*t)["match_dem"].value<int64_t>()) {
      if (*m < 0 || *m >= int64_t(out.demPaths.size())) {
        return fail(where + " ('" + layer.name + "'): 'match_dem' must index one of the " +
                    std::to_string(out.demPaths.size()) + " DEM(s) in 'dems'");
      }
      layer.matchDem = int(*m);
    }
    layer.matchCoarse = (*t)["match_coarse"].value_or(false);
    for (const auto& other : out.layers) {
      if (other.name == layer.name) return fail(where + ": duplicate layer name '" + layer.name + "'");
    }
    out.layers.push_back(std::move(layer));
  }
  return out;
}

}  // namespace strata::procgen
