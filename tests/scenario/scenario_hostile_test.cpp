// Issue 19: what a hostile (or careless) user can feed a scenario. Every numeric key of the
// format gets NaN, inf, -inf, 0, a negative number and 1e30; each case is refused with the file,
// the line and the key, or means what docs/scenario.md says it means and runs to the end: no
// abort, no hang, no NaN in the results. Then the derived sizes: the interval count, a grid too
// large for the memory (refused at once) or too small, a dam that holds no water, erosion with
// nothing loose to erode.
#include <gtest/gtest.h>

#include <chrono>
#include <cmath>
#include <fstream>
#include <optional>
#include <regex>
#include <string>
#include <thread>
#include <vector>

#include <strata/core/interrupt.hpp>
#include <strata/scenario/domain.hpp>
#include <strata/scenario/run.hpp>

#include "scenario_fixture.hpp"
#include "strata_test.hpp"

namespace strata::scenario {
namespace {

using namespace test_support;

// A line of the scenario: its key, and the numbers on it ({} in the text, their usual values).
struct Line {
  std::string key;   // empty: no number on this line
  std::string text;  // with "{}" for each number
  std::vector<std::string> values;
  std::string tag;  // what expectations match on
};

// The scenario as lines. A 24 x 18 km piece of the Grand Canyon at 600 m cells, with every kind
// of source, erosion on a sand layer, two minutes.
struct HostileScenario {
  std::vector<Line> lines;

  HostileScenario() {
    auto text = [&](const std::string& l) { lines.push_back({"", l, {}, ""}); };
    auto line = [&](const std::string& key, const std::string& l, std::vector<std::string> v,
                    const std::string& tag = "") {
      lines.push_back({key, l, std::move(v), tag.empty() ? key : tag});
    };
    text("name = \"hostile\"");
    text("[terrain]");
    text("dem = \"" + strata::test::dataPath("grand_canyon/grand_canyon_512.tif") + "\"");
    text("[[terrain.layer]]");
    text("material = \"sand\"");
    line("terrain.layer[0].thickness", "thickness = {}", {"1"});
    text("[region]");
    line("region.bbox_lonlat", "bbox_lonlat = [{}, {}, {}, {}]", {"-112.25", "36.02", "-112.001", "36.18"});
    line("region.cell_size", "cell_size = {}", {"600"});
    text("[model]");
    text("kind = \"flood\"");
    line("model.manning_n", "manning_n = {}", {"0.04"});
    line("model.cfl", "cfl = {}", {"0.45"});
    line("model.max_step", "max_step = {}", {"30"});
    text("boundary = { west = \"open\", east = \"closed\", south = \"open\", north = \"open\" }");
    text("[erosion]");
    text("enabled = true");
    text("law = \"force-based\"");
    line("erosion.capacity", "capacity = {}", {"0.05"});
    line("erosion.erosion_rate", "erosion_rate = {}", {"0.01"});
    line("erosion.deposition_rate", "deposition_rate = {}", {"0.01"});
    text("[materials.sand]");
    line("materials.sand.critical_shear", "critical_shear = {}", {"0.25"});
    line("materials.sand.settling_velocity", "settling_velocity = {}", {"0.07"});
    line("materials.sand.friction_angle", "friction_angle = {}", {"30"});
    line("materials.sand.dissolution_rate", "dissolution_rate = {}", {"0"});
    text("[water]");
    line("water.evaporation", "evaporation = {}", {"2e-8"});
    text("[[water.inflow]]");
    text("name = \"Colorado\"");
    line("water.inflow[0].line_lonlat", "line_lonlat = [[{}, {}], [-112.0225, 36.08]]", {"-112.0225", "36.063"});
    line("water.inflow[0].hydrograph", "hydrograph = [[0, 0], [{}, {}], [{}, 2000]]", {"60", "2000", "120"}, "curve");
    text("[water.rain]");
    line("water.rain.rate", "rate = {}", {"3e-6"});
    line("water.rain.start", "start = {}", {"0"});
    line("water.rain.end", "end = {}", {"60"});
    text("[[water.dam_break]]");
    line("water.dam_break[0].polygon_lonlat",
         "polygon_lonlat = [[{}, {}], [-112.08, 36.08], [-112.08, 36.12], [-112.12, 36.12]]", {"-112.12", "36.08"},
         "dam polygon");
    line("water.dam_break[0].surface", "surface = {}", {"800"});
    text("[[water.level]]");
    text("name = \"stage\"");
    line("water.level[0].line_lonlat", "line_lonlat = [[{}, {}], [-112.03, 36.08]]", {"-112.03", "36.063"});
    line("water.level[0].stage", "stage = [[0, 850], [{}, {}], [{}, 840]]", {"60", "850", "120"}, "curve");
    text("[time]");
    line("time.duration", "duration = {}", {"120"});
    line("time.output_interval", "output_interval = {}", {"60"});
    line("time.spin_up", "spin_up = {}", {"0"});  // 0: a spin-up would be refused with the dam break
    text("[outputs]");
    line("outputs.wet_threshold", "wet_threshold = {}", {"0.1"});
    text("pictures = false");
    text("plots = false");
  }

