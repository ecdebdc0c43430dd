#pragma once
// What the tiled runners (TiledSolver, AdaptiveSolver) share: cutting a tile's input out
// of a region's grids, which of a tile's edges keep the region's open/closed setting, and
// sources split per cell so a tile that sees only some of a source's cells feeds each its share.
#include <cstdint>
#include <vector>

#include <strata/gis/raster.hpp>
#include <strata/sim/input.hpp>

namespace strata::sim::detail {

/// Cells [x0, x1) x [y0, y1) of `g` (an empty grid stays empty).
inline gis::Grid<float> crop(const gis::Grid<float>& g, int x0, int y0, int x1, int y1) {
  if (g.size() == 0) return {};
  gis::Grid<float> out(x1 - x0, y1 - y0);
  for (int y = y0; y < y1; ++y) {
    for (int x = x0; x < x1; ++x) out.at(x - x0, y - y0) = g.at(x, y);
  }
  return out;
}

/// The open edges of a tile spanning [ex0, ex1) x [ey0, ey1) (halo included) of a width x height
/// region: only the region's own edges keep their setting; inner tile edges lie in the halo,
/// whose outer cells are overwritten every step.
inline uint32_t tileOpenEdges(uint32_t regionEdges, int ex0, int ey0, int ex1, int ey1, int width, int height) {
  uint32_t e = 0;
  if (ex0 == 0) e |= regionEdges & kEdgeWest;
  if (ex1 == width) e |= regionEdges & kEdgeEast;
  if (ey0 == 0) e |= regionEdges & kEdgeNorth;
  if (ey1 == height) e |= regionEdges & kEdgeSouth;
  return e;
}

/// One source per cell of `source`, each carrying its share of the hydrograph.
inline std::vector<Source> perCellSources(const Source& source) {
  std::vector<Source> out;
  const double n = double(source.cells.size());
  auto samples = source.dischargeM3S.samples();
  for (auto& s : samples) s[1] /= n;
  for (const auto& cell : source.cells) out.push_back(Source{{cell}, TimeSeries(samples)});
  return out;
}

}  // namespace strata::sim::detail
