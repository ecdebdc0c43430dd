#pragma once
// Depression filling by priority flood (Barnes, Lehman & Mulla 2014), tile by tile (Barnes 2016,
// "Parallel priority-flood depression filling for trillion cell digital elevation models"):
// every cell that does not drain is raised to the level at which it would spill, the lowest
// level over all paths to a draining cell of the highest cell on the path (4-neighbours, cells
// of the region only). Each tile is flooded on its own from its draining cells and its
// perimeter; where two floods meet, and across tile borders, the two labels are joined at the
// level water would cross; the spill level of every label is then found on that graph (small:
// the tiles' perimeters), and each cell is raised to its label's. The result is the one priority
// flood's over the whole grid, on any tiling; the tiles can be flooded in separate processes
// (the graph is what they exchange).

#include <cstdint>
#include <vector>

#include <strata/gis/raster.hpp>

namespace strata::gis {

/// What a depression fill works on: elevations, which cells belong to the region (others are
/// walls, never crossed) and which drain (open edges, holes: the floods start there). The grids
/// hold the cells of `area` of a grid `gridWidth` cells wide (by default the whole grid): a
/// process that holds only some rows of the grid (and floods only tiles inside them) gives those.
struct FillInput {
  const Grid<float>* elevation = nullptr;
  const Grid<uint8_t>* inside = nullptr;
  const Grid<uint8_t>* drains = nullptr;
  CellRect area{};    ///< empty: the whole grid, the grids' own size
  int gridWidth = 0;  ///< 0: the grids' width
};

/// A join of two labels at the level water crosses between them.
struct SpillEdge {
  int64_t a = 0, b = 0;
  float level = 0;
};

/// Label of the draining cells' flood; a tile's perimeter cell c (row-major index in the whole grid)
/// seeds label kFirstPerimeterLabel + c; 0: not reached.
inline constexpr int64_t kDrainLabel = 1;
inline constexpr int64_t kFirstPerimeterLabel = 2;

/// One tile (inside the input's area) flooded on its own (phase 1).
struct TileFlood {
  CellRect tile;
  Grid<float> filled;            ///< the tile's elevations raised within the tile
  Grid<int64_t> label;           ///< the label whose flood reached each cell (0: none)
  std::vector<SpillEdge> edges;  ///< where two labels met inside the tile (the lowest meeting of each pair)
};
TileFlood floodTile(const FillInput& in, const CellRect& tile);

/// Joins across the borders of `tiles` (which partition the grid) between cells of the input's
/// area: 4-neighbours in two tiles, both of the region, at the higher of their elevations
/// (perimeter cells seed their own labels, so this needs no tile's flood).
std::vector<SpillEdge> borderEdges(const FillInput& in, const std::vector<CellRect>& tiles);

/// The spill level of every label reached from kDrainLabel over `edges` (phase 2), as sorted
/// (label, level) pairs; labels not listed never drain.
std::vector<std::pair<int64_t, float>> spillLevels(const std::vector<SpillEdge>& edges);

/// Phase 3: the tile's final elevations: a cell whose label drains at level s becomes
/// max(its filled elevation, s); a cell not reached, or whose label never drains, keeps its own.
Grid<float> finishTile(const FillInput& in, const TileFlood& flood,
                       const std::vector<std::pair<int64_t, float>>& spill);

/// The three phases in one process: the filled elevations of the whole grid.
Grid<float> fillDepressions(const FillInput& in, const std::vector<CellRect>& tiles);

}  // namespace strata::gis
