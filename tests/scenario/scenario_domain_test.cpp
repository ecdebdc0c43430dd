// From scenario to solver input on the real Grand Canyon DEM: window, cell sizes, sources, and the
// checks that need the terrain (region inside the DEM, sources inside the region).
#include <gtest/gtest.h>

#include <cstdio>

#include <limits>

#include <queue>

#include <strata/gis/geodesy.hpp>
#include <strata/scenario/domain.hpp>

#include "scenario_fixture.hpp"
#include "strata_test.hpp"

namespace strata::scenario {
namespace {

Result<ScenarioDomain> domainOf(const std::string& region, const std::string& water, const std::string& extra = "") {
  const std::string text = "[terrain]\ndem = \"" + test::dataPath("grand_canyon/grand_canyon_512.tif") + "\"\n" +
                           extra + "[region]\n" + region + "\n" + water + "\n[time]\nduration = \"1 h\"\n";
  auto s = parseScenario(text, "/runs/t.toml");
  if (!s) return s.error();
  return buildDomain(*s);
}

const std::string kInflow =
    "[[water.inflow]]\nname = \"river\"\nat_lonlat = [-112.0225, 36.0713]\nhydrograph = [[0, 100], [3600, 100]]\n";

TEST(ScenarioDomain, CutsTheRegionWindowWithGeodesicCellSizes) {
  auto d = domainOf("bbox_lonlat = [-112.5, 36.01, -112.001, 36.3]", kInflow);
  ASSERT_TRUE(d) << d.message();
  const auto& g = d->bed.georef;
  // 1/512 degree cells: (112.5 - 112.001) * 512 = 255.5 -> 256 columns; (36.3 - 36.01) * 512 -> 149 rows.
  EXPECT_EQ(g.width, 256);
  EXPECT_EQ(g.height, 149);
  ASSERT_EQ(d->input.rowDxM.size(), size_t(g.height));
  // Row dx * dy is the geodesic cell area of that row (the solver's volumes are then exact).
  for (int y : {0, g.height / 2, g.height - 1}) {
    EXPECT_NEAR(d->input.rowDxM[size_t(y)] * d->input.dyM, d->cellAreaM2.at(g.width / 2, y), 1e-6);
  }
  // A 1/512 degree cell at 36 N is about 176 m east-west and 217 m north-south.
  EXPECT_NEAR(d->input.rowDxM[0], 176.0, 2.0);
  EXPECT_NEAR(d->input.dyM, 216.8, 1.0);
  ASSERT_EQ(d->sources.size(), 1u);
  EXPECT_EQ(d->sources[0].cells.size(), 1u);
  EXPECT_LE(d->input.datumM, 800.0);  // the datum is the region's lowest point, rounded down
}

TEST(ScenarioDomain, ResamplesToTheAskedCellSize) {
  auto d = domainOf("bbox_lonlat = [-112.5, 36.01, -112.001, 36.3]\ncell_size = \"434 m\"", kInflow);
  ASSERT_TRUE(d) << d.message();
  EXPECT_EQ(d->bed.georef.width, 127);  // half the native resolution
  EXPECT_NEAR(d->input.dyM, 434.0, 5.0);
}

// Issue 15: a scenario's `dem = [a, b]` list was mosaicked with bilinear resampling, so coarser
// cells lost the lowest-elevation rule a single DEM keeps (the bed rose by 92 m on average on the
// canyon, damming it). A list of the same DEM twice now gives the single DEM's bed bit for bit.
TEST(ScenarioDomain, ADemListKeepsTheLowestElevationRule) {
  const std::string dem = test::dataPath("grand_canyon/grand_canyon_512.tif");
  const std::string region = "bbox_lonlat = [-112.5, 36.01, -112.001, 36.3]\ncell_size = \"600 m\"";
  auto one = domainOf(region, kInflow);
  const std::string text = "[terrain]\ndem = [\"" + dem + "\", \"" + dem + "\"]\n[region]\n" + region + "\n" + kInflow +
                           "\n[time]\nduration = \"1 h\"\n";
  auto s = parseScenario(text, "/runs/t.toml");
  ASSERT_TRUE(s) << s.message();
  auto two = buildDomain(*s);
  ASSERT_TRUE(one && two);
  ASSERT_EQ(one->bed.values.size(), two->bed.values.size());
  double meanRise = 0;
  for (size_t i = 0; i < one->bed.values.size(); ++i) {
    meanRise += double(two->bed.values.data[i]) - double(one->bed.values.data[i]);
  }
  meanRise /= double(one->bed.values.size());
  EXPECT_EQ(two->bed.values.data, one->bed.values.data) << "mean rise " << meanRise << " m";
}

TEST(ScenarioDomain, PolygonRegionMasksOutsideCellsAsWalls) {
  auto d = domainOf("polygon_lonlat = [[-112.5, 36.01], [-112.001, 36.01], [-112.001, 36.3]]", kInflow);
  ASSERT_TRUE(d) << d.message();
  const auto& g = d->bed.georef;
  EXPECT_EQ(d->inside.at(g.width - 1, g.height - 1), 1);  // south-east corner: inside the triangle
  EXPECT_EQ(d->inside.at(0, 0), 0);                       // north-west corner: outside
  EXPECT_EQ(d->input.baseM.at(0, 0), kWallElevationM);
}

TEST(ScenarioDomain, RegionOutsideTheDemIsRefused) {
  auto d = domainOf("bbox_lonlat = [-112.5, 35.5, -112.1, 36.3]", kInflow);
  ASSERT_FALSE(d);
  EXPECT_EQ(d.message(),
            "/runs/t.toml:4: key 'region.bbox_lonlat': the region is not inside the DEM " +
                std::filesystem::path(test::dataPath("grand_canyon/grand_canyon_512.tif")).lexically_normal().string() +
                " (extent [-113.00014, 36.000139, -112.00014, 37.000139] in its CRS)");
}

TEST(ScenarioDomain, SourceOutsideTheRegionIsRefused) {
  auto d = domainOf("bbox_lonlat = [-112.9, 36.3, -112.5, 36.6]", kInflow);
  ASSERT_FALSE(d);
  EXPECT_EQ(d.message(), "/runs/t.toml:7: key 'water.inflow[0].at_lonlat': the source \"river\" is outside the region");
}

TEST(ScenarioDomain, UnknownMaterialIsRefused) {
  auto d = domainOf("bbox_lonlat = [-112.5, 36.01, -112.001, 36.3]", kInflow,
                    "[[terrain.layer]]\nmaterial = \"cheese\"\nthickness = \"1 m\"\n");
  ASSERT_FALSE(d);
  EXPECT_EQ(
      d.message(),
      "/runs/t.toml:4: key 'terrain.layer[0].material': unknown material \"cheese\" (rock, soil, sand, sediment)");
}

TEST(ScenarioDomain, DamBreakFillsThePolygonToItsSurface) {
  auto d = domainOf("bbox_lonlat = [-112.5, 36.01, -112.001, 36.3]",
                    "[[water.dam_break]]\npolygon_lonlat = [[-112.1, 36.05], [-112.02, 36.05], [-112.02, 36.1], "
                    "[-112.1, 36.1]]\nsurface = \"1000 m\"\n");
  ASSERT_TRUE(d) << d.message();
  double volume = 0;
  const auto& g = d->bed.georef;
  for (int y = 0; y < g.height; ++y) {
    for (int x = 0; x < g.width; ++x) {
      const float h = d->input.waterDepthM.at(x, y);
      if (h > 0) {
        EXPECT_NEAR(h + d->bed.values.at(x, y), 1000.0f, 1e-3f);  // a flat lake surface
      }
      volume += double(h) * d->cellAreaM2.at(x, y);
    }
  }
  EXPECT_GT(volume, 0);
  EXPECT_DOUBLE_EQ(volume, d->damBreakVolumeM3);
}

TEST(ScenarioDomain, LinesAndPolygonsOnCells) {
  const auto cells = cellsAlong({{0.5, 0.5}, {3.5, 0.5}}, 10, 10);
  EXPECT_EQ(cells, (std::vector<std::pair<int, int>>{{0, 0}, {1, 0}, {2, 0}, {3, 0}}));
  const std::vector<std::array<double, 2>> square{{1, 1}, {3, 1}, {3, 3}, {1, 3}};
  EXPECT_TRUE(insidePolygon(square, 2, 2));
  EXPECT_FALSE(insidePolygon(square, 0.5, 2));
}

}  // namespace
}  // namespace strata::scenario

