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
// Streaming (BM_StreamedVsWhole, BM_StreamRefill): the same synthetic DEM drawn from a whole-
// DEM texture and streamed from a tile store (ingested once into $TMPDIR/strata_bench_stream_N),
// with the viewer gliding east; and the cost of refilling the stack when the viewer moves by
// one page.
// Drapes (BM_DrapeLoad, BM_DrapeFrame): the Grand Canyon's EPSG:4326 DEM draped as a ramp over
// its EPSG:3857 version (GDAL's warp with the exact transformer, then the ramp), and the frame
// time with and without a drape, side by side.
// Cast shadows (BM_CastShadows): the horizon search on the CPU at three sun elevations.
// The look (BM_LookFrame): frames plain, with sky and air, with cast shadows, with MSAA 4.
// Figures: docs/benchmarks.md ("Render").
#include <benchmark/benchmark.h>

#include "bench_context.hpp"

#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <map>
#include <memory>
#include <optional>
#include <thread>

#include <strata/gis/dem_io.hpp>
#include <strata/gl/objects.hpp>
#include <strata/gl/state.hpp>
#include <strata/render/drape.hpp>
#include <strata/render/screen_error.hpp>
#include <strata/render/sliding_grid.hpp>
#include <strata/render/sun.hpp>
#include <strata/render/synthetic_dem.hpp>
#include <strata/render/terrain_renderer.hpp>
#include <strata/terrain/ingest.hpp>
#include <strata/terrain/tile_store.hpp>

