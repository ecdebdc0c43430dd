#pragma once
// Runs a scenario on a solver (the GL backend on a hardware GPU, the CPU backend otherwise, or as
// asked) and writes its run folder: GeoTIFF maps in the region's CRS, a CSV time series, PNG
// plots, pictures, a Markdown report, and a checkpoint at every output interval that `resume`
// continues from. Every file is written to a temporary and renamed into place, so an interrupted
// run never leaves a half-written file that looks complete. Ctrl-C (see core/interrupt.hpp) stops
// after the step under way; the outputs stay those of the last finished interval.
//
// One run writes into a run folder at a time (a lock on outDir/run.lock, held for the whole run).
// A folder that holds an earlier run's outputs is refused unless the run resumes it (--resume)
// or replaces them (--overwrite: only the files a run writes are removed, never others); the
// temporaries of a run that was killed are removed when the next one starts.

#include <cstdint>
#include <filesystem>
#include <functional>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include <strata/core/result.hpp>
#include <strata/scenario/scenario.hpp>

namespace strata::scenario {

struct RunOptions {
  std::filesystem::path outDir;   ///< the run folder (created)
  std::string command = "flood";  ///< the command that runs it ("flood", "erode"), recorded in checkpoints
  /// Overrides the scenario's [model] backend when set.
  std::optional<Backend> backend;
  bool resume = false;     ///< continue from outDir/checkpoint.bin
  bool overwrite = false;  ///< replace the outputs of an earlier run in outDir (only the files a run writes)
  /// Refuse grids whose run needs more memory than this (bytes; 0: what the machine has available).
  uint64_t memoryBudgetBytes = 0;
  bool pictures = true;  ///< render before / peak / after pictures
  /// Pictures of a region over this many cells a side are drawn from every k-th cell of each row
  /// and column (the smallest k that brings it within), so that the rendered bed and the state
  /// gathered for it stay bounded whatever the region.
  int pictureCells = 4096;
  bool plots = true;  ///< PNG plots of the time series (matplotlib)
  /// Stop after this many output intervals (tests of interrupt-and-resume); -1 = run to the end.
  int stopAfterIntervals = -1;
  /// Run over the ranks of MPI_COMM_WORLD (`mpirun -np N strata flood`; docs/distributed.md,
  /// "Scenario runs"): MPI is initialised by the caller, and every rank calls runScenario with the
  /// same scenario and options. The ranks build the domain row by row (or rank 0 builds it whole
  /// when a step needs the whole region) into the model input (input/); each rank reads its
  /// blocks' windows of it, writes its blocks of the maps and its own part of each checkpoint
  /// (checkpoint.R-of-N.bin); rank 0 writes the series, pictures, plots and report. A run is
  /// resumed on the same number of ranks. Failures are the same on every rank.
  bool distributed = false;
  /// Called with the simulated time and the duration (s) during the run (at most ~5 times a
  /// wall-clock second, and at each output interval's end); returning false stops the run as a
  /// Ctrl-C does (a resumable folder, RunSummary::completed false). For callers such as the
  /// Python module; one process only.
  std::function<bool(double timeS, double durationS)> onProgress;
};

/// One row of the time series (series.csv).
struct SeriesRow {
  double timeS = 0;
  long long steps = 0;
  double dtS = 0;
  double waterM3 = 0, floodedAreaKm2 = 0, inflowM3 = 0, rainM3 = 0, outflowM3 = 0, evaporationM3 = 0,
         infiltrationM3 = 0;
  double balanceErrorRel = 0;
  double maxDepthM = 0;
  double sedimentM3 = 0, erodedM3 = 0, depositedM3 = 0;
};

/// Where the material went in an erosion run (m^3, summed in double over every cell of the grid,
/// cell areas as the solver's: its row dx times its float32 dy): docs/scenario.md, "Erosion
/// outputs".
struct MaterialBudget {
  std::vector<std::string> layers;                       ///< material of each layer, bottom first
  std::vector<double> initialM3, finalM3;                ///< per layer
  std::vector<double> exposedInitialM2, exposedFinalM2;  ///< area where the layer is the topmost one
  double erodedM3 = 0;                                   ///< sum over cells of the net loss of thickness (cut)
  double depositedM3 = 0;                                ///< sum over cells of the net gain (fill)
  double suspendedM3 = 0;                                ///< carried by the water at the end
  double outflowM3 = 0;                                  ///< carried out through open edges
  double initialM3Total = 0;                             ///< all layers + suspended at the start
  /// final layers + suspended + outflow - initial: 0 up to float rounding (E9).
  double balanceM3() const {
    double fin = 0;
    for (double v : finalM3) fin += v;
    return fin + suspendedM3 + outflowM3 - initialM3Total;
  }
};

/// What a spin-up (Scenario::spinUpS) did: how the river stood at t = 0.
struct SpinUpSummary {
  double seconds = 0;         ///< how long it ran; 0: no spin-up
  double longestS = 0;        ///< the scenario's spin_up: the longest it could run
  double toleranceRel = 0;    ///< the scenario's spin_up_tolerance (0: none, it ran longestS)
  bool steady = false;        ///< the stored water changed by less than the tolerance (it stopped there)
  double windowS = 0;         ///< the last tenth of longestS, over which the two rates below are taken
  double baseFlowM3S = 0;     ///< the inflows at t = 0, held through the spin-up
  double storedM3 = 0;        ///< water in the region at t = 0
  double outflowM3S = 0;      ///< leaving through open edges and levels over the window
  double storageRateM3S = 0;  ///< change of the stored water over the window (0 at equilibrium)
  long long steps = 0;
};

/// What happened, for the report and the command's summary line.
/// One gauge or section over the run (the report's table; the rows are in gauges.csv and
/// sections.csv).
struct ProbeSummary {
  std::string name;
  int x = 0, y = 0;                  ///< a gauge's cell (column, row of the region)
  int faces = 0;                     ///< a section's cell faces
  double peak = 0;                   ///< a gauge's largest depth (m); a section's largest discharge (m^3/s, signed)
  double peakTimeS = -1;             ///< when (s; -1: never wet / nothing crossed)
  double volumeM3 = 0;               ///< a section: the net volume across it, left to right
  double forwardM3 = 0, backM3 = 0;  ///< a section: left to right and right to left (both >= 0)
};

struct RunSummary {
  bool completed = false;            ///< false: stopped by Ctrl-C or stopAfterIntervals
  std::string backend;               ///< what ran it (Solver::backendName)
  int ranks = 1;                     ///< MPI ranks it ran on (1: one process)
  double simulatedS = 0, wallS = 0;  ///< from t = 0; the wall time includes a spin-up's
  long long steps = 0;               ///< from t = 0 (a spin-up's are SpinUpSummary::steps)
  std::vector<SeriesRow> series;
  std::vector<std::string> files;          ///< written, relative to the run folder
  std::optional<MaterialBudget> material;  ///< erosion runs
  SpinUpSummary spinUp;
  std::vector<ProbeSummary> gauges, sections;  ///< [[outputs.gauge]], [[outputs.section]]
};

Result<RunSummary> runScenario(const strata::scenario::Scenario& scenario, const RunOptions& options);

/// The files a run writes into its folder that exist in `runDir` (relative paths), and the
/// temporaries of runs that were killed while writing them.
std::vector<std::string> runFolderOutputs(const std::filesystem::path& runDir);
std::vector<std::string> runFolderTemporaries(const std::filesystem::path& runDir);

/// The CSV text of a series (header + rows), as series.csv holds it.
std::string seriesCsv(const std::vector<SeriesRow>& rows);
/// A series.csv read back: its columns by header name (a run stopped before its first output
/// interval has no rows: refused, as is a cell that is not a number, naming file and line).
Result<std::map<std::string, std::vector<double>>> readSeriesCsv(const std::filesystem::path& file);

}  // namespace strata::scenario
