#include "decomposition.hpp"

#include <algorithm>
#include <cmath>
#include <numeric>

namespace strata::sim::detail {

BlockGrid BlockGrid::make(int width, int height, int ranks, int blocksPerRank, int blockWidth, int blockHeight,
                          int halo) {
  BlockGrid g;
  g.width = width;
  g.height = height;
  g.halo = halo;
  if (blockWidth <= 0 || blockHeight <= 0) {
    // About ranks * blocksPerRank blocks: a count that deals evenly to the ranks first, then
    // blocks as square as the region allows.
    const int n = std::max(1, ranks * blocksPerRank);
    double best = 1e300;
    for (int bx = 1; bx <= n; ++bx) {
      const int by = (n + bx - 1) / bx;
      if (bx > width || by > height) continue;
      const double count = double(bx) * by, perRank = std::ceil(count / ranks);
      const double uneven = perRank * ranks / count;  // 1 when every rank gets as many
      const double w = double(width) / bx, h = double(height) / by;
      const double aspect = std::max(w / h, h / w);
      const double score = uneven * (1.0 + 0.1 * (aspect - 1.0)) * (count / n);
      if (score < best) {
        best = score;
        blockWidth = (width + bx - 1) / bx;
        blockHeight = (height + by - 1) / by;
      }
    }
    if (blockWidth <= 0 || blockHeight <= 0) {
      blockWidth = width;
      blockHeight = height;
    }
  }
  g.blockWidth = std::clamp(blockWidth, std::min(2, width), width);
  g.blockHeight = std::clamp(blockHeight, std::min(2, height), height);
  g.blocksX = (width + g.blockWidth - 1) / g.blockWidth;
  g.blocksY = (height + g.blockHeight - 1) / g.blockHeight;
  return g;
}

CellRect BlockGrid::interior(int block) const {
  const int bx = block % blocksX, by = block / blocksX;
  const int x0 = bx * blockWidth, y0 = by * blockHeight;
  return {x0, y0, std::min(width, x0 + blockWidth) - x0, std::min(height, y0 + blockHeight) - y0};
}

CellRect BlockGrid::extent(int block) const {
  const CellRect r = interior(block);
  const int x0 = std::max(0, r.x - halo), y0 = std::max(0, r.y - halo);
  const int x1 = std::min(width, r.x + r.width + halo), y1 = std::min(height, r.y + r.height + halo);
  return {x0, y0, x1 - x0, y1 - y0};
}

std::vector<HaloPiece> haloPieces(const BlockGrid& g) {
  std::vector<HaloPiece> out;
  for (int d = 0; d < g.count(); ++d) {
    const CellRect e = g.extent(d);
    const int bx0 = e.x / g.blockWidth, bx1 = (e.x + e.width - 1) / g.blockWidth;
    const int by0 = e.y / g.blockHeight, by1 = (e.y + e.height - 1) / g.blockHeight;
    for (int by = by0; by <= by1; ++by) {
      for (int bx = bx0; bx <= bx1; ++bx) {
        const int s = by * g.blocksX + bx;
        if (s == d) continue;
        const CellRect i = g.interior(s);
        const int x0 = std::max(e.x, i.x), x1 = std::min(e.x + e.width, i.x + i.width);
        const int y0 = std::max(e.y, i.y), y1 = std::min(e.y + e.height, i.y + i.height);
        if (x0 < x1 && y0 < y1) out.push_back({s, d, {x0, y0, x1 - x0, y1 - y0}});
      }
    }
  }
  std::sort(out.begin(), out.end(),
            [](const HaloPiece& a, const HaloPiece& b) { return a.src != b.src ? a.src < b.src : a.dst < b.dst; });
  return out;
}

namespace {

// Position of (x, y) along the Hilbert curve filling an n x n square (n a power of two).
uint64_t hilbertIndex(uint64_t n, uint64_t x, uint64_t y) {
  uint64_t d = 0;
  for (uint64_t s = n / 2; s > 0; s /= 2) {
    const uint64_t rx = (x & s) ? 1 : 0, ry = (y & s) ? 1 : 0;
    d += s * s * ((3 * rx) ^ ry);
    if (ry == 0) {  // rotate the quadrant
      if (rx == 1) {
        x = n - 1 - x;
        y = n - 1 - y;
      }
      std::swap(x, y);
    }
  }
  return d;
}

}  // namespace

std::vector<int> hilbertOrder(int blocksX, int blocksY) {
  uint64_t n = 1;
  while (n < uint64_t(std::max(blocksX, blocksY))) n *= 2;
  std::vector<std::pair<uint64_t, int>> keyed;
  for (int by = 0; by < blocksY; ++by) {
    for (int bx = 0; bx < blocksX; ++bx)
      keyed.push_back({hilbertIndex(n, uint64_t(bx), uint64_t(by)), by * blocksX + bx});
  }
  std::sort(keyed.begin(), keyed.end());
  std::vector<int> order;
  for (const auto& [key, b] : keyed) order.push_back(b);
  return order;
}

std::vector<int> partition(const std::vector<int>& order, const std::vector<double>& weight, int ranks) {
  std::vector<int> owner(weight.size(), 0);
  double total = 0;
  for (int b : order) total += weight[size_t(b)];
  if (!(total > 0)) {  // nothing weighs anything: split by count
    for (size_t k = 0; k < order.size(); ++k) owner[size_t(order[k])] = int(k * size_t(ranks) / order.size());
    return owner;
  }
  double before = 0;
  for (int b : order) {
    const double mid = before + 0.5 * weight[size_t(b)];
    owner[size_t(b)] = std::clamp(int(mid / total * ranks), 0, ranks - 1);
    before += weight[size_t(b)];
  }
  return owner;
}

double imbalance(const std::vector<int>& owner, const std::vector<double>& weight, int ranks) {
  std::vector<double> load(size_t(ranks), 0.0);
  for (size_t b = 0; b < owner.size(); ++b) load[size_t(owner[b])] += weight[b];
  const double total = std::accumulate(load.begin(), load.end(), 0.0);
  if (!(total > 0)) return 1.0;
  return *std::max_element(load.begin(), load.end()) / (total / ranks);
}

}  // namespace strata::sim::detail
