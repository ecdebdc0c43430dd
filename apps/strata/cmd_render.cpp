// strata render: offscreen terrain rendering through EGL to PNG (colour) and EXR (depth,
// elevation), from one camera or along a keyframed flight path.
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <limits>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <strata/gis/dem_io.hpp>
#include <strata/gl/context.hpp>
#include <strata/render/flight_path.hpp>
#include <strata/render/image_io.hpp>
#include <strata/render/overlay.hpp>
#include <strata/render/sliding_grid.hpp>
#include <strata/render/synthetic_dem.hpp>
#include <strata/render/terrain_renderer.hpp>
#include <strata/terrain/tile_store.hpp>

#include "../common/view_options.hpp"
#include "commands.hpp"

namespace strata::app {
namespace {

using namespace strata::render;

struct RenderArgs {
  std::string dem;
  std::string assignCrs, assignGeotransform;  ///< for a DEM file without its own
  std::string output = "render.png";
  std::string depthOut, elevationOut;
  std::optional<double> lon, lat, height, agl;
  double heading = 0, pitch = -30, fov = 45;
  std::string size = "1280x720";
  std::string renderer = "ring";
  int circles = 256;
  double rangeM = 0, softMinM = 0, softFactor = 5;
  bool planetary = false;
  std::string voids = "fill";
  float exaggeration = 1;
  std::optional<float> seaLevel;
  float fogM = 0;
  apps::ViewArgs view;
  std::string path;
  int frames = 0;
  int clipSize = 512, pageSize = 64, uploadPages = 64;
  double gpuBudgetMiB = 256;
  bool overwrite = false;
};

// "synthetic:SIZE[:SEED]" (a rough fractal terrain of SIZE^2 cells of 30 m), else a DEM file
// (any raster GDAL reads, through strata::gis::readDem).
Result<gis::Raster> loadDem(const std::string& spec, bool planetary, const std::string& assignCrs,
                            const std::string& assignGeotransform) {
  if (spec.rfind("synthetic:", 0) == 0) {
    int size = 0;
    unsigned seed = 1;
    if (std::sscanf(spec.c_str() + 10, "%d:%u", &size, &seed) < 1 || size < 4 || size > 8192) {
      return fail("DEM '" + spec + "': expected synthetic:SIZE[:SEED] with SIZE in 4..8192");
    }
    return syntheticDem(size, 30.0, 400.0, seed);
  }
  // Planetary mode draws on the body's ellipsoid from lon/lat: an equirectangular DEM on a
  // sphere (LOLA's LDEM) is relabelled in degrees on the fly.
  std::optional<gis::GeoTransform> gt;
  if (!assignGeotransform.empty()) {
    STRATA_TRY(gt, gis::parseGeoTransform(assignGeotransform, "--assign-geotransform"));
  }
  STRATA_TRY(const gis::ReadOptions ro, gis::assignMissingGeoref(spec, assignCrs, gt));
  return planetary ? gis::readDemLonLat(spec, ro) : gis::readDem(spec, ro);
}

Result<std::unique_ptr<TerrainRenderer>> makeRenderer(const RenderArgs& a) {
  if (a.renderer == "grid") {
    STRATA_TRY(auto r, GridRenderer::create());
    return std::unique_ptr<TerrainRenderer>(std::move(r));
  }
  if (a.renderer == "sliding") {
    STRATA_TRY(auto r, SlidingGridRenderer::create());
    return std::unique_ptr<TerrainRenderer>(std::move(r));
  }
  if (a.renderer != "ring") return fail("--renderer '" + a.renderer + "': expected ring, sliding or grid");
  STRATA_TRY(auto r,
             RingRenderer::create(
                 {.circles = a.circles, .softFactor = a.softFactor, .softMinM = a.softMinM, .rangeM = a.rangeM}));
  return std::unique_ptr<TerrainRenderer>(std::move(r));
}

// Replaces the one printf-style integer field of `pattern` (e.g. frame_%04d.png) with `i`.
Result<std::string> frameName(const std::string& pattern, int i) {
  const auto pos = pattern.find('%');
  const auto end = pattern.find('d', pos == std::string::npos ? 0 : pos);
  if (pos == std::string::npos || end == std::string::npos || pattern.find('%', pos + 1) != std::string::npos ||
      pattern.find_first_not_of("0123456789", pos + 1) != end) {
    return fail("-o '" + pattern + "': with --path it needs one integer field such as frame_%04d.png");
  }
  std::vector<char> buf(pattern.size() + 32);
  std::snprintf(buf.data(), buf.size(), pattern.c_str(), i);
  return std::string(buf.data());
}

Status writeOutputs(const OffscreenTarget& target, const FrameGeometry& frame, const std::string& colourPath,
                    const std::string& depthPath, const std::string& elevationPath) {
  const int w = target.width(), h = target.height();
  STRATA_TRY_STATUS(render::writeImage8(colourPath, w, h, 4, target.colour()));
  if (!depthPath.empty()) {
    // Distance along the view axis (m) from the reversed depth; NaN where nothing was drawn.
    auto depth = target.depth();
    for (float& d : depth) d = d > 0 ? float(frame.nearM / double(d)) : std::numeric_limits<float>::quiet_NaN();
    STRATA_TRY_STATUS(render::writeImageFloat(depthPath, w, h, 1, depth));
  }
  if (!elevationPath.empty()) STRATA_TRY_STATUS(render::writeImageFloat(elevationPath, w, h, 1, target.elevation()));
  return {};
}

void reportStream(const TerrainScene& scene) {
  if (auto* st = scene.streamed()) {
    const auto s = st->stats();
    std::printf("streamed: %llu frames, %llu pages copied, %d pending, %zu of %zu GPU bytes\n",
                static_cast<unsigned long long>(s.frames), static_cast<unsigned long long>(s.pagesCopied), s.pending,
                s.gpuBytes, s.gpuBudgetBytes);
  }
}

// Every number given on the command line: finite (CLI11 reads "nan" and "inf", and its Range
// check lets NaN through: --fov nan crashed) and within what the renderer can draw.
void checkNumbers(const RenderArgs& a) {
  auto check = [](const char* option, std::optional<double> v, double lo, double hi) {
    if (!v) return;
    if (!std::isfinite(*v))
      exitCommand("render", std::string(option) + " " + std::to_string(*v) + ": not a finite number");
    if (*v < lo || *v > hi) {
      char msg[160];
      std::snprintf(msg, sizeof msg, "%s %g: expected %g to %g", option, *v, lo, hi);
      exitCommand("render", msg);
    }
  };
  check("--lon", a.lon, -1e9, 1e9);  // degrees, or metres of a projected CRS
  check("--lat", a.lat, -1e9, 1e9);
  check("--height", a.height, -1e8, 1e8);
  check("--agl", a.agl, -1e8, 1e8);
  check("--heading", a.heading, -3600, 3600);
  check("--pitch", a.pitch, -90, 90);
  check("--fov", a.fov, 1, 170);
  check("--exaggeration", double(a.exaggeration), 1e-3, 1e3);
  if (a.seaLevel) check("--sea-level", double(*a.seaLevel), -1e6, 1e6);
  check("--fog", double(a.fogM), 0, 1e9);
  check("--gpu-budget", a.gpuBudgetMiB, 1, 1 << 20);
  if (!a.path.empty() && (a.frames < 2 || a.frames > 1000000)) {
    exitCommand("render", "--frames " + std::to_string(a.frames) + ": a flight path needs 2 to 1000000 frames");
  }
}

// The files this render writes must not exist unless --overwrite says to replace them.
void checkOutputs(const RenderArgs& a) {
  if (a.overwrite) return;
  std::vector<std::string> outputs;
  for (const std::string& pattern : {a.output, a.depthOut, a.elevationOut}) {
    if (pattern.empty()) continue;
    if (a.path.empty()) {
      outputs.push_back(pattern);
      continue;
    }
    for (int i = 0; i < a.frames; ++i) {
      auto name = frameName(pattern, i);
      if (!name) exitCommand("render", name.message());
      outputs.push_back(*name);
    }
  }
  for (const auto& f : outputs) {
    std::error_code ec;
    if (std::filesystem::exists(f, ec)) exitCommand("render", f + ": exists (use --overwrite to replace it)");
  }
}

void run(const RenderArgs& a) {
  int w = 0, h = 0;
  if (std::sscanf(a.size.c_str(), "%dx%d", &w, &h) != 2 || w < 1 || h < 1 || w > 16384 || h > 16384) {
    exitCommand("render", "--size '" + a.size + "': expected WxH, e.g. 1280x720");
  }
  if (a.height && a.agl) exitCommand("render", "--height and --agl: give one of them");
  checkNumbers(a);
  checkOutputs(a);
  Shading shading;
  shading.exaggeration = a.exaggeration;
  shading.seaLevelM = a.seaLevel;
  shading.fogM = a.fogM;
  if (a.planetary) shading.sky = {0, 0, 0, 1};
  const VoidMode voids = a.voids == "holes" ? VoidMode::kHoles : VoidMode::kFill;

  auto ctx = gl::HeadlessContext::create({.debugOutput = false});
  if (!ctx) exitCommand("render", ctx.message());
  // A folder with a manifest is a tile store: its elevation is streamed around the viewer.
  auto scene = [&]() -> Result<TerrainScene> {
    if (!std::filesystem::is_regular_file(std::filesystem::path(a.dem) / "manifest.toml")) {
      STRATA_TRY(auto dem, loadDem(a.dem, a.planetary, a.assignCrs, a.assignGeotransform));
      return TerrainScene::create(dem, {.planetary = a.planetary, .voids = voids});
    }
    STRATA_TRY(auto opened, strata::terrain::TileStore::open(a.dem));
    return TerrainScene::createStreamed(std::move(opened),
                                        {.clipSize = a.clipSize,
                                         .pageSize = a.pageSize,
                                         .uploadPagesPerFrame = a.uploadPages,
                                         .gpuBudgetBytes = size_t(a.gpuBudgetMiB * 1048576.0)},
                                        {.planetary = a.planetary});
  }();
  if (!scene)
    exitCommand("render", scene.message().starts_with(a.dem + ":") ? scene.message() : a.dem + ": " + scene.message());
  if (auto st = apps::applyView(a.view, *scene, shading); !st) exitCommand("render", st.message());
  auto renderer = makeRenderer(a);
  if (!renderer) exitCommand("render", renderer.message());
  auto target = OffscreenTarget::create(w, h, a.view.msaa);
  if (!target) exitCommand("render", target.message());

  // The camera: default over the DEM's centre, 1000 m above the ground.
  const auto& c = scene->georef().transform.c;
  CameraPose cam;
  cam.lon = a.lon.value_or(c[0] + c[1] * scene->width() / 2.0);
  cam.lat = a.lat.value_or(c[3] + c[5] * scene->height() / 2.0);
  const double ground = shading.exaggeration * scene->heightAt(cam.lon, cam.lat);
  cam.heightM = a.height ? *a.height : ground + a.agl.value_or(1000.0);
  cam.headingDeg = a.heading;
  cam.pitchDeg = a.pitch;
  cam.fovYDeg = a.fov;

  // Overlays over the drawn picture (its colour only: depth and elevation keep the terrain's).
  std::optional<Overlay> overlay;
  if (a.view.layers.scaleBar) {
    auto o = Overlay::create();
    if (!o) exitCommand("render", o.message());
    overlay.emplace(std::move(*o));
  }
  auto drawOverlays = [&](const CameraPose& pose) {
    if (!overlay) return;
    const auto bar = overlay->drawScaleBarOver(*target, *scene, pose, shading);
    if (bar && a.path.empty()) std::printf("scale bar: %s, %.0f pixels\n", bar->label.c_str(), bar->pixels);
  };

  if (a.path.empty()) {
    if (auto* st = scene->streamed()) {
      // One picture: draw until every page of the windows is resident (each draw copies at
      // most --upload-pages of them), so the image is the full-resolution one.
      for (int i = 0; i < 10000; ++i) {
        if (auto s = (*renderer)->draw(*scene, cam, shading, *target); !s) exitCommand("render", s.message());
        if (st->stats().pending == 0) break;
      }
    } else if (auto s = (*renderer)->draw(*scene, cam, shading, *target); !s) {
      exitCommand("render", s.message());
    }
    drawOverlays(cam);
    const auto frame = frameGeometry(*scene, cam, shading, w, h);
    if (auto s = writeOutputs(*target, frame, a.output, a.depthOut, a.elevationOut); !s)
      exitCommand("render", s.message());
    std::printf("%s: %dx%d, %zu triangles (%s)\n", a.output.c_str(), w, h, (*renderer)->trianglesPerFrame(*scene),
                (*renderer)->name().c_str());
    reportStream(*scene);
    return;
  }
  auto path = FlightPath::load(a.path);
  if (!path) exitCommand("render", path.message());
  for (int i = 0; i < a.frames; ++i) {
    const CameraPose pose = path->at(double(i) / double(a.frames - 1));
    if (auto s = (*renderer)->draw(*scene, pose, shading, *target); !s) exitCommand("render", s.message());
    auto name = frameName(a.output, i);
    if (!name) exitCommand("render", name.message());
    auto depthName = a.depthOut.empty() ? Result<std::string>(std::string()) : frameName(a.depthOut, i);
    auto elevName = a.elevationOut.empty() ? Result<std::string>(std::string()) : frameName(a.elevationOut, i);
    if (!depthName) exitCommand("render", depthName.message());
    if (!elevName) exitCommand("render", elevName.message());
    drawOverlays(pose);
    const auto frame = frameGeometry(*scene, pose, shading, w, h);
    if (auto s = writeOutputs(*target, frame, *name, *depthName, *elevName); !s) exitCommand("render", s.message());
  }
  std::printf("%d frames %dx%d along %s\n", a.frames, w, h, a.path.c_str());
  reportStream(*scene);
}

}  // namespace

void addRenderCommand(CLI::App& app) {
  auto a = std::make_shared<RenderArgs>();
  auto* cmd = app.add_subcommand("render", "Render a DEM offscreen to PNG (and EXR depth/elevation)");
  cmd->add_option("dem", a->dem,
                  "DEM file, synthetic:SIZE[:SEED] for a generated terrain, or a tile store folder (streamed)")
      ->required();
  cmd->add_option("--assign-crs", a->assignCrs, "CRS for a DEM file that has none (EPSG:n, WKT or PROJ)");
  cmd->add_option("--assign-geotransform", a->assignGeotransform,
                  "Geotransform c0,c1,c2,c3,c4,c5 (GDAL's order) for a DEM file that has none");
  cmd->add_option("-o,--output", a->output, "Colour PNG (with --path: a pattern such as frame_%04d.png)");
  cmd->add_option("--depth", a->depthOut, "Also write the distance along the view axis (m) to this EXR");
  cmd->add_option("--elevation", a->elevationOut, "Also write the rendered elevation (m) to this EXR");
  cmd->add_option("--lon", a->lon, "Camera longitude (deg); easting (m) for projected DEMs; default: DEM centre");
  cmd->add_option("--lat", a->lat, "Camera latitude (deg); northing (m) for projected DEMs; default: DEM centre");
  cmd->add_option("--height", a->height, "Camera height above the datum (m)");
  cmd->add_option("--agl", a->agl, "Camera height above the ground (m; default 1000)");
  cmd->add_option("--heading", a->heading, "View direction, clockwise from north (deg)");
  cmd->add_option("--pitch", a->pitch, "View direction above the horizontal (deg; negative looks down)")
      ->check(CLI::Range(-90.0, 90.0));
  cmd->add_option("--fov", a->fov, "Vertical field of view (deg)")->check(CLI::Range(1.0, 170.0));
  cmd->add_option("--size", a->size, "Image size WxH");
  cmd->add_option("--renderer", a->renderer,
                  "ring (concentric rings), sliding (sliding sampling grid) or grid (brute-force full grid)");
  cmd->add_option("--circles", a->circles, "Ring renderer: circles (6n^2 triangles)")->check(CLI::Range(1, 2048));
  cmd->add_option("--range", a->rangeM,
                  "Ring renderer: view range (m; of arc on a body); default: the DEM's farthest corner, or the "
                  "horizon over the lowest terrain plus the highest summit's")
      ->check(CLI::NonNegativeNumber);
  cmd->add_option("--soft-min", a->softMinM,
                  "Ring renderer: floor of the softened viewer height f(h) = max(K h, this) (m); default: a twelfth "
                  "of the view range")
      ->check(CLI::NonNegativeNumber);
  cmd->add_option("--soft-factor", a->softFactor, "Ring renderer: K in f(h) = max(K h, --soft-min)")
      ->check(CLI::PositiveNumber);
  cmd->add_flag(
      "--planetary", a->planetary,
      "Draw on the body's ellipsoid (geographic DEMs, or equirectangular ones on a sphere such as LOLA's LDEM)");
  cmd->add_option("--voids", a->voids,
                  "No-data cells: fill (from the cells around them, as gdal_fillnodata) or holes (not drawn)")
      ->check(CLI::IsMember({"fill", "holes"}));
  cmd->add_option("--exaggeration", a->exaggeration, "Vertical exaggeration");
  cmd->add_option("--sea-level", a->seaLevel, "Water wherever the terrain is below this elevation (m)");
  cmd->add_option("--fog", a->fogM, "Haze distance (m); 0: none");
  apps::addViewOptions(*cmd, a->view);
  cmd->add_option("--path", a->path, "Keyframe file (lon lat height heading pitch [fov] per line)");
  cmd->add_option("--frames", a->frames, "Frames to render along --path");
  cmd->add_option("--clip-size", a->clipSize, "Store: texels a side of each streamed level's window")
      ->check(CLI::Range(16, 16384));
  cmd->add_option("--page-size", a->pageSize, "Store: texels a side of a streamed page")->check(CLI::Range(8, 4096));
  cmd->add_option("--upload-pages", a->uploadPages, "Store: pages copied into the stack per frame at most")
      ->check(CLI::Range(1, 1 << 20));
  cmd->add_option("--gpu-budget", a->gpuBudgetMiB, "Store: GPU memory for the streamed elevation (MiB)");
  cmd->add_flag("--overwrite", a->overwrite, "Replace output files that exist");
  cmd->callback([a] { run(*a); });
}

}  // namespace strata::app
