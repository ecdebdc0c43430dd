// strata: the command-line front end.
#include "commands.hpp"

int main(int argc, char** argv) {
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
