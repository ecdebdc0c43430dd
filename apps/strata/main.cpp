// strata: the command-line front end.
#include <mpi.h>

#include <csignal>
#include <cstdio>
#include <cstdlib>
#include <cstring>

#include <strata/core/log.hpp>
#include <strata/core/process.hpp>

#include "commands.hpp"

namespace strata::app {
namespace {

MpiLaunch gLaunch;

// Open MPI's mpirun, MPICH's Hydra and PMIx launchers set these in every rank's environment.
bool launchedByMpirun() {
  for (const char* v : {"OMPI_COMM_WORLD_SIZE", "PMI_SIZE", "PMIX_RANK"}) {
    if (std::getenv(v)) return true;
  }
  return false;
}

}  // namespace

const MpiLaunch& mpiLaunch() { return gLaunch; }

void exitCommand(std::string_view command, const std::string& what, int code) {
  std::fprintf(stderr, "strata %.*s: %s\n", int(command.size()), command.data(), what.c_str());
  throw CLI::RuntimeError(code);
}

std::string number(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%g", v);
  return buf;
}

}  // namespace strata::app

int main(int argc, char** argv) {
  strata::preferSleepingOpenMpWaits(argv);  // may start this program again, before anything else
  // Over the file size limit (ulimit -f) a write fails with EFBIG and the message names the file,
  // instead of the process dying silently of SIGXFSZ.
  std::signal(SIGXFSZ, SIG_IGN);
  // A child (the plotting python) that dies early makes the write to its stdin fail with EPIPE,
  // which runProcess reports, instead of killing strata silently with SIGPIPE.
  std::signal(SIGPIPE, SIG_IGN);
  // Under mpirun strata is one rank of a distributed run (docs/distributed.md): MPI is up for the
  // whole program, `flood` and `erode` run over the ranks, and the ranks but the first print
  // only errors. Run by hand, MPI is never started.
  auto& launch = strata::app::gLaunch;
  if (strata::app::launchedByMpirun()) {
    int provided = 0;
    MPI_Init_thread(&argc, &argv, MPI_THREAD_FUNNELED, &provided);
    launch.active = true;
    MPI_Comm_rank(MPI_COMM_WORLD, &launch.rank);
    MPI_Comm_size(MPI_COMM_WORLD, &launch.size);
    if (launch.rank != 0 && !std::getenv("STRATA_LOG")) strata::log::setLevel(strata::log::Level::Error);
    const bool runCommand = argc > 1 && (std::strcmp(argv[1], "flood") == 0 || std::strcmp(argv[1], "erode") == 0);
    if (launch.size > 1 && !runCommand) {
      if (launch.rank == 0) {
        std::fprintf(stderr, "strata: only `strata flood` and `strata erode` run over MPI ranks (%d ranks given)\n",
                     launch.size);
      }
      MPI_Finalize();
      return 2;
    }
  }
  CLI::App app{"Strata: GIS terrain visualisation and what-if erosion and flood simulation on the GPU"};
  app.require_subcommand(1);
  strata::app::addGpuInfoCommand(app);
  strata::app::addInfoCommand(app);
  strata::app::addFloodCommands(app);
  strata::app::addGenerateCommand(app);
  strata::app::addRenderCommand(app);
  strata::app::addCheckCommand(app);
  strata::app::addIngestCommand(app);
  strata::app::addExportCommand(app);
  strata::app::addCompareCommand(app);
  const int rc = [&] {
    CLI11_PARSE(app, argc, argv);
    return 0;
  }();
  if (launch.active) MPI_Finalize();
  return rc;
}
