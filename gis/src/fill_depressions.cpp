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

}  // namespace

TileFlood floodTile(const FillInput& in, const CellRect& t) {
  const Grid<float>& z = *in.elevation;
  const Grid<uint8_t>& inside = *in.inside;
  const Grid<uint8_t>& drains = *in.drains;
  const int gw = z.width;
  TileFlood f;
  f.tile = t;
  f.filled = Grid<float>(t.width, t.height);
  f.label = Grid<int64_t>(t.width, t.height, 0);
  for (int y = 0; y < t.height; ++y) {
    for (int x = 0; x < t.width; ++x) f.filled.at(x, y) = z.at(t.x + x, t.y + y);
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
      if (!inside.at(gx, gy)) continue;
      const bool perimeter = x == 0 || y == 0 || x == t.width - 1 || y == t.height - 1;
      if (drains.at(gx, gy)) {
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
      if (!inside.at(t.x + n[0], t.y + n[1])) continue;
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
  const Grid<float>& z = *in.elevation;
  const Grid<uint8_t>& inside = *in.inside;
  const Grid<uint8_t>& drains = *in.drains;
  const int w = z.width, h = z.height;
  Grid<int32_t> tileOf(w, h, -1);
  for (size_t k = 0; k < tiles.size(); ++k) {
    const auto& t = tiles[k];
    for (int y = t.y; y < t.y + t.height; ++y) {
      for (int x = t.x; x < t.x + t.width; ++x) tileOf.at(x, y) = int32_t(k);
    }
  }
  auto labelOf = [&](int x, int y) {
    return drains.at(x, y) ? kDrainLabel : kFirstPerimeterLabel + int64_t(y) * w + x;
  };
  std::map<std::pair<int64_t, int64_t>, float> joins;
  for (int y = 0; y < h; ++y) {
    for (int x = 0; x < w; ++x) {
      if (!inside.at(x, y)) continue;
      STRATA_CHECK(tileOf.at(x, y) >= 0) << "fill: the tiles do not cover cell " << x << ", " << y;
      const int right[2][2] = {{x + 1, y}, {x, y + 1}};
      for (const auto& n : right) {
        if (n[0] >= w || n[1] >= h || !inside.at(n[0], n[1]) || tileOf.at(n[0], n[1]) == tileOf.at(x, y)) continue;
        join(joins, labelOf(x, y), labelOf(n[0], n[1]), std::max(z.at(x, y), z.at(n[0], n[1])));
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
  Grid<float> out(t.width, t.height);
  for (int y = 0; y < t.height; ++y) {
    for (int x = 0; x < t.width; ++x) {
      const float own = in.elevation->at(t.x + x, t.y + y);
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
