#pragma once
// Filling a DEM's voids (no-data cells, e.g. SRTM's on steep summits) from the valid cells
// around them, as `gdal_fillnodata` does.

#include <cstddef>

#include <strata/core/result.hpp>
#include <strata/gis/raster.hpp>

namespace strata::gis {

/// Fills every no-data cell of `grid` in place with GDAL's fill-nodata (GDALFillNodata: each
/// void cell takes the inverse-distance weighted mean of the valid cells found along rays from
/// it; no smoothing passes), searching as far as the grid's larger side so that no void is
/// left. A filled value lies between the lowest and the highest valid cell around its void:
/// a summit void stays high. Returns the number of cells filled; fails on a grid without a
/// valid cell.
Result<size_t> fillVoids(Grid<float>& grid);

}  // namespace strata::gis
