#pragma once
// From a scenario to what the solver starts from: the region cut from the DEM (read as a window,
// nothing outside it), per-row cell sizes and geodesic cell areas, the layers, the sources
// placed on cells, the initial water. Checks that need the terrain happen here, before any
// simulation: the region must lie inside the DEM and every source inside the region; messages
// name the scenario file, line and key.

#include <array>
#include <cstdint>
#include <string>
#include <vector>

#include <strata/core/result.hpp>
#include <strata/gis/raster.hpp>
#include <strata/scenario/scenario.hpp>
#include <strata/sim/input.hpp>

namespace strata::scenario {

struct ScenarioDomain {
  /// The grids hold rows [firstRow, firstRow + their height) of the region: all of it but where a
  /// rank of a run over MPI builds its own rows (scenario/src/domain_rows.hpp).
  int firstRow = 0;
  gis::Raster bed;                   ///< the region's bedrock elevation (m); georef of the region
  gis::Grid<uint8_t> inside;         ///< 1 for cells of the region, 0 outside a polygon region (walls)
  gis::Grid<double> cellAreaM2;      ///< geodesic area of each cell (m^2)
  sim::SimInput input;               ///< ready for a solver's create()
  sim::SimParams params;             ///< from [model], [erosion], [water]
  std::vector<sim::Source> sources;  ///< inflows, on cells
  std::vector<std::string> sourceNames;
  std::vector<sim::LevelBoundary> levels;  ///< fixed water levels, on cells (stage in m above the DEM's reference)
  std::vector<std::string> levelNames;
  /// [[outputs.gauge]]: the cell of each gauge.
  struct GaugeCell {
    std::string name;
    int x = 0, y = 0;
  };
  std::vector<GaugeCell> gauges;
  /// [[outputs.section]]: the cell faces its line crosses. A face joins two cells' centres: an x
  /// face (x, y) the cells (x - 1, y) and (x, y), a y face (x, y) the cells (x, y - 1) and
  /// (x, y) (sim::Solver::readFaceMassFlux's numbering); `sign` turns the face's flux (positive
  /// east or south) into the section's (positive from the line's left to its right).
  struct SectionFace {
    bool xFace = true;
    int x = 0, y = 0;
    float sign = 1;
  };
  struct SectionFaces {
    std::string name;
    std::vector<SectionFace> faces;
    std::vector<std::pair<int, int>> cells;  ///< the cells the line passes through (its mean level)
  };
  std::vector<SectionFaces> sections;
  double rainMmPerHour = 0;             ///< uniform rain rate while it falls
  double rainStartS = 0, rainEndS = 0;  ///< rain falls in [start, end)
  /// [water.rain] frames: each frame's rain (mm/h per cell of these rows, no data as 0) from its
  /// time on; the last one's until rainFramesEndS.
  struct RainFrame {
    double startS = 0;
    gis::Grid<float> mmPerHour;
  };
  std::vector<RainFrame> rainFrames;
  double rainFramesEndS = 0;
  double damBreakVolumeM3 = 0;           ///< initial water from dam breaks
  double totalAreaM2 = 0;                ///< area of the region's cells
  std::array<float, 2> bedRangeM{0, 0};  ///< the lowest and highest bed of the region's cells (m)
  /// What [terrain] breach_inflows carved (nothing when off).
  struct {
    int paths = 0, cells = 0;          ///< paths carved, cells changed on them
    double maxCutM = 0, maxFillM = 0;  ///< the largest lowering and raising (m)
    double cutM3 = 0, fillM3 = 0;      ///< terrain removed and added
  } breach;
  /// The region's cells without data and what became of them ([terrain] voids): 1 where the
  /// source had no data (their bed is filled from the cells around them in every mode).
  gis::Grid<uint8_t> voids;
  int voidCells = 0;
  /// Per [[terrain.layer]]: the cells left without it by at_rest (too steep for its material).
  std::vector<int> layerCellsTooSteep;
  /// What conditioning ([terrain] breach_inflows, fill_depressions) did to the bed, cell by cell:
  /// the bed after less the bed before (m; < 0 cut, > 0 raised; no data outside the region);
  /// empty when neither is on. maps/conditioning.tif.
  gis::Grid<float> conditioningM;
  /// What [terrain] fill_depressions raised (nothing when off).
  struct {
    int cells = 0;
    double maxM = 0, volumeM3 = 0;
  } filled;
};

/// Elevation given to cells outside a polygon region: a wall no flood in a DEM tops.
inline constexpr float kWallElevationM = 20000.0f;

/// Builds the domain in named steps: the region's window of the DEM or store, the grid planned
/// (at least 4 x 4 cells, and a run on it must fit in `memoryBudgetBytes`, 0: the memory the
/// machine has available; refused naming region.cell_size before anything is read), the bed
/// (resampled to region.cell_size, mosaicked), the polygon mask, geodesic cell sizes, the layer
/// stack (with erosion on, some loose material), the model parameters, and the inflows, levels,
/// rain and dam breaks placed on cells. One process's build (over MPI ranks each builds its own
/// rows: scenario/src/domain_rows.hpp, with the same bits).
Result<ScenarioDomain> buildDomain(const Scenario& scenario, uint64_t memoryBudgetBytes = 0);

/// Cell sizes of a georeferenced grid as the solvers use them: the geodesic area of each cell,
/// dy the geodesic length of a column cell, and per-row dx such that dx * dy is the row's cell
/// area (at the grid's middle column).
struct CellSizes {
  gis::Grid<double> cellAreaM2;
  double dyM = 0;
  std::vector<double> rowDxM;
};
Result<CellSizes> measureCells(const gis::Georef& georef);

/// The solver parameters a scenario's [model], [erosion] and [water] ask for.
sim::SimParams modelParams(const Scenario& scenario);

/// Cells (x, y) a polyline passes through, each once, in order (sampled at a quarter cell).
std::vector<std::pair<int, int>> cellsAlong(const std::vector<std::array<double, 2>>& pixelPoints, int width,
                                            int height);

/// The faces between 4-neighbouring cells of a width x height grid (both cells inside it) whose
/// centre-to-centre segment a polyline of pixel points crosses, each once, with the sign that makes
/// a flux across it positive from the line's left to its right.
std::vector<ScenarioDomain::SectionFace> facesCrossed(const std::vector<std::array<double, 2>>& pixelPoints, int width,
                                                      int height);

/// Whether pixel-space point (x, y) lies inside the polygon (even-odd rule).
bool insidePolygon(const std::vector<std::array<double, 2>>& polygon, double x, double y);

}  // namespace strata::scenario