namespace strata::scenario {
namespace {

// A fixed level across the Colorado at the inflow's longitude (lines 5-8 of domainOf's text).
std::string levelWater(const std::string& stage, const std::string& place =
                                                     "line_lonlat = [[-112.0225, 36.063], "
                                                     "[-112.0225, 36.08]]") {
  return "[[water.level]]\nname = \"river stage\"\n" + place + "\nstage = " + stage + "\n";
}

TEST(ScenarioDomain, FixedLevelOnTheCellsOfItsLine) {
  auto d = domainOf("bbox_lonlat = [-112.5, 36.01, -112.001, 36.3]", levelWater("[[0, 700], [3600, 900]]"));
  ASSERT_TRUE(d) << d.message();
  ASSERT_EQ(d->levels.size(), 1u);
  EXPECT_EQ(d->levelNames[0], "river stage");
  // 36.063 .. 36.08 at 1/512 degree: 9 or 10 rows of one column.
  EXPECT_GE(d->levels[0].cells.size(), 9u);
  EXPECT_LE(d->levels[0].cells.size(), 10u);
  for (auto [x, y] : d->levels[0].cells) EXPECT_EQ(x, d->levels[0].cells[0].first);
  EXPECT_EQ(d->levels[0].stageM.at(1800), 800.0);  // absolute elevations, interpolated
  EXPECT_EQ(d->levels[0].stageM.at(7200), 900.0);  // held after the last sample
  // A polygon takes the cells whose centre is inside.
  auto p =
      domainOf("bbox_lonlat = [-112.5, 36.01, -112.001, 36.3]",
               levelWater("[[0, 700], [3600, 900]]",
                          "polygon_lonlat = [[-112.1, 36.05], [-112.05, 36.05], [-112.05, 36.1], [-112.1, 36.1]]"));
  ASSERT_TRUE(p) << p.message();
  // 0.05 degrees a side at 1/512 degree: about 25 x 25 cells.
  EXPECT_NEAR(double(p->levels[0].cells.size()), 25.6 * 25.6, 60.0);
}

TEST(ScenarioDomain, FixedLevelErrorsNameTheKey) {
  const std::string region = "bbox_lonlat = [-112.5, 36.01, -112.001, 36.3]";
  auto below = domainOf(region, levelWater("[[0, 0], [3600, 10]]"));
  ASSERT_FALSE(below);
  // The river bed under the line is at 803 m.
  EXPECT_EQ(below.message(),
            "/runs/t.toml:8: key 'water.level[0].stage': the stage (at most 10.00 m) never rises above the bed of the "
            "level's cells (lowest 803.34 m): it would hold no water");
  auto outside = domainOf(region, levelWater("[[0, 700]]", "line_lonlat = [[-112.0225, 36.063], [-112.6, 36.08]]"));
  ASSERT_FALSE(outside);
  EXPECT_EQ(outside.message(),
            "/runs/t.toml:7: key 'water.level[0].line_lonlat': the level \"river stage\" is outside the region");
  auto empty = domainOf(region, levelWater("[[0, 700]]",
                                           "polygon_lonlat = [[-112.3, 36.1], [-112.3, 36.2], "
                                           "[-112.3001, 36.15]]"));
  ASSERT_FALSE(empty);
  EXPECT_EQ(
      empty.message(),
      "/runs/t.toml:7: key 'water.level[0].polygon_lonlat': the level \"river stage\" covers no cell of the region");
}

// [terrain] breach_inflows and fill_depressions on the real canyon at 600 m cells: afterwards no
// cell of the region is in a depression (a second priority flood from the open edges raises
// nothing), the breach's cut and fill nearly balance (isotonic regression keeps the path's sum;
// the cells' areas differ a little by row), and without the keys the bed is the DEM's.
TEST(ScenarioDomain, BreachingAndFillingLeaveNoDepression) {
  const auto dir = strata::test::tempDir("breach");
  std::string text = test_support::scenarioText();
  const auto plain = parseScenario(text, dir / "plain.toml");
  ASSERT_TRUE(plain) << plain.message();
  text.replace(text.find("[region]"), 8, "breach_inflows = true\nfill_depressions = true\n[region]");
  const auto conditioned = parseScenario(text, dir / "conditioned.toml");
  ASSERT_TRUE(conditioned) << conditioned.message();
  auto a = buildDomain(*plain);
  auto b = buildDomain(*conditioned);
  ASSERT_TRUE(a && b);
  EXPECT_EQ(a->breach.cells, 0);
  EXPECT_EQ(a->filled.cells, 0);
  EXPECT_EQ(b->breach.paths, 1);
  EXPECT_GT(b->breach.cells, 0);
  EXPECT_GT(b->filled.cells, 0);
  EXPECT_NEAR(b->breach.cutM3, b->breach.fillM3, 0.02 * b->breach.cutM3);
  // Only lowered or raised where the report says: every changed cell is counted.
  const auto& za = a->input.baseM;
  const auto& zb = b->input.baseM;
  int changed = 0;
  for (size_t i = 0; i < za.size(); ++i) changed += za.data[i] != zb.data[i];
  EXPECT_LE(changed, b->breach.cells + b->filled.cells);
  EXPECT_GE(changed, b->filled.cells);
  // No depression: from the open edges (west, south, north) every cell is reached without
  // descending into it.
  const int w = zb.width, h = zb.height;
  std::vector<float> spill(zb.size(), std::numeric_limits<float>::infinity());
  using Entry = std::pair<float, int>;
  std::priority_queue<Entry, std::vector<Entry>, std::greater<>> q;
  for (int y = 0; y < h; ++y) {
    for (int x = 0; x < w; ++x) {
      if (x == 0 || y == 0 || y == h - 1) {
        spill[size_t(y * w + x)] = zb.at(x, y);
        q.push({zb.at(x, y), y * w + x});
      }
    }
  }
  while (!q.empty()) {
    const auto [level, c] = q.top();
    q.pop();
    if (level > spill[size_t(c)]) continue;
    const int x = c % w, y = c / w;
    for (const auto& n : {std::pair{x - 1, y}, std::pair{x + 1, y}, std::pair{x, y - 1}, std::pair{x, y + 1}}) {
      if (n.first < 0 || n.first >= w || n.second < 0 || n.second >= h) continue;
      const int k = n.second * w + n.first;
      const float l = std::max(level, zb.data[size_t(k)]);
      if (l < spill[size_t(k)]) {
        spill[size_t(k)] = l;
        q.push({l, k});
      }
    }
  }
  int pits = 0;
  for (size_t i = 0; i < zb.size(); ++i) pits += spill[i] > zb.data[i];
  EXPECT_EQ(pits, 0) << "cells below their spill level after fill_depressions";
  std::printf(
      "breach: %d cells, cut %.1f m max / %.3g m3, fill %.1f m max / %.3g m3; filled %d cells, %.1f m max, "
      "%.3g m3\n",
      b->breach.cells, b->breach.maxCutM, b->breach.cutM3, b->breach.maxFillM, b->breach.fillM3, b->filled.cells,
      b->filled.maxM, b->filled.volumeM3);
}

}  // namespace
}  // namespace strata::scenario
