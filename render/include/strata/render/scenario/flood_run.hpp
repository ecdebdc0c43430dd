#pragma once
// Runs a scenario on the GPU and writes its run folder: GeoTIFF maps in the region's CRS, a CSV
// time series, PNG plots, pictures, a Markdown report, and a checkpoint at every output interval
// that `resume` continues from. Every file is written to a temporary and renamed into place, so
// an interrupted run never leaves a half-written file that looks complete. Ctrl-C (see
// core/interrupt.hpp) stops at once; the outputs stay those of the last finished interval.

#include <filesystem>
#include <string>
#include <vector>

#include <strata/core/result.hpp>
#include <strata/terrain/scenario.hpp>

namespace strata::render::scenario {

struct RunOptions {
  std::filesystem::path outDir;  ///< the run folder (created)
  bool resume = false;           ///< continue from outDir/checkpoint.bin
  bool pictures = true;          ///< render before / peak / after pictures
  bool plots = true;             ///< PNG plots of the time series (matplotlib)
  /// Stop after this many output intervals (tests of interrupt-and-resume); -1 = run to the end.
  int stopAfterIntervals = -1;
};

/// One row of the time series (series.csv).
struct SeriesRow {
  double timeS = 0;
  long long steps = 0;
  double dtS = 0;
  double waterM3 = 0, floodedAreaKm2 = 0, inflowM3 = 0, rainM3 = 0, outflowM3 = 0, evaporationM3 = 0;
  double balanceErrorRel = 0;
  double maxDepthM = 0;
  double sedimentM3 = 0, erodedM3 = 0, depositedM3 = 0;
};

/// What happened, for the report and the command's summary line.
struct RunSummary {
  bool completed = false;  ///< false: stopped by Ctrl-C or stopAfterIntervals
  double simulatedS = 0, wallS = 0;
  long long steps = 0;
  std::vector<SeriesRow> series;
  std::vector<std::string> files;  ///< written, relative to the run folder
};

Result<RunSummary> runScenario(const strata::terrain::Scenario& scenario, const RunOptions& options);

/// The CSV text of a series (header + rows), as series.csv holds it.
std::string seriesCsv(const std::vector<SeriesRow>& rows);

}  // namespace strata::render::scenario
