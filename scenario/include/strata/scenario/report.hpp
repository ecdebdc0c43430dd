#pragma once
// The run folder's plots and report.md: the scenario and what happened, in numbers people can
// put in front of others, with the maps, plots and pictures next to it.

#include <filesystem>
#include <string>
#include <vector>

#include <strata/core/result.hpp>
#include <strata/scenario/domain.hpp>
#include <strata/scenario/run.hpp>
#include <strata/sim/solver.hpp>

namespace strata::scenario {

struct ReportInput {
  const strata::scenario::Scenario& scenario;
  const strata::scenario::ScenarioDomain& domain;
  const RunSummary& summary;
  sim::FloodStats flood;                   ///< per-cell maxima, arrival and duration at the end of the run
  std::string backend;                     ///< what ran the simulation (Solver::backendName)
  std::vector<std::string> pictures = {};  ///< rendered pictures (relative paths), if any
  std::string maxDepthLegend = {};         ///< what the max-depth picture's colours mean
};

/// plots/*.png: the time series (scenario/plots/plot_series.py) and the maps over a hillshade
/// (scenario/plots/plot_maps.py), with Debian's matplotlib. Returns the files written (relative).
Result<std::vector<std::string>> writePlots(const std::filesystem::path& runDir, const gis::Raster& bed,
                                            bool completed);

/// report.md.
Status writeReport(const std::filesystem::path& runDir, const ReportInput& input);

}  // namespace strata::scenario
