#pragma once
// The ranks of an MPI communicator a run is spread over, and the collective operations the run,
// the domain's build and the distributed solver share (docs/distributed.md). A one-process run
// is Ranks::single(): one lead rank, nothing is exchanged and MPI is never called. Everything
// but the accessors is collective over the communicator: every rank calls it in the same order.

#include <mpi.h>

#include <string>
#include <utility>
#include <vector>

#include <strata/core/result.hpp>
#include <strata/sim/exact_sum.hpp>

namespace strata::sim {

class Ranks {
 public:
  /// One process: no MPI.
  static Ranks single() { return {}; }
  /// The ranks of `comm` (MPI must be initialised).
  static Ranks of(MPI_Comm comm);
  /// The ranks of MPI_COMM_WORLD (`strata` initialises MPI under mpirun).
  static Ranks world() { return of(MPI_COMM_WORLD); }

  bool distributed() const { return distributed_; }
  bool lead() const { return rank_ == 0; }
  int rank() const { return rank_; }
  int size() const { return size_; }
  /// How many of the ranks run on this rank's machine and so share its memory
  /// (MPI_COMM_TYPE_SHARED). Collective: every rank calls it.
  int onThisMachine() const;
  MPI_Comm comm() const { return comm_; }  ///< MPI_COMM_NULL for single()

  /// Collective: success on every rank, or the failure of the lowest failing rank on every rank
  /// (its message, after "rank R: " for R > 0), so that no rank is left waiting in a collective
  /// call. The one "ranks agree" of Strata.
  Status agree(const Status& local) const;
  /// Collective: whether any rank has been asked to stop (Ctrl-C, SIGTERM).
  bool anyInterrupted() const;
  /// Collective: the lead's `bytes` on every rank.
  std::string fromLead(std::string bytes) const;
  /// Collective: the smallest and largest of `value` over the ranks.
  std::pair<long long, long long> minMax(long long value) const;
  /// Collective: whether `value` holds on every rank.
  bool all(bool value) const;
  /// Collective: `sums` added over the ranks, in place (exact: the same on any number of ranks).
  void sum(std::vector<ExactSum>& sums) const;
  /// Collective: every rank's `values` (the same count on each), in rank order, on every rank.
  std::vector<double> allGather(const std::vector<double>& values) const;
  /// Collective: each of `values` the smallest (largest) over the ranks, in place.
  void min(std::vector<double>& values) const;
  void max(std::vector<double>& values) const;
  /// Collective: every rank's `bytes`, in rank order, on the lead (nothing elsewhere).
  std::vector<std::string> gatherToLead(const std::string& bytes) const;
  /// Collective: every rank's `bytes`, in rank order, on every rank.
  std::vector<std::string> allGatherBytes(const std::string& bytes) const;
  /// Collective: sends `up` to the rank before this one and `down` to the one after it; returns
  /// what they sent (the one before's `down`, the one after's `up`; empty where there is none).
  std::pair<std::string, std::string> swapWithNeighbours(const std::string& up, const std::string& down) const;

 private:
  bool distributed_ = false;
  int rank_ = 0, size_ = 1;
  MPI_Comm comm_ = MPI_COMM_NULL;
};

/// Allreduce of `n` ExactSums in place over `comm` (collective): the sum is exact, so the same on
/// any number of ranks.
void allreduceExact(ExactSum* sums, int n, MPI_Comm comm);

}  // namespace strata::sim
