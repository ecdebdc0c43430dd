// Also the flat-plain flood after the EA's test 4, whole, by scheme, backend and cell size
// (flat_plain/..., issue 35).
// Simulation step cost side by side in one run: the CPU backend (sim::CpuSolver) with 1 and 2
// OpenMP threads (and all cores, on a machine with more than two), and the GL backend
// (sim::GlSolver) on whatever GL the machine has (Mesa llvmpipe without a GPU), at 256^2 to 4096^2
// (4096^2 is for a GPU or a many-core machine: filter it out on a small one), for the virtual-pipe model, pipes +
// erosion + thermal weathering on four layers, and flood mode. Before the benchmarks the program measures the machine's
// floors with the same threads and instruction set the CPU kernels use: memory bandwidth (a STREAM triad, a[i] = b[i] +
// s c[i] on 64 MB arrays) and peak float throughput (independent multiply + add chains; the kernels do not contract
// into FMA). Each benchmark reports ms per step, cell updates per second, the bytes and flops one cell costs per step
// (counted from the code, below) and its time as a multiple of the bandwidth floor
// (bytes x cells / bandwidth) and of the compute floor (flops x cells / peak); the GL rows are
// measured against the GL device's own bandwidth (a shader copy, bench_context.hpp), taken in the
// same run.
//   build/bench/strata_bench_sim [--benchmark_filter=...]
// Figures go to docs/benchmarks.md.
#include <benchmark/benchmark.h>
#include <omp.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <functional>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "bench_context.hpp"
#include "flat_plain.hpp"

#include <strata/gl/context.hpp>
#include <strata/gl/objects.hpp>
#include <strata/gl/state.hpp>
#include <strata/sim/cpu_solver.hpp>
#include <strata/sim/gl/gl_solver.hpp>
#include <strata/terrain/material.hpp>

