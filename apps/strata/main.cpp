// strata: the command-line front end.
#include <csignal>

#include "commands.hpp"

int main(int argc, char** argv) {
  // Over the file size limit (ulimit -f) a write fails with EFBIG and the message names the file,
  // instead of the process dying silently of SIGXFSZ.
  std::signal(SIGXFSZ, SIG_IGN);
  // A child (the plotting python) that dies early makes the write to its stdin fail with EPIPE,
  // which runProcess reports, instead of killing strata silently with SIGPIPE.
  std::signal(SIGPIPE, SIG_IGN);
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
  CLI11_PARSE(app, argc, argv);
  return 0;
}
