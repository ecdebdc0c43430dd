// Terrain renderers side by side: frame time (draw + glFinish, wall clock: on llvmpipe the
// "GPU" is the CPU), the GPU timer query's figure, the time until draw() returns, triangles per
// second and the screen-space error against the full-resolution grid, for the ring renderer at
// several circle counts and the brute-force grid; and the ring renderer's own CPU work per frame
// (frame geometry and ring layout, what the seed claims is near zero and independent of the
// terrain's size).
// Synthetic DEMs of growing size from the same kind of camera (the ring's cost does not grow
// with the DEM; the grid's does). The Grand Canyon errors are in the gpu test's report
// (build/test-output/render/ring_error.txt).
//   build/bench/strata_bench_render [--benchmark_filter=...]
// Figures: docs/benchmarks.md ("Render").
#include <benchmark/benchmark.h>

#include "bench_context.hpp"

#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <map>
#include <memory>

#include <strata/render/gl/objects.hpp>
#include <strata/render/terrain/screen_error.hpp>
#include <strata/render/terrain/sliding_grid.hpp>
#include <strata/render/terrain/synthetic_dem.hpp>
#include <strata/render/terrain/terrain_renderer.hpp>

namespace {
using namespace strata::render;
using namespace strata::render::terrain;

// Synthetic DEM of size^2 cells of 30 m, cached; the camera 1500 m above its south-centre,
// looking north 20 degrees down.
struct Setup {
  std::unique_ptr<TerrainScene> scene;
  CameraPose camera;
};

Setup& synthetic(int size) {
  static std::map<int, Setup> cache;
  auto it = cache.find(size);
  if (it != cache.end()) return it->second;
  strata::bench::glContext();
  auto scene = TerrainScene::create(syntheticDem(size, 30.0, 400.0, 1));
  if (!scene) {
    std::fprintf(stderr, "%s\n", scene.message().c_str());
    std::exit(1);
  }
  Setup s;
  s.scene = std::make_unique<TerrainScene>(std::move(scene).value());
  const double x = 500000 + size * 30.0 / 2, y = 4000000 - size * 30.0 * 0.9;
  s.camera = {.lon = x, .lat = y, .heightM = s.scene->heightAt(x, y) + 1500, .headingDeg = 0, .pitchDeg = -20};
  return cache.emplace(size, std::move(s)).first->second;
}

// Renders with `renderer` until the benchmark is done; reports GPU time as the iteration time
// and the CPU submission time, triangles/s and screen-space error as counters.
void runFrames(benchmark::State& state, TerrainRenderer& renderer, const TerrainScene& scene, const CameraPose& camera,
               int w, int h) {
  auto target = OffscreenTarget::create(w, h);
  if (!target) {
    state.SkipWithError(target.message().c_str());
    return;
  }
  const Shading shading;
  if (auto s = renderer.draw(scene, camera, shading, *target); !s) {  // warm-up: compiles, uploads
    state.SkipWithError(s.message().c_str());
    return;
  }
  glFinish();
  double submitMs = 0, timerMs = 0;
  for (auto _ : state) {
    gl::GpuTimer t;
    const auto c0 = std::chrono::steady_clock::now();
    t.begin();
    (void)renderer.draw(scene, camera, shading, *target);
    t.end();
    const auto c1 = std::chrono::steady_clock::now();
    glFinish();
    const auto c2 = std::chrono::steady_clock::now();
    submitMs += std::chrono::duration<double, std::milli>(c1 - c0).count();
    timerMs += t.milliseconds();
    state.SetIterationTime(std::chrono::duration<double>(c2 - c0).count());
  }
  const double tris = double(renderer.trianglesPerFrame(scene));
  state.counters["submit_ms"] = submitMs / double(state.iterations());
  state.counters["gpu_timer_ms"] = timerMs / double(state.iterations());
  state.counters["triangles"] = tris;
  state.counters["tris/s"] = benchmark::Counter(tris * double(state.iterations()), benchmark::Counter::kIsRate);
  const ScreenError e = screenSpaceError(scene, camera, shading, *target);
  state.counters["err_mean_px"] = e.meanPx;
  state.counters["err_p99_px"] = e.p99Px;
}

// Ring (circles = range(0) > 0), sliding grid (range(0) = -levels, 2x64 cells a level) or the
// full grid (range(0) = 0) on a synthetic DEM of range(1)^2 cells.
void BM_Synthetic(benchmark::State& state) {
  Setup& s = synthetic(int(state.range(1)));
  const int circles = int(state.range(0));
  std::unique_ptr<TerrainRenderer> r;
  if (circles < 0) {
    auto g = SlidingGridRenderer::create({.halfCells = 64, .levels = -circles});
    if (!g) return state.SkipWithError(g.message().c_str());
    r = std::move(g).value();
  } else if (circles == 0) {
    auto g = GridRenderer::create();
    if (!g) return state.SkipWithError(g.message().c_str());
    r = std::move(g).value();
  } else {
    auto g = RingRenderer::create({.circles = circles});
    if (!g) return state.SkipWithError(g.message().c_str());
    r = std::move(g).value();
  }
  state.SetLabel(r->name());
  runFrames(state, *r, *s.scene, s.camera, int(state.range(2)), int(state.range(3)));
}
BENCHMARK(BM_Synthetic)
    ->ArgNames({"circles", "dem", "w", "h"})
    ->Args({64, 512, 640, 360})
    ->Args({128, 512, 640, 360})
    ->Args({192, 512, 640, 360})
    ->Args({256, 512, 640, 360})
    ->Args({0, 512, 640, 360})
    ->Args({-4, 512, 640, 360})
    ->Args({-6, 2048, 640, 360})
    ->Args({128, 1024, 640, 360})
    ->Args({0, 1024, 640, 360})
    ->Args({128, 2048, 640, 360})
    ->Args({0, 2048, 640, 360})
    ->Args({128, 512, 1280, 720})
    ->Args({0, 512, 1280, 720})
    ->UseManualTime()
    ->Unit(benchmark::kMillisecond)
    ->MinTime(0.3);

// The ring renderer's CPU work per frame: frame geometry (camera, projection, ground height) and
// the ring layout, for DEMs of range(0)^2 cells. No GL calls are timed.
void BM_RingCpuPerFrame(benchmark::State& state) {
  Setup& s = synthetic(int(state.range(0)));
  auto ring = RingRenderer::create({.circles = 256});
  if (!ring) return state.SkipWithError(ring.message().c_str());
  const Shading shading;
  CameraPose cam = s.camera;
  for (auto _ : state) {
    cam.lon += 0.01;
    const FrameGeometry f = frameGeometry(*s.scene, cam, shading, 1280, 720);
    benchmark::DoNotOptimize((*ring)->layout(*s.scene, f));
  }
}
BENCHMARK(BM_RingCpuPerFrame)->ArgName("dem")->Arg(512)->Arg(2048)->Unit(benchmark::kMicrosecond);

}  // namespace
int main(int argc, char** argv) { return strata::bench::benchGlMain(argc, argv); }