namespace {
using namespace strata;
namespace ts = strata::sim;

// What one interior cell costs per step on the CPU backend, counted from sim/src/cpu_*.cpp:
// bytes are the arrays a pass streams through memory (a neighbour's value read again by the next
// cell or row is a cache hit; the face pass's per-thread scratch rows stay in cache), flops are
// the adds, subtracts, multiplies, divides, square roots, minima and maxima of the cell's
// arithmetic (compares and selects not counted).
//  - sources (W11): h, two evaporation sums in and out: 24 B; 8 flops.
//  - pipe_flux (W1, W2): h, bed, 4 outflows in, 4 outflows out: 40 B; 15 per pipe + K: 68 flops.
//  - pipe_update (W3, W4): h, s, 4 outflows in, the state out: 40 B; 30 flops (+ 75 flops of
//    sediment fractions when erosion is on).
//  - with erosion: tilt (E0) 8 B, 10 flops; erode (E1-E4, E6) h, s, hu, hv, tilt, 4 layers, base
//    in, s, 4 layers, bed, scour out: 68 B; the force-based law 48 flops, the shear-stress law 62
//    (its cube root and exponential each counted as 10); thermal_flux (E7, E8) bed, scour, 4
//    layers in, 4 outflows out: 40 B; per direction 8 flops of E7 and 22 of E8 (a square root,
//    two divisions, Culmann's test): 120 flops (thermal_apply runs only where material moves:
//    nowhere on this gentle terrain).
//  - flood mode: sources 24 B / 8; each face pass (W13-W17, W21, W23): h, hu, hv, bed in (19 B
//    with the 3 extra rows of each 16-row run), 2 faces x 4 fluxes and the 2 bed-source terms out
//    (40 B), the corrector's also reading the old ones (40 B): 59 B / 236 flops and 99 B / 246
//    flops (primitives 3, sides 72, HLL 2 x 68, bed source 25); updates (W18, W24): faces 32 B,
//    state 16 B, sources 8 B in, 16 B out: 72 B / 56 flops, the corrector 4 B of limits more and
//    W25 and W19 (one std::pow) 76 B / 76 flops; fv_limit (W25) 16 B / 15; the wave speed (W10)
//    12 B / 10. W34's depth error, read and written by the sources and the corrector: 8 B each;
//    18 flops in the sources (rain and evaporation, 9 each), 24 more in the corrector (four
//    TwoSums of 6 and the fold, against one add before).
struct Work {
  double bytes, flops;
};
constexpr Work kPipes{24 + 40 + 40, 8 + 68 + 30};
constexpr Work kErosion{kPipes.bytes + 8 + 68 + 40, kPipes.flops + 75 + 10 + 48 + 120};
constexpr Work kFlood{32 + 59 + 72 + 99 + 16 + 84 + 12, 26 + 236 + 56 + 246 + 15 + 100 + 10};
// Flood mode's local-inertial scheme (W30-W33): sources 24 B / 8; the face pass reads h, bed and
// the cell's four applied face discharges (24 B; a neighbour's are cache hits) and writes its east
// and south faces (8 B), 45 flops a face (W31 3, W1a 5, q* 4, h^(7/3) with its cube root 12, the
// implicit friction 16, the tangential mean 4, the division); fv_limit 16 B / 15; the update reads
// 3 faces, a limit, h and s (20 B) and writes h, s, hu, hv and the four applied faces (32 B), 17
// flops; the wave speed h alone, 4 B / 2. W34 as in flood mode: the sources and the update read and
// write the depth error (8 B each; 18 and 24 flops more).
constexpr Work kFloodInertial{32 + 32 + 16 + 60 + 4, 26 + 90 + 15 + 41 + 2};
// Flood mode with sediment (E5's denominators and transport: 12 B, 40 flops) and the erosion
// passes above, by law.
constexpr Work kFloodForceBased{kFlood.bytes + 12 + 8 + 68 + 40, kFlood.flops + 40 + 10 + 48 + 120};
constexpr Work kFloodShear{kFlood.bytes + 12 + 8 + 68 + 40, kFlood.flops + 40 + 10 + 62 + 120};
// Flood mode on a Green-Ampt soil (W11b, infiltrationRow after the sources): Ks and G in, the
// infiltration sum and its error in and out: 24 B; the capacity's three Newton steps (divisions
// and the series or a logarithm, counted as 10, each) and the cell's update: 90 flops.
constexpr Work kFloodInfiltration{kFlood.bytes + 24, kFlood.flops + 90};

// ---------------------------------------------------------------------------------------------
// The machine's floors (measured once, before the benchmarks)

// The STREAM triad over [0, n), built for the instruction sets the CPU kernels are.
[[gnu::target_clones("default", "arch=x86-64-v3")]] void triad(double* a, const double* b, const double* c, double s,
                                                               long n, int threads) {
#pragma omp parallel for schedule(static) num_threads(threads)
  for (long i = 0; i < n; ++i) a[i] = b[i] + s * c[i];
}

// `iterations` rounds of 12 independent chains of 8-float vectors, each a multiply then an add
// (the kernels do not contract into FMA: this file is built with -ffp-contract=off too), enough
// chains to cover the latency; returns a value so nothing is optimised away.
using Vec8 = float __attribute__((vector_size(32)));
[[gnu::target_clones("default", "arch=x86-64-v3")]] float chains(long iterations, float m, float c) {
  const Vec8 vm = {m, m, m, m, m, m, m, m}, vc = {c, c, c, c, c, c, c, c};
  Vec8 a0 = vc, a1 = vc + 1, a2 = vc + 2, a3 = vc + 3, a4 = vc + 4, a5 = vc + 5, a6 = vc + 6, a7 = vc + 7, a8 = vc + 8,
       a9 = vc + 9, a10 = vc + 10, a11 = vc + 11;
  for (long it = 0; it < iterations; ++it) {
    a0 = a0 * vm + vc, a1 = a1 * vm + vc, a2 = a2 * vm + vc, a3 = a3 * vm + vc, a4 = a4 * vm + vc, a5 = a5 * vm + vc;
    a6 = a6 * vm + vc, a7 = a7 * vm + vc, a8 = a8 * vm + vc, a9 = a9 * vm + vc, a10 = a10 * vm + vc,
    a11 = a11 * vm + vc;
  }
  const Vec8 sum = a0 + a1 + a2 + a3 + a4 + a5 + a6 + a7 + a8 + a9 + a10 + a11;
  return sum[0] + sum[1] + sum[2] + sum[3] + sum[4] + sum[5] + sum[6] + sum[7];
}
constexpr double kChainFlops = 12 * 8 * 2;  // per iteration

// The thread counts the CPU rows run with: 1, 2 and, on a machine with more cores, all of them.
std::vector<int> threadCounts() {
  std::vector<int> t{1, 2};
  if (omp_get_num_procs() > 2) t.push_back(omp_get_num_procs());
  return t;
}

struct Floors {
  std::map<int, double> bandwidthGBs;  // by thread count
  std::map<int, double> peakGflops;
  double glCopyGBs = 0;  // the GL device's shader copy of floats in 16 x 16 groups (bench_context.hpp)
};
Floors gFloors;

double bestOf(int runs, const std::function<void()>& f) {
  double best = 1e30;
  for (int r = 0; r < runs; ++r) {
    const auto t0 = std::chrono::steady_clock::now();
    f();
    best = std::min(best, std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count());
  }
  return best;
}

void measureFloors() {
  const long n = 1L << 23;  // 64 MB per array, far beyond the caches
  std::vector<double> a(size_t(n), 0.0), b(size_t(n), 1.0), c(size_t(n), 2.0);
  for (int threads : threadCounts()) {
    triad(a.data(), b.data(), c.data(), 3.0, n, threads);  // first touch
    const double s = bestOf(5, [&] { triad(a.data(), b.data(), c.data(), 3.0, n, threads); });
    gFloors.bandwidthGBs[threads] = 3.0 * 8.0 * double(n) / s / 1e9;
    const long iterations = 10000000;
    std::vector<float> results(size_t(threads), 0.0f);
    const double t = bestOf(3, [&] {
#pragma omp parallel num_threads(threads)
      results[omp_get_thread_num()] = chains(iterations, 0.999999f, 1e-7f);
    });
    if (results[0] == 12345.0f) std::printf("\n");  // keeps the chains
    gFloors.peakGflops[threads] = kChainFlops * double(iterations) * threads / t / 1e9;
  }
}

// ---------------------------------------------------------------------------------------------
// The benchmarks

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

ts::SimParams pipes() {
  ts::SimParams p;
  p.maxDtS = 0.2f;
  p.pipeAreaM2 = 100.0f;
  p.rainMmPerHour = 10.0f;
  return p;
}
ts::SimParams erosion() {
  ts::SimParams p = pipes();
  p.erosionEnabled = true;
  p.thermalEnabled = true;
  p.erosionLaw = ts::ErosionLaw::kForceBased;  // the pipes have no Manning n for a shear stress
  p.capacityK = 0.05f;
  p.erosionRate = 0.5f;
  p.depositionRate = 0.3f;
  return p;
}
ts::SimParams flood() {
  ts::SimParams p;
  p.waterModel = ts::WaterModel::kFiniteVolume;
  p.maxDtS = 5.0f;
  p.cflAlpha = 0.45f;
  p.manningN = 0.03f;
  return p;
}
ts::SimParams floodInertial() {
  ts::SimParams p = flood();
  p.floodScheme = ts::FloodScheme::kLocalInertial;
  p.cflAlpha = 0.7f;
  return p;
}
// Flood mode with erosion, weathering and bank failure on four layers, by law (issue 30: the
// shear-stress law's cost beside the force-based one's).
ts::SimParams floodErosion(ts::ErosionLaw law) {
  ts::SimParams p = flood();
  p.erosionEnabled = true;
  p.thermalEnabled = true;
  p.erosionLaw = law;
  p.capacityK = 0.05f;
  p.erosionRate = 0.5f;
  p.depositionRate = 0.3f;
  return p;
}

std::optional<gl::HeadlessContext> gContext;

// threads 0: the GL backend; else the CPU backend with that many threads, every cell every step
// unless `skip` (then dry blocks are skipped, and cell updates still count every cell).
void run(benchmark::State& state, const ts::SimParams& p, Work work, int threads, bool skip, bool soil = false) {
  const int n = int(state.range(0));
  auto input = terrainOf(n);
  if (soil) {  // a sandy loam's Green-Ampt parameters (Rawls et al. 1983) everywhere
    input.infiltrationMmPerHour = gis::Grid<float>(n, n, 10.9f);
    input.infiltrationSuctionM = gis::Grid<float>(n, n, 0.110f * 0.3f);
  }
  std::unique_ptr<ts::Solver> sim;
  if (threads == 0) {
    if (!gContext) {
      state.SkipWithError("no GL context");
      return;
    }
    auto s = ts::GlSolver::create(input, p);
    if (s) sim = std::make_unique<ts::GlSolver>(std::move(s).value());
  } else {
    auto s = ts::CpuSolver::create(input, p, ts::CpuOptions{threads, skip});
    if (s) sim = std::make_unique<ts::CpuSolver>(std::move(s).value());
  }
  if (!sim) {
    state.SkipWithError("the solver could not be created");
    return;
  }
  auto finish = [&] {
    if (threads == 0) gl::finish();
  };
  sim->step(2);  // warm up: first dispatches compile, pages are touched
  finish();
  const int steps = n >= 1024 ? 1 : 4;
  double seconds = 0;
  const gl::CallCounts calls0 = gl::callCounts();
  for (auto _ : state) {
    const auto t0 = std::chrono::steady_clock::now();
    sim->step(steps);
    finish();
    const double t = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    seconds += t;
    state.SetIterationTime(t / steps);
  }
  const double cells = double(n) * n, perStep = seconds / (double(state.iterations()) * steps);
  state.counters["cells/s"] = benchmark::Counter(cells * double(state.iterations()), benchmark::Counter::kIsRate);
  state.counters["B/cell"] = work.bytes;
  state.counters["flop/cell"] = work.flops;
  if (threads == 0) {
    // What a step asks of the host: dispatches, and reads back (each a wait for the GPU).
    const gl::CallCounts calls1 = gl::callCounts();
    const double stepsRun = double(state.iterations()) * steps;
    state.counters["dispatches/step"] = double(calls1.dispatches - calls0.dispatches) / stepsRun;
    state.counters["reads/step"] = double(calls1.hostReads - calls0.hostReads) / stepsRun;
    // GL: the floor is the device's own shader-copy bandwidth (no GPU peak-flop figure is measured).
    if (gFloors.glCopyGBs > 0)
      state.counters["x_bw_floor"] = perStep / (work.bytes * cells / (gFloors.glCopyGBs * 1e9));
    return;
  }
  const double bwFloor = work.bytes * cells / (gFloors.bandwidthGBs[threads] * 1e9);
  const double flopFloor = work.flops * cells / (gFloors.peakGflops[threads] * 1e9);
  state.counters["x_bw_floor"] = perStep / bwFloor;
  state.counters["x_flop_floor"] = perStep / flopFloor;
}

// A halo exchange's share of GL work: read an 8-cell strip down the east side of an n x n grid
// (what haloParts carries in pipe mode without erosion: state, fluxes, the carried accumulators)
// and write it back on the west side, as a block on a rank does for each neighbour every step.
// Wall time (host transfers, not GPU time).
void glHaloStrip(benchmark::State& state) {
  if (!gContext) {
    state.SkipWithError("no GL context");
    return;
  }
  const int n = int(state.range(0));
  const ts::SimParams params;
  auto sim = ts::GlSolver::create(terrainOf(n), params);
  if (!sim) {
    state.SkipWithError(sim.message().c_str());
    return;
  }
  double bytes = 0;
  for (auto _ : state) {
    ts::CellBlock b = sim->readBlock(n - 16, 0, 8, n, ts::haloParts(params));
    b.rect.x = 0;
    sim->writeBlock(b);
    bytes = 0;
    ts::CellBlock::forEachPart(
        b, 0, [&](unsigned, const std::vector<float>& v, size_t, size_t) { bytes += 4.0 * double(v.size()); });
  }
  state.counters["bytes_per_strip"] = bytes;
}

// The flat-plain flood after the Environment Agency's test 4 (tests/support/flat_plain.hpp) run
// whole by one solver, as issue 35 compares with LISFLOOD-FP: 5 h, or 1 h at cells of 1 m and
// less (the 1 m case). Arg: the cell size in metres. threads 0: GL; else the CPU backend
// with OpenMP's default count (grid-capped, tuned). Reports the steps and the solver's wall time.
// GL takes its steps as advance() does, chosen on the GPU (W35); `hostSteps` chooses each on the
// host instead (a 4-byte read of the wave speed a step): the two side by side are W35's gain.
// `localSteps`: the CPU backend with W37's local time steps (3 levels); the CPU runs count their
// cell updates.
void flatPlain(benchmark::State& state, ts::FloodScheme scheme, bool gl, bool hostSteps = false,
               bool localSteps = false) {
  const double cellM = double(state.range(0));
  const auto plain = test::flatPlain(cellM);
  const double duration = cellM <= 1.0 ? 3600.0 : test::kPlainDurationS;
  for (auto _ : state) {
    std::unique_ptr<ts::Solver> sim;
    if (gl) {
      if (!gContext) return state.SkipWithError("no GL context");
      auto s = ts::GlSolver::create(plain.input, test::flatPlainParams(scheme));
      if (s) sim = std::make_unique<ts::GlSolver>(std::move(s).value());
    } else {
      auto p = test::flatPlainParams(scheme);
      p.localStepLevels = localSteps ? ts::kMaxLocalStepLevels : 0;
      auto s = ts::CpuSolver::create(plain.input, p);
      if (s) sim = std::make_unique<ts::CpuSolver>(std::move(s).value());
    }
    if (!sim || !sim->addSource(plain.breach)) return state.SkipWithError("the solver could not be created");
    const auto t0 = std::chrono::steady_clock::now();
    const gl::CallCounts calls0 = gl::callCounts();
    if (hostSteps) {
      while (!ts::Solver::reached(sim->timeS(), duration)) {
        sim->stepWithDt(std::min(sim->nextDt(), duration - sim->timeS()));
      }
    } else {
      sim->advance(duration);
    }
    if (gl) gl::finish();
    const gl::CallCounts calls1 = gl::callCounts();
    state.SetIterationTime(std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count());
    const auto st = sim->stats();
    state.counters["steps"] = double(st.steps);
    state.counters["balance"] = st.waterBalanceM3() / st.inflowM3;
    state.counters["cell_steps/s"] = benchmark::Counter(double(st.steps) * double(plain.input.baseM.size()),
                                                        benchmark::Counter::kIsIterationInvariantRate);
    if (const auto* cpu = dynamic_cast<const ts::CpuSolver*>(sim.get())) {
      state.counters["cell_updates"] = double(cpu->cellUpdates());
    }
    if (gl) {
      state.counters["dispatches/step"] = double(calls1.dispatches - calls0.dispatches) / double(st.steps);
      state.counters["reads/step"] = double(calls1.hostReads - calls0.hostReads) / double(st.steps);
    }
    state.SetLabel(sim->backendName());
  }
}

void registerAll() {
  for (auto [scheme, name] : {std::pair{ts::FloodScheme::kFiniteVolume, "finite_volume"},
                              std::pair{ts::FloodScheme::kLocalInertial, "inertial"}}) {
    for (const char* kind : {"cpu", "cpu_local_steps", "gl", "gl_host_steps"}) {
      const bool gl = kind[0] == 'g', hostSteps = kind[2] == '_', local = std::string(kind) == "cpu_local_steps";
      if (local && scheme != ts::FloodScheme::kLocalInertial) continue;  // W37 is the local-inertial scheme's
      benchmark::RegisterBenchmark(
          (std::string("flat_plain/") + name + "/" + kind).c_str(),
          [scheme = scheme, gl, hostSteps, local](benchmark::State& s) { flatPlain(s, scheme, gl, hostSteps, local); })
          ->Arg(20)
          ->Arg(10)
          ->Arg(5)
          ->Arg(2)
          ->Arg(1)
          ->Iterations(1)
          ->UseManualTime()
          ->Unit(benchmark::kSecond);
    }
  }
  struct Model {
    const char* name;
    ts::SimParams params;
    Work work;
    bool soil = false;
  };
  const Model models[] = {
      {"pipes", pipes(), kPipes},
      {"pipes_erosion_thermal_4layers", erosion(), kErosion},
      {"flood", flood(), kFlood},
      {"flood_inertial", floodInertial(), kFloodInertial},
      {"flood_green_ampt", flood(), kFloodInfiltration, true},
      {"flood_erosion_forcebased_4layers", floodErosion(ts::ErosionLaw::kForceBased), kFloodForceBased},
      {"flood_erosion_shear_4layers", floodErosion(ts::ErosionLaw::kShearStress), kFloodShear}};
  struct Variant {
    const char* name;
    int threads;
    bool skip;
  };
  std::vector<Variant> variants = {{"cpu_1thread", 1, false}, {"cpu_2threads", 2, false}, {"gl", 0, false}};
  static std::string allThreads;  // outlives the registrations that point at it
  if (const int all = omp_get_num_procs(); all > 2) {
    allThreads = "cpu_" + std::to_string(all) + "threads";
    variants.insert(variants.begin() + 2, Variant{allThreads.c_str(), all, false});
  }
  for (const auto& m : models) {
    for (const auto& v : variants) {
      const std::string name = std::string(m.name) + "/" + v.name;
      benchmark::RegisterBenchmark(name.c_str(),
                                   [m, v](benchmark::State& s) { run(s, m.params, m.work, v.threads, v.skip, m.soil); })
          ->Arg(256)
          ->Arg(512)
          ->Arg(1024)
          ->Arg(2048)
          ->Arg(4096)
          ->UseManualTime()
          ->Unit(benchmark::kMillisecond);
    }
  }
  // Flood mode skipping the dry blocks of this terrain (the production setting): the cell updates
  // still count every cell.
  benchmark::RegisterBenchmark("flood/cpu_2threads_skipping_dry_blocks",
                               [](benchmark::State& s) { run(s, flood(), kFlood, 2, true); })
      ->Arg(256)
      ->Arg(512)
      ->Arg(1024)
      ->Arg(2048)
      ->Arg(4096)
      ->UseManualTime()
      ->Unit(benchmark::kMillisecond);
  benchmark::RegisterBenchmark("gl_halo_strip", glHaloStrip)->Arg(512)->Arg(2048)->Unit(benchmark::kMillisecond);
}

}  // namespace

