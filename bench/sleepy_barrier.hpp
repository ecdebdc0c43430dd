#pragma once
// For benchmarks that compare one rank with all of them in one mpirun job.

#include <mpi.h>
#include <unistd.h>

namespace strata::bench {

/// A barrier that sleeps instead of spinning: the ranks left out of a one-rank run give the core
/// to rank 0.
inline void sleepyBarrier() {
  MPI_Request r;
  MPI_Ibarrier(MPI_COMM_WORLD, &r);
  int done = 0;
  while (!done) {
    MPI_Test(&r, &done, MPI_STATUS_IGNORE);
    if (!done) usleep(500);
  }
}

}  // namespace strata::bench
