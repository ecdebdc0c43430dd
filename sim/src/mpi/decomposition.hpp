#pragma once
// How a distributed run cuts its region (pure functions, no MPI): a grid of rectangular blocks,
// each with a halo; the halo pieces each block needs from the others; blocks ordered along a
// Hilbert curve and cut into contiguous runs of about equal work, one run per rank.
#include <cstdint>
#include <vector>

#include <strata/sim/region.hpp>

namespace strata::sim::detail {

struct BlockGrid {
  int width = 0, height = 0;               // the region (cells)
  int blockWidth = 0, blockHeight = 0;     // interior cells of a block (the last row/column may be narrower)
  int blocksX = 0, blocksY = 0, halo = 0;  // blocks per row / column, halo width (cells)

  /// `blockWidth` / `blockHeight` > 0: blocks of that size; otherwise about ranks * blocksPerRank
  /// blocks, a count that deals evenly to the ranks and as square as the region allows. Sizes
  /// are clamped to at least 2 cells and at most the region.
  static BlockGrid make(int width, int height, int ranks, int blocksPerRank, int blockWidth, int blockHeight, int halo);
  int count() const { return blocksX * blocksY; }
  CellRect interior(int block) const;
  CellRect extent(int block) const;  ///< interior + halo, clipped to the region
  int blockAt(int x, int y) const { return (y / blockHeight) * blocksX + x / blockWidth; }
};

/// A rectangle of `src`'s interior that lies in `dst`'s halo (global cells).
struct HaloPiece {
  int src = 0, dst = 0;
  CellRect rect;
};
/// Every halo piece, sorted by (src, dst).
std::vector<HaloPiece> haloPieces(const BlockGrid& grid);

/// The blocks in Hilbert-curve order (neighbours along the curve are neighbours in the grid, so
/// a contiguous run of it is a compact set of blocks).
std::vector<int> hilbertOrder(int blocksX, int blocksY);

/// The rank of every block: `order` cut into `ranks` contiguous runs of about equal total weight
/// (a block goes to the run its weight's midpoint falls in). Deterministic: every rank computes
/// the same from the same weights.
std::vector<int> partition(const std::vector<int>& order, const std::vector<double>& weight, int ranks);

/// The busiest rank's load over the mean load (1 = even; 0 weights: 1).
double imbalance(const std::vector<int>& owner, const std::vector<double>& weight, int ranks);

}  // namespace strata::sim::detail
