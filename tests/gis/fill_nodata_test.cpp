// Filling voids with GDAL's fill-nodata: a summit void stays a summit, not a pit.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>

#include <strata/gis/dem_io.hpp>
#include <strata/gis/fill_nodata.hpp>

#include "gis_test_util.hpp"
#include "strata_test.hpp"

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

// A rank of a run over MPI fills the voids of its rows from the rows voidFillRows names, found
// by reading more rows until they reach: on Rainier's SRTM (1201 x 1201 cells, 0.6% voids, some
// dozens of cells across) each band of rows is then filled with the whole grid's bits. Filled
// from their own rows alone, bands crossing a void are not.
TEST(FillVoids, RowsFilledFromTheirSpanHaveTheWholeFillsBits) {
  auto dem = readDem(test::dataFile("rainier/mt_rainier_90m.tif"));
  ASSERT_TRUE(dem) << dem.message();
  const Grid<float>& source = dem->values;
  const int w = source.width, h = source.height;
  auto rowsOf = [&](int y0, int y1) {
    Grid<float> g(w, y1 - y0);
    std::copy(source.data.begin() + ptrdiff_t(y0) * w, source.data.begin() + ptrdiff_t(y1) * w, g.data.begin());
    return g;
  };
  Grid<float> whole = source;
  auto filled = fillVoids(whole);
  ASSERT_TRUE(filled) << filled.message();
  EXPECT_GT(*filled, 5000u);
  int bandsWithVoids = 0, bandsAloneDiffer = 0, grown = 0;
  for (int band = 0; band < 9; ++band) {
    const int y0 = h * band / 9, y1 = h * (band + 1) / 9;
    // Read a margin of 2 rows, then twice as many until the span is held.
    std::optional<std::array<int, 2>> span;
    int top = y0, bottom = y1;
    for (int margin = 2; !span; margin *= 2) {
      top = std::max(0, y0 - margin), bottom = std::min(h, y1 + margin);
      span = voidFillRows(rowsOf(top, bottom), top, h, y0, y1);
      grown += span ? 0 : 1;
      if (!span) {
        ASSERT_FALSE(top == 0 && bottom == h);
      }
    }
    ASSERT_GE((*span)[0], top);
    ASSERT_LE((*span)[1], bottom);
    Grid<float> rows = rowsOf((*span)[0], (*span)[1]);
    const bool voids = std::any_of(rows.data.begin() + ptrdiff_t(y0 - (*span)[0]) * w,
                                   rows.data.begin() + ptrdiff_t(y1 - (*span)[0]) * w, isNoData);
    bandsWithVoids += voids ? 1 : 0;
    ASSERT_TRUE(fillVoids(rows, std::max(w, h)));
    for (int y = y0; y < y1; ++y) {
      for (int x = 0; x < w; ++x) {
        ASSERT_EQ(rows.at(x, y - (*span)[0]), whole.at(x, y)) << "band " << band << " at " << x << "," << y;
      }
    }
    Grid<float> alone = rowsOf(y0, y1);
    ASSERT_TRUE(fillVoids(alone, std::max(w, h)));
    bool differ = false;
    for (int y = y0; y < y1 && !differ; ++y) {
      for (int x = 0; x < w && !differ; ++x) differ = alone.at(x, y - y0) != whole.at(x, y);
    }
    bandsAloneDiffer += differ ? 1 : 0;
  }
  std::printf("bands with voids %d, differing when filled alone %d, reads grown %d times\n", bandsWithVoids,
              bandsAloneDiffer, grown);
  EXPECT_GE(bandsWithVoids, 3);
  EXPECT_GE(bandsAloneDiffer, 1);
}

// The next column matters: a void cell whose own column has a valid cell just above it takes its
// upper-right value from far above, where the void to its right ends. Its span reaches that row,
// and the rows of its own column's valid cells alone would fill it otherwise.
TEST(FillVoids, ASpanReachesTheNextColumnsValidCells) {
  Grid<float> g(8, 30);
  for (int y = 0; y < g.height; ++y) {
    for (int x = 0; x < g.width; ++x) g.at(x, y) = float(100 * x + y);
  }
  g.at(3, 20) = kNoData;
  for (int y = 5; y <= 25; ++y) {
    for (int x = 4; x < 8; ++x) g.at(x, y) = kNoData;
  }
  Grid<float> whole = g;
  ASSERT_TRUE(fillVoids(whole));
  const auto span = voidFillRows(g, 0, g.height, 20, 21);
  ASSERT_TRUE(span);
  EXPECT_EQ(*span, (std::array<int, 2>{4, 27}));
  auto fillRows = [&](int y0, int y1) {
    Grid<float> rows(g.width, y1 - y0);
    std::copy(g.data.begin() + ptrdiff_t(y0) * g.width, g.data.begin() + ptrdiff_t(y1) * g.width, rows.data.begin());
    EXPECT_TRUE(fillVoids(rows, std::max(g.width, g.height)));
    return rows.at(3, 20 - y0);
  };
  EXPECT_EQ(fillRows(4, 27), whole.at(3, 20));
  EXPECT_NE(fillRows(19, 22), whole.at(3, 20));  // the rows of column 3's valid cells above and below
}

}  // namespace
}  // namespace strata::gis
