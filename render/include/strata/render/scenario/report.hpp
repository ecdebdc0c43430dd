#pragma once
// The run folder's plots and report.md: the scenario and what happened, in numbers people can
// put in front of others, with the maps, plots and pictures next to it.

#include <filesystem>
#include <string>
#include <vector>

#include <strata/core/result.hpp>
#include <strata/render/scenario/flood_run.hpp>
#include <strata/render/sim/simulation.hpp>
#include <strata/terrain/scenario_domain.hpp>

namespace strata::render::scenario {

struct ReportInput {
  const strata::terrain::Scenario& scenario;
  const strata::terrain::ScenarioDomain& domain;
  const RunSummary& summary;
  sim::FloodStats flood;                   ///< per-cell maxima, arrival and duration at the end of the run
  std::string device;                      ///< the GL renderer the run used
  std::vector<std::string> pictures = {};  ///< rendered pictures (relative paths), if any
};

/// plots/*.png: the time series (tools/plot_series.py) and the maps over a hillshade
/// (tools/plot_maps.py), with Debian's matplotlib. Returns the files written (relative).
Result<std::vector<std::string>> writePlots(const std::filesystem::path& runDir, const gis::Raster& bed,
                                            bool completed);

/// report.md.
Status writeReport(const std::filesystem::path& runDir, const ReportInput& input);

}  // namespace strata::render::scenario