namespace {
using namespace strata;
using namespace strata::render;

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
  strata::bench::sharedContext();
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
               int w, int h, const Shading& shading = {}, int samples = 1) {
  auto target = OffscreenTarget::create(w, h, samples);
  if (!target) {
    state.SkipWithError(target.message().c_str());
    return;
  }
  if (auto s = renderer.draw(scene, camera, shading, *target); !s) {  // warm-up: compiles, uploads
    state.SkipWithError(s.message().c_str());
    return;
  }
  gl::finish();
  double submitMs = 0, timerMs = 0;
  for (auto _ : state) {
    gl::GpuTimer t;
    const auto c0 = std::chrono::steady_clock::now();
    t.begin();
    (void)renderer.draw(scene, camera, shading, *target);
    t.end();
    const auto c1 = std::chrono::steady_clock::now();
    gl::finish();
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

// The synthetic DEM of size^2 cells as a tile store (tiles of 256 cells, 2^5..2^8), streamed
// with windows of 512 texels in pages of 64 and a 64 MiB GPU budget.
std::unique_ptr<TerrainScene> streamedSynthetic(int size, int uploadPages, size_t gpuBudget = size_t(64) << 20,
                                                bool waitForDisk = true, double loadDelayMs = 0) {
  strata::bench::sharedContext();  // also when no whole-DEM benchmark ran first
  const auto dir = std::filesystem::temp_directory_path() / ("strata_bench_stream_" + std::to_string(size));
  if (!std::filesystem::exists(dir / "manifest.toml")) {
    std::filesystem::remove_all(dir);
    const auto dem = syntheticDem(size, 30.0, 400.0, 1);
    strata::terrain::WindowReader read = [&dem](int x, int y, int w,
                                                int h) -> strata::Result<strata::gis::Grid<float>> {
      strata::gis::Grid<float> g(w, h, strata::gis::kNoData);
      for (int j = 0; j < h; ++j) {
        for (int i = 0; i < w; ++i) {
          if (dem.values.contains(x + i, y + j)) g.at(i, j) = dem.values.at(x + i, y + j);
        }
      }
      return g;
    };
    strata::terrain::IngestOptions o;
    o.metric = {.minExp = 5, .maxExp = 8};
    auto rep =
        strata::terrain::ingest(dir, dem.georef, {{{"bedrock", strata::terrain::LayerKind::Bedrock, ""}, read}}, o);
    if (!rep) {
      std::fprintf(stderr, "%s\n", rep.message().c_str());
      std::exit(1);
    }
  }
  auto store = strata::terrain::TileStore::open(
      dir, {.budgetBytes = size_t(256) << 20, .prefetch = false, .loadDelayMs = loadDelayMs});
  if (!store) {
    std::fprintf(stderr, "%s\n", store.message().c_str());
    std::exit(1);
  }
  auto scene = TerrainScene::createStreamed(std::move(store).value(), {.clipSize = 512,
                                                                       .pageSize = 64,
                                                                       .uploadPagesPerFrame = uploadPages,
                                                                       .gpuBudgetBytes = gpuBudget,
                                                                       .waitForDisk = waitForDisk});
  if (!scene) {
    std::fprintf(stderr, "%s\n", scene.message().c_str());
    std::exit(1);
  }
  return std::make_unique<TerrainScene>(std::move(scene).value());
}

// Ring renderer (128 circles, 640x360) on a synthetic DEM of range(1)^2 cells, whole-DEM
// texture (range(0) = 0) or streamed from a store (range(0) = 1), the viewer gliding east 15 m
// (half a cell) a frame: the draw's CPU time (submit_ms, including the stack's refill), the GPU
// timer and the wall time to glFinish.
void BM_StreamedVsWhole(benchmark::State& state) {
  const bool streamed = state.range(0) != 0;
  const int size = int(state.range(1));
  Setup& s = synthetic(size);
  std::unique_ptr<TerrainScene> owned = streamed ? streamedSynthetic(size, 64) : nullptr;
  const TerrainScene& scene = streamed ? *owned : *s.scene;
  auto ring = RingRenderer::create({.circles = 128});
  if (!ring) return state.SkipWithError(ring.message().c_str());
  auto target = OffscreenTarget::create(640, 360);
  if (!target) return state.SkipWithError(target.message().c_str());
  const Shading shading;
  CameraPose cam = s.camera;
  // Warm-up: compiles, and (streamed) fills the windows.
  for (int i = 0; i < 100; ++i) {
    if (auto r = (*ring)->draw(scene, cam, shading, *target); !r) return state.SkipWithError(r.message().c_str());
    if (!streamed || scene.streamed()->stats().pending == 0) break;
  }
  gl::finish();
  double submitMs = 0, timerMs = 0;
  uint64_t copied0 = streamed ? scene.streamed()->stats().pagesCopied : 0;
  for (auto _ : state) {
    cam.lon += 15.0;
    gl::GpuTimer t;
    const auto c0 = std::chrono::steady_clock::now();
    t.begin();
    (void)(*ring)->draw(scene, cam, shading, *target);
    t.end();
    const auto c1 = std::chrono::steady_clock::now();
    gl::finish();
    const auto c2 = std::chrono::steady_clock::now();
    submitMs += std::chrono::duration<double, std::milli>(c1 - c0).count();
    timerMs += t.milliseconds();
    state.SetIterationTime(std::chrono::duration<double>(c2 - c0).count());
  }
  state.SetLabel(streamed ? "streamed" : "whole");
  state.counters["submit_ms"] = submitMs / double(state.iterations());
  state.counters["gpu_timer_ms"] = timerMs / double(state.iterations());
  if (streamed) {
    const auto st = scene.streamed()->stats();
    state.counters["pages/frame"] = double(st.pagesCopied - copied0) / double(state.iterations());
    state.counters["gpu_MiB"] = double(st.gpuBytes) / 1048576.0;
  }
}
BENCHMARK(BM_StreamedVsWhole)
    ->ArgNames({"streamed", "dem"})
    ->Args({0, 2048})
    ->Args({1, 2048})
    ->UseManualTime()
    ->Unit(benchmark::kMillisecond)
    ->Iterations(6);

// Refill when the viewer moves by one page (64 cells) east or west along a 16-page stretch:
// update() alone (CPU, page uploads from the store's RAM cache into the GPU tile cache, GPU
// copies into the stack) to glFinish. Pages per move and how many came from RAM (GPU cache
// misses): with a 64 MiB budget (range(0) = 64) the stretch stays in the GPU cache; with 4 MiB
// (the stack takes 3.4 of it) nearly every page is uploaded again.
void BM_StreamRefill(benchmark::State& state) {
  auto scene = streamedSynthetic(2048, 1000, size_t(state.range(0)) << 20);
  auto* st = scene->streamed();
  glm::dvec2 cell(512, 1024);
  if (auto r = st->update(cell); !r) return state.SkipWithError(r.message().c_str());
  gl::finish();
  const auto before = st->stats();
  int step = 0;
  for (auto _ : state) {
    cell.x += ((step++ / 16) % 2 ? -64.0 : 64.0);
    const auto c0 = std::chrono::steady_clock::now();
    (void)st->update(cell);
    gl::finish();
    state.SetIterationTime(std::chrono::duration<double>(std::chrono::steady_clock::now() - c0).count());
  }
  const auto after = st->stats();
  const double n = double(state.iterations());
  state.counters["pages/move"] = double(after.pagesCopied - before.pagesCopied) / n;
  state.counters["ram_uploads/move"] = double(after.cache.uploads - before.cache.uploads) / n;
}
BENCHMARK(BM_StreamRefill)
    ->ArgName("budget_MiB")
    ->Arg(64)
    ->Arg(4)
    ->UseManualTime()
    ->Unit(benchmark::kMillisecond)
    ->MinTime(0.3);

// A move of one page with a COLD RAM cache (cleared before each move; the 4 MiB GPU budget
// keeps no spare page either), so every entering page needs a tile decode: update() + glFinish
// with waitForDisk (range(0) = 1: the frame decodes) or without (0: the store's loader decodes,
// the frame copies what is ready). Untimed after each move, the loader is let catch up so that
// every move starts from full windows; catch_up_ms is that wait (asynchronous mode). range(1):
// milliseconds added to every tile decode (0: this machine's disk and page cache; 10: a slow
// disk or network store).
void BM_StreamColdRefill(benchmark::State& state) {
  const bool wait = state.range(0) != 0;
  auto scene = streamedSynthetic(2048, 1000, size_t(4) << 20, wait, double(state.range(1)));
  auto* st = scene->streamed();
  glm::dvec2 cell(512, 1024);
  auto settle = [&]() -> strata::Status {
    while (st->stats().pending > 0) {
      STRATA_TRY_STATUS(st->update(cell));
      if (st->stats().pending > 0) std::this_thread::sleep_for(std::chrono::microseconds(200));
    }
    return {};
  };
  if (auto r = settle(); !r) return state.SkipWithError(r.message().c_str());
  gl::finish();
  const auto before = st->stats();
  const auto loads0 = st->store().cacheStats();
  double catchUpMs = 0, waiting = 0;
  int step = 0;
  for (auto _ : state) {
    st->store().clearCache();
    cell.x += ((step++ / 16) % 2 ? -64.0 : 64.0);
    const auto c0 = std::chrono::steady_clock::now();
    (void)st->update(cell);
    gl::finish();
    const auto c1 = std::chrono::steady_clock::now();
    state.SetIterationTime(std::chrono::duration<double>(c1 - c0).count());
    waiting += st->stats().lastFramePagesWaiting;
    if (auto r = settle(); !r) return state.SkipWithError(r.message().c_str());
    catchUpMs += std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - c1).count();
  }
  const auto after = st->stats();
  const auto loads1 = st->store().cacheStats();
  const double n = double(state.iterations());
  state.SetLabel(wait ? "blocking" : "async");
  state.counters["pages/move"] = double(after.pagesCopied - before.pagesCopied) / n;
  state.counters["deferred/move"] = waiting / n;
  state.counters["caller_decodes/move"] = double(loads1.syncLoads - loads0.syncLoads) / n;
  state.counters["loader_decodes/move"] = double(loads1.requestLoads - loads0.requestLoads) / n;
  state.counters["catch_up_ms"] = catchUpMs / n;
}
BENCHMARK(BM_StreamColdRefill)
    ->ArgNames({"wait", "delay_ms"})
    ->Args({1, 0})
    ->Args({0, 0})
    ->Args({1, 10})
    ->Args({0, 10})
    ->UseManualTime()
    ->Unit(benchmark::kMillisecond)
    ->Iterations(32);  // two sweeps of the stretch (a fixed count: the untimed catch-up dominates)

const std::string kDrapeDem = std::string(STRATA_DATA_DIR) + "/grand_canyon/grandcanyon_srtm_3857.tif";
const std::string kDrapeRaster = std::string(STRATA_DATA_DIR) + "/grand_canyon/grand_canyon_512.tif";

// loadDrape at range(0) texels per DEM cell a side (512^2 cells).
void BM_DrapeLoad(benchmark::State& state) {
  auto info = gis::probeDem(kDrapeDem);
  if (!info) return state.SkipWithError(info.message().c_str());
  DrapeOptions o;
  o.texelsPerCell = int(state.range(0));
  for (auto _ : state) {
    auto img = loadDrape(kDrapeRaster, info->georef, o);
    if (!img) return state.SkipWithError(img.message().c_str());
    benchmark::DoNotOptimize(img->rgba.data());
  }
  const double texels = double(info->georef.width) * info->georef.height * o.texelsPerCell * o.texelsPerCell;
  state.counters["Mtexels"] = texels / 1e6;
  state.counters["texels/s"] = benchmark::Counter(texels * double(state.iterations()), benchmark::Counter::kIsRate);
}
BENCHMARK(BM_DrapeLoad)->ArgName("texels_per_cell")->Arg(1)->Arg(4)->Unit(benchmark::kMillisecond);

// The ring renderer (256 circles, 960 x 540) over the 3857 DEM, without (0) and with (1) the drape.
void BM_DrapeFrame(benchmark::State& state) {
  strata::bench::sharedContext();
  auto dem = gis::readDem(kDrapeDem);
  if (!dem) return state.SkipWithError(dem.message().c_str());
  auto scene = TerrainScene::create(*dem);
  if (!scene) return state.SkipWithError(scene.message().c_str());
  if (state.range(0)) {
    auto img = loadDrape(kDrapeRaster, scene->georef());
    if (!img) return state.SkipWithError(img.message().c_str());
    if (auto st = scene->setDrape(*img); !st) return state.SkipWithError(st.message().c_str());
  }
  auto ring = RingRenderer::create({.circles = 256});
  if (!ring) return state.SkipWithError(ring.message().c_str());
  const auto& c = scene->georef().transform.c;
  const double x = c[0] + c[1] * scene->width() * 0.5, y = c[3] + c[5] * scene->height() * 0.8;
  const CameraPose cam{.lon = x, .lat = y, .heightM = scene->heightAt(x, y) + 3000, .headingDeg = 0, .pitchDeg = -25};
  state.SetLabel(state.range(0) ? "drape" : "no drape");
  runFrames(state, **ring, *scene, cam, 960, 540);
}
BENCHMARK(BM_DrapeFrame)->ArgName("drape")->Arg(0)->Arg(1)->UseManualTime()->Unit(benchmark::kMillisecond);

// The look's costs side by side (ring 256 circles, 960 x 540, the Grand Canyon from 3 km):
// 0 plain, 1 the sky pass and aerial perspective (Earth's air), 2 cast shadows (the lighting's
// extra texture read), 3 MSAA with 4 samples.
void BM_LookFrame(benchmark::State& state) {
  strata::bench::sharedContext();
  auto dem = gis::readDem(kDrapeRaster);
  if (!dem) return state.SkipWithError(dem.message().c_str());
  auto scene = TerrainScene::create(*dem);
  if (!scene) return state.SkipWithError(scene.message().c_str());
  auto ring = RingRenderer::create({.circles = 256});
  if (!ring) return state.SkipWithError(ring.message().c_str());
  Shading shading;
  int samples = 1;
  const char* labels[] = {"plain", "sky and air", "cast shadows", "MSAA 4"};
  if (state.range(0) == 1) shading.atmosphere = atmosphereFor(scene->georef().body);
  if (state.range(0) == 2) {
    shading.sunDir = glm::vec3(sunDirectionEnu(250.0, 20.0));
    if (auto st = scene->castShadows({.subsolarLonLat = std::nullopt, .dirEnu = glm::dvec3(shading.sunDir)}, 1.0f);
        !st) {
      return state.SkipWithError(st.message().c_str());
    }
  }
  if (state.range(0) == 3) samples = 4;
  const double x = -112.3, y = 36.3;
  const CameraPose cam{.lon = x, .lat = y, .heightM = scene->heightAt(x, y) + 2500, .headingDeg = 120, .pitchDeg = -10};
  state.SetLabel(labels[state.range(0)]);
  runFrames(state, **ring, *scene, cam, 960, 540, shading, samples);
}
BENCHMARK(BM_LookFrame)->ArgName("look")->DenseRange(0, 3)->UseManualTime()->Unit(benchmark::kMillisecond);

// Cast shadows on the CPU (castShadows, OpenMP over rows) for the Grand Canyon's 512^2 cells at
// a sun elevation of range(0) degrees from the west: the lower the sun, the farther each cell's
// horizon search runs (out to where the DEM's highest point could no longer rise above the sun).
void BM_CastShadows(benchmark::State& state) {
  auto dem = gis::readDem(kDrapeRaster);
  if (!dem) return state.SkipWithError(dem.message().c_str());
  SunSpec sun;
  sun.dirEnu = sunDirectionEnu(270.0, double(state.range(0)));
  double shadowed = 0;
  for (auto _ : state) {
    const auto lit = castShadows(dem->values, dem->georef, sun, 1.0f);
    shadowed = 0;
    for (float v : lit.data) shadowed += v < 0.5f ? 1 : 0;
    benchmark::DoNotOptimize(lit.data.data());
  }
  const double cells = double(dem->values.size());
  state.counters["shadowed"] = shadowed / cells;
  state.counters["cells/s"] = benchmark::Counter(cells * double(state.iterations()), benchmark::Counter::kIsRate);
}
BENCHMARK(BM_CastShadows)->ArgName("sun_elev_deg")->Arg(5)->Arg(10)->Arg(30)->Unit(benchmark::kMillisecond);

}  // namespace
int main(int argc, char** argv) { return strata::bench::benchGlMain(argc, argv); }
