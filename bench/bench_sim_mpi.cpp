// The distributed run (DistributedSolver, CPU blocks) against one rank, side by side in one
// mpirun job: every comparison runs the one-rank case on rank 0 (MPI_COMM_SELF; the other ranks
// sleep in a barrier) and the all-rank case on MPI_COMM_WORLD, alternating, `reps` times; each
// run prints one JSON line (rank 0). Figures go to docs/benchmarks.md.
//
//   mpirun -np P build/bench/strata_bench_sim_mpi strong N STEPS [reps]
//       a fully wet N x N flood (every block active): wall ms per step on 1 rank and on P,
//       the speed-up, and per step the halo bytes, messages, the computed over interior cells,
//       time in the passes, in the exchange and blocked waiting.
//   mpirun -np P build/bench/strata_bench_sim_mpi weak N STEPS [reps]
//       the same flood on N x N for 1 rank and N x (P N) for P ranks (work per rank fixed).
//   mpirun -np P build/bench/strata_bench_sim_mpi canyon STEPS [reps]
//       a spring in the Grand Canyon (grand_canyon_512.tif, 512 x 512 real DEM, flood mode): the
//       flood fills a small part. Plain CpuSolver on one rank, then P ranks: one block each,
//       no skipping (the even split); 32 blocks per rank skipping idle blocks, even split; the same
//       balanced by work at start and every 100 steps (with the cost of each re-balance).
//
// Threads: run with OMP_NUM_THREADS=1 to measure ranks, not threads.
#include <mpi.h>
#include <time.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <functional>
#include <string>
#include <vector>

#include <strata/sim/cpu_solver.hpp>
#include <strata/sim/mpi/distributed_solver.hpp>

#include "canyon_flood.hpp"
#include "sleepy_barrier.hpp"

namespace {
using strata::bench::sleepyBarrier;
using namespace strata;
using namespace strata::sim;

int rank() {
  int r = 0;
  MPI_Comm_rank(MPI_COMM_WORLD, &r);
  return r;
}
int size() {
  int n = 0;
  MPI_Comm_size(MPI_COMM_WORLD, &n);
  return n;
}

double cpuSeconds() {
  timespec t{};
  clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &t);
  return double(t.tv_sec) + 1e-9 * double(t.tv_nsec);
}

// A flood that keeps every cell wet and moving: 1 m of water over a rolling bed, with a 1 m bump
// sloshing about (flood mode, closed box, W10 steps).
SimInput wetScene(int w, int h) {
  SimInput in;
  in.baseM = gis::Grid<float>(w, h);
  in.waterDepthM = gis::Grid<float>(w, h);
  in.rowDxM = {10.0};
  in.dyM = 10.0;
  in.datumM = 1000.0;
  in.materials = terrain::defaultMaterials();
  in.layersM = {gis::Grid<float>(w, h, 1.0f)};
  in.materials.resize(1);
  for (int y = 0; y < h; ++y) {
    for (int x = 0; x < w; ++x) {
      in.baseM.at(x, y) = float(1000.0 + 0.3 * std::sin(0.05 * x) * std::cos(0.07 * y));
      const double dx = x - 0.3 * w, dy = y - 0.4 * h;
      in.waterDepthM.at(x, y) = float(1.0 + std::exp(-(dx * dx + dy * dy) / (0.01 * w * w)));
    }
  }
  return in;
}
SimParams floodParams() {
  SimParams p;
  p.waterModel = WaterModel::kFiniteVolume;
  p.cflAlpha = 0.45f;
  p.maxDtS = 10.0f;
  p.manningN = 0.03f;
  return p;
}

double sumAll(double x) {
  double s = 0;
  MPI_Allreduce(&x, &s, 1, MPI_DOUBLE, MPI_SUM, MPI_COMM_WORLD);
  return s;
}
double maxAll(double x) {
  double s = 0;
  MPI_Allreduce(&x, &s, 1, MPI_DOUBLE, MPI_MAX, MPI_COMM_WORLD);
  return s;
}

// One run on one rank (rank 0 alone, the others sleeping), timed: wall and CPU ms per step.
struct OneRank {
  double ms = 0, cpuMs = 0;
};
OneRank oneRank(const std::function<std::unique_ptr<Solver>()>& make, int steps) {
  OneRank o;
  if (rank() == 0) {
    auto sim = make();
    const double t0 = MPI_Wtime(), c0 = cpuSeconds();
    sim->step(steps);
    o.ms = 1e3 * (MPI_Wtime() - t0) / steps;
    o.cpuMs = 1e3 * (cpuSeconds() - c0) / steps;
  }
  sleepyBarrier();
  return o;
}

