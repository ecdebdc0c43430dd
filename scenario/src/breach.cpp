#include "breach.hpp"

#include <algorithm>
#include <chrono>
#include <cstdint>
#include <cstring>
#include <limits>
#include <queue>

#include <strata/core/bytes.hpp>
#include <strata/core/log.hpp>

namespace strata::scenario::detail {
namespace {

// A cell's place in the flood's order: its path's highest cell, then the path's length, then the
// sum of the path's elevations (of paths as high and as long, the one along the valley floor),
// then the cell (row-major over the region), so no two cells tie and the order is the same on any
// number of ranks.
struct Key {
  float top = std::numeric_limits<float>::infinity();
  int32_t length = std::numeric_limits<int32_t>::max();
  double sum = std::numeric_limits<double>::infinity();
  int64_t cell = std::numeric_limits<int64_t>::max();
  auto operator<=>(const Key&) const = default;
};
constexpr Key kNone{};

// A cell of another rank reached from one of this rank's: the cell, the neighbour it was reached
// from (as the index of the step back to it) and that neighbour's key.
struct Reached {
  Key from;
  int64_t cell;
  int32_t back;
  int32_t unused = 0;
};
static_assert(std::is_trivially_copyable_v<Reached> && sizeof(Reached) == 40);

struct PathCell {
  int64_t cell;
  double areaM2;
  float z;
  int32_t unused = 0;
};
static_assert(std::is_trivially_copyable_v<PathCell> && sizeof(PathCell) == 24);

// The four steps to a neighbour; step i ^ 1 goes back.
constexpr int kStep[4][2] = {{-1, 0}, {1, 0}, {0, -1}, {0, 1}};
constexpr int8_t kUnseen = -2, kStart = -1;

}  // namespace

// At a canyon's own DEM resolution the river's floor, narrower than a cell, is averaged with the
// walls: the grid holds dams across the river that the real one does not have, and a flood ponds
// behind them. From each inflow, the path to an open edge whose highest cell is lowest (a
// 4-neighbour priority flood, ties broken by length, then by the sum of elevations, then by the
// cell) is given the
// non-increasing elevation profile closest to its own (isotonic regression): dams on it are cut,
// pits on it filled, and it never climbs (a form of least-cost breaching, cf. Lindsay 2016).
// Cells off the path are left as they are.
Status breachInflowPaths(const Scenario& s, const Ranks& ranks, const std::vector<int>& rowStarts,
                         const std::vector<sim::Source>& sources, const std::vector<std::string>& names,
                         ScenarioDomain& d) {
  if (!s.terrain.breachInflows) return {};
  const int w = d.bed.values.width, held = d.bed.values.height, me = ranks.rank();
  const int h = rowStarts.back(), y0 = rowStarts[size_t(me)], y1 = rowStarts[size_t(me) + 1];
  STRATA_CHECK(d.firstRow == y0 && y1 - y0 <= held) << "breachInflowPaths: the rows held are not the rank's";
  const auto& open = s.model.boundaries;  // W E S N
  auto outlet = [&](int x, int y) {
    return (x == 0 && open[0] == Boundary::Open) || (x == w - 1 && open[1] == Boundary::Open) ||
           (y == h - 1 && open[2] == Boundary::Open) || (y == 0 && open[3] == Boundary::Open);
  };
  auto ownerOf = [&](int y) {
    return int(std::upper_bound(rowStarts.begin(), rowStarts.end(), y) - rowStarts.begin()) - 1;
  };
  auto local = [&](int64_t cell) { return size_t(cell - int64_t(y0) * w); };  // in d's grids
  auto& z = d.input.baseM;
  std::vector<int8_t> from(size_t(y1 - y0) * size_t(w));

  for (size_t k = 0; k < sources.size(); ++k) {
    const auto started = std::chrono::steady_clock::now();
    long long rounds = 0, taken = 0;
    // The flood: from the inflow's cells until the first open-edge cell in key order.
    std::fill(from.begin(), from.end(), kUnseen);
    std::priority_queue<Key, std::vector<Key>, std::greater<>> queue;
    for (auto [x, y] : sources[k].cells) {
      if (y < y0 || y >= y1) continue;
      const int64_t cell = int64_t(y) * w + x;
      if (from[local(cell)] == kUnseen) queue.push({z.data[local(cell)], 0, double(z.data[local(cell)]), cell});
      from[local(cell)] = kStart;
    }
    auto reach = [&](int64_t cell, const Key& by, int back) {
      const size_t c = local(cell);
      if (from[c] != kUnseen || !d.inside.data[c]) return;
      from[c] = int8_t(back);
      queue.push({std::max(by.top, z.data[c]), by.length + 1, by.sum + double(z.data[c]), cell});
    };
    Key end = kNone;
    std::vector<Reached> arrived;
    for (;;) {
      // Cells reached from other ranks' last round, in the order their neighbours were taken.
      std::sort(arrived.begin(), arrived.end(), [](const Reached& a, const Reached& b) { return a.from < b.from; });
      for (const Reached& r : arrived) reach(r.cell, r.from, r.back);
      arrived.clear();
      ByteWriter next;
      next.pod(queue.empty() ? kNone : queue.top());
      const auto tops = ranks.allGatherBytes(next.out);
      Key first = kNone, others = kNone;
      for (int r = 0; r < int(tops.size()); ++r) {
        Key t;
        std::memcpy(&t, tops[size_t(r)].data(), sizeof t);
        first = std::min(first, t);
        if (r != me) others = std::min(others, t);
      }
      if (!(first < end)) break;  // nothing left that comes before the outlet found
      ++rounds;
      // Take cells while nothing another rank holds, or could still send, comes first: what this
      // rank sends now comes after the cell it was reached from, and so does all that follows it.
      Key bound = std::min(others, end), found = kNone;
      std::vector<Reached> sent;
      while (!queue.empty() && queue.top() < bound) {
        const Key e = queue.top();
        queue.pop();
        ++taken;
        const int x = int(e.cell % w), y = int(e.cell / w);
        if (outlet(x, y)) {
          found = e;
          break;
        }
        for (int i = 0; i < 4; ++i) {
          const int nx = x + kStep[i][0], ny = y + kStep[i][1];
          if (nx < 0 || nx >= w || ny < 0 || ny >= h) continue;
          const int64_t cell = int64_t(ny) * w + nx;
          if (ny >= y0 && ny < y1) {
            reach(cell, e, i ^ 1);
          } else {
            sent.push_back({e, cell, i ^ 1});
            bound = std::min(bound, Key{e.top, e.length + 1, -std::numeric_limits<double>::infinity(), 0});
          }
        }
      }
      ByteWriter out;
      out.pod(found);
      out.vec(sent);
      for (const std::string& bytes : ranks.allGatherBytes(out.out)) {
        ByteReader in{bytes};
        Key theirs;
        std::vector<Reached> reached;
        in.pod(theirs);
        in.vec(reached);
        STRATA_CHECK(in.ok) << "breachInflowPaths: a rank's round did not decode";
        end = std::min(end, theirs);
        for (const Reached& r : reached) {
          if (ownerOf(int(r.cell / w)) == me) arrived.push_back(r);
        }
      }
    }
    if (end == kNone) {
      return fail(s.at("terrain.breach_inflows") + "no open edge can be reached from the inflow \"" + names[k] +
                  "\" (open an edge in model.boundary)");
    }

    // The path, back from the outlet: each rank follows it over its rows and hands it on.
    std::vector<PathCell> path;
    for (int64_t cell = end.cell; cell >= 0;) {
      const int owner = ownerOf(int(cell / w));
      ByteWriter out;
      if (owner == me) {
        std::vector<PathCell> part;
        int64_t at = cell, next = -1;
        for (;;) {
          const size_t c = local(at);
          part.push_back({at, d.cellAreaM2.data[c], z.data[c]});
          if (from[c] == kStart) break;
          const int b = from[c];
          const int x = int(at % w) + kStep[b][0], y = int(at / w) + kStep[b][1];
          at = int64_t(y) * w + x;
          if (y < y0 || y >= y1) {
            next = at;
            break;
          }
        }
        out.vec(part);
        out.pod(next);
      }
      const std::string handed = std::move(ranks.allGatherBytes(out.out)[size_t(owner)]);
      ByteReader in{handed};
      std::vector<PathCell> part;
      in.vec(part);
      in.pod(cell);
      STRATA_CHECK(in.ok) << "breachInflowPaths: a part of the path did not decode";
      path.insert(path.end(), part.begin(), part.end());
    }
    std::reverse(path.begin(), path.end());

    // The non-increasing profile closest to the path's (least squares: pool adjacent violators),
    // so a dam is cut and a pit on the path is filled by about as much, not a trench dug down to
    // the deepest pit. Every rank has the whole path: the figures are the same everywhere.
    struct Pool {
      double sum;
      int count;
      double mean() const { return sum / count; }
    };
    std::vector<Pool> pools;
    for (const PathCell& p : path) {
      pools.push_back({double(p.z), 1});
      while (pools.size() > 1 && pools.back().mean() > pools[pools.size() - 2].mean()) {
        pools[pools.size() - 2].sum += pools.back().sum;
        pools[pools.size() - 2].count += pools.back().count;
        pools.pop_back();
      }
    }
    size_t at = 0;
    for (const auto& pool : pools) {
      const float level = float(pool.mean());
      for (int i = 0; i < pool.count; ++i, ++at) {
        const PathCell& p = path[at];
        const double change = double(level) - double(p.z);
        if (change == 0) continue;
        ++d.breach.cells;
        (change < 0 ? d.breach.maxCutM : d.breach.maxFillM) =
            std::max(change < 0 ? d.breach.maxCutM : d.breach.maxFillM, std::abs(change));
        (change < 0 ? d.breach.cutM3 : d.breach.fillM3) += std::abs(change) * p.areaM2;
        const int64_t c = p.cell - int64_t(y0) * w;
        if (c < 0 || c >= int64_t(z.size())) continue;  // another rank's rows
        z.data[size_t(c)] = level;
        d.bed.values.data[size_t(c)] = level;
      }
    }
    ++d.breach.paths;
    if (ranks.lead()) {
      log::debug("breach") << "inflow \"" << names[k] << "\": a path of " << path.size() << " cells, " << taken
                           << " cells taken on the lead, " << rounds << " rounds over " << ranks.size() << " rank(s), "
                           << std::chrono::duration<double>(std::chrono::steady_clock::now() - started).count() << " s";
    }
  }
  return {};
}

}  // namespace strata::scenario::detail
