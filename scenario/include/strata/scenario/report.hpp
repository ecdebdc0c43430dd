#pragma once
// The run folder's plots and report.md: the scenario and what happened, in numbers people can
// put in front of others, with the maps, plots and pictures next to it.

#include <array>
#include <filesystem>
#include <string>
#include <vector>

#include <strata/core/result.hpp>
#include <strata/scenario/domain.hpp>
#include <strata/scenario/run.hpp>
#include <strata/sim/solver.hpp>

namespace strata::scenario {

/// The flood's extremes over the run (cells of the region, (x, y) = (column, row); value -1 and
/// no cell when nothing was wet), reduced over the ranks of a run over MPI.
struct FloodSummary {
  struct AtCell {
    double value = -1;
    int x = 0, y = 0;
  };
  AtCell deepest;                ///< the largest depth (m)
  AtCell fastest;                ///< the largest speed (m/s)
  AtCell farthest;               ///< the wet cell farthest (geodesic, m) from the first inflow's first cell
  double farthestArrivalS = -1;  ///< when water first reached it (-1: never above the threshold)
  double everWetM2 = 0;          ///< area of the cells wet at some time (the model's cell areas)
  /// That area by hazard class (hazard.hpp: low, moderate, significant, extreme).
  std::array<double, 4> hazardClassM2{};
  /// Water at the end that stands in closed depressions of the bed: in cells a priority flood
  /// from the open edges raises (gis::fillDepressions), the part of the depth below the spill
  /// level (m^3, the model's cell areas); the deepest such water and its cell; all water at the end.
  double pondedM3 = 0, waterAtEndM3 = 0;
  AtCell deepestPonded;
  /// [terrain] voids = "fill": the area of filled void cells ever deeper than the wet threshold,
  /// their number, and the deepest water on one (one process only: a run over MPI ranks does
  /// not hold the void mask, and leaves these at 0).
  double wetVoidM2 = 0;
  int wetVoidCells = 0;
  AtCell deepestVoid;
  /// A lower bound of each wet cell's largest Froude number over the run, its fastest speed over
  /// sqrt(g x its deepest water) (when the speed peaked the water was no deeper): the largest,
  /// and the area where it is above 1 (flow that was certainly supercritical at some time).
  AtCell froude;
  double supercriticalM2 = 0;
};

struct ReportInput {
  const strata::scenario::Scenario& scenario;
  const strata::scenario::ScenarioDomain& domain;
  const RunSummary& summary;
  FloodSummary flood;                      ///< over the whole run, at its end
  std::string backend;                     ///< what ran the simulation (Solver::backendName)
  std::vector<std::string> pictures = {};  ///< rendered pictures (relative paths), if any
  std::string maxDepthLegend = {};         ///< what the max-depth picture's colours mean
};

/// plots/*.png: the time series (scenario/plots/plot_series.py) and the maps over a hillshade of
/// maps/elevation.tif (scenario/plots/plot_maps.py; the run writes the elevation map once the
/// domain is built), with Debian's matplotlib. Returns the files written (relative), the
/// elevation map first.
/// What the report warns about (one paragraph each, Markdown): water ending in closed depressions
/// of the bed (more than a fifth of the water at the end), speeds above 10 m/s, water over filled
/// voids of the DEM, supercritical flow under the local-inertial scheme. Also logged.
std::vector<std::string> runWarnings(const ReportInput& in);

/// `haveSeries` false (a run stopped before its first output interval): no series plots.
Result<std::vector<std::string>> writePlots(const std::filesystem::path& runDir, bool haveSeries);

/// report.md.
Status writeReport(const std::filesystem::path& runDir, const ReportInput& input);

/// A volume as the report writes it, in the unit that fits: "740 m³" under ten thousand, "69.3
/// thousand m³" under a million, "4.2 million m³" above (a 2 km² run's volumes read "0.0 million
/// m³" when all were in millions).
std::string volumeText(double m3);

}  // namespace strata::scenario