int main(int argc, char** argv) {
  benchmark::Initialize(&argc, argv);
  measureFloors();
  std::string stream, peak;
  char text[160];
  for (int threads : threadCounts()) {
    std::snprintf(text, sizeof text, "%s%.1f GB/s (%d thread%s)", stream.empty() ? "" : ", ",
                  gFloors.bandwidthGBs[threads], threads, threads == 1 ? "" : "s");
    stream += text;
    std::snprintf(text, sizeof text, "%s%.1f GFLOP/s (%d thread%s)", peak.empty() ? "" : ", ",
                  gFloors.peakGflops[threads], threads, threads == 1 ? "" : "s");
    peak += text;
  }
  benchmark::AddCustomContext("stream_triad", stream);
  benchmark::AddCustomContext("peak_mul_add", peak);
  auto ctx = gl::HeadlessContext::create({.debugOutput = false});
  if (ctx) {
    gContext.emplace(std::move(ctx).value());
    benchmark::AddCustomContext("gl_renderer", gContext->info().renderer);
    gFloors.glCopyGBs = bench::shaderCopyGBs(16);
    std::snprintf(text, sizeof text, "%.1f GB/s (floats in 16 x 16 groups, read + written)", gFloors.glCopyGBs);
    benchmark::AddCustomContext("gl_shader_copy", text);
  } else {
    benchmark::AddCustomContext("gl_renderer", "none: " + ctx.message());
  }
  registerAll();
  benchmark::RunSpecifiedBenchmarks();
  benchmark::Shutdown();
  gContext.reset();  // while the driver is loaded: NVIDIA's EGL crashed tearing it down after main
  return 0;
}
