#pragma once
// Running a simulation on a selected region of a larger terrain: cut the region's input out,
// simulate it, write its layers back. Regions are cell rectangles of the full grid (a bbox in
// map coordinates becomes one through the grid's Georef).

#include <functional>
#include <vector>

#include <strata/core/result.hpp>
#include <strata/gis/raster.hpp>
#include <strata/sim/input.hpp>

namespace strata::sim {

/// Rectangles of cells are gis::CellRect: [x, x + width) x [y, y + height).
using gis::CellRect;

/// The part of `full` inside `rect`: every grid cropped, per-row dx cut to its rows, materials,
/// dy and datum kept. Fails with a message naming the rectangle if it is empty, smaller than
/// 2x2 or not inside the grid.
Result<SimInput> cutRegion(const SimInput& full, const CellRect& rect);

/// Writes a region's layer thicknesses (e.g. Simulation::readLayers() after a run) back into the
/// full terrain's layers at `rect`; cells outside `rect` are untouched.
Status writeBackLayers(std::vector<gis::Grid<float>>& fullLayers, const std::vector<gis::Grid<float>>& regionLayers,
                       const CellRect& rect);

/// A region's input read one window at a time: what a run whose region may exceed one process's
/// memory is built from (each rank of a distributed run reads only its blocks plus their halos).
/// The shape is known up front; `read` returns the input of the cells in a window.
struct RegionSource {
  int width = 0, height = 0;                 ///< cells
  std::vector<terrain::Material> materials;  ///< one per layer
  std::vector<double> rowDxM;                ///< cell size east-west: one value, or one per row (m)
  double dyM = 1.0;                          ///< cell size north-south (m)
  double datumM = 0.0;                       ///< elevations are stored relative to this (m)
  /// The input of the cells of `window` (inside the region): each grid window-sized (water and
  /// rain may be empty), rowDxM for its rows (or the one value), the same materials, dy and datum.
  std::function<Result<SimInput>(const CellRect& window)> read;
};

/// A RegionSource over an input held in memory (cutRegion per window); it keeps its own copy.
RegionSource regionSourceOf(SimInput whole);

/// Checks a RegionSource's shape: at least 2x2 cells, rowDxM one value or one per row, positive
/// finite cell sizes, a finite datum, at least one material, a reader.
Status checkRegionSource(const RegionSource& region);

/// source.read(window), checked against the shape: grids window-sized, the region's materials,
/// dy and datum, rowDxM one value or one per window row. Fails naming the window.
Result<SimInput> readWindow(const RegionSource& region, const CellRect& window);

}  // namespace strata::sim
