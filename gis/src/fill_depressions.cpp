#include <strata/gis/fill_depressions.hpp>

#include <algorithm>
#include <functional>
#include <map>
#include <queue>
#include <utility>

#include <strata/core/check.hpp>

namespace strata::gis {
namespace {

// The lowest join of each pair of labels (a < b), in a stable order.
std::vector<SpillEdge> lowestJoins(const std::map<std::pair<int64_t, int64_t>, float>& joins) {
  std::vector<SpillEdge> out;
  out.reserve(joins.size());
  for (const auto& [pair, level] : joins) out.push_back({pair.first, pair.second, level});
  return out;
}

void join(std::map<std::pair<int64_t, int64_t>, float>& joins, int64_t a, int64_t b, float level) {
  if (a == b) return;
  const auto key = std::minmax(a, b);
  auto [it, added] = joins.emplace(key, level);
  if (!added) it->second = std::min(it->second, level);
}

// The input's area and the whole grid's width.
CellRect areaOf(const FillInput& in) {
  return in.area.empty() ? CellRect{0, 0, in.elevation->width, in.elevation->height} : in.area;
}
int64_t gridWidthOf(const FillInput& in) { return in.gridWidth > 0 ? in.gridWidth : in.elevation->width; }

// The input's grids at whole-grid cell (x, y) (inside its area).
struct At {
  const FillInput& in;
  CellRect a;
  size_t index(int x, int y) const { return size_t(y - a.y) * size_t(a.width) + size_t(x - a.x); }
  float z(int x, int y) const { return in.elevation->data[index(x, y)]; }
  bool inside(int x, int y) const { return in.inside->data[index(x, y)] != 0; }
  bool drains(int x, int y) const { return in.drains->data[index(x, y)] != 0; }
};

}  // namespace

TileFlood floodTile(const FillInput& in, const CellRect& t) {
  const CellRect a = areaOf(in);
  STRATA_CHECK(t.x >= a.x && t.y >= a.y && t.x + t.width <= a.x + a.width && t.y + t.height <= a.y + a.height)
      << "fill: a tile outside the input's area";
  const At at{in, a};
  const int64_t gw = gridWidthOf(in);
  TileFlood f;
  f.tile = t;
  f.filled = Grid<float>(t.width, t.height);
  f.label = Grid<int64_t>(t.width, t.height, 0);
  for (int y = 0; y < t.height; ++y) {
    for (int x = 0; x < t.width; ++x) f.filled.at(x, y) = at.z(t.x + x, t.y + y);
  }
  // Seeds: the draining cells, and the tile's perimeter (each its own label).
  struct Entry {
    float level;
    int cell;  // in the tile
    bool operator>(const Entry& o) const { return level != o.level ? level > o.level : cell > o.cell; }
  };
  std::priority_queue<Entry, std::vector<Entry>, std::greater<>> queue;
  for (int y = 0; y < t.height; ++y) {
    for (int x = 0; x < t.width; ++x) {
      const int gx = t.x + x, gy = t.y + y;
      if (!at.inside(gx, gy)) continue;
      const bool perimeter = x == 0 || y == 0 || x == t.width - 1 || y == t.height - 1;
      if (at.drains(gx, gy)) {
        f.label.at(x, y) = kDrainLabel;
      } else if (perimeter) {
        f.label.at(x, y) = kFirstPerimeterLabel + int64_t(gy) * gw + gx;
      } else {
        continue;
      }
      queue.push({f.filled.at(x, y), y * t.width + x});
    }
  }
  std::map<std::pair<int64_t, int64_t>, float> joins;
  while (!queue.empty()) {
    const Entry e = queue.top();
    queue.pop();
    const int x = e.cell % t.width, y = e.cell / t.width;
    const int64_t mine = f.label.at(x, y);
    const float level = f.filled.at(x, y);
    const int next[4][2] = {{x - 1, y}, {x + 1, y}, {x, y - 1}, {x, y + 1}};
    for (const auto& n : next) {
      if (n[0] < 0 || n[0] >= t.width || n[1] < 0 || n[1] >= t.height) continue;
      if (!at.inside(t.x + n[0], t.y + n[1])) continue;
      int64_t& theirs = f.label.at(n[0], n[1]);
      float& nz = f.filled.at(n[0], n[1]);
      if (theirs != 0) {
        join(joins, mine, theirs, std::max(level, nz));
        continue;
      }
      theirs = mine;
      nz = std::max(nz, level);
      queue.push({nz, n[1] * t.width + n[0]});
    }
  }
  f.edges = lowestJoins(joins);
  return f;
}

std::vector<SpillEdge> borderEdges(const FillInput& in, const std::vector<CellRect>& tiles) {
  const CellRect a = areaOf(in);
  const At at{in, a};
  const int64_t gw = gridWidthOf(in);
  Grid<int32_t> tileOf(a.width, a.height, -1);
  for (size_t k = 0; k < tiles.size(); ++k) {
    const auto t = tiles[k].intersected(a);
    for (int y = t.y; y < t.y + t.height; ++y) {
      for (int x = t.x; x < t.x + t.width; ++x) tileOf.data[at.index(x, y)] = int32_t(k);
    }
  }
  auto labelOf = [&](int x, int y) {
    return at.drains(x, y) ? kDrainLabel : kFirstPerimeterLabel + int64_t(y) * gw + x;
  };
  std::map<std::pair<int64_t, int64_t>, float> joins;
  for (int y = a.y; y < a.y + a.height; ++y) {
    for (int x = a.x; x < a.x + a.width; ++x) {
      if (!at.inside(x, y)) continue;
      const int32_t mine = tileOf.data[at.index(x, y)];
      STRATA_CHECK(mine >= 0) << "fill: the tiles do not cover cell " << x << ", " << y;
      const int next[2][2] = {{x + 1, y}, {x, y + 1}};
      for (const auto& n : next) {
        if (n[0] >= a.x + a.width || n[1] >= a.y + a.height || !at.inside(n[0], n[1]) ||
            tileOf.data[at.index(n[0], n[1])] == mine)
          continue;
        join(joins, labelOf(x, y), labelOf(n[0], n[1]), std::max(at.z(x, y), at.z(n[0], n[1])));
      }
    }
  }
  return lowestJoins(joins);
}

std::vector<std::pair<int64_t, float>> spillLevels(const std::vector<SpillEdge>& edges) {
  std::map<int64_t, std::vector<std::pair<int64_t, float>>> graph;
  for (const auto& e : edges) {
    graph[e.a].push_back({e.b, e.level});
    graph[e.b].push_back({e.a, e.level});
  }
  // Minimax from the drain: a label spills at the lowest level over all chains of joins to it
  // of the highest join on the chain.
  std::map<int64_t, float> level;
  using Entry = std::pair<float, int64_t>;
  std::priority_queue<Entry, std::vector<Entry>, std::greater<>> queue;
  level[kDrainLabel] = -std::numeric_limits<float>::infinity();
  queue.push({level[kDrainLabel], kDrainLabel});
  while (!queue.empty()) {
    const auto [l, label] = queue.top();
    queue.pop();
    if (l > level[label]) continue;  // a stale entry
    for (const auto& [other, join] : graph[label]) {
      const float through = std::max(l, join);
      auto it = level.find(other);
      if (it == level.end() || through < it->second) {
        level[other] = through;
        queue.push({through, other});
      }
    }
  }
  return {level.begin(), level.end()};
}

Grid<float> finishTile(const FillInput& in, const TileFlood& f, const std::vector<std::pair<int64_t, float>>& spill) {
  const CellRect& t = f.tile;
  const At at{in, areaOf(in)};
  Grid<float> out(t.width, t.height);
  for (int y = 0; y < t.height; ++y) {
    for (int x = 0; x < t.width; ++x) {
      const float own = at.z(t.x + x, t.y + y);
      const int64_t label = f.label.at(x, y);
      auto it = std::lower_bound(spill.begin(), spill.end(), std::pair<int64_t, float>{label, -1e38f},
                                 [](const auto& a, const auto& b) { return a.first < b.first; });
      const bool drains = label != 0 && it != spill.end() && it->first == label;
      out.at(x, y) = drains ? std::max(f.filled.at(x, y), it->second) : own;
    }
  }
  return out;
}

Grid<float> fillDepressions(const FillInput& in, const std::vector<CellRect>& tiles) {
  std::vector<TileFlood> floods;
  std::vector<SpillEdge> edges = borderEdges(in, tiles);
  for (const auto& t : tiles) {
    floods.push_back(floodTile(in, t));
    edges.insert(edges.end(), floods.back().edges.begin(), floods.back().edges.end());
  }
  const auto spill = spillLevels(edges);
  Grid<float> out(in.elevation->width, in.elevation->height);
  for (const auto& f : floods) {
    const Grid<float> part = finishTile(in, f, spill);
    for (int y = 0; y < f.tile.height; ++y) {
      for (int x = 0; x < f.tile.width; ++x) out.at(f.tile.x + x, f.tile.y + y) = part.at(x, y);
    }
  }
  return out;
}

}  // namespace strata::gis
