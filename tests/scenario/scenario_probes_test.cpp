// Issue 31: gauges and cross-sections ([[outputs.gauge]], [[outputs.section]]). A dam break in a
// closed piece of the Grand Canyon with a section across the canyon below the dam: the volume the
// section reports is the water that ended on its far side (all of it crossed the line), the
// gauge's peak is the max_depth map's value at its cell, and a run stopped and resumed writes the
// same rows as one that was not.
#include <gtest/gtest.h>

#include <cmath>
#include <fstream>
#include <sstream>

#include <strata/scenario/domain.hpp>
#include <strata/scenario/run.hpp>

#include "scenario_fixture.hpp"
#include "strata_test.hpp"

namespace strata::scenario {
namespace {

using namespace test_support;

// On the fixture's dam break (damBreakText): the section runs from the north edge to the south
// edge at -112.1 (heading south, so positive is from its left, east, to its right, west); the
// gauge stands in the canyon below it.
const std::string kProbes =
    "[[outputs.gauge]]\nname = \"below the dam\"\nat_lonlat = [-112.1284, 36.098]\n"
    "[[outputs.section]]\nname = \"across the canyon\"\nline_lonlat = [[-112.1, 36.1815], [-112.1, 36.02]]\n";

Scenario load(const std::filesystem::path& dir, const std::string& text) {
  std::filesystem::create_directories(dir);
  std::ofstream(dir / "dam.toml") << text;
  auto s = loadScenario(dir / "dam.toml");
  EXPECT_TRUE(s) << s.message();
  return *s;
}

TEST(ScenarioProbes, FacesCrossedByALineCarryTheSignOfItsRightHandSide) {
  // A line heading south between columns 2 and 3 (x = 3.0 in pixels, the face between cells 2
  // and 3) over rows 0..3: four x faces (3, y); its right is west, so an eastward flux counts -1.
  auto south = facesCrossed({{3.0, 0.2}, {3.0, 3.8}}, 6, 4);
  ASSERT_EQ(south.size(), 4u);
  for (const auto& f : south) {
    EXPECT_TRUE(f.xFace);
    EXPECT_EQ(f.x, 3);
    EXPECT_EQ(f.sign, -1.0f);
  }
  // Heading east along y = 2.0: the y faces (x, 2) for x = 0..4, a southward flux positive.
  auto east = facesCrossed({{0.2, 2.0}, {4.9, 2.0}}, 6, 4);
  ASSERT_EQ(east.size(), 5u);
  for (const auto& f : east) {
    EXPECT_FALSE(f.xFace);
    EXPECT_EQ(f.y, 2);
    EXPECT_EQ(f.sign, 1.0f);
  }
  // A diagonal crosses x and y faces alternately, each once; a line back over itself crosses none
  // in net.
  auto diagonal = facesCrossed({{0.7, 0.7}, {3.7, 3.7}}, 6, 4);
  EXPECT_EQ(diagonal.size(), 6u);
  EXPECT_TRUE(facesCrossed({{3.0, 0.2}, {3.0, 3.8}, {3.0, 0.2}}, 6, 4).empty());
  // Faces at the grid's edge (one cell outside) are not section faces.
  EXPECT_TRUE(facesCrossed({{0.0, 0.2}, {0.0, 3.8}}, 6, 4).empty());
}

TEST(ScenarioProbes, SectionVolumeIsTheWaterThatCrossedAndGaugePeakIsTheMap) {
  const auto dir = strata::test::tempDir("probes");
  const Scenario s = load(dir, damBreakText(kProbes));
  auto summary = runScenario(s, cpuOptions(dir / "run", true));
  ASSERT_TRUE(summary) << summary.message();
  ASSERT_EQ(summary->sections.size(), 1u);
  ASSERT_EQ(summary->gauges.size(), 1u);
  const auto& section = summary->sections[0];
  const auto& gauge = summary->gauges[0];

  // The water west of the section's faces at the end, in the solver's cell areas (row dx x dy).
  auto d = buildDomain(s);
  ASSERT_TRUE(d) << d.message();
  auto depth = gis::readDem((dir / "run" / "maps" / "final_depth.tif").string(), allowEmpty());
  ASSERT_TRUE(depth) << depth.message();
  ASSERT_EQ(d->sections.size(), 1u);
  const int faceX = d->sections[0].faces.front().x;
  for (const auto& f : d->sections[0].faces) ASSERT_EQ(f.x, faceX);  // a straight north-south line
  EXPECT_EQ(section.faces, d->bed.georef.height);                    // edge to edge
  double west = 0, initialWest = 0;
  for (int y = 0; y < depth->georef.height; ++y) {
    for (int x = 0; x < faceX; ++x) {
      const double h = depth->values.at(x, y);
      const double area = d->input.rowDxM[size_t(y)] * d->input.dyM;
      if (std::isfinite(h)) west += h * area;
      initialWest += double(d->input.waterDepthM.at(x, y)) * area;
    }
  }
  EXPECT_EQ(initialWest, 0.0);
  EXPECT_GT(west, 1e7) << "the flood crossed the section";
  // 1e-5 of the lake: the final depths come from a float32 map (the run's own balance is ~1e-7).
  EXPECT_NEAR(section.volumeM3, west, 1e-5 * d->damBreakVolumeM3);
  EXPECT_GT(section.peak, 0.0);  // east to west
  EXPECT_GT(section.peakTimeS, 0.0);

  // The gauge's peak: the max_depth map at its cell, exactly (both taken after every step).
  auto maxDepth = gis::readDem((dir / "run" / "maps" / "max_depth.tif").string(), allowEmpty());
  ASSERT_TRUE(maxDepth) << maxDepth.message();
  EXPECT_GT(gauge.peak, 1.0);
  EXPECT_EQ(float(gauge.peak), maxDepth->values.at(gauge.x, gauge.y));

  // The rows: one a minute from t = 0, long format, the names quoted; the last volume is the summary's.
  const std::string sections = slurp(dir / "run" / "sections.csv");
  EXPECT_EQ(sections.rfind("time_s,section,discharge_m3_s,volume_m3,mean_level_m\n0.000,\"across the canyon\",0,0,", 0),
            0u)
      << sections;
  EXPECT_EQ(std::count(sections.begin(), sections.end(), '\n'), 1 + 21);
  // The last row's volume is the summary's (written with 9 digits).
  const size_t lastRow = sections.rfind('\n', sections.size() - 2) + 1;
  std::stringstream last(sections.substr(lastRow));
  std::string field;
  for (int k = 0; k < 4; ++k) std::getline(last, field, ',');
  EXPECT_NEAR(std::stod(field), section.volumeM3, 1e-8 * section.volumeM3) << sections.substr(lastRow);
  const std::string gauges = slurp(dir / "run" / "gauges.csv");
  EXPECT_EQ(std::count(gauges.begin(), gauges.end(), '\n'), 1 + 21);
  for (const char* f : {"plots/gauges.png", "plots/sections.png"}) {
    EXPECT_TRUE(std::filesystem::exists(dir / "run" / f)) << f;
  }
  const std::string report = slurp(dir / "run" / "report.md");
  EXPECT_NE(report.find("## Gauges and sections"), std::string::npos);
  EXPECT_NE(report.find("| across the canyon | 30 |"), std::string::npos) << report;
}

TEST(ScenarioProbes, AStoppedAndResumedRunWritesTheSameRows) {
  const auto dir = strata::test::tempDir("probes-resume");
  const Scenario s = load(dir, damBreakText(kProbes));
  auto whole = cpuOptions(dir / "whole", true);
  whole.plots = false;
  auto once = runScenario(s, whole);
  ASSERT_TRUE(once) << once.message();
  auto parts = cpuOptions(dir / "parts", true);
  parts.plots = false;
  parts.stopAfterIntervals = 2;
  auto first = runScenario(s, parts);
  ASSERT_TRUE(first) << first.message();
  EXPECT_FALSE(first->completed);
  parts.stopAfterIntervals = -1;
  parts.resume = true;
  auto second = runScenario(s, parts);
  ASSERT_TRUE(second) << second.message();
  EXPECT_TRUE(second->completed);
  for (const char* f : {"gauges.csv", "sections.csv"}) {
    EXPECT_EQ(slurp(dir / "whole" / f), slurp(dir / "parts" / f)) << f;
  }
  EXPECT_EQ(second->sections[0].volumeM3, once->sections[0].volumeM3);
  EXPECT_EQ(second->gauges[0].peak, once->gauges[0].peak);
}

// W37 on real terrain: the dam break with the local-inertial scheme, with and without local time
// steps (max_step 2 min, so that the grid's step can be 4 of the finest: the lake's blocks step at
// ~15 s, the canyon's at up to 60 s). With them the section still reports the water that crossed it
// (each face's flux summed over its own shorter steps, Solver::integrateFaces), the report says they
// ran, the flooded cells are the one-step run's, and the deepest water is at least as close to a
// run at 1 s steps (the time-converged answer) as the one-step run's: this dam break is violent
// for the local-inertial scheme (supercritical; the report warns), whose deepest water moves by up
// to 25 m with the step (72.5 m at its own ~15 s steps, 62.3 m capped at 16 s, 62.8 m at 1 s).
TEST(ScenarioProbes, LocalStepsKeepTheSectionVolumeAndTheInertialAnswer) {
  const auto dir = strata::test::tempDir("probes-local");
  std::string text = damBreakText(kProbes);
  const std::string kind = "kind = \"flood\"\n";
  text.insert(text.find(kind) + kind.size(), "scheme = \"inertial\"\n");
  std::string fineText = text;
  fineText.insert(fineText.find(kind) + kind.size(), "max_step = \"1 s\"\n");
  const Scenario fine = load(dir / "fine", fineText);
  text.insert(text.find(kind) + kind.size(), "max_step = \"2 min\"\n");
  const Scenario one = load(dir / "one", text);
  text.insert(text.find(kind) + kind.size(), "local_steps = true\n");
  const Scenario local = load(dir / "local", text);
  ASSERT_TRUE(local.model.localSteps);
  auto a = runScenario(one, cpuOptions(dir / "one" / "run"));
  auto b = runScenario(local, cpuOptions(dir / "local" / "run"));
  auto c = runScenario(fine, cpuOptions(dir / "fine" / "run"));
  ASSERT_TRUE(a && b && c) << (!a ? a.message() : !b ? b.message() : c.message());

  auto d = buildDomain(local);
  ASSERT_TRUE(d) << d.message();
  auto depth = gis::readDem((dir / "local" / "run" / "maps" / "final_depth.tif").string(), allowEmpty());
  ASSERT_TRUE(depth) << depth.message();
  const int faceX = d->sections[0].faces.front().x;
  double west = 0;
  for (int y = 0; y < depth->georef.height; ++y) {
    for (int x = 0; x < faceX; ++x) {
      const double h = depth->values.at(x, y);
      if (std::isfinite(h)) west += h * d->input.rowDxM[size_t(y)] * d->input.dyM;
    }
  }
  std::printf("local steps: west of the section %.0f m^3, the section %.0f m^3 (one step for the grid: %.0f m^3)\n",
              west, b->sections[0].volumeM3, a->sections[0].volumeM3);
  EXPECT_GT(west, 1e7);
  EXPECT_NEAR(b->sections[0].volumeM3, west, 1e-5 * d->damBreakVolumeM3);
  EXPECT_NE(slurp(dir / "local" / "run" / "report.md").find("local time steps"), std::string::npos);

  auto mapOf = [&](const char* run) {
    auto m = gis::readDem((dir / run / "run" / "maps" / "max_depth.tif").string(), allowEmpty());
    EXPECT_TRUE(m) << m.message();
    return m ? m->values : gis::Grid<float>();
  };
  const auto mapA = mapOf("one"), mapB = mapOf("local"), mapC = mapOf("fine");
  ASSERT_EQ(mapA.data.size(), mapB.data.size());
  ASSERT_EQ(mapA.data.size(), mapC.data.size());
  auto wet = [](float v) { return std::isfinite(v) && v > 0.1f; };
  auto deep = [&](float v) { return wet(v) ? double(v) : 0.0; };
  long long both = 0, either = 0, wetCells = 0;
  double timeError = 0, localError = 0, timeMean = 0, localMean = 0;
  for (size_t i = 0; i < mapA.data.size(); ++i) {
    both += wet(mapA.data[i]) && wet(mapB.data[i]);
    either += wet(mapA.data[i]) || wet(mapB.data[i]);
    const double ea = std::abs(deep(mapA.data[i]) - deep(mapC.data[i]));
    const double eb = std::abs(deep(mapB.data[i]) - deep(mapC.data[i]));
    timeError = std::max(timeError, ea);
    localError = std::max(localError, eb);
    if (wet(mapC.data[i])) timeMean += ea, localMean += eb, ++wetCells;
  }
  const double fit = double(both) / double(either);
  std::printf(
      "local steps: flooded cells F = %.4f (%lld of %lld); max depths from 1 s steps' worst %.3f m, mean %.3f m (one "
      "step for the grid: %.3f, %.3f m); gauge peak %.3f m (one step %.3f m, 1 s steps %.3f m)\n",
      fit, both, either, localError, localMean / double(wetCells), timeError, timeMean / double(wetCells),
      b->gauges[0].peak, a->gauges[0].peak, c->gauges[0].peak);
  EXPECT_GT(fit, 0.98);
  EXPECT_LT(localError, timeError);
  EXPECT_LT(localMean, timeMean);
}

TEST(ScenarioProbes, BadProbesAreRefusedNamingTheKey) {
  const auto dir = strata::test::tempDir("probes-bad");
  auto refused = [&](const std::string& text) {
    std::ofstream(dir / "bad.toml") << text;
    auto s = loadScenario(dir / "bad.toml");
    if (!s) return s.message();
    auto d = buildDomain(*s);
    return d ? std::string("accepted") : d.message();
  };
  const std::string file = (dir / "bad.toml").string();
  EXPECT_EQ(refused(damBreakText("[[outputs.section]]\nline_lonlat = [[-112.1, 36.1]]\n")),
            file + ":20: key 'outputs.section[0].line_lonlat': a line needs at least 2 points");
  EXPECT_EQ(refused(damBreakText("[[outputs.gauge]]\nname = \"g\"\n")),
            file + ":19: key 'outputs.gauge[0]': missing at_lonlat or at_xy");
  EXPECT_EQ(refused(damBreakText("[[outputs.gauge]]\nat_lonlat = [-111.5, 36.1]\n")),
            file + ":20: key 'outputs.gauge[0].at_lonlat': the gauge \"gauge 1\" is outside the region");
  EXPECT_EQ(refused(damBreakText("[[outputs.gauge]]\nat_lonlat = [-112.1, 36.1]\nheight = 3\n")),
            file + ":21: key 'outputs.gauge[0].height': unknown key (expected one of: name, at_lonlat, at_xy)");
  std::string fine = damBreakText(kProbes);
  fine.replace(fine.find("probe_interval = \"1 min\""), 24, "probe_interval = 0.001");
  EXPECT_NE(refused(fine).find("key 'outputs.probe_interval': more than a million rows over the duration (1200000"),
            std::string::npos)
      << refused(fine);
  std::string pipe = damBreakText(kProbes);
  pipe.replace(pipe.find("kind = \"flood\""), 14, "kind = \"pipe\"");
  EXPECT_NE(refused(pipe).find("key 'outputs.section': sections need the flood model's face fluxes"), std::string::npos)
      << refused(pipe);
}

}  // namespace
}  // namespace strata::scenario
