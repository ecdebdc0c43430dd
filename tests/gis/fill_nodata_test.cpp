// Filling voids with GDAL's fill-nodata: a summit void stays a summit, not a pit.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

#include <strata/gis/fill_nodata.hpp>

namespace strata::gis {
namespace {

// A cone 1000 m high at cell (16, 16), falling 50 m per cell, on 33 x 33 cells.
Grid<float> cone() {
  Grid<float> g(33, 33);
  for (int y = 0; y < g.height; ++y) {
    for (int x = 0; x < g.width; ++x) g.at(x, y) = float(1000.0 - 50.0 * std::hypot(x - 16, y - 16));
  }
  return g;
}

TEST(FillVoids, ASummitVoidIsFilledBetweenTheCellsAroundIt) {
  auto g = cone();
  // A 7 x 7 void on the summit (its cells 850..1000 m) and one touching the grid's edge.
  for (int y = 13; y <= 19; ++y) {
    for (int x = 13; x <= 19; ++x) g.at(x, y) = kNoData;
  }
  for (int y = 0; y < 3; ++y) g.at(5, y) = kNoData;
  // The valid ring around the summit void: the fill must stay within its range.
  float ringLo = 1e9f, ringHi = -1e9f;
  for (int y = 12; y <= 20; ++y) {
    for (int x = 12; x <= 20; ++x) {
      if (x == 12 || x == 20 || y == 12 || y == 20)
        ringLo = std::min(ringLo, g.at(x, y)), ringHi = std::max(ringHi, g.at(x, y));
    }
  }
  auto filled = fillVoids(g);
  ASSERT_TRUE(filled) << filled.message();
  EXPECT_EQ(*filled, size_t(49 + 3));
  for (int y = 13; y <= 19; ++y) {
    for (int x = 13; x <= 19; ++x) {
      EXPECT_GE(g.at(x, y), ringLo - 1e-3f) << x << "," << y;
      EXPECT_LE(g.at(x, y), ringHi + 1e-3f) << x << "," << y;
    }
  }
  // The old fill (the grid's lowest valid value) would have put the summit 700 m below its ring.
  const auto whole = cone();
  const float lowest = *std::min_element(whole.data.begin(), whole.data.end());
  EXPECT_GT(ringLo - lowest, 500.0f);
  // The edge void lies on a slope: it takes values between its valid neighbours' (within the
  // cone's range over the few cells around it).
  for (int y = 0; y < 3; ++y) {
    EXPECT_GE(g.at(5, y), std::min(whole.at(4, y), whole.at(6, 3)) - 30.0f);
    EXPECT_LE(g.at(5, y), std::max(whole.at(6, y), whole.at(5, 3)) + 30.0f);
  }
  // Valid cells are untouched.
  EXPECT_EQ(g.at(0, 0), whole.at(0, 0));
  EXPECT_EQ(g.at(12, 12), whole.at(12, 12));
}

TEST(FillVoids, NoVoidsIsANoOpAndAllVoidsIsAnError) {
  auto g = cone();
  auto none = fillVoids(g);
  ASSERT_TRUE(none) << none.message();
  EXPECT_EQ(*none, 0u);
  EXPECT_EQ(g.data, cone().data);
  Grid<float> empty(4, 4, kNoData);
  auto r = fillVoids(empty);
  ASSERT_FALSE(r);
  EXPECT_NE(r.message().find("no valid cell"), std::string::npos) << r.message();
}

}  // namespace
}  // namespace strata::gis
