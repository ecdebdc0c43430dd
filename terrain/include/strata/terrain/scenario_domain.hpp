#pragma once
// From a scenario to what the solver starts from: the region cut from the DEM (read as a window,
// nothing outside it), per-row cell sizes and geodesic cell areas, the layers, the sources
// placed on cells, the initial water. Checks that need the terrain happen here, before any
// simulation: the region must lie inside the DEM and every source inside the region; messages
// name the scenario file, line and key.

#include <string>
#include <vector>

#include <strata/core/result.hpp>
#include <strata/gis/raster.hpp>
#include <strata/terrain/scenario.hpp>
#include <strata/terrain/sim/sim_params.hpp>

namespace strata::terrain {

struct ScenarioDomain {
  gis::Raster bed;                   ///< the region's bedrock elevation (m); georef of the region
  gis::Grid<uint8_t> inside;         ///< 1 for cells of the region, 0 outside a polygon region (walls)
  gis::Grid<double> cellAreaM2;      ///< geodesic area of each cell (m^2)
  sim::SimInput input;               ///< ready for Simulation::create
  sim::SimParams params;             ///< from [model], [erosion], [water]
  std::vector<sim::Source> sources;  ///< inflows, on cells
  std::vector<std::string> sourceNames;
  std::vector<sim::LevelBoundary> levels;  ///< fixed water levels, on cells (stage in m above the DEM's reference)
  std::vector<std::string> levelNames;
  double rainMmPerHour = 0;             ///< uniform rain rate while it falls
  double rainStartS = 0, rainEndS = 0;  ///< rain falls in [start, end)
  double damBreakVolumeM3 = 0;          ///< initial water from dam breaks
  double totalAreaM2 = 0;               ///< area of the region's cells
};

/// Elevation given to cells outside a polygon region: a wall no flood in a DEM tops.
inline constexpr float kWallElevationM = 20000.0f;

Result<ScenarioDomain> buildDomain(const Scenario& scenario);

/// Cells (x, y) a polyline passes through, each once, in order (sampled at a quarter cell).
std::vector<std::pair<int, int>> cellsAlong(const std::vector<std::array<double, 2>>& pixelPoints, int width,
                                            int height);

/// Whether pixel-space point (x, y) lies inside the polygon (even-odd rule).
bool insidePolygon(const std::vector<std::array<double, 2>>& polygon, double x, double y);

}  // namespace strata::terrain
