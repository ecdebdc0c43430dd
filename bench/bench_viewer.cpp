// strata-view frame times offscreen (EGL: llvmpipe, or the NVIDIA GPU where there is one): the
// Viewer flying over a DEM at 1280x720, without and with a live simulation region. Prints one
// JSON line per configuration. Usage: strata_bench_viewer [DEM] [FRAMES]. docs/benchmarks.md.
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <string>

#include <strata/gis/dem_io.hpp>
#include <strata/gl/context.hpp>
#include <strata/gl/state.hpp>
#include <strata/viewer/viewer.hpp>

using namespace strata;
using namespace strata::viewer;

int main(int argc, char** argv) {
  const std::string demPath = argc > 1 ? argv[1] : std::string(STRATA_DATA_DIR) + "/grand_canyon/grand_canyon_512.tif";
  const int frames = argc > 2 ? std::atoi(argv[2]) : 60;
  auto ctx = gl::HeadlessContext::create({.debugOutput = false});
  if (!ctx) {
    std::fprintf(stderr, "%s\n", ctx.message().c_str());
    return 1;
  }
  auto dem = gis::readDem(demPath);
  if (!dem) {
    std::fprintf(stderr, "%s\n", dem.message().c_str());
    return 1;
  }
  const auto& c = dem->georef.transform.c;
  const double lon = c[0] + c[1] * dem->values.width * 0.5, lat = c[3] + c[5] * dem->values.height * 0.55;
  const double dLon = c[1] * 32, dLat = c[5] * 32;  // a 64 x 64 cell simulation region
  for (const bool sim : {false, true}) {
    ViewerOptions options;
    options.width = 1280;
    options.height = 720;
    auto viewer = Viewer::create(*dem, options);
    if (!viewer) {
      std::fprintf(stderr, "%s\n", viewer.message().c_str());
      return 1;
    }
    Viewer& v = **viewer;
    bool ok = bool(v.handle(GoToCommand{lon, lat, 2500})) && bool(v.handle(LookCommand{0, -25})) &&
              bool(v.handle(KeyCommand{"W", true}));
    if (sim) {
      ok = ok && bool(v.handle(RegionCommand{lon - dLon, lat - dLat, lon + dLon, lat + dLat})) &&
           bool(v.handle(ToolCommand{"spring"})) && bool(v.handle(BrushCommand{500, 5000})) &&
           bool(v.handle(StrokeCommand{lon, lat})) && bool(v.handle(SimCommand{SimCommand::kSpeed, 8})) &&
           bool(v.handle(SimCommand{SimCommand::kPlay, 1}));
    }
    if (!ok) {
      std::fprintf(stderr, "bench_viewer: set-up command failed\n");
      return 1;
    }
    for (int i = 0; i < 3; ++i) (void)v.frame(1.0 / 30.0);  // compile, upload, warm caches
    double cpu = 0, gpu = 0, simMs = 0;
    const auto t0 = std::chrono::steady_clock::now();
    for (int i = 0; i < frames; ++i) {
      if (auto s = v.frame(1.0 / 30.0); !s) {
        std::fprintf(stderr, "bench_viewer: %s\n", s.message().c_str());
        return 1;
      }
      cpu += v.times().cpuMs;
      gpu += v.times().gpuMs;
      simMs += v.times().simMs;
    }
    (void)v.pick(640, 360);  // reads a depth texel: waits for the last frame
    const double wall = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
    std::printf(
        "{\"config\": \"%s\", \"renderer\": \"%s\", \"frames\": %d, \"wall_ms\": %.2f, \"cpu_ms\": %.2f, "
        "\"gpu_ms\": %.2f, \"sim_ms\": %.2f, \"size\": \"1280x720\", \"circles\": %d}\n",
        sim ? "flight+sim64x64x8" : "flight", ctx->info().renderer.c_str(), frames, wall / frames, cpu / frames,
        gpu / frames, simMs / frames, options.circles);
    if (!sim) continue;
    // Showing the region's water and suspended sediment, alone: the CPU round trip the viewer
    // used first (read both fields back, paste them into scene-sized grids, upload with mips)
    // against the GPU-to-GPU copy of the state buffer it uses now; glFinish after each.
    const auto& sm = *v.region()->sim;
    const auto& r = v.region()->rect;
    auto& scene = v.scene();
    auto timeMs = [&](auto&& body) {
      gl::finish();
      const auto t = std::chrono::steady_clock::now();
      for (int i = 0; i < frames; ++i) {
        body();
        gl::finish();
      }
      return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t).count() / frames;
    };
    const double roundTrip = timeMs([&] {
      for (int field = 0; field < 2; ++field) {
        const auto g = field == 0 ? sm.readWaterDepth() : sm.readSuspended();
        gis::Grid<float> full(scene.width(), scene.height(), 0.0f);
        for (int y = 0; y < r.height; ++y)
          std::copy_n(&g.data[size_t(y) * size_t(r.width)], r.width, &full.at(r.x, r.y + y));
        (void)(field == 0 ? scene.setWaterDepth(full) : scene.setSuspendedSediment(full));
      }
    });
    const double gpuCopy = timeMs([&] { scene.copyWaterState(sm.stateBuffer(), r.x, r.y, r.width, r.height); });
    std::printf(
        "{\"config\": \"water-display\", \"renderer\": \"%s\", \"scene\": \"%dx%d\", \"region\": \"%dx%d\", "
        "\"cpu_roundtrip_ms\": %.3f, \"gpu_copy_ms\": %.3f}\n",
        ctx->info().renderer.c_str(), scene.width(), scene.height(), r.width, r.height, roundTrip, gpuCopy);
  }
  return 0;
}
