// GPU simulation step cost (render::sim::Simulation), timed with GPU timer queries: ms per
// step, cell updates per second, and the bytes each step moves per cell (what the kernels read
// and write once per cell, counting neighbour reads as cache hits), for the virtual-pipe water
// model alone and with erosion + thermal weathering on four layers, and for flood mode.
//   build/bench/strata_bench_sim [--benchmark_filter=...]
// Figures go to docs/benchmarks.md.
#include <benchmark/benchmark.h>

#include "bench_context.hpp"

#include <cmath>

#include <strata/render/gl/objects.hpp>
#include <strata/render/sim/simulation.hpp>
#include <strata/terrain/material.hpp>

namespace {
using namespace strata;
namespace ts = strata::terrain::sim;

// Bytes per cell per step, summed over the kernels (see the kernel headers for what each reads
// and writes): sources 40, pipe_flux 56, pipe_update 56; erode 76, thermal_flux 40,
// thermal_apply 56; flood: fv_face 2 x 48, fv_update 2 x 56 (+ sediment, accumulators, the
// corrector's 4 B of W25 limits), fv_limit 52 (own faces, state, limit), wave speed 16.
constexpr double kPipeBytes = 152, kErosionBytes = 152 + 172, kFloodBytes = 40 + 96 + 140 + 52 + 16;

// A rolling 4-layer terrain with water in its hollows, n x n cells of 10 m.
ts::SimInput terrainOf(int n) {
  ts::SimInput in;
  in.baseM = gis::Grid<float>(n, n);
  in.waterDepthM = gis::Grid<float>(n, n);
  in.rowDxM = {10.0};
  in.dyM = 10.0;
  in.datumM = 2000.0;
  in.materials = terrain::defaultMaterials();
  in.layersM.assign(4, gis::Grid<float>(n, n, 0.5f));
  for (int y = 0; y < n; ++y) {
    for (int x = 0; x < n; ++x) {
      const double fx = double(x) / n, fy = double(y) / n;
      const double b = 5.0 * std::sin(9.0 * fx) * std::cos(7.0 * fy) + 3.0 * fx;
      in.baseM.at(x, y) = float(2000.0 + b);
      in.waterDepthM.at(x, y) = float(std::max(0.0, 1.0 - b));
    }
  }
  return in;
}

// `levelEdge`: the whole west column held at a fixed level (W26) 1 m above the datum.
void run(benchmark::State& state, ts::SimParams p, double bytesPerCell, bool levelEdge = false) {
  strata::bench::glContext();
  const int n = int(state.range(0));
  const auto input = terrainOf(n);
  auto sim = render::sim::Simulation::create(input, p);
  if (!sim) {
    state.SkipWithError(sim.message().c_str());
    return;
  }
  if (levelEdge) {
    ts::LevelBoundary level;
    for (int y = 0; y < n; ++y) level.cells.push_back({0, y});
    level.stageM = {{0.0, input.datumM + 1.0}};
    if (auto st = sim->addLevel(level); !st) state.SkipWithError(st.message().c_str());
  }
  sim->step(2);  // warm up: first dispatches compile and page in
  const int stepsPerIteration = n >= 1024 ? 1 : 4;
  for (auto _ : state) {
    render::gl::GpuTimer t;
    t.begin();
    sim->step(stepsPerIteration);
    t.end();
    state.SetIterationTime(t.milliseconds() * 1e-3 / stepsPerIteration);
  }
  const double cells = double(n) * n;
  state.counters["cells/s"] = benchmark::Counter(cells * double(state.iterations()), benchmark::Counter::kIsRate);
  state.counters["B/cell/step"] = bytesPerCell;
  state.counters["gpu_MB"] = double(sim->gpuBytes()) / 1e6;
  state.SetBytesProcessed(int64_t(double(state.iterations()) * cells * bytesPerCell));
}

void BM_SimPipes(benchmark::State& state) {
  ts::SimParams p;
  p.maxDtS = 0.2f;
  p.pipeAreaM2 = 100.0f;
  p.rainMmPerHour = 10.0f;
  run(state, p, kPipeBytes);
}

void BM_SimPipesErosion4Layers(benchmark::State& state) {
  ts::SimParams p;
  p.maxDtS = 0.2f;
  p.pipeAreaM2 = 100.0f;
  p.rainMmPerHour = 10.0f;
  p.erosionEnabled = 1;
  p.thermalEnabled = 1;
  p.capacityK = 0.05f;
  p.erosionRate = 0.5f;
  p.depositionRate = 0.3f;
  run(state, p, kErosionBytes);
}

void BM_SimFlood(benchmark::State& state) {
  ts::SimParams p;
  p.waterModel = int32_t(ts::WaterModel::kFiniteVolume);
  p.maxDtS = 5.0f;
  p.cflAlpha = 0.45f;
  p.manningN = 0.03f;
  run(state, p, kFloodBytes);
}

// BM_SimFlood with a fixed level on its west edge: the level pass's cost, side by side.
void BM_SimFloodLevelEdge(benchmark::State& state) {
  ts::SimParams p;
  p.waterModel = int32_t(ts::WaterModel::kFiniteVolume);
  p.maxDtS = 5.0f;
  p.cflAlpha = 0.45f;
  p.manningN = 0.03f;
  run(state, p, kFloodBytes, true);
}

BENCHMARK(BM_SimPipes)->Arg(256)->Arg(512)->Arg(1024)->Arg(2048)->UseManualTime()->Unit(benchmark::kMillisecond);
BENCHMARK(BM_SimPipesErosion4Layers)
    ->Arg(256)
    ->Arg(512)
    ->Arg(1024)
    ->Arg(2048)
    ->UseManualTime()
    ->Unit(benchmark::kMillisecond);
BENCHMARK(BM_SimFlood)->Arg(256)->Arg(512)->Arg(1024)->Arg(2048)->UseManualTime()->Unit(benchmark::kMillisecond);
BENCHMARK(BM_SimFloodLevelEdge)->Arg(256)->Arg(512)->Arg(1024)->UseManualTime()->Unit(benchmark::kMillisecond);

}  // namespace

int main(int argc, char** argv) { return strata::bench::benchGlMain(argc, argv); }