  // The text with number `pos` of line `which` (-1: none) replaced by `value`.
  std::string text(int which = -1, size_t pos = 0, const std::string& value = "") const {
    std::string out;
    for (size_t i = 0; i < lines.size(); ++i) {
      std::string l = lines[i].text;
      for (size_t k = 0; k < lines[i].values.size(); ++k) {
        l.replace(l.find("{}"), 2, int(i) == which && k == pos ? value : lines[i].values[k]);
      }
      out += l + "\n";
    }
    return out;
  }
  int lineOf(const std::string& key) const {
    for (size_t i = 0; i < lines.size(); ++i) {
      if (lines[i].key == key || lines[i].text == key) return int(i);
    }
    return -1;
  }
};

// What a case must get: refused naming `key` on that key's line (the slot's own unless given),
// or accepted with the meaning docs/scenario.md gives it.
struct Expectation {
  bool accepted = false;
  std::string refusingKey;  // empty: the slot's own key
  const char* meaning = "";
};

// Which (line, number, value) are accepted, and what they mean; everything else is refused.
std::optional<Expectation> expectationFor(const Line& line, size_t pos, const std::string& value) {
  const std::string& k = line.tag;
  if (value == "0") {
    if (k == "model.manning_n") return Expectation{true, "", "no friction"};
    if (k == "erosion.capacity" || k == "erosion.erosion_rate" || k == "erosion.deposition_rate" ||
        k == "materials.sand.dissolution_rate") {
      return Expectation{true, "", "that process is off"};
    }
    if (k == "materials.sand.critical_shear") return Expectation{true, "", "any flow entrains sand"};
    if (k == "materials.sand.settling_velocity") return Expectation{true, "", "the load never settles"};
    if (k == "water.evaporation") return Expectation{true, "", "no evaporation"};
    if (k == "water.rain.rate") return Expectation{true, "", "no rain"};
    if (k == "water.rain.start") return Expectation{true, "", "rain from the start"};
    if (k == "time.spin_up") return Expectation{true, "", "no spin-up"};
    if (k == "curve" && pos == 1) return Expectation{true, "", "a sample of 0"};
    if (k == "dam polygon")
      return Expectation{true, "", "a polygon reaching outside the region: its cells inside fill"};
    if (k == "terrain.layer[0].thickness") return Expectation{false, "terrain", "erosion with nothing loose to erode"};
  }
  if (value == "-1") {
    if (k == "curve" && pos == 1 && line.key == "water.level[0].stage") {
      return Expectation{true, "", "a stage 1 m below the datum"};
    }
    if (k == "dam polygon")
      return Expectation{true, "", "a polygon reaching outside the region: its cells inside fill"};
  }
  if (value == "1e30") {
    if (k == "curve" && pos == 2) return Expectation{true, "", "the curve's last sample lies far beyond the run"};
    if (k == "water.rain.end") return Expectation{true, "", "rain until the run ends"};
  }
  return std::nullopt;
}

struct Outcome {
  bool refused = false;
  std::string message;
  bool completed = false;
  bool finite = true;
  double seconds = 0;
};

// Parses, builds and runs (CPU, no pictures or plots) with a watchdog: a run still going after
// 60 s is interrupted and reported as not completed.
Outcome attempt(const std::string& text, const std::filesystem::path& dir) {
  Outcome o;
  const auto start = std::chrono::steady_clock::now();
  const auto file = dir / "hostile.toml";
  std::ofstream(file) << text;
  auto s = loadScenario(file);
  if (!s) {
    o.refused = true;
    o.message = s.message();
    return o;
  }
  RunOptions opt;
  opt.outDir = dir / "run";
  opt.backend = Backend::kCpu;
  opt.pictures = false;
  opt.plots = false;
  opt.overwrite = true;
  setInterrupted(false);
  std::atomic<bool> done{false};
  std::thread watchdog([&] {
    for (int i = 0; i < 600 && !done; ++i) std::this_thread::sleep_for(std::chrono::milliseconds(100));
    if (!done) setInterrupted(true);
  });
  auto run = runScenario(*s, opt);
  done = true;
  watchdog.join();
  setInterrupted(false);
  o.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  if (!run) {
    o.refused = true;
    o.message = run.message();
    return o;
  }
  o.completed = run->completed;
  for (const auto& r : run->series) {
    for (double v : {r.waterM3, r.inflowM3, r.rainM3, r.outflowM3, r.balanceErrorRel, r.maxDepthM, r.erodedM3}) {
      o.finite = o.finite && std::isfinite(v);
    }
  }
  return o;
}

TEST(ScenarioHostile, TheBaseScenarioRunsWithEverySource) {
  const auto dir = strata::test::tempDir("hostile-base");
  const HostileScenario sc;
  const auto o = attempt(sc.text(), dir);
  ASSERT_FALSE(o.refused) << o.message;
  EXPECT_TRUE(o.completed);
  EXPECT_TRUE(o.finite);
}

// The table: every numeric key (and each number of its pairs) x {nan, inf, -inf, 0, -1, 1e30}.
TEST(ScenarioHostile, EveryNumberNonFiniteZeroNegativeOrHuge) {
  const auto dir = strata::test::tempDir("hostile-table");
  const HostileScenario sc;
  const std::vector<std::string> values{"nan", "inf", "-inf", "0", "-1", "1e30"};
  int cases = 0, accepted = 0;
  for (size_t i = 0; i < sc.lines.size(); ++i) {
    const Line& line = sc.lines[i];
    for (size_t pos = 0; pos < line.values.size(); ++pos) {
      for (const auto& v : values) {
        ++cases;
        const std::string what = line.key + " (line " + std::to_string(i + 1) + ": " + line.text + ", number " +
                                 std::to_string(pos) + ") = " + v;
        const auto expected = expectationFor(line, pos, v);
        const auto o = attempt(sc.text(int(i), pos, v), dir);
        EXPECT_LT(o.seconds, 30) << what;
        if (expected && expected->accepted) {
          ++accepted;
          EXPECT_FALSE(o.refused) << what << " should mean: " << expected->meaning << "; got " << o.message;
          EXPECT_TRUE(o.refused || o.completed) << what << ": did not finish";
          EXPECT_TRUE(o.finite) << what << ": non-finite results";
          continue;
        }
        EXPECT_TRUE(o.refused) << what << " was accepted";
        if (!o.refused) continue;
        const std::string key = expected && !expected->refusingKey.empty() ? expected->refusingKey : line.key;
        const int at = key == line.key ? int(i) + 1 : sc.lineOf("[" + key + "]") + 1;
        const std::string prefix = (dir / "hostile.toml").string() + ":" + std::to_string(at) + ": key '" + key + "': ";
        EXPECT_EQ(o.message.substr(0, prefix.size()), prefix) << what << ": " << o.message;
        EXPECT_EQ(o.message.find('\n'), std::string::npos) << what << ": one line: " << o.message;
        for (const char* internal : {"cflAlpha", "maxDtS", "manningN", "sim params", "STRATA_CHECK"}) {
          EXPECT_EQ(o.message.find(internal), std::string::npos) << what << ": " << o.message;
        }
      }
    }
  }
  EXPECT_EQ(cases, 37 * 6);
  EXPECT_EQ(accepted, 21);
}

// Quantities with units go through the same checks.
TEST(ScenarioHostile, QuantitiesWithUnitsAreCheckedToo) {
  const HostileScenario sc;
  auto slotOf = [&](const std::string& key) { return sc.lineOf(key); };
  const std::string file = "/runs/h.toml";
  auto message = [&](const std::string& key, const std::string& value) {
    auto s = parseScenario(sc.text(slotOf(key), 0, value), file);
    return s ? std::string("accepted") : s.message();
  };
  auto at = [&](const std::string& key) {
    return file + ":" + std::to_string(slotOf(key) + 1) + ": key '" + key + "': ";
  };
  EXPECT_EQ(message("water.rain.rate", "\"nan mm/h\""),
            at("water.rain.rate") + "\"nan mm/h\" does not start with a number");
  EXPECT_EQ(message("model.max_step", "\"inf s\""), at("model.max_step") + "\"inf s\" does not start with a number");
  EXPECT_EQ(message("time.duration", "\"1e308 d\""), at("time.duration") + "\"1e308 d\" is too large");
  EXPECT_EQ(message("time.duration", "\"1e9 h\""), at("time.duration") + "must be at most 3650 d");
  EXPECT_EQ(message("water.dam_break[0].surface", "\"1e30 m\""),
            at("water.dam_break[0].surface") + "must be at most 100 km");
  EXPECT_EQ(message("water.evaporation", "inf"), at("water.evaporation") + "not a finite number (inf)");
  EXPECT_EQ(message("outputs.wet_threshold", "nan"), at("outputs.wet_threshold") + "not a finite number (nan)");
  EXPECT_EQ(message("model.manning_n", "nan"), at("model.manning_n") + "not a finite number (nan)");
  EXPECT_EQ(message("region.cell_size", "nan"), at("region.cell_size") + "not a finite number (nan)");
  EXPECT_EQ(message("water.inflow[0].hydrograph", "inf").substr(0, at("water.inflow[0].hydrograph").size()),
            at("water.inflow[0].hydrograph"));
  // The overflow: 1e9 h in steps of 1e-9 s. Within the duration's range, the interval
  // count still is bounded.
  auto s = parseScenario(sc.text(slotOf("time.output_interval"), 0, "\"1e-9 s\""), file);
  ASSERT_FALSE(s);
  EXPECT_EQ(s.message(),
            at("time.output_interval") + "gives 1.2e+11 output intervals over the duration (at most 100000)");
}

// The demo's region (scenarios/grand_canyon_flood.toml) with a cell size.
std::string demoRegion(const std::string& cellSize, const std::string& extra = "") {
  return "[terrain]\ndem = \"" + strata::test::dataPath("grand_canyon/grand_canyon_512.tif") + "\"\n" + extra +
         "[region]\nbbox_lonlat = [-112.75, 36.01, -112.001, 36.45]\ncell_size = " + cellSize +
         "\n[[water.inflow]]\nline_lonlat = [[-112.0225, 36.063], [-112.0225, 36.080]]\n"
         "hydrograph = [[0, 0], [1800, 5000]]\n[time]\nduration = \"1 min\"\n";
}

// Issue 19: 4.3 m cells on the demo's region asked for 220 million cells (179 million square ones); after 2 min 45 s
// and 7.8 GB the run died of std::bad_alloc. The grid is planned before anything is read.
TEST(ScenarioHostile, OversizedRegionIsRefusedAtOnceNamingTheKeyAndTheSize) {
  auto s = parseScenario(demoRegion("\"4.3 m\""), "/runs/demo.toml");
  ASSERT_TRUE(s) << s.message();
  for (const uint64_t budget : {uint64_t(8) << 30, uint64_t(0)}) {  // 8 GiB, then what this machine has
    const auto start = std::chrono::steady_clock::now();
    auto d = buildDomain(*s, budget);
    const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    ASSERT_FALSE(d);
    EXPECT_LT(seconds, 1.0);
    EXPECT_TRUE(std::regex_match(d.message(),
                                 std::regex("/runs/demo.toml:5: key 'region.cell_size': 4.3 m cells: 15680 x 11391 = "
                                            "178.6 million cells need about [0-9]+.[0-9] GB of memory, and "
                                            "[0-9.]+ GB are available \\(use larger cells or a smaller region\\)")))
        << d.message();
  }
  // The same through runScenario, with nothing written.
  const auto dir = strata::test::tempDir("oversized");
  std::ofstream(dir / "demo.toml") << demoRegion("\"4.3 m\"");
  auto file = loadScenario(dir / "demo.toml");
  ASSERT_TRUE(file) << file.message();
  RunOptions opt;
  opt.outDir = dir / "run";
  opt.backend = Backend::kCpu;
  opt.memoryBudgetBytes = uint64_t(8) << 30;
  const auto start = std::chrono::steady_clock::now();
  auto run = runScenario(*file, opt);
  EXPECT_LT(std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count(), 1.0);
  ASSERT_FALSE(run);
  EXPECT_NE(run.message().find("key 'region.cell_size': 4.3 m cells"), std::string::npos) << run.message();
  EXPECT_FALSE(std::filesystem::exists(opt.outDir));
}

// 1e6 km cells gave 4 x 4 cells silently.
TEST(ScenarioHostile, CellsLargerThanTheRegionAreRefused) {
  auto s = parseScenario(demoRegion("\"1e6 km\""), "/runs/demo.toml");
  ASSERT_TRUE(s) << s.message();
  auto d = buildDomain(*s);
  ASSERT_FALSE(d);
  EXPECT_EQ(d.message(),
            "/runs/demo.toml:5: key 'region.cell_size': 1e+09 m cells give 0 x 0 cells over the region (67.43 x "
            "48.98 km); at least 4 x 4 are needed");
  // Just enough: 12 km (the native cells' north-south size, times the scale on both axes).
  s = parseScenario(demoRegion("\"12 km\""), "/runs/demo.toml");
  ASSERT_TRUE(s) << s.message();
  d = buildDomain(*s);
  ASSERT_TRUE(d) << d.message();
  EXPECT_EQ(d->bed.georef.width, 6);
  EXPECT_EQ(d->bed.georef.height, 4);
}

// `strata erode` (erosion on) over bare bedrock eroded 0 m3 without a word: refused.
TEST(ScenarioHostile, ErosionWithNothingLooseToErodeIsRefused) {
  auto s = parseScenario(demoRegion("\"2 km\"", ""), "/runs/demo.toml");
  ASSERT_TRUE(s) << s.message();
  s->erosion.enabled = true;  // what `strata erode` does
  auto d = buildDomain(*s);
  ASSERT_FALSE(d);
  EXPECT_EQ(d.message(),
            "/runs/demo.toml:1: key 'terrain': erosion needs loose material, and the terrain has none over the region "
            "(add a [[terrain.layer]] with a material and a thickness, docs/scenario.md)");
  // A layer of no thickness is no better; one of some is.
  s = parseScenario(demoRegion("\"2 km\"", "[[terrain.layer]]\nmaterial = \"sand\"\nthickness = 0\n"), "/runs/d.toml");
  ASSERT_TRUE(s) << s.message();
  s->erosion.enabled = true;
  EXPECT_FALSE(buildDomain(*s));
  s = parseScenario(demoRegion("\"2 km\"", "[[terrain.layer]]\nmaterial = \"sand\"\nthickness = \"1 cm\"\n"),
                    "/runs/d.toml");
  ASSERT_TRUE(s) << s.message();
  s->erosion.enabled = true;
  EXPECT_TRUE(buildDomain(*s));
}

// Ctrl-C is polled after every step: on a grid whose intervals take seconds, the run returns
// within a second of the flag (the issue asked for within a second during a step loop).
TEST(ScenarioHostile, InterruptIsHonouredWithinASecond) {
  const auto dir = strata::test::tempDir("interrupt");
  std::string text = scenarioText();
  auto edit = [&](const std::string& from, const std::string& to) { text.replace(text.find(from), from.size(), to); };
  edit("cell_size = \"600 m\"", "cell_size = \"100 m\"");  // ~250 x 200 square cells
  edit("duration = \"20 min\"", "duration = \"20 h\"");
  edit("output_interval = \"5 min\"", "output_interval = \"10 h\"");
  std::ofstream(dir / "big.toml") << text;
  auto s = loadScenario(dir / "big.toml");
  ASSERT_TRUE(s) << s.message();
  RunOptions opt;
  opt.outDir = dir / "run";
  opt.backend = Backend::kCpu;
  opt.pictures = false;
  opt.plots = false;
  setInterrupted(false);
  std::chrono::steady_clock::time_point raised;
  std::thread ctrlC([&] {
    std::this_thread::sleep_for(std::chrono::seconds(2));
    raised = std::chrono::steady_clock::now();
    setInterrupted(true);
  });
  auto run = runScenario(*s, opt);
  const auto returned = std::chrono::steady_clock::now();
  ctrlC.join();
  setInterrupted(false);
  ASSERT_TRUE(run) << run.message();
  EXPECT_FALSE(run->completed);
  EXPECT_TRUE(run->series.empty()) << "the first 10 h interval should not have finished in 2 s";
  EXPECT_GT(run->steps, 0);
  const double seconds = std::chrono::duration<double>(returned - raised).count();
  EXPECT_LT(seconds, 1.0);
  std::printf("returned %.3f s after the interrupt, %lld steps done\n", seconds, run->steps);
}

}  // namespace
}  // namespace strata::scenario
