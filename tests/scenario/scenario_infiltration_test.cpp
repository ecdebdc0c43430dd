// Issue 31, spatial inputs: infiltration ([water.infiltration], W11b) and rain from a raster
// series ([water.rain] frames). Rain of 40 mm/h on a plane over a soil
// losing 5 mm/h on its west half and 15 mm/h on its east half (a raster): every cell is wet at
// every step, so the soil takes rate x wet area x time, a quarter of the rain, and the balance of
// series.csv still closes; the report says so. Green-Ampt runs through the same keys; bad values
// are refused naming file, line and key.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <fstream>

#include <strata/gis/dem_io.hpp>
#include <strata/gis/geodesy.hpp>
#include <strata/scenario/run.hpp>

#include "scenario_fixture.hpp"
#include "strata_test.hpp"

namespace strata::scenario::infiltration_test {
namespace {

using namespace test_support;

constexpr int kW = 60, kH = 40;  // 10 m cells, UTM 12N
constexpr double kX0 = 400000, kY0 = 4000000;

gis::Raster grid(float fill) { return utmRaster(kW, kH, kX0, kY0, 10, fill); }

// A plane falling south at 2 %; the loss rates 5 mm/h west and 15 mm/h east of its middle.
void writeInputs(const std::filesystem::path& dir) {
  gis::Raster dem = grid(0), loss = grid(0);
  for (int y = 0; y < kH; ++y) {
    for (int x = 0; x < kW; ++x) {
      dem.values.at(x, y) = float(100.0 + 0.2 * (kH - y));
      loss.values.at(x, y) = x < kW / 2 ? 5.0f : 15.0f;
    }
  }
  ASSERT_TRUE(gis::writeGeoTiff((dir / "dem.tif").string(), dem));
  ASSERT_TRUE(gis::writeGeoTiff((dir / "loss.tif").string(), loss));
}

std::string text(const std::string& infiltration) {
  return "name = \"soaking plane\"\n[terrain]\ndem = \"dem.tif\"\n[model]\nkind = \"flood\"\nboundary = { west = "
         "\"closed\", east = \"closed\", south = \"open\", north = \"closed\" }\n[water.rain]\nrate = \"40 mm/h\"\n"
         "[water.infiltration]\n" +
         infiltration +
         "[time]\nduration = \"30 min\"\noutput_interval = \"10 min\"\n[outputs]\nmaps = [\"max_depth\"]\n";
}

struct Outcome {
  std::vector<std::vector<double>> series;
  std::string report;
};

Result<Outcome> run(const std::filesystem::path& dir, const std::string& name, const std::string& infiltration) {
  std::ofstream(dir / (name + ".toml")) << text(infiltration);
  auto s = loadScenario(dir / (name + ".toml"));
  if (!s) return s.error();
  auto r = runScenario(*s, cpuOptions(dir / name));
  if (!r) return r.error();
  return Outcome{readCsv(dir / name / "series.csv"), slurp(dir / name / "report.md")};
}

// series.csv's columns (scenario/src/run.cpp, seriesCsv).
constexpr size_t kRain = 6, kInfiltration = 9, kBalance = 10;

TEST(ScenarioInfiltration, ConstantLossTakesRateTimesWetAreaTimesTimeAndTheBalanceCloses) {
  const auto dir = strata::test::tempDir("infiltration");
  writeInputs(dir);
  auto mapped = run(dir, "mapped", "model = \"constant\"\nrate = \"10 mm/h\"\nraster = \"loss.tif\"\n");
  ASSERT_TRUE(mapped) << mapped.message();
  ASSERT_EQ(mapped->series.size(), 3u);
  const auto& last = mapped->series.back();
  // 40 mm/h on 600 x 400 m for 30 min (the model's cells are the ground's areas: UTM's scale
  // factor makes them 0.06 % larger here); the soil's mean rate is 10 mm/h: a quarter of it.
  const double rain = last[kRain];
  std::printf("rain %.3f m3 (600 x 400 m: %.3f), infiltrated %.3f m3 (expected %.3f), balance %.3g\n", rain,
              40e-3 * 600 * 400 * 0.5, last[kInfiltration], rain / 4, last[kBalance]);
  EXPECT_NEAR(rain, 40e-3 * 600 * 400 * 0.5, 1e-3 * rain);
  EXPECT_NEAR(last[kInfiltration], rain / 4, 1e-6 * rain);
  for (const auto& row : mapped->series) EXPECT_LT(std::abs(row[kBalance]), 1e-6);
  EXPECT_NE(mapped->report.find("infiltration at a constant loss of the rate per cell from `"), std::string::npos)
      << mapped->report;
  EXPECT_NE(mapped->report.find("loss.tif` (10 mm/h where it has no data)"), std::string::npos) << mapped->report;
  EXPECT_NE(mapped->report.find("| water that soaked into the ground | 1201 m³ (25% of what entered) |"),
            std::string::npos)
      << mapped->report;

  // Green-Ampt on the same plane: the soil takes more than Ks alone would (the suction term) and
  // less than the rain; the balance closes.
  auto ga = run(dir, "ga",
                "model = \"green_ampt\"\nconductivity = \"10 mm/h\"\nsuction = \"110 mm\"\nmoisture_deficit = 0.3\n");
  ASSERT_TRUE(ga) << ga.message();
  const auto& g = ga->series.back();
  std::printf("Green-Ampt: infiltrated %.3f m3 of %.3f m3 of rain\n", g[kInfiltration], g[kRain]);
  EXPECT_GT(g[kInfiltration], 10e-3 * 600 * 400 * 0.5);
  EXPECT_LT(g[kInfiltration], g[kRain]);
  for (const auto& row : ga->series) EXPECT_LT(std::abs(row[kBalance]), 1e-6);
  EXPECT_NE(ga->report.find("infiltration by Green-Ampt (Ks 10 mm/h, suction head 110 mm, moisture deficit 0.3)"),
            std::string::npos)
      << ga->report;
}

TEST(ScenarioInfiltration, BadSoilIsRefusedNamingFileLineAndKey) {
  const auto dir = strata::test::tempDir("infiltration_bad");
  writeInputs(dir);
  const std::string file = (dir / "bad.toml").string();
  struct Case {
    std::string infiltration, message;
  };
  // [water.infiltration] is on line 9 of text(); its keys follow from line 10.
  const Case cases[] = {
      {"model = \"horton\"\n",
       ":10: key 'water.infiltration.model': \"horton\": expected \"constant\" or \"green_ampt\""},
      {"model = \"constant\"\n", ":9: key 'water.infiltration.rate': missing: the loss rate, e.g. \"5 mm/h\""},
      {"model = \"constant\"\nrate = \"-2 mm/h\"\n", ":11: key 'water.infiltration.rate': "},
      {"model = \"green_ampt\"\nconductivity = \"10 mm/h\"\nsuction = \"110 mm\"\nmoisture_deficit = 1.5\n",
       ":13: key 'water.infiltration.moisture_deficit': "},
      {"model = \"green_ampt\"\nrate = \"10 mm/h\"\n", ":11: key 'water.infiltration.rate': unknown key"},
      {"model = \"constant\"\nrate = \"5 mm/h\"\nraster = \"missing.tif\"\n", ":12: key 'water.infiltration.raster': "},
  };
  for (const auto& c : cases) {
    std::ofstream(file) << text(c.infiltration);
    auto s = loadScenario(file);
    Status status = s ? Status{} : Status(s.error());
    if (s) {
      auto r = runScenario(*s, cpuOptions(dir / "out"));
      if (!r) status = r.error();
    }
    ASSERT_FALSE(status) << c.infiltration;
    EXPECT_NE(status.message().find(file + c.message), std::string::npos) << status.message();
  }
  // A negative rate in the raster: named with its cell.
  gis::Raster bad = grid(5.0f);
  bad.values.at(3, 2) = -1.0f;
  ASSERT_TRUE(gis::writeGeoTiff((dir / "negative.tif").string(), bad));
  auto r = run(dir, "negative", "model = \"constant\"\nrate = \"5 mm/h\"\nraster = \"negative.tif\"\n");
  ASSERT_FALSE(r);
  EXPECT_NE(r.message().find("key 'water.infiltration.raster': "), std::string::npos) << r.message();
  EXPECT_NE(r.message().find("loss rate -1.000000 mm/h at column 3, row 2 of the region"), std::string::npos)
      << r.message();
}

// Rain frames: 20 mm/h on the plane's west half for 10 min, 60 mm/h everywhere for 10 min, then
// 30 mm/h on the east half until 25 min, then none: each output interval's rain is its frames'
// rate x area x time, the balance closes, the report names the frames.
TEST(ScenarioRainFrames, EachFrameRainsItsRasterForItsTime) {
  const auto dir = strata::test::tempDir("rain_frames");
  writeInputs(dir);
  gis::Raster west = grid(0), all = grid(60), east = grid(0);
  for (int y = 0; y < kH; ++y) {
    for (int x = 0; x < kW; ++x) (x < kW / 2 ? west : east).values.at(x, y) = x < kW / 2 ? 20.0f : 30.0f;
  }
  ASSERT_TRUE(gis::writeGeoTiff((dir / "f0.tif").string(), west));
  ASSERT_TRUE(gis::writeGeoTiff((dir / "f1.tif").string(), all));
  ASSERT_TRUE(gis::writeGeoTiff((dir / "f2.tif").string(), east));
  std::string t = text("model = \"constant\"\nrate = \"0 mm/h\"\n");
  const std::string frames =
      "[water.rain]\nframes = [[\"0 min\", \"f0.tif\"], [\"10 min\", \"f1.tif\"], [\"20 min\", \"f2.tif\"]]\n"
      "end = \"25 min\"\n";
  const std::string uniform = "[water.rain]\nrate = \"40 mm/h\"\n";
  t.replace(t.find(uniform), uniform.size(), frames);
  std::ofstream(dir / "frames.toml") << t;
  auto s = loadScenario(dir / "frames.toml");
  ASSERT_TRUE(s) << s.message();
  auto r = runScenario(*s, cpuOptions(dir / "frames"));
  ASSERT_TRUE(r) << r.message();
  const auto series = readCsv(dir / "frames" / "series.csv");
  ASSERT_EQ(series.size(), 3u);
  const double area = 600.0 * 400.0, mmh = 1e-3 / 3600;  // the nominal area: the cells' is 0.06 % more
  const double expected[3] = {20 * mmh * area / 2 * 600, 20 * mmh * area / 2 * 600 + 60 * mmh * area * 600,
                              20 * mmh * area / 2 * 600 + 60 * mmh * area * 600 + 30 * mmh * area / 2 * 300};
  for (size_t k = 0; k < 3; ++k) {
    std::printf("t = %.0f s: rain %.3f m3 (nominal %.3f), balance %.2g\n", series[k][0], series[k][kRain], expected[k],
                series[k][kBalance]);
    EXPECT_NEAR(series[k][kRain], expected[k], 1e-3 * expected[k]);
    EXPECT_LT(std::abs(series[k][kBalance]), 1e-6);
  }
  // The ratios to rounding (the same cells' areas in each; float32 rates; measured 2.5e-9, 1.4e-8).
  EXPECT_NEAR(series[1][kRain] / series[0][kRain], expected[1] / expected[0], 1e-7);
  EXPECT_NEAR(series[2][kRain] / series[0][kRain], expected[2] / expected[0], 1e-7);
  const std::string report = slurp(dir / "frames" / "report.md");
  EXPECT_NE(report.find("| rain | 3 raster frames (mm/h), `"), std::string::npos) << report;
  EXPECT_NE(report.find("f2.tif` at 20 min 00 s, falling until 25 min 00 s |"), std::string::npos) << report;

  // Refusals, naming file, line and key.
  const std::string file = (dir / "bad.toml").string();
  const std::pair<std::string, std::string> cases[] = {
      {"frames = [[\"10 min\", \"f0.tif\"], [\"5 min\", \"f1.tif\"]]\n",
       ":8: key 'water.rain.frames[1]': not after the frame before it"},
      {"frames = [[\"0 min\", \"f0.tif\"], [\"2 h\", \"f1.tif\"]]\n",
       ":8: key 'water.rain.frames[1]': after the run ends (time.duration is 30 min 00 s)"},
      {"frames = [[\"0 min\", \"f0.tif\"]]\nrate = \"5 mm/h\"\n",
       ":9: key 'water.rain.rate': the frames carry the rain: no rate, raster or start beside them"},
      {"frames = [\"f0.tif\"]\n", ":8: key 'water.rain.frames[0]': expected [time, \"raster.tif\"]"},
  };
  for (const auto& [rain, message] : cases) {
    std::string bad = t;
    bad.replace(bad.find(frames), frames.size(), "[water.rain]\n" + rain);
    std::ofstream(file) << bad;
    auto refused = loadScenario(file);
    ASSERT_FALSE(refused) << rain;
    EXPECT_NE(refused.message().find(file + message), std::string::npos) << refused.message();
  }
  gis::Raster negative = grid(5);
  negative.values.at(3, 2) = -4.0f;
  ASSERT_TRUE(gis::writeGeoTiff((dir / "negative.tif").string(), negative));
  std::string bad = t;
  bad.replace(bad.find("f1.tif"), 6, "negative.tif");
  std::ofstream(file) << bad;
  auto parsed = loadScenario(file);
  ASSERT_TRUE(parsed) << parsed.message();
  auto refused = runScenario(*parsed, cpuOptions(dir / "negative"));
  ASSERT_FALSE(refused);
  EXPECT_NE(refused.message().find(":8: key 'water.rain.frames': water.rain.frames[1] "), std::string::npos)
      << refused.message();
  EXPECT_NE(refused.message().find("rain -4.000000 mm/h at column 3, row 2 of the region"), std::string::npos)
      << refused.message();
}

}  // namespace
}  // namespace strata::scenario::infiltration_test
