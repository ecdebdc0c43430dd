#include "settle.hpp"

#include <cmath>

#include <strata/core/bytes.hpp>

namespace strata::scenario::detail {

// Thermal weathering (E7, docs/sim-erosion.md) tests a cell's topmost layer: it sheds when the bed
// (base + layers) drops to a 4-neighbour by more than tan(its angle of repose) x the distance; the
// layers below it are tested only once it is gone. So, until nothing changes: wherever the topmost
// layer is an at_rest one and its cell would shed, that layer is left off (the next layer down
// becomes the top and is tested in turn). Cells outside a polygon region are walls and are not
// compared.
void settleAtRest(const Scenario& s, const Ranks& ranks, int height, int own, ScenarioDomain& d) {
  const size_t L = d.input.layersM.size(), first = L - s.terrain.layers.size();  // the scenario's, on top
  d.layerCellsTooSteep.assign(s.terrain.layers.size(), 0);
  bool any = false;
  for (const auto& spec : s.terrain.layers) any |= spec.atRest;
  if (!any) return;
  const int w = d.input.baseM.width, held = d.input.baseM.height;
  STRATA_CHECK(own > 0 && own <= held && held <= own + 1 && d.firstRow + own <= height)
      << "settleAtRest: the rows held are not the rank's";
  std::vector<double> tanRepose(L);
  for (size_t k = 0; k < L; ++k) tanRepose[k] = std::tan(double(d.input.materials[k].talusAngleDeg) * M_PI / 180.0);
  auto bed = [&](int x, int y) {
    double z = d.input.baseM.at(x, y);
    for (const auto& l : d.input.layersM) z += l.at(x, y);
    return z;
  };

  // A border row as the neighbouring rank sees it: each cell's bed, or NaN outside the region.
  auto borderRow = [&](int y) {
    std::vector<double> row(static_cast<size_t>(w));
    for (int x = 0; x < w; ++x) row[size_t(x)] = d.inside.at(x, y) ? bed(x, y) : std::nan("");
    ByteWriter out;
    out.vec(row);
    return out.out;
  };
  auto decode = [&](const std::string& bytes) {
    std::vector<double> row;
    if (bytes.empty()) return row;  // no rank there: the region's edge
    ByteReader in{bytes};
    in.vec(row);
    STRATA_CHECK(in.ok && row.size() == size_t(w)) << "settleAtRest: a border row did not decode";
    return row;
  };

  for (;;) {
    const auto [before, after] = ranks.swapWithNeighbours(borderRow(0), borderRow(own - 1));
    const std::vector<double> above = decode(before), below = decode(after);
    // The neighbour's bed, or NaN where there is none to compare with.
    auto neighbourBed = [&](int x, int y) {
      if (x < 0 || x >= w) return std::nan("");
      if (y < 0) return above.empty() ? std::nan("") : above[size_t(x)];
      if (y >= own) return below.empty() ? std::nan("") : below[size_t(x)];
      return d.inside.at(x, y) ? bed(x, y) : std::nan("");
    };
    bool changedHere = false;
    for (bool changed = true; changed;) {
      changed = false;
      for (int y = 0; y < own; ++y) {
        for (int x = 0; x < w; ++x) {
          if (!d.inside.at(x, y)) continue;
          size_t top = L;
          for (size_t k = L; k-- > 0;) {
            if (d.input.layersM[k].at(x, y) > 0) {
              top = k;
              break;
            }
          }
          if (top == L || top < first || !s.terrain.layers[top - first].atRest) continue;
          const double z = bed(x, y);
          const int next[4][3] = {{x - 1, y, 0}, {x + 1, y, 0}, {x, y - 1, 1}, {x, y + 1, 1}};
          for (const auto& n : next) {
            const double zn = neighbourBed(n[0], n[1]);
            if (std::isnan(zn)) continue;
            const double length = n[2] == 0 ? d.input.rowDxM[size_t(y)] : d.input.dyM;
            if (z - zn > tanRepose[top] * length) {
              d.input.layersM[top].at(x, y) = 0;
              d.layerCellsTooSteep[top - first] += 1;
              changed = true;
              break;
            }
          }
        }
      }
      changedHere |= changed;
    }
    if (!ranks.minMax(changedHere ? 1 : 0).second) break;  // settled everywhere against current borders
  }
}

}  // namespace strata::scenario::detail
