// strata check SCENARIO: every problem of a scenario file in one pass, raster paths included.
#include <algorithm>
#include <fstream>
#include <sstream>

#include <strata/core/files.hpp>
#include <strata/gis/dem_io.hpp>
#include <strata/scenario/scenario.hpp>

namespace strata::scenario {

std::vector<std::string> checkScenarioFile(const std::filesystem::path& file) {
  if (auto ok = requireRegularFile(file, "a scenario file"); !ok) {
    std::error_code ec;
    return {std::filesystem::exists(file, ec) ? ok.message() : file.string() + ": no such scenario file"};
  }
  std::ifstream in(file);
  std::stringstream text;
  text << in.rdbuf();
  if (!in && !in.eof()) return {file.string() + ": cannot read"};
  ScenarioCheck check = checkScenarioText(text.str(), file);
  if (const auto& s = check.scenario) {
    auto line = [&](const std::string& key) { return s->keyLines.count(key) ? s->keyLines.at(key) : 0; };
    // Each raster as the run opens it: a regular file (not a FIFO or a folder) that GDAL reads.
    auto raster = [&](const std::string& key, const std::string& path) {
      if (check.hasProblem(key)) return;
      Status ok = requireRegularFile(path, "a raster");
      if (ok) ok = statusOf(gis::probeDem(path));
      if (!ok) check.problems.push_back({line(key), key, s->at(key) + oneLine(ok.message())});
    };
    for (const auto& dem : s->terrain.dems) raster("terrain.dem", dem);
    for (size_t i = 0; i < s->terrain.layers.size(); ++i) {
      if (!s->terrain.layers[i].raster.empty()) {
        raster("terrain.layer[" + std::to_string(i) + "].raster", s->terrain.layers[i].raster);
      }
    }
    if (s->water.rain && !s->water.rain->raster.empty()) raster("water.rain.raster", s->water.rain->raster);
    if (s->water.rain) {
      for (const auto& f : s->water.rain->frames) raster("water.rain.frames", f.raster);
    }
    if (!s->model.manningRaster.empty()) raster("model.manning_raster", s->model.manningRaster);
    if (!s->model.landCoverRaster.empty()) raster("model.land_cover.raster", s->model.landCoverRaster);
    if (s->water.infiltration && !s->water.infiltration->raster.empty()) {
      raster("water.infiltration.raster", s->water.infiltration->raster);
    }
    if (!s->terrain.store.empty() && !check.hasProblem("terrain.store")) {
      std::error_code ec;
      if (!std::filesystem::is_regular_file(std::filesystem::path(s->terrain.store) / "manifest.toml", ec)) {
        check.problems.push_back({line("terrain.store"), "terrain.store",
                                  s->at("terrain.store") + s->terrain.store + ": not a tile store (no manifest.toml)"});
      }
    }
  }
  std::stable_sort(check.problems.begin(), check.problems.end(),
                   [](const ScenarioCheck::Problem& a, const ScenarioCheck::Problem& b) { return a.line < b.line; });
  std::vector<std::string> out;
  for (auto& p : check.problems) out.push_back(std::move(p.message));
  return out;
}

}  // namespace strata::scenario