// One run on all ranks: wall ms per step and the counters summed (or maxed) over ranks.
struct Outcome {
  double ms = 0, cpuMs = 0, haloBytes = 0, messages = 0, computed = 0, interior = 0, stepS = 0, exchangeS = 0,
         waitS = 0, reduceS = 0, activeFraction = 0;
  std::vector<RebalanceReport> rebalances;
  std::string backend;
};
Outcome allRanks(DistributedSolver& sim, int steps) {
  MPI_Barrier(MPI_COMM_WORLD);
  const auto c0 = sim.counters();
  const double t0 = MPI_Wtime(), cpu0 = cpuSeconds();
  sim.step(steps);
  const double wall = MPI_Wtime() - t0, cpu = cpuSeconds() - cpu0;
  const auto& c = sim.counters();
  Outcome o;
  o.ms = 1e3 * maxAll(wall) / steps;
  o.cpuMs = 1e3 * maxAll(cpu) / steps;
  o.haloBytes = sumAll(c.haloBytesSent - c0.haloBytesSent) / steps;
  o.messages = sumAll(double(c.messagesSent - c0.messagesSent)) / steps;
  o.computed = sumAll(c.computedCells - c0.computedCells);
  o.interior = sumAll(c.interiorCells - c0.interiorCells);
  o.stepS = maxAll(c.stepSeconds - c0.stepSeconds);
  o.exchangeS = maxAll(c.exchangeSeconds - c0.exchangeSeconds);
  o.waitS = maxAll(c.waitSeconds - c0.waitSeconds);
  o.reduceS = maxAll(c.reduceSeconds - c0.reduceSeconds);
  const double active = sumAll(double(c.activeBlockSteps - c0.activeBlockSteps));
  const double idle = sumAll(double(c.idleBlockSteps - c0.idleBlockSteps));
  o.activeFraction = active / std::max(1.0, active + idle);
  o.rebalances.assign(c.rebalances.begin() + ptrdiff_t(c0.rebalances.size()), c.rebalances.end());
  o.backend = sim.backendName();
  return o;
}

void print(const char* run, const OneRank& one, const Outcome& o, double cells, int steps) {
  if (rank() != 0) return;
  std::printf(
      "{\"run\": \"%s\", \"ranks\": %d, \"backend\": \"%s\", \"ms_per_step_1rank\": %.2f, \"ms_per_step\": %.2f, "
      "\"speedup\": %.3f, \"cpu_ms_per_step_1rank\": %.2f, \"cpu_ms_per_step_busiest_rank\": %.2f, "
      "\"cpu_speedup\": %.3f, \"halo_bytes_per_step\": %.0f, \"messages_per_step\": %.1f, "
      "\"computed_over_interior\": %.3f, \"interior_over_region\": %.3f, \"active_block_fraction\": %.3f, "
      "\"pass_s\": %.3f, \"exchange_s\": %.3f, \"wait_s\": %.3f, \"reduce_s\": %.3f",
      run, size(), o.backend.c_str(), one.ms, o.ms, one.ms / o.ms, one.cpuMs, o.cpuMs, one.cpuMs / o.cpuMs, o.haloBytes,
      o.messages, o.computed / std::max(1.0, o.interior), o.interior / (cells * steps), o.activeFraction, o.stepS,
      o.exchangeS, o.waitS, o.reduceS);
  for (const auto& r : o.rebalances) {
    std::printf(
        ", \"rebalance\": {\"imbalance_before\": %.2f, \"after\": %.2f, \"blocks_moved\": %d, \"bytes\": %.0f, "
        "\"seconds\": %.4f}",
        r.imbalanceBefore, r.imbalanceAfter, r.blocksMoved, r.bytesMoved, r.seconds);
  }
  std::printf("}\n");
  std::fflush(stdout);
}

