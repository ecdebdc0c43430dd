// strata flood SCENARIO / strata erode SCENARIO: run a what-if scenario and write its
// run folder (maps, series, plots, report). Ctrl-C stops cleanly; --resume continues. Under
// mpirun the run is spread over the ranks (docs/distributed.md); rank 0 prints for all.
#include <algorithm>
#include <cstdio>
#include <memory>

#include <strata/scenario/run.hpp>
#include <strata/scenario/scenario.hpp>
#include <strata/sim/mpi/ranks.hpp>

#include "commands.hpp"

namespace strata::app {
namespace {

struct FloodArgs {
  std::string scenario, outDir, backend;
  bool resume = false, overwrite = false, noPictures = false, noPlots = false;
  int pictureCells = scenario::RunOptions{}.pictureCells;
};

void addRunCommand(CLI::App& app, const char* name, const char* help, bool erosion) {
  auto* cmd = app.add_subcommand(name, help);
  cmd->footer(
      "[model] kind = \"flood\" (the default) is the finite-volume shallow-water model with Manning friction "
      "whose answers converge with the step and the cell size; [model] scheme = \"inertial\" swaps in the faster "
      "local-inertial scheme (Bates et al. 2010) for gently varying, subcritical floodplain flow (water only). "
      "kind = \"pipe\" is the virtual-pipe model of "
      "interactive terrain authoring: it has no friction, and its depths and speeds depend on the pipe area and the "
      "time step; they are not physical (docs/sim-water.md).");
  auto args = std::make_shared<FloodArgs>();
  cmd->add_option("scenario", args->scenario, "Scenario file (TOML, see docs/scenario.md)")->required();
  cmd->add_option("-o,--out", args->outDir, "Run folder (default: runs/<scenario name>)");
  auto* resume = cmd->add_flag("--resume", args->resume, "Continue an interrupted run from its checkpoint");
  cmd->add_flag("--overwrite", args->overwrite,
                "Replace the outputs of an earlier run in the run folder (only the files a run writes)")
      ->excludes(resume);
  cmd->add_option("--backend", args->backend,
                  "auto (GL on a hardware GPU, else the CPU), cpu or gpu; overrides [model] backend");
  cmd->add_flag("--no-pictures", args->noPictures, "Do not render pictures");
  cmd->add_flag("--no-plots", args->noPlots, "Do not draw plots");
  cmd->add_option("--picture-cells", args->pictureCells,
                  "Pictures of a larger region are drawn from every k-th cell, k bringing it within this many "
                  "cells a side")
      ->check(CLI::Range(16, 16384))
      ->capture_default_str();
  cmd->callback([args, name, erosion] {
    const auto& mpi = mpiLaunch();
    // One line per failure, from rank 0 only (every rank fails alike).
    auto failWith = [&](const std::string& what, int code) {
      if (mpi.rank == 0) exitCommand(name, what, code);
      throw CLI::RuntimeError(code);
    };
    auto scenario = scenario::loadScenario(args->scenario);
    // Every rank reads the scenario; a rank that cannot fails the run on every rank.
    const sim::Ranks ranks = mpi.active ? sim::Ranks::world() : sim::Ranks::single();
    const Status loaded = ranks.agree(statusOf(scenario));
    if (!loaded) failWith(loaded.message(), 1);
    if (erosion && !scenario->erosion.enabled) {
      scenario->erosion.enabled = true;
      for (const auto& m : scenario::erosionOutputMaps()) {
        auto& maps = scenario->outputs.maps;
        if (std::find(maps.begin(), maps.end(), m) == maps.end()) maps.push_back(m);
      }
    }
    scenario::RunOptions opt;
    opt.command = name;
    if (!args->backend.empty()) {
      auto backend = scenario::parseBackend(args->backend);
      if (!backend) failWith("--backend: " + backend.message(), 2);
      opt.backend = *backend;
    }
    opt.outDir = args->outDir.empty() ? std::filesystem::path("runs") / scenario->file.stem()
                                      : std::filesystem::path(args->outDir);
    opt.resume = args->resume;
    opt.overwrite = args->overwrite;
    opt.pictures = !args->noPictures && scenario->outputs.pictures;
    opt.plots = !args->noPlots && scenario->outputs.plots;
    opt.pictureCells = args->pictureCells;
    opt.distributed = mpi.active;
    auto run = scenario::runScenario(*scenario, opt);
    if (!run) failWith(run.message(), 1);
    if (mpi.rank == 0) {
      std::printf("%s: %s\n", run->completed ? "finished" : "stopped", (opt.outDir / "report.md").c_str());
    }
    if (!run->completed) throw CLI::RuntimeError(130);
  });
}

}  // namespace

void addFloodCommands(CLI::App& app) {
  addRunCommand(app, "flood", "Run a flood what-if scenario and write maps, series, plots and a report", false);
  addRunCommand(app, "erode", "Run a scenario with erosion and deposition switched on", true);
}

}  // namespace strata::app
