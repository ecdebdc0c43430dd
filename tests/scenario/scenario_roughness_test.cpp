// Issue 31: roughness maps. Two valleys side by side, a ridge between them, each with a lake held
// behind a dam: a Manning raster of n = 0.03 over the west half and 0.08 over the east half gives,
// in each valley, the answer of a run with that valley's n everywhere (the flows never meet; the
// runs differ only in their CFL steps), and the two valleys' answers differ (the map is used).
// A land-cover raster with a class table gives the raster run's answer; a class the table lacks,
// and an n outside 0..1, are refused naming the key.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <fstream>

#include <strata/gis/dem_io.hpp>
#include <strata/gis/geodesy.hpp>
#include <strata/scenario/run.hpp>

#include "scenario_fixture.hpp"
#include "strata_test.hpp"

namespace strata::scenario {
namespace {

using namespace test_support;

constexpr int kW = 60, kH = 40;  // 10 m cells, UTM 12N
constexpr double kX0 = 400000, kY0 = 4000000;

gis::Raster grid(float fill) { return utmRaster(kW, kH, kX0, kY0, 10, fill); }

// Two V valleys draining south at 2 %, their floors at columns 15 and 45, a 20 m ridge between.
void writeInputs(const std::filesystem::path& dir) {
  gis::Raster dem = grid(0), n = grid(0), classes = grid(0);
  for (int y = 0; y < kH; ++y) {
    for (int x = 0; x < kW; ++x) {
      const int floor = x < kW / 2 ? 15 : 45;
      dem.values.at(x, y) = float(100.0 + 0.2 * (kH - y) + 1.0 * std::abs(x - floor) + (x == kW / 2 ? 20.0 : 0.0));
      n.values.at(x, y) = x < kW / 2 ? 0.03f : 0.08f;
      classes.values.at(x, y) = x < kW / 2 ? 30.0f : 10.0f;  // ESA WorldCover: 30 grassland, 10 tree cover
    }
  }
  ASSERT_TRUE(gis::writeGeoTiff((dir / "dem.tif").string(), dem));
  ASSERT_TRUE(gis::writeGeoTiff((dir / "n.tif").string(), n));
  ASSERT_TRUE(gis::writeGeoTiff((dir / "classes.tif").string(), classes));
}

std::string text(const std::string& model) {
  auto lake = [](double x0, double x1) {
    return "[[water.dam_break]]\npolygon_xy = [[" + std::to_string(kX0 + x0) + ", " + std::to_string(kY0) + "], [" +
           std::to_string(kX0 + x1) + ", " + std::to_string(kY0) + "], [" + std::to_string(kX0 + x1) + ", " +
           std::to_string(kY0 - 80) + "], [" + std::to_string(kX0 + x0) + ", " + std::to_string(kY0 - 80) +
           "]]\nsurface = \"112 m\"\n";
  };
  return "name = \"two valleys\"\n[terrain]\ndem = \"dem.tif\"\n[model]\nkind = \"flood\"\nboundary = { west = "
         "\"closed\", east = \"closed\", south = \"open\", north = \"closed\" }\n" +
         model + "\n" + lake(60, 250) + lake(360, 550) +
         "[time]\nduration = \"10 min\"\noutput_interval = \"10 min\"\n[outputs]\nwet_threshold = \"0.01 m\"\n"
         "maps = [\"max_depth\"]\n";
}

Result<gis::Raster> maxDepth(const std::filesystem::path& dir, const std::string& name, const std::string& model) {
  std::ofstream(dir / (name + ".toml")) << text(model);
  auto s = loadScenario(dir / (name + ".toml"));
  if (!s) return s.error();
  auto run = runScenario(*s, cpuOptions(dir / name));
  if (!run) return run.error();
  return gis::readDem((dir / name / "maps" / "max_depth.tif").string(), allowEmpty());
}

TEST(ScenarioRoughness, AManningMapActsAsEachHalfsOwnN) {
  const auto dir = strata::test::tempDir("roughness");
  writeInputs(dir);
  auto mapped = maxDepth(dir, "mapped", "manning_n = 0.05\nmanning_raster = \"n.tif\"");
  auto smooth = maxDepth(dir, "smooth", "manning_n = 0.03");
  auto rough = maxDepth(dir, "rough", "manning_n = 0.08");
  ASSERT_TRUE(mapped) << mapped.message();
  ASSERT_TRUE(smooth && rough);
  double worst[2] = {0, 0}, differ = 0;
  int wet = 0;
  for (int y = 0; y < kH; ++y) {
    for (int x = 0; x < kW; ++x) {
      auto v = [&](const gis::Raster& r) {
        const float d = r.values.at(x, y);
        return std::isfinite(d) ? double(d) : 0.0;
      };
      const bool west = x < kW / 2;
      const double own = west ? v(*smooth) : v(*rough);
      worst[west ? 0 : 1] = std::max(worst[west ? 0 : 1], std::abs(v(*mapped) - own));
      differ = std::max(differ, std::abs(v(*smooth) - v(*rough)));
      wet += v(*mapped) > 0.05;
    }
  }
  std::printf(
      "roughness: largest |mapped - own n| %.3g m west, %.3g m east; n 0.03 vs 0.08 differ by %.3g m; "
      "%d cells wetter than 5 cm\n",
      worst[0], worst[1], differ, wet);
  EXPECT_GT(wet, 100);
  EXPECT_GT(differ, 0.05) << "n = 0.03 and 0.08 must give other depths, or the test shows nothing";
  // Measured: 2.2e-9 m west, 1.1e-3 m east against 0.38 m between the two n (the runs' CFL steps
  // differ: the west valley's faster flow sets them in the mapped and the smooth run).
  EXPECT_LT(worst[0], 0.05 * differ) << "west";
  EXPECT_LT(worst[1], 0.05 * differ) << "east";

  // A map of one value is that n everywhere, bit for bit.
  ASSERT_TRUE(gis::writeGeoTiff((dir / "n008.tif").string(), grid(0.08f)));
  auto constant = maxDepth(dir, "constant", "manning_n = 0.05\nmanning_raster = \"n008.tif\"");
  ASSERT_TRUE(constant) << constant.message();
  EXPECT_EQ(constant->values.data, rough->values.data);

  // The same map from land-cover classes and a table of n per class: the same answer, bit for bit.
  auto classes = maxDepth(dir, "classes",
                          "manning_n = 0.05\n[model.land_cover]\nraster = \"classes.tif\"\nmanning = { 30 = "
                          "0.03, 10 = 0.08 }");
  ASSERT_TRUE(classes) << classes.message();
  EXPECT_EQ(classes->values.data, mapped->values.data);

  // Refusals, naming the key.
  auto missing = maxDepth(dir, "missing", "[model.land_cover]\nraster = \"classes.tif\"\nmanning = { 30 = 0.03 }");
  ASSERT_FALSE(missing);
  EXPECT_NE(missing.message().find("key 'model.land_cover.manning': no n for class 10 of"), std::string::npos)
      << missing.message();
  gis::Raster bad = grid(0.04f);
  bad.values.at(3, 2) = 2.5f;
  ASSERT_TRUE(gis::writeGeoTiff((dir / "bad.tif").string(), bad));
  auto outside = maxDepth(dir, "outside", "manning_raster = \"bad.tif\"");
  ASSERT_FALSE(outside);
  EXPECT_NE(outside.message().find("key 'model.manning_raster': "), std::string::npos) << outside.message();
  EXPECT_NE(outside.message().find("Manning's n 2.500000 at column 3, row 2 of the region"), std::string::npos)
      << outside.message();
}

}  // namespace
}  // namespace strata::scenario
