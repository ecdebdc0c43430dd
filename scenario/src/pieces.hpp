#pragma once
// What a run's outputs read of the solver's state, without gathering a grid to one process: the
// rectangles this process holds (its rank's blocks over MPI ranks, the whole region in one
// process) with their values, the maps written from them rank by rank, and the areas, volumes
// and extremes computed from them and reduced over the ranks (exactly: the same on any number of
// ranks). docs/distributed.md, "Scenario runs".

#include <filesystem>
#include <functional>
#include <string>
#include <vector>

#include <strata/core/result.hpp>
#include <strata/gis/dem_io.hpp>
#include <strata/sim/mpi/ranks.hpp>
#include <strata/sim/region.hpp>
#include <strata/sim/solver.hpp>

namespace strata::scenario::detail {

using sim::Ranks;

/// A rectangle of the region this process holds and the state on it.
struct Piece {
  gis::CellRect rect;
  gis::Grid<uint8_t> inside;  ///< 1 for the region's cells, 0 for walls (a polygon's outside, voids as walls)
  gis::Grid<float> depth;     ///< water depth (m)
  sim::FloodStats flood;
  /// Erosion runs only: suspended sediment (m of material), the bed now (above the datum) and the
  /// layers now and at the start (thicknesses, bottom first).
  gis::Grid<float> suspended, bed;
  std::vector<gis::Grid<float>> layers, initialLayers;
};

/// The model input of a window of the region (what the solver started from): the domain's in one
/// process, the run folder's input/*.tif over MPI ranks.
using InputWindow = std::function<Result<sim::SimInput>(const gis::CellRect&)>;

/// This process's pieces (local: nothing is exchanged). Walls are the cells whose base elevation
/// is kWallElevationM in the model input.
Result<std::vector<Piece>> readPieces(const sim::Solver& solver, const InputWindow& input, bool erosion);

/// How maps/elevation.tif is written: the bed the model used (conditioned), in metres.
gis::WriteOptions elevationMapOptions();
/// How maps/conditioning.tif is written: the bed the model used less the DEM's, in metres.
gis::WriteOptions conditioningMapOptions();

/// Collective: writes the GeoTIFF `file` (`georef` and `options` used by the lead only) from every
/// rank's `windows` (cells of the grid). The lead creates a temporary beside `file`, the ranks
/// write their windows into it in turn (rank order: GDAL has one writer at a time), and the lead
/// renames it into place: a reader never sees a partial raster.
Status writeRaster(const Ranks& ranks, const std::filesystem::path& file, const gis::Georef& georef,
                   const gis::WriteOptions& options, const std::vector<gis::GridWindow>& windows);

/// Collective: writes the GeoTIFF `file` (`georef` and `options` used by the lead only) from every
/// rank's pieces, `values` giving a piece's grid (NaN: no data), through writeRaster.
Status writeMapFile(const Ranks& ranks, const std::filesystem::path& file, const gis::Georef& georef,
                    const gis::WriteOptions& options, const std::vector<Piece>& pieces,
                    const std::function<gis::Grid<float>(const Piece&)>& values);

/// Pictures of a region over `cells` cells a side (RunOptions::pictureCells) are drawn from every
/// k-th cell of each row and column, k the smallest that brings it within.
int pictureStride(int width, int height, int cells);

/// Collective: on the lead, the grid of every `stride`-th cell of each row and column of a
/// `width` x `height` region (cells (k stride, j stride)), `value(piece, index in the piece)`
/// from the ranks' pieces that hold them; empty elsewhere.
gis::Grid<float> gatherStrided(const Ranks& ranks, const std::vector<Piece>& pieces, int stride, int width, int height,
                               const std::function<float(const Piece&, size_t)>& value);

/// The GeoTIFF at `path` at every `stride`-th cell of each row and column (read a band of rows at
/// a time: never the whole raster), with its georeference scaled to match.
Result<gis::Raster> readStrided(const std::filesystem::path& path, int stride);

/// A largest value and its cell (the first in row-major order among equals), with a value of that
/// cell that goes with it.
struct Extreme {
  double value = -1;
  int x = 0, y = 0;
  double with = 0;
};
/// Collective: the largest of the ranks' extremes (ties: the first cell in row-major order).
Extreme largest(const Ranks& ranks, const Extreme& mine);
/// Whether `a` goes before `b` as the largest (larger value; among equals, the earlier cell).
bool beats(const Extreme& a, const Extreme& b);

}  // namespace strata::scenario::detail
