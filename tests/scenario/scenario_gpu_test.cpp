// The flood scenario end to end with a GL context (llvmpipe in CI): a small region of the real
// Grand Canyon DEM, a river inflow, maps, series, pictures, report; interrupt-and-resume; the GL
// and CPU backends side by side.
#include <gtest/gtest.h>

#include <cmath>
#include <fstream>
#include <iterator>
#include <sstream>

#include <strata/core/files.hpp>
#include <strata/gis/dem_io.hpp>
#include <strata/gis/geodesy.hpp>
#include <strata/render/image_io.hpp>
#include <strata/scenario/domain.hpp>
#include <strata/scenario/run.hpp>

#include "gl_fixture.hpp"
#include "scenario_fixture.hpp"
#include "strata_test.hpp"

namespace strata::scenario {
namespace {

using test::GlTest;

using namespace test_support;

TEST_F(GlTest, FloodScenarioWritesMapsSeriesAndReport) {
  const auto dir = test::tempDir("flood");
  const auto scenario = writeScenario(dir);
  RunOptions opt;
  opt.outDir = dir / "run";
  auto summary = runScenario(scenario, opt);
  ASSERT_TRUE(summary) << summary.message();
  EXPECT_TRUE(summary->completed);
  ASSERT_EQ(summary->series.size(), 4u);

  // GeoTIFFs open in gdalinfo with the DEM's CRS (EPSG:4326) and the region's geotransform.
  auto domain = strata::scenario::buildDomain(scenario);
  ASSERT_TRUE(domain) << domain.message();
  const auto& gt = domain->bed.georef.transform.c;
  for (const char* map : {"max_depth", "max_speed", "arrival_time", "inundation_duration", "final_depth"}) {
    const auto path = opt.outDir / "maps" / (std::string(map) + ".tif");
    ASSERT_TRUE(std::filesystem::exists(path)) << path;
    const std::string info = strata::test::runProgram({"gdalinfo", "-json", path}).output;
    EXPECT_NE(info.find("ID[\\\"EPSG\\\",4326]"), std::string::npos) << map << ": " << info.substr(0, 400);
    EXPECT_NE(info.find("\"noDataValue\":-32768"), std::string::npos) << map;
    const auto at = info.find("\"geoTransform\":[");
    ASSERT_NE(at, std::string::npos) << map;
    const char* p = info.c_str() + at + 16;
    for (int k = 0; k < 6; ++k) {
      char* end = nullptr;
      const double v = std::strtod(p, &end);
      EXPECT_NEAR(v, gt[k], 1e-12 * std::max(1.0, std::abs(gt[k]))) << map << " geotransform term " << k;
      p = end;
      while (*p == ',' || *p == ' ' || *p == '\n') ++p;
    }
  }

  // The series: volume balance (in - out - stored) within 1e-4 of what came in.
  const auto rows = readCsv(opt.outDir / "series.csv");
  ASSERT_EQ(rows.size(), 4u);
  for (const auto& r : rows) {
    const double in = r[5] + r[6], out = r[7] + r[8], stored = r[3];
    EXPECT_LT(std::abs(in - out - stored), 1e-4 * in) << "t = " << r[0];
  }
  EXPECT_GT(rows.back()[5], 0.9 * 20000 * 17.5 * 60);  // inflow: 17.5 min at full rate, plus the ramp

  // The flooded area equals the sum of geodesic areas of the cells wetter than the threshold.
  auto depth = gis::readDem((opt.outDir / "maps" / "final_depth.tif").string(), allowEmpty());
  ASSERT_TRUE(depth) << depth.message();
  auto areas = gis::cellAreasM2(depth->georef);
  ASSERT_TRUE(areas);
  double wet = 0;
  for (size_t i = 0; i < depth->values.size(); ++i) {
    if (depth->values.data[i] > 0.1f) wet += areas->data[i];
  }
  EXPECT_GT(wet, 0);
  // 1e-6: the CSV keeps 9 significant digits and the depths pass through float32 GeoTIFF.
  EXPECT_NEAR(rows.back()[4], wet / 1e6, 1e-6 * wet / 1e6);

  // Plots and the report.
  for (const char* f : {"plots/water.png", "plots/area.png", "plots/max_depth.png", "pictures/before.png",
                        "pictures/peak.png", "pictures/after.png", "pictures/max_depth.png", "report.md"}) {
    EXPECT_TRUE(std::filesystem::exists(opt.outDir / f)) << f;
  }
  std::ifstream report(opt.outDir / "report.md");
  std::stringstream text;
  text << report.rdbuf();
  // The max-depth picture drapes the map in the ramp's colours, which the 'after' picture (the
  // terrain's tint and water) does not have: the ramp's deep yellow, red well over blue.
  auto yellow = [](const render::Image8& im) {
    int n = 0;
    for (size_t i = 0; i + 3 < im.pixels.size(); i += size_t(im.channels)) {
      n += im.pixels[i] > 180 && im.pixels[i + 1] > 160 && im.pixels[i + 2] < 90;
    }
    return n;
  };
  auto maxPic = render::readImage8((opt.outDir / "pictures" / "max_depth.png").string());
  auto afterPic = render::readImage8((opt.outDir / "pictures" / "after.png").string());
  ASSERT_TRUE(maxPic && afterPic);
  EXPECT_GT(yellow(*maxPic), 20);
  EXPECT_EQ(yellow(*afterPic), 0);
  EXPECT_NE(text.str().find("![pictures/max_depth.png](pictures/max_depth.png)"), std::string::npos);
  EXPECT_NE(text.str().find("`max_depth.png`: the largest depth each cell had, from 0.10 m"), std::string::npos);
  EXPECT_NE(text.str().find("| largest flooded area |"), std::string::npos);
  EXPECT_NE(text.str().find("| volume balance error at the end |"), std::string::npos);
}

TEST_F(GlTest, InterruptedAndResumedRunEqualsAnUninterruptedOne) {
  const auto dir = test::tempDir("resume");
  const auto scenario = writeScenario(dir);
  RunOptions whole;
  whole.outDir = dir / "whole";
  whole.plots = false;
  ASSERT_TRUE(runScenario(scenario, whole));

  RunOptions part = whole;
  part.outDir = dir / "part";
  part.stopAfterIntervals = 2;
  auto first = runScenario(scenario, part);
  ASSERT_TRUE(first) << first.message();
  EXPECT_FALSE(first->completed);
  EXPECT_EQ(readCsv(part.outDir / "series.csv").size(), 2u);  // outputs up to the last interval
  part.stopAfterIntervals = -1;
  part.resume = true;
  auto second = runScenario(scenario, part);
  ASSERT_TRUE(second) << second.message();
  EXPECT_TRUE(second->completed);

  const auto a = readCsv(whole.outDir / "series.csv"), b = readCsv(part.outDir / "series.csv");
  ASSERT_EQ(a.size(), b.size());
  for (size_t r = 0; r < a.size(); ++r) {
    for (size_t c = 0; c < a[r].size(); ++c) {
      // The same steps on the same state: equal to the digits the CSV keeps.
      EXPECT_NEAR(a[r][c], b[r][c], 1e-7 * std::max(1.0, std::abs(a[r][c]))) << "row " << r << " column " << c;
    }
  }
  for (const char* map : {"max_depth", "final_depth", "arrival_time"}) {
    auto x = gis::readDem((whole.outDir / "maps" / (std::string(map) + ".tif")).string(), allowEmpty());
    auto y = gis::readDem((part.outDir / "maps" / (std::string(map) + ".tif")).string(), allowEmpty());
    ASSERT_TRUE(x && y);
    for (size_t i = 0; i < x->values.size(); ++i) {
      const float u = x->values.data[i], v = y->values.data[i];
      ASSERT_TRUE((std::isnan(u) && std::isnan(v)) || std::abs(u - v) <= 1e-5f * std::max(1.0f, std::abs(u)))
          << map << " cell " << i << ": " << u << " vs " << v;
    }
  }
}

// The test scenario with a fixed level across the canyon instead of its inflow, whose stage rises
// 50 m in 10 minutes and falls 30 m in the next 10, written to dir/level.toml.
std::filesystem::path writeLevelScenario(const std::filesystem::path& dir) {
  std::string text = scenarioText();
  const auto from = text.find("[[water.inflow]]"), to = text.find("[time]");
  text.replace(from, to - from,
               "[[water.level]]\nname = \"river stage\"\nline_lonlat = [[-112.0225, 36.063], [-112.0225, 36.08]]\n"
               "stage = [[0, 800], [10, 850], [20, 820]]\nstage_units = [\"min\", \"m\"]\n");
  std::ofstream(dir / "level.toml") << text;
  return dir / "level.toml";
}

// W26 end to end: no inflow, only the rising and falling level: water pours in through the
// level, then part of it drains back out through it. The CSV's balance (in - out - stored)
// closes as for inflows.
TEST_F(GlTest, FloodScenarioWithARisingAndFallingLevelBalances) {
  const auto dir = test::tempDir("flood-level");
  auto scenario = strata::scenario::loadScenario(writeLevelScenario(dir));
  ASSERT_TRUE(scenario) << scenario.message();
  RunOptions opt;
  opt.outDir = dir / "run";
  opt.pictures = false;
  opt.plots = false;
  auto summary = runScenario(*scenario, opt);
  ASSERT_TRUE(summary) << summary.message();
  const auto rows = readCsv(opt.outDir / "series.csv");
  ASSERT_EQ(rows.size(), 4u);
  for (const auto& r : rows) {
    const double in = r[5] + r[6], out = r[7] + r[8], stored = r[3];
    std::printf("t = %.0f s: in %.6g out %.6g stored %.6g, balance %.3g\n", r[0], in, out, stored,
                (in - out - stored) / in);
    EXPECT_LT(std::abs(in - out - stored), 1e-4 * in) << "t = " << r[0];
  }
  EXPECT_GT(rows[1][5], 1e6);  // the rising stage pours millions of m3 in
  // and the falling one takes part of it back out (nothing has reached an open edge yet): the
  // stored water falls (measured on the square 600 m cells: by 3.5% in the last 5 minutes; the
  // water far from the line drains back slowly). The exchange is counted net per cell since the
  // start, so the level's inflow column falls.
  EXPECT_LT(rows.back()[3], 0.98 * rows[2][3]);
  EXPECT_LT(rows.back()[5], rows[2][5]);
  // The level's cells end at the final stage: depth = 820 m - bed.
  auto domain = strata::scenario::buildDomain(*scenario);
  ASSERT_TRUE(domain) << domain.message();
  auto depth = gis::readDem((opt.outDir / "maps" / "final_depth.tif").string(), allowEmpty());
  ASSERT_TRUE(depth) << depth.message();
  ASSERT_FALSE(domain->levels[0].cells.empty());
  for (auto [x, y] : domain->levels[0].cells) {
    const double expect = std::max(0.0, 820.0 - double(domain->bed.values.at(x, y)));
    // float32 depths relative to a datum ~800 m: 1 mm.
    EXPECT_NEAR(depth->values.at(x, y), expect, 1e-3) << x << ", " << y;
  }
}

// pictures/peak.png is the last interval at which the stored water reached a new high, drawn
// once (when the water falls from it, or the run ends or stops), not at every new high. The
// rising and falling level peaks at the third of four intervals: run whole, and stopped at the
// peak (which draws it) and resumed (which keeps the state it resumes from as the peak, and
// draws it when the water falls), the peak pictures are the same image. (This view of the
// canyon shows no change between the last two intervals: 'after' is the same image as 'peak'.)
TEST_F(GlTest, PeakPictureIsTheHighestIntervalsAcrossAResume) {
  const auto dir = test::tempDir("peak-picture");
  auto scenario = strata::scenario::loadScenario(writeLevelScenario(dir));
  ASSERT_TRUE(scenario) << scenario.message();
  RunOptions whole;
  whole.outDir = dir / "whole";
  whole.plots = false;
  auto a = runScenario(*scenario, whole);
  ASSERT_TRUE(a) << a.message();
  RunOptions part = whole;
  part.outDir = dir / "part";
  part.stopAfterIntervals = 3;
  auto b = runScenario(*scenario, part);
  ASSERT_TRUE(b) << b.message();
  EXPECT_FALSE(b->completed);
  EXPECT_TRUE(std::filesystem::exists(part.outDir / "pictures" / "peak.png"));  // drawn when it stopped
  part.stopAfterIntervals = -1;
  part.resume = true;
  auto c = runScenario(*scenario, part);
  ASSERT_TRUE(c) << c.message();
  const auto rows = readCsv(whole.outDir / "series.csv");
  ASSERT_EQ(rows.size(), 4u);
  EXPECT_LT(rows[3][3], rows[2][3]);  // the peak is the third interval's
  EXPECT_GT(rows[2][3], rows[1][3]);
  auto bytes = [](const std::filesystem::path& f) {
    std::ifstream in(f, std::ios::binary);
    return std::string(std::istreambuf_iterator<char>(in), {});
  };
  const std::string peakWhole = bytes(whole.outDir / "pictures" / "peak.png");
  EXPECT_FALSE(peakWhole.empty());
  EXPECT_EQ(peakWhole, bytes(part.outDir / "pictures" / "peak.png"));
  EXPECT_EQ(bytes(whole.outDir / "pictures" / "after.png"), bytes(part.outDir / "pictures" / "after.png"));
}

TEST_F(GlTest, ResumeRefusesACheckpointOfAnotherScenario) {
  const auto dir = test::tempDir("resume-other");
  auto scenario = writeScenario(dir);
  RunOptions opt;
  opt.outDir = dir / "run";
  opt.plots = false;
  opt.stopAfterIntervals = 1;
  ASSERT_TRUE(runScenario(scenario, opt));
  std::ofstream(scenario.file, std::ios::app) << "# edited\n";  // and read again, as --resume reads it
  auto edited = loadScenario(scenario.file);
  ASSERT_TRUE(edited) << edited.message();
  opt.resume = true;
  auto again = runScenario(*edited, opt);
  ASSERT_FALSE(again);
  EXPECT_EQ(again.message(),
            (opt.outDir / "checkpoint.bin").string() + ": written by a different scenario (the file changed)");
}

// The same scenario on the GL backend and on the CPU backend: the same equations in float32 on
// the same grid, so the maps agree to rounding (measured on llvmpipe: max depth within 3.8e-6 m,
// arrival times equal), and both balances close.
TEST_F(GlTest, GpuAndCpuBackendsAgreeOnTheCanyonFlood) {
  const auto dir = test::tempDir("backends");
  const auto scenario = writeScenario(dir);
  std::vector<std::filesystem::path> runs;
  for (Backend b : {Backend::kGpu, Backend::kCpu}) {
    RunOptions opt;
    opt.outDir = dir / (b == Backend::kGpu ? "gpu" : "cpu");
    opt.backend = b;
    opt.pictures = false;
    opt.plots = false;
    auto summary = runScenario(scenario, opt);
    ASSERT_TRUE(summary) << summary.message();
    EXPECT_NE(summary->backend.find(b == Backend::kGpu ? "GL" : "CPU"), std::string::npos) << summary->backend;
    runs.push_back(opt.outDir);
  }
  const auto g = readCsv(runs[0] / "series.csv"), c = readCsv(runs[1] / "series.csv");
  ASSERT_EQ(g.size(), c.size());
  for (size_t r = 0; r < g.size(); ++r) {
    // Balance (column 9): both close to 1e-6 of what entered; stored water (3) and flooded area
    // (4) agree to 1e-4 relative: the two backends round the same float32 sums in other orders.
    EXPECT_LT(std::abs(g[r][9]), 1e-6);
    EXPECT_LT(std::abs(c[r][9]), 1e-6);
    EXPECT_NEAR(g[r][3], c[r][3], 1e-4 * g[r][3]) << "row " << r;
    EXPECT_NEAR(g[r][4], c[r][4], 1e-2 * std::max(1.0, g[r][4])) << "row " << r;
  }
  for (const char* map : {"max_depth", "arrival_time"}) {
    auto x = gis::readDem((runs[0] / "maps" / (std::string(map) + ".tif")).string(), allowEmpty());
    auto y = gis::readDem((runs[1] / "maps" / (std::string(map) + ".tif")).string(), allowEmpty());
    ASSERT_TRUE(x && y);
    double maxDiff = 0, sumDiff = 0;
    int both = 0, onlyOne = 0;
    for (size_t i = 0; i < x->values.size(); ++i) {
      const float u = x->values.data[i], v = y->values.data[i];
      if (std::isnan(u) != std::isnan(v)) ++onlyOne;
      if (std::isnan(u) || std::isnan(v)) continue;
      ++both;
      maxDiff = std::max(maxDiff, double(std::abs(u - v)));
      sumDiff += std::abs(u - v);
    }
    std::printf("%s: GL vs CPU max |diff| %.3g, mean %.3g over %d cells, %d cells wet in one only\n", map, maxDiff,
                both ? sumDiff / both : 0.0, both, onlyOne);
    if (std::string(map) == "max_depth") {
      EXPECT_LT(maxDiff, 1e-4);  // m: float32 rounding of depths of tens of metres, not a different flood
      EXPECT_EQ(onlyOne, 0);
    } else {
      EXPECT_LE(maxDiff, 10.0);  // s: a step or two (rounding can move a cell across the threshold a step later)
      EXPECT_LE(onlyOne, 1);
    }
  }
}

}  // namespace
}  // namespace strata::scenario
