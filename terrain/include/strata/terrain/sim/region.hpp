#pragma once
// Running a simulation on a selected region of a larger terrain: cut the region's input out,
// simulate it, write its layers back. Regions are cell rectangles of the full grid (a bbox in
// map coordinates becomes one through the grid's Georef).

#include <vector>

#include <strata/core/result.hpp>
#include <strata/gis/raster.hpp>
#include <strata/terrain/sim/sim_params.hpp>

namespace strata::terrain::sim {

/// A rectangle of cells [x0, x0 + width) x [y0, y0 + height) of a grid.
struct CellRect {
  int x0 = 0, y0 = 0, width = 0, height = 0;
};

/// The part of `full` inside `rect`: every grid cropped, per-row dx cut to its rows, materials,
/// dy and datum kept. Fails with a message naming the rectangle if it is empty, smaller than
/// 2x2 or not inside the grid.
Result<SimInput> cutRegion(const SimInput& full, const CellRect& rect);

/// Writes a region's layer thicknesses (e.g. Simulation::readLayers() after a run) back into the
/// full terrain's layers at `rect`; cells outside `rect` are untouched.
Status writeBackLayers(std::vector<gis::Grid<float>>& fullLayers, const std::vector<gis::Grid<float>>& regionLayers,
                       const CellRect& rect);

}  // namespace strata::terrain::sim
