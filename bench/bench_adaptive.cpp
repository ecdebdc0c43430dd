// Adaptive tiles against the full-resolution run, side by side in one process: a flood from a
// spring in the Grand Canyon (tests/support/canyon_flood.hpp). For each run one JSON line:
// wall ms per step (host transfers included), relative L1 of depth and wet-area agreement
// (h > 0.1 m) against the full-resolution run, water-balance error over the inflow, and the
// fraction of cell updates (tile interiors, and with the halos the GPU also computes). Runs: full resolution (one
// Simulation), the same tiles all at level 0 (TiledSolver: the cost of tiling alone), adaptive with the default
// options, adaptive "coarse" (no look-ahead, speed and depth references 0.5), and "coarse" without refluxing (to
// measure what the flux matching buys).
//   build/bench/strata_bench_adaptive [n steps tile [notiled]]   (defaults 256 300 64)
// Figures go to docs/benchmarks.md.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <functional>
#include <string>

#include <strata/gl/context.hpp>
#include <strata/sim/adaptive_solver.hpp>
#include <strata/sim/gl/gl_solver.hpp>
#include <strata/sim/tiled_solver.hpp>

#include "canyon_flood.hpp"

namespace {
using namespace strata;
using namespace strata::sim;

struct Outcome {
  gis::Grid<float> depth;
  SimStats stats;
  double msPerStep = 0, cellFraction = 1, computedFraction = 1;
};

template <class Sim>
Outcome runIt(Sim& sim, int steps, const std::function<double()>& fraction, const std::function<double()>& computed) {
  const auto t0 = std::chrono::steady_clock::now();
  sim.step(steps);
  Outcome o;
  o.depth = sim.readWaterDepth();
  o.msPerStep = 1e3 * std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count() / steps;
  o.stats = sim.stats();
  o.cellFraction = fraction();
  o.computedFraction = computed();
  return o;
}

void report(const char* name, const Outcome& o, const Outcome& full, const std::vector<double>& rowDx, double dy) {
  double diff = 0, total = 0;
  long both = 0, either = 0;
  const int w = o.depth.width;
  for (size_t i = 0; i < o.depth.size(); ++i) {
    const double a = rowDx[i / size_t(w)] * dy;
    diff += std::abs(double(o.depth.data[i]) - double(full.depth.data[i])) * a;
    total += double(full.depth.data[i]) * a;
    both += o.depth.data[i] > 0.1f && full.depth.data[i] > 0.1f;
    either += o.depth.data[i] > 0.1f || full.depth.data[i] > 0.1f;
  }
  std::printf(
      "{\"run\": \"%s\", \"ms_per_step\": %.2f, \"speedup\": %.3f, \"rel_l1_depth\": %.4g, \"wet_agreement\": %.5f, "
      "\"balance_error\": %.3g, \"cell_fraction\": %.4f, \"computed_fraction\": %.4f, \"time_s\": %.1f, \"stored_m3\": "
      "%.7g}\n",
      name, o.msPerStep, full.msPerStep / o.msPerStep, diff / total, double(both) / double(std::max(1L, either)),
      std::abs(o.stats.waterBalanceM3()) / std::max(1.0, o.stats.inflowM3), o.cellFraction, o.computedFraction,
      o.stats.timeS, o.stats.storedWaterM3);
  std::fflush(stdout);
}
}  // namespace

int main(int argc, char** argv) {
  const int n = argc > 1 ? std::atoi(argv[1]) : 256, steps = argc > 2 ? std::atoi(argv[2]) : 300,
            tile = argc > 3 ? std::atoi(argv[3]) : 64;
  auto ctx = gl::HeadlessContext::create({.debugOutput = false});
  if (!ctx) {
    std::fprintf(stderr, "%s\n", ctx.message().c_str());
    return 1;
  }
  // The window's south-west part holds the main canyon; the spring sits in the river channel.
  const int x0 = std::min(288, 512 - n), y0 = std::min(353, 512 - n);
  auto scene = test::canyonFlood(std::string(STRATA_DATA_DIR) + "/grand_canyon/grand_canyon_512.tif", x0, y0, n, 352,
                                 417, 5000.0);
  if (!scene) {
    std::fprintf(stderr, "%s\n", scene.message().c_str());
    return 1;
  }
  std::printf("{\"grid\": %d, \"steps\": %d, \"tile\": %d, \"renderer\": \"%s\"}\n", n, steps, tile,
              ctx->info().renderer.c_str());
  auto full = GlSolver::create(scene->input, scene->params);
  if (!full || !full->addSource(scene->spring)) return 1;
  const auto ref = runIt(
      *full, steps, [] { return 1.0; }, [] { return 1.0; });
  report("full", ref, ref, scene->input.rowDxM, scene->input.dyM);
  if (argc <= 4 || std::string(argv[4]) != "notiled") {
    auto tiled = TiledSolver::create(scene->input, scene->params, TileOptions{tile, tile, 8}, glSolverFactory());
    if (!tiled || !tiled->addSource(scene->spring)) return 1;
    report("tiled_level0",
           runIt(
               *tiled, steps, [] { return 1.0; },
               [&] {
                 const double e =
                     double(n / tile) * (tile + 16.0) - 16.0;  // extended cells per row, region edges clipped
                 return e * e / (double(n) * n);
               }),
           ref, scene->input.rowDxM, scene->input.dyM);
  }
  AdaptiveOptions def;
  def.tileSize = tile;
  AdaptiveOptions coarse = def;
  coarse.lookaheadCells = 0;
  coarse.speedRefMS = 0.5f;
  coarse.depthChangeRefM = 0.5f;
  AdaptiveOptions noReflux = coarse;
  noReflux.reflux = false;
  for (auto [name, o] : {std::pair{"adaptive_default", def}, std::pair{"adaptive_coarse", coarse},
                         std::pair{"adaptive_coarse_no_reflux", noReflux}}) {
    auto a = AdaptiveSolver::create(scene->input, scene->params, o, glSolverFactory());
    if (!a) {
      std::fprintf(stderr, "%s\n", a.message().c_str());
      return 1;
    }
    if (!a->addSource(scene->spring)) return 1;
    report(name,
           runIt(
               *a, steps, [&] { return a->cellFraction(); }, [&] { return a->computedCellFraction(); }),
           ref, scene->input.rowDxM, scene->input.dyM);
  }
  return 0;
}
