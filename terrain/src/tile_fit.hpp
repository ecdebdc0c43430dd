#pragma once
// Private: the error-bounded fit of one tile: the coarsest resolution the store's metric allows,
// its samples (block means) and their error against the full-resolution cells.

#include <cstdint>
#include <vector>

#include <strata/gis/raster.hpp>
#include <strata/terrain/tile_store.hpp>

namespace strata::terrain::detail {

/// The exponent, samples and error of one tile under the store's metric.
struct Fit {
  int exp = 0;
  std::vector<gis::Grid<float>> samples;  ///< per field, 2^exp a side
  std::vector<float> lo, hi, maxErr, rmsErr;
  std::vector<uint64_t> valid;
  bool empty() const;
};

/// Fits a tile's full-resolution fields (2^maxExp a side each; only the first wIn x hIn cells are
/// inside the grid, the rest is ignored) to `metric`: the coarsest exponent allowed, its samples
/// and its error against `full`. Range metric: the exponent follows the tile's range against
/// `evalRange` (per field); `keep` supplies the min/max it is chosen from (a resampled tile keeps
/// its source's statistics). Either metric keeps voids void: no sample mixes data and no data.
Fit fitTile(const std::vector<gis::Grid<float>>& full, int wIn, int hIn, const TileMetricParams& metric,
            const std::vector<float>& evalRange, const TileRecord* keep);

/// Per-field min/max over the first wIn x hIn cells of each field (NaN: no data), and the count
/// of cells with data when `valid` is given.
void fieldRanges(const std::vector<gis::Grid<float>>& fields, int wIn, int hIn, std::vector<float>& lo,
                 std::vector<float>& hi, std::vector<uint64_t>* valid = nullptr);

/// Base cells of block (bx, by) of side b inside the grid's first wIn x hIn cells.
uint64_t cellsInGrid(int bx, int by, int b, int wIn, int hIn);

}  // namespace strata::terrain::detail
