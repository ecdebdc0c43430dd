// Procedural terrain: the CDF 5/3 and 9/7 transforms on the GPU (timer queries) next to the CPU
// reference, and whole generation runs (wall time: compile + fill + inverse + read back).
//   build/bench/strata_bench_procgen [--benchmark_filter=...]
// Figures: docs/benchmarks.md, "Procedural".
#include <benchmark/benchmark.h>

#include "bench_context.hpp"

#include <chrono>
#include <cmath>

#include <strata/procgen/generator.hpp>
#include <strata/procgen/wavelet.hpp>
#include <strata/procgen/wavelet_gpu.hpp>

namespace {
using namespace strata;
constexpr int kLevels = 6;

strata::gis::Grid<float> field(int n) {
  strata::gis::Grid<float> g(n, n);
  for (int y = 0; y < n; ++y) {
    for (int x = 0; x < n; ++x) g.at(x, y) = float(1000.0 + 300.0 * std::sin(x * 0.05) * std::cos(y * 0.03));
  }
  return g;
}

void BM_WaveletGpu(benchmark::State& state, bool inverse, strata::procgen::Wavelet kind) {
  strata::bench::sharedContext();
  const int n = int(state.range(0));
  auto wavelet = procgen::WaveletGpu::create();
  if (!wavelet) {
    state.SkipWithError(wavelet.message().c_str());
    return;
  }
  auto tex = procgen::uploadGrid(field(n));
  wavelet->forward(tex, kLevels, kind);  // warm-up (allocates the scratch texture)
  for (auto _ : state) {
    gl::GpuTimer t;
    t.begin();
    if (inverse) {
      wavelet->inverse(tex, kLevels, kind);
    } else {
      wavelet->forward(tex, kLevels, kind);
    }
    t.end();
    state.SetIterationTime(t.milliseconds() * 1e-3);
  }
}
using strata::procgen::Wavelet;
void BM_Cdf53ForwardGpu(benchmark::State& s) { BM_WaveletGpu(s, false, Wavelet::Cdf53); }
void BM_Cdf53InverseGpu(benchmark::State& s) { BM_WaveletGpu(s, true, Wavelet::Cdf53); }
void BM_Cdf97ForwardGpu(benchmark::State& s) { BM_WaveletGpu(s, false, Wavelet::Cdf97); }
void BM_Cdf97InverseGpu(benchmark::State& s) { BM_WaveletGpu(s, true, Wavelet::Cdf97); }
BENCHMARK(BM_Cdf53ForwardGpu)->Arg(512)->Arg(1024)->Arg(2048)->UseManualTime()->Unit(benchmark::kMillisecond);
BENCHMARK(BM_Cdf53InverseGpu)->Arg(512)->Arg(1024)->Arg(2048)->UseManualTime()->Unit(benchmark::kMillisecond);
BENCHMARK(BM_Cdf97ForwardGpu)->Arg(512)->Arg(1024)->Arg(2048)->UseManualTime()->Unit(benchmark::kMillisecond);
BENCHMARK(BM_Cdf97InverseGpu)->Arg(512)->Arg(1024)->Arg(2048)->UseManualTime()->Unit(benchmark::kMillisecond);

// The CPU reference, single-threaded: the baseline of the GPU figures above.
void BM_WaveletForwardCpu(benchmark::State& state, Wavelet kind) {
  const auto g = field(int(state.range(0)));
  for (auto _ : state) benchmark::DoNotOptimize(strata::procgen::forwardTransform(g, kLevels, kind));
}
void BM_Cdf53ForwardCpu(benchmark::State& s) { BM_WaveletForwardCpu(s, Wavelet::Cdf53); }
void BM_Cdf97ForwardCpu(benchmark::State& s) { BM_WaveletForwardCpu(s, Wavelet::Cdf97); }
BENCHMARK(BM_Cdf53ForwardCpu)->Arg(512)->Arg(1024)->Arg(2048)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_Cdf97ForwardCpu)->Arg(512)->Arg(1024)->Arg(2048)->Unit(benchmark::kMillisecond);

// A whole run of seed example 1 (height form) and of a level-form script with histogram
// matching against a DEM (the CPU sort per band included), wall time.
void BM_Generate(benchmark::State& state, const char* glsl, bool withDem) {
  strata::bench::sharedContext();
  const int n = int(state.range(0));
  procgen::GenerateOptions o;
  o.width = o.height = n;
  o.seed = 7;
  o.levels = kLevels;
  if (withDem) {
    o.dems.push_back(field(512));
    o.matchDem = 0;
  }
  for (auto _ : state) {
    auto r = procgen::generate({"bench.glsl", glsl, 1}, o);
    if (!r) {
      state.SkipWithError(r.message().c_str());
      return;
    }
    benchmark::DoNotOptimize(r->data.data());
  }
}
constexpr const char* kHeight =
    "float height(vec2 p) {\n"
    "  float hills = 120.0 * fbm(p / 96.0, 7, 0.5, 2.0);\n"
    "  float dunes = wave(p, normalize(vec2(1.0, 0.3)), 24.0, 4.0, 0.0);\n"
    "  return hills + dunes + peak(p, 0.5 * SIZE, 0.12 * SIZE.x, 600.0);\n"
    "}\n";
constexpr const char* kLike =
    "float level(vec2 p, int lvl) {\n"
    "  return lvl == LEVELS ? dem0Level(p, lvl) : whiteCoeff(p, lvl);\n"
    "}\n";
void BM_GenerateFbmWavesMountain(benchmark::State& s) { BM_Generate(s, kHeight, false); }
void BM_GenerateLikeDem(benchmark::State& s) { BM_Generate(s, kLike, true); }
BENCHMARK(BM_GenerateFbmWavesMountain)->Arg(512)->Arg(1024)->Arg(2048)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK(BM_GenerateLikeDem)->Arg(512)->Arg(1024)->Arg(2048)->Unit(benchmark::kMillisecond)->UseRealTime();

}  // namespace

int main(int argc, char** argv) { return strata::bench::benchGlMain(argc, argv); }
