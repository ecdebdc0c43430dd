#pragma once
// Filling a DEM's voids (no-data cells, e.g. SRTM's on steep summits) from the valid cells
// around them, as `gdal_fillnodata` does.

#include <array>
#include <cstddef>
#include <optional>

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
/// As fillVoids, searching `maxSearchCells` far.
Result<size_t> fillVoids(Grid<float>& grid, int maxSearchCells);

/// The rows [first, last) of a grid that fillVoids reads to fill the voids of its rows [y0, y1):
/// filling just those rows, searching as far as fillVoids searches the whole grid (the larger of
/// its sides), gives the whole fill's bits in rows [y0, y1) (a rank of a run over MPI fills its
/// rows so). GDALFillNodata takes a void's value from the nearest valid cell of each of four
/// quadrants around it, each cell the first valid one above (below) it in a column; the nearest
/// in the upper quadrants is no farther than the first valid cell above the void in its own
/// column, or in the next column to the right (the same column at the grid's right edge), so no
/// row above the higher of those two is read (the grid's top row where a column has none), and
/// likewise below. `rows` holds rows [top, top + rows.height) of a grid `height` rows high, and
/// must hold rows [y0, y1); nothing where they do not reach those cells (read more rows, ask
/// again).
std::optional<std::array<int, 2>> voidFillRows(const Grid<float>& rows, int top, int height, int y0, int y1);

}  // namespace strata::gis