std::unique_ptr<DistributedSolver> distributed(const SimInput& in, const SimParams& p, const DistributedOptions& o,
                                               MPI_Comm comm = MPI_COMM_WORLD) {
  DistributedOptions opt = o;
  opt.comm = comm;
  auto s = DistributedSolver::create(in, p, opt, cpuSolverFactory());
  if (!s) {
    std::fprintf(stderr, "%s\n", s.message().c_str());
    MPI_Abort(MPI_COMM_WORLD, 1);
  }
  return std::make_unique<DistributedSolver>(std::move(s).value());
}
std::unique_ptr<Solver> plain(const SimInput& in, const SimParams& p, const Source* spring) {
  auto s = CpuSolver::create(in, p);
  if (!s || (spring && !s->addSource(*spring))) MPI_Abort(MPI_COMM_WORLD, 1);
  return std::make_unique<CpuSolver>(std::move(s).value());
}

}  // namespace

int main(int argc, char** argv) {
  int provided = 0;
  MPI_Init_thread(&argc, &argv, MPI_THREAD_FUNNELED, &provided);
  const std::string mode = argc > 1 ? argv[1] : "strong";
  const int reps = mode == "canyon" ? (argc > 3 ? std::atoi(argv[3]) : 1) : (argc > 4 ? std::atoi(argv[4]) : 2);
  if (mode == "strong" || mode == "weak") {
    const int n = argc > 2 ? std::atoi(argv[2]) : 512, steps = argc > 3 ? std::atoi(argv[3]) : 20;
    const SimInput one = wetScene(n, n);
    const SimInput all = mode == "weak" ? wetScene(n, n * size()) : one;
    DistributedOptions o;
    o.blocksPerRank = 1;
    for (int r = 0; r < reps; ++r) {
      const OneRank ms1 = oneRank([&] { return plain(one, floodParams(), nullptr); }, steps);
      auto sim = distributed(all, floodParams(), o);
      print((mode + "_1_block_per_rank").c_str(), ms1, allRanks(*sim, steps), double(all.baseM.size()), steps);
      sim.reset();
      DistributedOptions four = o;
      four.blocksPerRank = 4;
      auto sim4 = distributed(all, floodParams(), four);
      print((mode + "_4_blocks_per_rank").c_str(), ms1, allRanks(*sim4, steps), double(all.baseM.size()), steps);
    }
  } else if (mode == "canyon") {
    const int steps = argc > 2 ? std::atoi(argv[2]) : 300;
    auto scene = test::canyonFlood(std::string(STRATA_DATA_DIR) + "/grand_canyon/grand_canyon_512.tif", 0, 0, 512, 352,
                                   417, 5000.0);
    if (!scene) {
      std::fprintf(stderr, "%s\n", scene.message().c_str());
      MPI_Abort(MPI_COMM_WORLD, 1);
    }
    const double cells = double(scene->input.baseM.size());
    for (int r = 0; r < reps; ++r) {
      const OneRank ms1 = oneRank([&] { return plain(scene->input, scene->params, &scene->spring); }, steps);
      struct Case {
        const char* name;
        DistributedOptions o;
      };
      DistributedOptions even;
      even.blocksPerRank = 1;
      even.skipIdle = false;
      even.balanceAtStart = false;
      DistributedOptions skip;
      skip.blocksPerRank = 32;
      skip.balanceAtStart = false;
      DistributedOptions balanced = skip;
      balanced.balanceAtStart = true;
      balanced.rebalanceEvery = 100;
      for (const auto& c :
           {Case{"canyon_even_1_block_per_rank", even}, Case{"canyon_32_blocks_per_rank_skip_idle_even", skip},
            Case{"canyon_32_blocks_per_rank_skip_idle_balanced", balanced}}) {
        auto sim = distributed(scene->input, scene->params, c.o);
        if (!sim->addSource(scene->spring)) MPI_Abort(MPI_COMM_WORLD, 1);
        const auto start = sim->counters().rebalances;
        Outcome out = allRanks(*sim, steps);
        out.rebalances.insert(out.rebalances.begin(), start.begin(), start.end());
        print(c.name, ms1, out, cells, steps);
        const auto st = sim->stats();
        if (rank() == 0) {
          std::printf("{\"run\": \"%s\", \"time_s\": %.1f, \"stored_m3\": %.7g, \"balance_error\": %.3g}\n", c.name,
                      st.timeS, st.storedWaterM3, std::abs(st.waterBalanceM3()) / std::max(1.0, st.inflowM3));
        }
      }
    }
  } else {
    if (rank() == 0)
      std::fprintf(stderr, "usage: strata_bench_sim_mpi strong|weak N STEPS [reps] | canyon STEPS [reps]\n");
    MPI_Finalize();
    return 2;
  }
  MPI_Finalize();
  return 0;
}
