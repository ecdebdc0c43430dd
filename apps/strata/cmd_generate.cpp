// strata generate SCRIPT -o OUT: procedural terrain from a generation script (docs/procgen.md),
// one float EXR per material layer. DEMs are read with GDAL here until gis::readDem is on main;
// the outputs become GeoTIFFs once gis::writeGeoTiff is (EXR carries the georeference as
// strata:* attributes meanwhile).
#include <gdal_priv.h>

#include <OpenImageIO/imageio.h>

#include <cstdio>
#include <filesystem>
#include <regex>

#include <strata/core/files.hpp>
#include <strata/core/log.hpp>
#include <strata/render/gl/context.hpp>
#include <strata/render/procgen/generator.hpp>
#include <strata/render/procgen/script_file.hpp>

#include "commands.hpp"

namespace strata::app {
namespace {

// Band 1 of a raster in metres (scale/offset applied), nodata as NaN.
Result<gis::Grid<float>> readDemBand(const std::string& path) {
  GDALAllRegister();
  std::unique_ptr<GDALDataset> ds(static_cast<GDALDataset*>(GDALOpen(path.c_str(), GA_ReadOnly)));
  if (!ds || ds->GetRasterCount() < 1) return fail(path + ": cannot open as a raster (GDAL)");
  auto* band = ds->GetRasterBand(1);
  gis::Grid<float> g(ds->GetRasterXSize(), ds->GetRasterYSize());
  if (band->RasterIO(GF_Read, 0, 0, g.width, g.height, g.data.data(), g.width, g.height, GDT_Float32, 0, 0, nullptr) !=
      CE_None) {
    return fail(path + ": cannot read band 1");
  }
  int hasNoData = 0;
  const double noData = band->GetNoDataValue(&hasNoData);
  const double scale = band->GetScale(), offset = band->GetOffset();
  for (float& v : g.data) {
    if (hasNoData && double(v) == noData) {
      v = gis::kNoData;
    } else {
      v = float(double(v) * scale + offset);
    }
  }
  return g;
}

Status writeExr(const std::filesystem::path& target, const gis::Grid<float>& heights,
                const std::optional<render::procgen::OutputGeoref>& georef, const std::string& script, uint32_t seed) {
  const auto temporary = temporaryPathFor(target);
  auto out = OIIO::ImageOutput::create("openexr");
  if (!out) return fail(target.string() + ": OpenImageIO has no EXR writer");
  OIIO::ImageSpec spec(heights.width, heights.height, 1, OIIO::TypeDesc::FLOAT);
  spec.channelnames = {"Y"};
  spec.attribute("compression", "zip");
  spec.attribute("strata:script", script);
  spec.attribute("strata:seed", int(seed));
  spec.attribute("strata:units", "m");
  if (georef) {
    spec.attribute("strata:epsg", georef->epsg);
    // Doubles: a UTM northing needs more than a float's 24 bits.
    spec.attribute("strata:originX", OIIO::TypeDesc::DOUBLE, &georef->originX);
    spec.attribute("strata:originY", OIIO::TypeDesc::DOUBLE, &georef->originY);
    spec.attribute("strata:cellSize", OIIO::TypeDesc::DOUBLE, &georef->cellSize);
  }
  if (!out->open(temporary.string(), spec) || !out->write_image(OIIO::TypeDesc::FLOAT, heights.data.data()) ||
      !out->close()) {
    std::error_code ec;
    std::filesystem::remove(temporary, ec);
    return fail(target.string() + ": cannot write EXR: " + out->geterror());
  }
  return commitTemporary(temporary, target);
}

Status run(const std::string& scriptPath, const std::string& outDir, uint32_t seed, const std::string& size,
           int levels) {
  std::smatch m;
  static const std::regex kSize(R"(^(\d{1,5})x(\d{1,5})$)");
  if (!std::regex_match(size, m, kSize)) return fail("--size '" + size + "': expected WxH, e.g. 512x512");
  const int w = std::stoi(m[1]), h = std::stoi(m[2]);
  STRATA_TRY(auto file, render::procgen::loadScriptFile(scriptPath));
  render::procgen::GenerateOptions options;
  options.width = w;
  options.height = h;
  options.seed = seed;
  options.levels = levels > 0 ? levels : file.levels;
  options.wavelet = file.wavelet;
  for (const auto& dem : file.demPaths) {
    STRATA_TRY(auto grid, readDemBand(dem));
    options.dems.push_back(std::move(grid));
  }
  std::error_code ec;
  std::filesystem::create_directories(outDir, ec);
  if (ec) return fail(outDir + ": cannot create the output folder: " + ec.message());
  STRATA_TRY(auto ctx, render::gl::HeadlessContext::create({.debugOutput = false}));
  for (const auto& layer : file.layers) {
    options.matchDem = layer.matchDem;
    options.matchCoarse = layer.matchCoarse;
    STRATA_TRY(auto heights, render::procgen::generate(layer.script, options));
    const auto target = std::filesystem::path(outDir) / (layer.name + ".exr");
    STRATA_TRY_STATUS(writeExr(target, heights, file.georef, scriptPath, seed));
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
  auto* cmd = app.add_subcommand("generate", "Procedural terrain from a generation script: one EXR per layer");
  struct Args {
    std::string script, out, size = "512x512";
    uint32_t seed = 1;
    int levels = 0;
  };
  auto args = std::make_shared<Args>();
  cmd->add_option("SCRIPT", args->script, "Generation script (TOML, see docs/procgen.md)")->required();
  cmd->add_option("-o,--out", args->out, "Output folder (one <layer>.exr per layer)")->required();
  cmd->add_option("--seed", args->seed, "Seed of every noise built-in (same seed, same bytes)");
  cmd->add_option("--size", args->size, "Output grid WxH in cells");
  cmd->add_option("--levels", args->levels, "Wavelet levels (default: the script's, else 6)");
  cmd->callback([args] {
    const auto status = run(args->script, args->out, args->seed, args->size, args->levels);
    if (!status) {
      std::fprintf(stderr, "strata generate: %s\n", status.message().c_str());
      throw CLI::RuntimeError(1);
    }
  });
}

}  // namespace strata::app
