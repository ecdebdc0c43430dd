// From scenario to solver input on the real Grand Canyon DEM: window, cell sizes, sources, and the
// checks that need the terrain (region inside the DEM, sources inside the region).
#include <gtest/gtest.h>

#include <strata/gis/geodesy.hpp>
#include <strata/terrain/scenario_domain.hpp>

#include "strata_test.hpp"

namespace strata::terrain {
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
  EXPECT_EQ(d.message(),
            "/runs/t.toml: key 'terrain.layer[0].material': unknown material \"cheese\" (rock, soil, sand, sediment)");
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
}  // namespace strata::terrain

namespace strata::terrain {
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
  EXPECT_EQ(d->levels[0].stageAt(1800), 800.0);  // absolute elevations, interpolated
  EXPECT_EQ(d->levels[0].stageAt(7200), 900.0);  // held after the last sample
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

}  // namespace
}  // namespace strata::terrain
