// main() of the multi-rank tests, run under mpirun (tests/sim/CMakeLists.txt): MPI up around
// GoogleTest; rank 0 prints as usual, the other ranks print only their failures (prefixed with
// the rank); the exit code is the worst over all ranks, so a failure on any rank fails the test,
// and a fatal failure (ASSERT) ends every rank at once.
#include <gtest/gtest.h>
#include <mpi.h>

#include <cstdio>
#include <cstdlib>

#include <strata/core/log.hpp>

namespace {

// Prints a rank's failures (ranks other than 0, whose default printer is off), and ends the
// whole job on a fatal one (ASSERT_*): a rank that leaves a test early would leave the others
// waiting in a collective call until the ctest timeout.
class FailurePrinter : public ::testing::EmptyTestEventListener {
 public:
  FailurePrinter(int rank, bool print) : rank_(rank), print_(print) {}
  void OnTestPartResult(const ::testing::TestPartResult& r) override {
    if (!r.failed()) return;
    if (print_) {
      std::fprintf(stderr, "[rank %d] %s:%d: Failure\n%s\n", rank_, r.file_name() ? r.file_name() : "?",
                   r.line_number(), r.summary());
    }
    if (r.fatally_failed()) {
      std::fprintf(stderr, "[rank %d] fatal failure: ending all ranks\n", rank_);
      std::fflush(stderr);
      std::fflush(stdout);
      MPI_Abort(MPI_COMM_WORLD, 1);
    }
  }

 private:
  int rank_;
  bool print_;
};

}  // namespace

int main(int argc, char** argv) {
  int provided = 0;
  MPI_Init_thread(&argc, &argv, MPI_THREAD_FUNNELED, &provided);
  ::testing::InitGoogleTest(&argc, argv);
  int rank = 0;
  MPI_Comm_rank(MPI_COMM_WORLD, &rank);
  auto& listeners = ::testing::UnitTest::GetInstance()->listeners();
  if (rank != 0) delete listeners.Release(listeners.default_result_printer());
  listeners.Append(new FailurePrinter(rank, rank != 0));
  if (!std::getenv("STRATA_LOG")) strata::log::setLevel(strata::log::Level::Warn);
  const int rc = RUN_ALL_TESTS();
  int worst = 0;
  MPI_Allreduce(&rc, &worst, 1, MPI_INT, MPI_MAX, MPI_COMM_WORLD);
  MPI_Finalize();
  return worst;
}
