// strata compare RUN_A RUN_B -o OUT: difference maps (B - A) and the headline numbers of two runs
// side by side (scenario/include/strata/scenario/compare.hpp).
#include <cstdio>

#include <strata/scenario/compare.hpp>

#include "commands.hpp"

namespace strata::app {

void addCompareCommand(CLI::App& app) {
  auto* cmd = app.add_subcommand(
      "compare", "What changed between two runs of one region: difference maps (B - A) and the headline numbers");
  auto opt = std::make_shared<scenario::CompareOptions>();
  auto a = std::make_shared<std::string>(), b = std::make_shared<std::string>(), out = std::make_shared<std::string>();
  cmd->add_option("run_a", *a, "The run compared against (a run folder)")->required();
  cmd->add_option("run_b", *b, "The what-if (a run folder of the same region and cells)")->required();
  cmd->add_option("-o,--out", *out, "A new folder for the comparison (refused if it holds anything)")->required();
  auto noPlots = std::make_shared<bool>(false);
  cmd->add_flag("--no-plots", *noPlots, "Do not draw the difference maps");
  cmd->callback([=] {
    opt->runA = *a;
    opt->runB = *b;
    opt->outDir = *out;
    opt->plots = !*noPlots;
    auto written = scenario::compareRuns(*opt);
    if (!written) {
      exitCommand("compare", written.message());
    }
    std::printf("compared: %s/compare.md (%zu files)\n", out->c_str(), written->size());
  });
}

}  // namespace strata::app
