// Depression filling tile by tile (Barnes 2016) against the one priority flood over the whole
// grid, on the shared Grand Canyon DEM: bit for bit on every tiling, with walls, holes and
// closed edges.
#include <gtest/gtest.h>

#include <cmath>
#include <queue>
#include <random>

#include <strata/gis/dem_io.hpp>
#include <strata/gis/fill_depressions.hpp>

#include "gis_test_util.hpp"
#include "strata_test.hpp"

namespace strata::gis {
namespace {

// The textbook priority flood (Barnes, Lehman & Mulla 2014) over the whole grid: the reference.
Grid<float> onePriorityFlood(const FillInput& in) {
  Grid<float> z = *in.elevation;
  const int w = z.width, h = z.height;
  using Entry = std::pair<float, int>;
  std::priority_queue<Entry, std::vector<Entry>, std::greater<>> queue;
  std::vector<uint8_t> seen(z.size(), 0);
  for (int c = 0; c < w * h; ++c) {
    if (in.drains->data[size_t(c)] && in.inside->data[size_t(c)])
      seen[size_t(c)] = 1, queue.push({z.data[size_t(c)], c});
  }
  while (!queue.empty()) {
    const auto [level, c] = queue.top();
    queue.pop();
    const int x = c % w, y = c / w;
    const int next[4][2] = {{x - 1, y}, {x + 1, y}, {x, y - 1}, {x, y + 1}};
    for (const auto& n : next) {
      if (n[0] < 0 || n[0] >= w || n[1] < 0 || n[1] >= h) continue;
      const size_t k = size_t(n[1]) * size_t(w) + size_t(n[0]);
      if (seen[k] || !in.inside->data[k]) continue;
      seen[k] = 1;
      z.data[k] = std::max(z.data[k], level);
      queue.push({z.data[k], int(k)});
    }
  }
  return z;
}

// Tiles of the grid: `cols` x `rows`, cut at the given fractions (uneven).
std::vector<CellRect> tiling(int w, int h, std::vector<int> xs, std::vector<int> ys) {
  xs.insert(xs.begin(), 0);
  xs.push_back(w);
  ys.insert(ys.begin(), 0);
  ys.push_back(h);
  std::vector<CellRect> tiles;
  for (size_t j = 0; j + 1 < ys.size(); ++j) {
    for (size_t i = 0; i + 1 < xs.size(); ++i) tiles.push_back({xs[i], ys[j], xs[i + 1] - xs[i], ys[j + 1] - ys[j]});
  }
  return tiles;
}

TEST(FillDepressions, EveryTilingEqualsOnePriorityFlood) {
  auto dem = readDem(test::dataFile("grand_canyon/grand_canyon_512.tif"));
  ASSERT_TRUE(dem) << dem.message();
  // Coarser than the DEM, so the canyon floor has dams and pits: every 2nd cell's minimum of 4
  // would be what a run does; here plain sampling, with pits dug at random.
  const int w = 256, h = 200;
  Grid<float> z(w, h);
  for (int y = 0; y < h; ++y) {
    for (int x = 0; x < w; ++x) z.at(x, y) = dem->values.at(2 * x, 2 * y + 50);
  }
  std::mt19937 rng(7);
  for (int k = 0; k < 400; ++k) z.at(int(rng() % w), int(rng() % h)) -= float(5 + rng() % 40);
  // The region: an ellipse (walls outside), a wall line across it with one gap, west and south
  // edges draining, and three holes.
  Grid<uint8_t> inside(w, h, 0), drains(w, h, 0);
  for (int y = 0; y < h; ++y) {
    for (int x = 0; x < w; ++x) {
      const double u = (x - 128.0) / 140, v = (y - 100.0) / 115;
      inside.at(x, y) = u * u + v * v <= 1.0 && !(x == 170 && y > 30 && y != 120) ? 1 : 0;
      drains.at(x, y) = x == 0 || y == h - 1;
    }
  }
  for (auto [x, y] : {std::pair{60, 60}, std::pair{200, 150}, std::pair{129, 97}}) drains.at(x, y) = 1;
  const FillInput in{&z, &inside, &drains};
  const Grid<float> reference = onePriorityFlood(in);
  size_t raised = 0, walled = 0;
  for (size_t i = 0; i < z.size(); ++i) raised += reference.data[i] > z.data[i] ? 1 : 0;
  for (size_t i = 0; i < z.size(); ++i) walled += inside.data[i] ? 0 : 1;
  ASSERT_GT(raised, 1000u);  // there is something to fill
  ASSERT_GT(walled, 1000u);

  const std::vector<std::pair<const char*, std::vector<CellRect>>> tilings = {
      {"one tile", {{0, 0, w, h}}},
      {"2 x 2", tiling(w, h, {128}, {100})},
      {"7 x 5 uneven", tiling(w, h, {3, 40, 41, 100, 170, 171}, {1, 60, 119, 120})},
      {"rows of one cell", tiling(w, h, {},
                                  [&] {
                                    std::vector<int> ys;
                                    for (int y = 1; y < h; ++y) ys.push_back(y);
                                    return ys;
                                  }())},
      {"32 x 32 cells",
       [&] {
         std::vector<int> xs, ys;
         for (int x = 32; x < w; x += 32) xs.push_back(x);
         for (int y = 32; y < h; y += 32) ys.push_back(y);
         return tiling(w, h, xs, ys);
       }()},
  };
  for (const auto& [name, tiles] : tilings) {
    const Grid<float> filled = fillDepressions(in, tiles);
    size_t differ = 0;
    for (size_t i = 0; i < z.size(); ++i) differ += filled.data[i] == reference.data[i] ? 0 : 1;
    EXPECT_EQ(differ, 0u) << name << ": " << tiles.size() << " tiles";
  }

  // As MPI ranks do it: each holds only its rows (and the row below, for the border's joins),
  // floods them, and only the joins travel; the spill levels come back.
  const std::vector<int> cuts = {0, 37, 38, 90, 151, h};
  std::vector<CellRect> strips;
  for (size_t k = 0; k + 1 < cuts.size(); ++k) strips.push_back({0, cuts[k], w, cuts[k + 1] - cuts[k]});
  struct Held {
    Grid<float> z;
    Grid<uint8_t> inside, drains;
    FillInput in;
    TileFlood flood;
  };
  std::vector<Held> held(strips.size());
  std::vector<SpillEdge> joins;
  for (size_t k = 0; k < strips.size(); ++k) {
    const CellRect area{0, strips[k].y, w, std::min(h - strips[k].y, strips[k].height + 1)};
    auto& m = held[k];
    m.z = Grid<float>(w, area.height);
    m.inside = Grid<uint8_t>(w, area.height);
    m.drains = Grid<uint8_t>(w, area.height);
    for (int y = 0; y < area.height; ++y) {
      for (int x = 0; x < w; ++x) {
        m.z.at(x, y) = z.at(x, area.y + y);
        m.inside.at(x, y) = inside.at(x, area.y + y);
        m.drains.at(x, y) = drains.at(x, area.y + y);
      }
    }
    m.in = {&m.z, &m.inside, &m.drains, area, w};
    m.flood = floodTile(m.in, strips[k]);
    const auto border = borderEdges(m.in, strips);
    joins.insert(joins.end(), border.begin(), border.end());
    joins.insert(joins.end(), m.flood.edges.begin(), m.flood.edges.end());
  }
  const auto spill = spillLevels(joins);
  size_t differ = 0;
  for (size_t k = 0; k < strips.size(); ++k) {
    const Grid<float> part = finishTile(held[k].in, held[k].flood, spill);
    for (int y = 0; y < strips[k].height; ++y) {
      for (int x = 0; x < w; ++x) differ += part.at(x, y) == reference.at(x, strips[k].y + y) ? 0 : 1;
    }
  }
  EXPECT_EQ(differ, 0u) << "rows held apart";
}

// A pit whose only outlet lies in the next tile, over a saddle in a third: filled to the saddle.
TEST(FillDepressions, APitDrainsThroughTwoOtherTiles) {
  Grid<float> z(9, 3, 50.0f);
  Grid<uint8_t> inside(9, 3, 1), drains(9, 3, 0);
  // A channel along the middle row, a pit at x = 1, a saddle of 20 m at x = 5, drained at x = 8.
  const float row[9] = {30, 2, 10, 10, 10, 20, 5, 5, 1};
  for (int x = 0; x < 9; ++x) z.at(x, 1) = row[x];
  drains.at(8, 1) = 1;
  const FillInput in{&z, &inside, &drains};
  const Grid<float> filled = fillDepressions(in, tiling(9, 3, {3, 6}, {}));
  const float expected[9] = {30, 20, 20, 20, 20, 20, 5, 5, 1};
  for (int x = 0; x < 9; ++x) EXPECT_EQ(filled.at(x, 1), expected[x]) << x;
  EXPECT_EQ(filled.at(4, 0), 50.0f);  // the banks are above every spill level: unchanged
  const Grid<float> reference = onePriorityFlood(in);
  EXPECT_EQ(filled.data, reference.data);
}

}  // namespace
}  // namespace strata::gis
