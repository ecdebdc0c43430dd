// A scenario's domain built by the MPI ranks (buildByRows: each rank its own rows, breach_inflows
// flooded by the ranks together, fill_depressions tile by tile) against one process
// (buildDomain), side by side in one mpirun job: each repetition builds the domain on rank 0
// alone (the other ranks sleep in a barrier), then on every rank, and rank 0 prints one JSON line
// (wall seconds: one process, the ranks' slowest). Figures go to docs/benchmarks.md.
//
//   OMP_NUM_THREADS=1 STRATA_LOG=debug mpirun -np P build/bench/strata_bench_build_mpi SCENARIO [reps]
//
// (STRATA_LOG=debug adds the breach's rounds and its time on each build.)
#include <mpi.h>

#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <string>

#include <strata/scenario/domain.hpp>
#include <strata/scenario/scenario.hpp>

#include "../scenario/src/build_rows.hpp"
#include "../scenario/src/domain_rows.hpp"
#include "sleepy_barrier.hpp"

namespace {
using strata::bench::sleepyBarrier;
using namespace strata;
using Clock = std::chrono::steady_clock;

double seconds(Clock::time_point from) { return std::chrono::duration<double>(Clock::now() - from).count(); }

}  // namespace

int main(int argc, char** argv) {
  int provided = 0;
  MPI_Init_thread(&argc, &argv, MPI_THREAD_FUNNELED, &provided);
  const auto ranks = scenario::detail::Ranks::world();
  if (argc < 2) {
    if (ranks.lead()) std::fprintf(stderr, "usage: mpirun -np P %s SCENARIO [reps]\n", argv[0]);
    MPI_Finalize();
    return 2;
  }
  const int reps = argc > 2 ? std::atoi(argv[2]) : 2;
  auto s = scenario::loadScenario(argv[1]);
  if (!s) {
    if (ranks.lead()) std::fprintf(stderr, "%s\n", s.message().c_str());
    MPI_Finalize();
    return 1;
  }
  int status = 0;
  for (int r = 0; r < reps && status == 0; ++r) {
    double one = 0;
    long long cells = 0;
    if (ranks.lead()) {
      const auto t = Clock::now();
      auto d = scenario::buildDomain(*s);
      one = seconds(t);
      if (!d) std::fprintf(stderr, "buildDomain: %s\n", d.message().c_str()), status = 1;
      if (d) cells = (long long)d->bed.values.size();
    }
    sleepyBarrier();
    MPI_Barrier(MPI_COMM_WORLD);
    const auto t = Clock::now();
    auto built = [&]() -> Result<scenario::detail::RowsBuilt> {
      STRATA_TRY(auto builder, scenario::detail::RowBuilder::plan(*s, 0, ranks.size(), false));
      return scenario::detail::buildByRows(builder, *s, ranks);
    }();
    double mine = seconds(t), slowest = 0;
    MPI_Allreduce(&mine, &slowest, 1, MPI_DOUBLE, MPI_MAX, MPI_COMM_WORLD);
    if (!built) {
      if (ranks.lead()) std::fprintf(stderr, "buildByRows: %s\n", built.message().c_str());
      status = 1;
    }
    if (ranks.lead() && status == 0) {
      std::printf(
          "{\"bench\": \"build\", \"scenario\": \"%s\", \"cells\": %lld, \"ranks\": %d, \"one_process_s\": %.3f, "
          "\"ranks_s\": %.3f, \"speedup\": %.2f}\n",
          argv[1], cells, ranks.size(), one, slowest, one / slowest);
      std::fflush(stdout);
    }
  }
  MPI_Finalize();
  return status;
}
