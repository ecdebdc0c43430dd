// strata generate SCRIPT -o OUT: procedural terrain from a generation script (docs/procgen.md),
// one file per material layer: a GeoTIFF (gis::writeGeoTiff) when the script gives a
// georeference, else a float EXR (no CRS to write).

#include <cstdio>
#include <filesystem>
#include <regex>

#include <strata/core/files.hpp>
#include <strata/core/log.hpp>
#include <strata/gis/dem_io.hpp>
#include <strata/gl/context.hpp>
#include <strata/procgen/generator.hpp>
#include <strata/procgen/script_file.hpp>
#include <strata/render/image_io.hpp>

#include "commands.hpp"

namespace strata::app {
namespace {

// A georeferenced layer: float32 GeoTIFF, north-up, origin at the top-left corner.
Status writeLayerGeoTiff(const std::filesystem::path& target, const gis::Grid<float>& heights,
                         const procgen::OutputGeoref& georef) {
  gis::Raster raster;
  raster.georef.epsg = georef.epsg;
  raster.georef.width = heights.width;
  raster.georef.height = heights.height;
  raster.georef.transform.c[0] = georef.originX;
  raster.georef.transform.c[1] = georef.cellSize;
  raster.georef.transform.c[2] = 0;
  raster.georef.transform.c[3] = georef.originY;
  raster.georef.transform.c[4] = 0;
  raster.georef.transform.c[5] = -georef.cellSize;
  raster.values = heights;
  return gis::writeGeoTiff(target.string(), raster);
}

// A layer without georeference: a float EXR (seed and script as attributes).
Status writeExr(const std::filesystem::path& target, const gis::Grid<float>& heights, const std::string& script,
                uint32_t seed) {
  const auto temporary = temporaryPathFor(target);
  render::ExrExtras extras;
  extras.channelNames = {"Y"};
  extras.strings = {{"strata:script", script}, {"strata:units", "m"}};
  extras.ints = {{"strata:seed", int(seed)}};
  if (auto st = render::writeImageFloat(temporary.string(), heights.width, heights.height, 1, heights.data, extras);
      !st) {
    std::error_code ec;
    std::filesystem::remove(temporary, ec);
    return fail(target.string() + ": cannot write EXR: " + st.message());
  }
  return commitTemporary(temporary, target);
}

Status run(const std::string& scriptPath, const std::string& outDir, uint32_t seed, const std::string& size,
           int levels) {
  std::smatch m;
  static const std::regex kSize(R"(^(\d{1,5})x(\d{1,5})$)");
  if (!std::regex_match(size, m, kSize)) return fail("--size '" + size + "': expected WxH, e.g. 512x512");
  const int w = std::stoi(m[1]), h = std::stoi(m[2]);
  STRATA_TRY(auto file, procgen::loadScriptFile(scriptPath));
  procgen::GenerateOptions options;
  options.width = w;
  options.height = h;
  options.seed = seed;
  options.levels = levels > 0 ? levels : file.levels;
  options.wavelet = file.wavelet;
  for (const auto& dem : file.demPaths) {
    STRATA_TRY(auto raster, gis::readDem(dem));
    options.dems.push_back(std::move(raster.values));
  }
  std::error_code ec;
  std::filesystem::create_directories(outDir, ec);
  if (ec) return fail(outDir + ": cannot create the output folder: " + ec.message());
  STRATA_TRY(auto ctx, gl::HeadlessContext::create({.debugOutput = false}));
  for (const auto& layer : file.layers) {
    options.matchDem = layer.matchDem;
    options.matchCoarse = layer.matchCoarse;
    STRATA_TRY(auto heights, procgen::generate(layer.script, options));
    const auto target = std::filesystem::path(outDir) / (layer.name + (file.georef ? ".tif" : ".exr"));
    if (file.georef) {
      STRATA_TRY_STATUS(writeLayerGeoTiff(target, heights, *file.georef));
    } else {
      STRATA_TRY_STATUS(writeExr(target, heights, scriptPath, seed));
    }
    float lo = heights.data.front(), hi = lo;
    for (float v : heights.data) {
      lo = std::min(lo, v);
      hi = std::max(hi, v);
    }
    std::printf("%s: %dx%d, %.2f..%.2f m\n", target.string().c_str(), w, h, double(lo), double(hi));
  }
  return {};
}

}  // namespace

void addGenerateCommand(CLI::App& app) {
  auto* cmd =
      app.add_subcommand("generate", "Procedural terrain from a generation script: one GeoTIFF (or EXR) per layer");
  struct Args {
    std::string script, out, size = "512x512";
    uint32_t seed = 1;
    int levels = 0;
  };
  auto args = std::make_shared<Args>();
  cmd->add_option("SCRIPT", args->script, "Generation script (TOML, see docs/procgen.md)")->required();
  cmd->add_option("-o,--out", args->out, "Output folder: <layer>.tif per layer (<layer>.exr without a [georef])")
      ->required();
  cmd->add_option("--seed", args->seed, "Seed of every noise built-in (same seed, same bytes)");
  cmd->add_option("--size", args->size, "Output grid WxH in cells");
  cmd->add_option("--levels", args->levels, "Wavelet levels (default: the script's, else 6)");
  cmd->callback([args] {
    const auto status = run(args->script, args->out, args->seed, args->size, args->levels);
    if (!status) {
      exitCommand("generate", status.message());
    }
  });
}

}  // namespace strata::app
