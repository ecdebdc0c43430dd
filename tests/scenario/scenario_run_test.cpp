// Scenario runs on the CPU backend with no GL context at all: the run folder (maps, series,
// plots, report), and run folders and scenario names that a shell would have misread.
#include <gdal.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <sstream>

#include <strata/core/progress.hpp>
#include <strata/gis/geodesy.hpp>
#include <strata/scenario/run.hpp>

#include "scenario_fixture.hpp"
#include "strata_test.hpp"

namespace strata::scenario {
namespace {

using namespace test_support;

TEST(ScenarioRun, FloodRunsOnTheCpuWithoutGl) {
  const auto dir = strata::test::tempDir("cpu-run");
  const auto scenario = writeScenario(dir);
  RunOptions opt;
  opt.outDir = dir / "run";
  opt.backend = Backend::kCpu;
  opt.pictures = false;  // pictures are drawn with GL; everything else needs none
  auto summary = runScenario(scenario, opt);
  ASSERT_TRUE(summary) << summary.message();
  EXPECT_TRUE(summary->completed);
  EXPECT_NE(summary->backend.find("CPU"), std::string::npos) << summary->backend;
  const auto rows = readCsv(opt.outDir / "series.csv");
  ASSERT_EQ(rows.size(), 4u);
  for (const auto& r : rows) {
    const double in = r[5] + r[6], out = r[7] + r[8], stored = r[3];
    EXPECT_LT(std::abs(in - out - stored), 1e-4 * in) << "t = " << r[0];
  }
  EXPECT_GT(rows.back()[5], 0.9 * 20000 * 17.5 * 60);  // inflow: 17.5 min at full rate, plus the ramp
  // dt_s is the shortest step W10 chose in the interval, not the last step of the interval cut
  // short to land on the output time (any value down to 0: issue 16's "0.01 s"). The flow here
  // changes slowly: no interval's shortest step is far below the mean.
  const double meanDt = summary->simulatedS / double(summary->steps);
  for (const auto& r : rows) EXPECT_GT(r[2], 0.3 * meanDt) << "t = " << r[0] << ": dt " << r[2];
  for (const char* f :
       {"maps/max_depth.tif", "maps/arrival_time.tif", "plots/water.png", "plots/max_depth.png", "report.md"}) {
    EXPECT_TRUE(std::filesystem::exists(opt.outDir / f)) << f;
  }
  EXPECT_NE(slurp(opt.outDir / "report.md").find("on CPU"), std::string::npos);
  // Issue 31: each map's band says what it is and in which unit (gdalinfo shows both; the times
  // are in seconds while the report writes hours). GDAL's unit type only for lengths (a DEM's
  // vertical unit to GDAL and readDem: the maps stay readable as DEMs and drapes).
  const struct {
    const char* file;
    const char* description;
    const char* units;
  } bands[] = {{"maps/max_depth.tif", "largest water depth", "m"},
               {"maps/max_speed.tif", "largest flow speed (m/s)", ""},
               {"maps/arrival_time.tif", "time the water first passed the wet threshold, from the start (s)", ""},
               {"maps/inundation_duration.tif", "time spent deeper than the wet threshold (s)", ""},
               {"maps/final_depth.tif", "water depth at the end", "m"},
               {"maps/elevation.tif", "bed elevation the model used (conditioned)", "m"}};
  for (const auto& b : bands) {
    GDALDatasetH ds = GDALOpen((opt.outDir / b.file).string().c_str(), GA_ReadOnly);
    ASSERT_NE(ds, nullptr) << b.file;
    GDALRasterBandH band = GDALGetRasterBand(ds, 1);
    EXPECT_STREQ(GDALGetDescription(band), b.description) << b.file;
    EXPECT_STREQ(GDALGetRasterUnitType(band), b.units) << b.file;
    // Issue 31: Cloud Optimized GeoTIFFs (rewritten once the run ends, keeping all of the above).
    const char* layout = GDALGetMetadataItem(ds, "LAYOUT", "IMAGE_STRUCTURE");
    EXPECT_STREQ(layout ? layout : "", "COG") << b.file;
    GDALClose(ds);
  }
}

// Issue 30: the pipe model does not converge (no friction); its report says that its depths are
// not physical, the flood mode's does not.
TEST(ScenarioRun, PipeRunsSayTheirDepthsAreNotPhysical) {
  const auto dir = strata::test::tempDir("pipe-run");
  std::string text = scenarioText();
  auto swap = [&](const std::string& from, const std::string& to) { text.replace(text.find(from), from.size(), to); };
  swap("kind = \"flood\"", "kind = \"pipe\"");
  swap("duration = \"20 min\"", "duration = \"5 min\"");
  const auto file = dir / "pipe.toml";
  std::ofstream(file) << text;
  auto scenario = loadScenario(file);
  ASSERT_TRUE(scenario) << scenario.message();
  RunOptions opt;
  opt.outDir = dir / "run";
  opt.backend = Backend::kCpu;
  opt.pictures = false;
  opt.plots = false;
  auto summary = runScenario(*scenario, opt);
  ASSERT_TRUE(summary) << summary.message();
  const std::string report = slurp(opt.outDir / "report.md");
  EXPECT_NE(report.find("virtual pipes: an interactive authoring model"), std::string::npos) << report;
  EXPECT_NE(report.find("not physical"), std::string::npos);
  // Issue 33: the bed the model used is written without pictures and plots too (the docs list
  // it among the maps), on the run's grid, and named among the run's files.
  auto bed = gis::readDem((opt.outDir / "maps" / "elevation.tif").string());
  ASSERT_TRUE(bed) << bed.message();
  EXPECT_GT(bed->georef.width, 10);
  EXPECT_GT(bed->georef.height, 10);
  EXPECT_NE(std::find(summary->files.begin(), summary->files.end(), "maps/elevation.tif"), summary->files.end());
}

// An erosion run writes what an erosion user needs (issue 16): net cut and fill, each layer's
// final thickness, the exposed material and the load at the end as GeoTIFFs, and a per-material
// table and the material balance in the report, which closes (E9) and agrees with the maps.
TEST(ScenarioRun, ErosionRunWritesMaterialMapsAndBalance) {
  const auto dir = strata::test::tempDir("erosion-run");
  std::string text = scenarioText();
  text +=
      "[[terrain.layer]]\nmaterial = \"rock\"\nthickness = \"20 m\"\n"
      "[[terrain.layer]]\nmaterial = \"sand\"\nthickness = \"1 m\"\n"
      "[erosion]\nenabled = true\n";
  std::ofstream(dir / "erode.toml") << text;
  auto scenario = loadScenario(dir / "erode.toml");
  ASSERT_TRUE(scenario) << scenario.message();
  RunOptions opt;
  opt.outDir = dir / "run";
  opt.backend = Backend::kCpu;
  opt.pictures = false;
  opt.plots = false;
  opt.command = "erode";
  auto summary = runScenario(*scenario, opt);
  ASSERT_TRUE(summary) << summary.message();
  ASSERT_TRUE(summary->material);
  const auto& b = *summary->material;
  ASSERT_EQ(b.layers.size(), 2u);
  EXPECT_EQ(b.layers[0], "rock");
  EXPECT_EQ(b.layers[1], "sand");
  const double rel = std::abs(b.balanceM3()) / b.initialM3Total;
  std::printf("erosion run: eroded %.4g, deposited %.4g, suspended %.4g, out %.4g m3, balance %.3g m3 (rel %.3g)\n",
              b.erodedM3, b.depositedM3, b.suspendedM3, b.outflowM3, b.balanceM3(), rel);
  EXPECT_GT(b.erodedM3, 1e3);  // the river did cut
  EXPECT_LT(rel, 1e-6);        // E9: float rounding of the receivers only
  // The maps hold what the table says: the net change map sums to deposited - eroded, and each
  // layer's map to its final volume (cell areas as the solver's: the region's rows).
  const auto change = gis::readDem((opt.outDir / "maps/terrain_change.tif").string(), allowEmpty());
  ASSERT_TRUE(change) << change.message();
  const auto& g = change->georef;
  const auto areas = gis::cellAreasM2(g);
  ASSERT_TRUE(areas) << areas.message();
  // The solver's cell area: the row's area at its middle column (scenario measureCells).
  auto cellM2 = [&](size_t i) { return areas->at(g.width / 2, int(i / size_t(g.width))); };
  double net = 0;
  for (size_t i = 0; i < change->values.size(); ++i) {
    if (!std::isnan(change->values.data[i])) net += double(change->values.data[i]) * cellM2(i);
  }
  EXPECT_NEAR(net, b.depositedM3 - b.erodedM3, 1e-3 * (b.depositedM3 + b.erodedM3));
  for (int k = 1; k <= 2; ++k) {
    const auto layer = gis::readDem((opt.outDir / ("maps/layer_" + std::to_string(k) + ".tif")).string(), allowEmpty());
    ASSERT_TRUE(layer) << layer.message();
    double v = 0;
    for (size_t i = 0; i < layer->values.size(); ++i) {
      const float t = layer->values.data[i];
      v += std::isnan(t) ? 0.0 : double(t) * cellM2(i);
    }
    EXPECT_NEAR(v, b.finalM3[size_t(k - 1)], 1e-3 * b.finalM3[0]) << "layer " << k;
  }
  const auto top = gis::readDem((opt.outDir / "maps/exposed_material.tif").string(), allowEmpty());
  ASSERT_TRUE(top) << top.message();
  int rockExposed = 0;
  for (float t : top->values.data) rockExposed += t == 0.0f;
  EXPECT_GT(rockExposed, 0);  // the sand has gone somewhere (steep walls it slid off, the channel)
  {
    // Each value's material and colour ride along as metadata (the plot's legend, gdalinfo).
    GDALAllRegister();
    GDALDatasetH ds = GDALOpen((opt.outDir / "maps/exposed_material.tif").string().c_str(), GA_ReadOnly);
    ASSERT_NE(ds, nullptr);
    const char* m0 = GDALGetMetadataItem(ds, "STRATA_MATERIAL_0", nullptr);
    const char* c0 = GDALGetMetadataItem(ds, "STRATA_COLOUR_0", nullptr);
    EXPECT_STREQ(m0, "rock");
    EXPECT_STREQ(c0, "0.450,0.360,0.300");
    GDALClose(ds);
  }
  EXPECT_TRUE(std::filesystem::exists(opt.outDir / "maps/suspended_sediment.tif"));
  const std::string report = slurp(opt.outDir / "report.md");
  EXPECT_NE(report.find("## Material"), std::string::npos);
  EXPECT_NE(report.find("| 2 | sand |"), std::string::npos) << report;
  EXPECT_NE(report.find("carried out through open edges"), std::string::npos);
}

// Issue 19: the report's plots once ran through a shell with the run folder in single quotes, so
// a scenario named x';touch PWNED;'.toml ran `touch PWNED`, and an apostrophe broke every run.
// Plots now start python with an argument vector: any name a file system allows works.
TEST(ScenarioRun, NamesAShellWouldMisreadAreJustNames) {
  const auto dir = strata::test::tempDir("names");
  const auto cwd = std::filesystem::current_path();
  std::filesystem::current_path(dir);
  const std::string nasty = "x';touch PWNED;' $(touch PWNED2) `touch PWNED3` it's";
  const auto file = dir / (nasty + ".toml");
  std::ofstream(file) << scenarioText();
  auto scenario = loadScenario(file);
  ASSERT_TRUE(scenario) << scenario.message();
  RunOptions opt;
  opt.outDir = dir / "runs" / nasty;
  opt.backend = Backend::kCpu;
  opt.pictures = false;
  auto summary = runScenario(*scenario, opt);
  std::filesystem::current_path(cwd);
  ASSERT_TRUE(summary) << summary.message();
  EXPECT_TRUE(std::filesystem::exists(opt.outDir / "plots" / "water.png"));
  EXPECT_TRUE(std::filesystem::exists(opt.outDir / "report.md"));
  for (const char* f : {"PWNED", "PWNED2", "PWNED3"}) {
    EXPECT_FALSE(std::filesystem::exists(dir / f)) << f << " was created: a shell read the name";
    EXPECT_FALSE(std::filesystem::exists(opt.outDir / f)) << f;
  }
}

// Issue 20: a river is never dry. `spin_up` runs the inflows at their t = 0 value (the base flow)
// before t = 0; the outputs and the balance start at t = 0 with that water as the initial water.
TEST(ScenarioRun, SpinUpStartsTheRunWithTheBaseFlowInItsBed) {
  const auto dir = strata::test::tempDir("spin-up");
  std::string text = scenarioText();
  auto replace = [&](const std::string& from, const std::string& to) {
    const auto at = text.find(from);
    ASSERT_NE(at, std::string::npos) << from;
    text.replace(at, from.size(), to);
  };
  replace("hydrograph = [[0, 0], [5, 20000], [20, 20000]]", "hydrograph = [[0, 400], [5, 20000], [20, 20000]]");
  replace("[time]\n", "[time]\nspin_up = \"3 h\"\n");
  std::ofstream(dir / "base.toml") << text;
  auto scenario = loadScenario(dir / "base.toml");
  ASSERT_TRUE(scenario) << scenario.message();
  RunOptions opt;
  opt.outDir = dir / "run";
  opt.backend = Backend::kCpu;
  opt.pictures = false;
  opt.plots = false;
  auto summary = runScenario(*scenario, opt);
  ASSERT_TRUE(summary) << summary.message();
  const auto& u = summary->spinUp;
  EXPECT_EQ(u.seconds, 3 * 3600.0);
  EXPECT_EQ(u.baseFlowM3S, 400.0);
  EXPECT_GT(u.steps, 0);
  EXPECT_GT(u.storedM3, 400.0 * 600);  // more than ten minutes of the base flow is in the river
  // Over the spin-up's last tenth, what came in left or was stored: 400 = out + dS/dt.
  EXPECT_NEAR(u.outflowM3S + u.storageRateM3S, 400.0, 4.0);

  const auto rows = readCsv(opt.outDir / "series.csv");
  ASSERT_EQ(rows.size(), 4u);
  // The first interval's inflow is the hydrograph's from t = 0 only: (400 + 20000) / 2 x 300 s.
  EXPECT_NEAR(rows[0][5], 0.5 * (400 + 20000) * 300, 1e-4 * 0.5 * (400 + 20000) * 300);
  for (const auto& r : rows) {
    // in - out = stored - stored at t = 0.
    const double in = r[5] + r[6], out = r[7] + r[8], stored = r[3];
    EXPECT_LT(std::abs(in - out - (stored - u.storedM3)), 1e-4 * (in + u.storedM3)) << "t = " << r[0];
    EXPECT_LT(std::abs(r[9]), 1e-4) << "the CSV's own balance column, t = " << r[0];
  }
  // The run's steps are its own (the series counts the solver's, the spin-up's included), and so
  // is its mean step.
  EXPECT_EQ(summary->steps + u.steps, (long long)rows.back()[1]);
  const std::string report = slurp(opt.outDir / "report.md");
  EXPECT_NE(report.find("| base flow | 400 m³/s"), std::string::npos) << report;
  EXPECT_NE(report.find(std::to_string(summary->steps) + " steps (mean step"), std::string::npos) << report;

  // A dam break starts at t = 0, before which the spin-up runs: refused, naming the key.
  std::string dam = text +
                    "[[water.dam_break]]\npolygon_lonlat = [[-112.1, 36.05], [-112.05, 36.05], [-112.05, "
                    "36.1]]\nsurface = \"900 m\"\n";
  std::ofstream(dir / "dam.toml") << dam;
  auto refused = loadScenario(dir / "dam.toml");
  ASSERT_FALSE(refused);
  EXPECT_NE(refused.message().find("key 'time.spin_up': a dam break releases its water at t = 0"), std::string::npos)
      << refused.message();
}

// A spin-up with a tolerance ends as soon as the river is steady (the stored water changing by
// less than that fraction of the base flow over a tenth of the longest spin-up), and the clock
// moves on to t = 0; one that cannot get there in time runs its whole length and says so.
TEST(ScenarioRun, SpinUpEndsOnceTheRiverIsSteady) {
  const auto dir = strata::test::tempDir("spin-up-steady");
  auto run = [&](const std::string& spinUp, const std::string& name) {
    std::string text = scenarioText();
    text.replace(text.find("[[0, 0], [5, 20000]"), 19, "[[0, 400], [5, 20000]");
    text.replace(text.find("[time]\n"), 7, "[time]\n" + spinUp);
    // Unconditioned, the river fills the DEM's pits and is still not steady after 48 h (nothing leaves).
    text.replace(text.find("[region]"), 8, "breach_inflows = true\nfill_depressions = true\n[region]");
    std::ofstream(dir / (name + ".toml")) << text;
    auto scenario = loadScenario(dir / (name + ".toml"));
    EXPECT_TRUE(scenario) << scenario.message();
    if (!scenario) return std::pair{SpinUpSummary{}, std::string()};
    auto summary = runScenario(*scenario, cpuOptions(dir / name));
    EXPECT_TRUE(summary) << summary.message();
    if (!summary) return std::pair{SpinUpSummary{}, std::string()};
    return std::pair{summary->spinUp, slurp(dir / name / "report.md")};
  };
  const auto [steady, report] = run("spin_up = \"48 h\"\nspin_up_tolerance = 0.01\n", "steady");
  EXPECT_TRUE(steady.steady);
  EXPECT_LT(steady.seconds, 0.75 * 48 * 3600) << "steady long before the longest spin-up";
  EXPECT_GT(steady.seconds, 48 * 3600 / 20.0) << "a river from dry is not steady at the first check";
  EXPECT_NEAR(std::fmod(steady.seconds, 48 * 3600 / 20.0), 0.0, 1e-6) << "it ends at a check";
  EXPECT_EQ(steady.windowS, 48 * 3600 / 10.0);
  EXPECT_LT(std::abs(steady.storageRateM3S), 0.01 * 400);
  EXPECT_NEAR(steady.outflowM3S + steady.storageRateM3S, 400.0, 0.4) << "what came in left or was stored";
  EXPECT_NE(
      report.find("run until steady: " + strata::formatDuration(steady.seconds) + " before t = 0 (of at most 48 h"),
      std::string::npos)
      << report;
  // Steady means it: twice as long a spin-up holds the same water at t = 0, within 1%.
  const auto [longer, longerReport] =
      run("spin_up = \"" + std::to_string(int(2 * steady.seconds)) + " s\"\n", "longer");
  EXPECT_FALSE(longer.steady);
  EXPECT_EQ(longer.seconds, double(int(2 * steady.seconds)));
  EXPECT_NEAR(steady.storedM3, longer.storedM3, 0.01 * longer.storedM3);
  EXPECT_LT(std::abs(longer.storageRateM3S), std::abs(steady.storageRateM3S));
  // Too short to get there: it runs its whole length, warns and says so in the report.
  const auto [early, earlyReport] = run("spin_up = \"1 h\"\nspin_up_tolerance = 0.01\n", "early");
  EXPECT_FALSE(early.steady);
  EXPECT_EQ(early.seconds, 3600.0);
  EXPECT_GT(early.storageRateM3S, 0.01 * 400);
  EXPECT_NE(earlyReport.find("**not steady**"), std::string::npos) << earlyReport;

  // A tolerance needs a spin-up and an inflow, and is a fraction in (0, 0.5]: refused naming the key.
  auto refused = [&](const std::string& time, const std::string& expected, bool noInflow = false) {
    std::string text = scenarioText();
    text.replace(text.find("[time]\n"), 7, "[time]\n" + time);
    if (noInflow) {
      const auto from = text.find("[[water.inflow]]"), to = text.find("[time]");
      text.replace(from, to - from, "[water.rain]\nrate = \"10 mm/h\"\n");
    }
    std::ofstream(dir / "bad.toml") << text;
    auto s = loadScenario(dir / "bad.toml");
    ASSERT_FALSE(s) << time;
    const auto line = std::count(text.begin(), text.begin() + std::ptrdiff_t(text.find("spin_up_tolerance")), '\n') + 1;
    EXPECT_NE(s.message().find("bad.toml:" + std::to_string(line) + ": " + expected), std::string::npos) << s.message();
  };
  refused("spin_up_tolerance = 0.01\n", "key 'time.spin_up_tolerance': needs a spin_up");
  refused("spin_up = \"1 h\"\nspin_up_tolerance = 0\n", "key 'time.spin_up_tolerance': must be positive");
  refused("spin_up = \"1 h\"\nspin_up_tolerance = 0.6\n", "key 'time.spin_up_tolerance': must be at most 0.5");
  refused("spin_up = \"1 h\"\nspin_up_tolerance = 0.01\n",
          "key 'time.spin_up_tolerance': is a fraction of the base flow", true);
}

}  // namespace
}  // namespace strata::scenario
