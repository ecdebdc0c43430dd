#include <gtest/gtest.h>

#include <strata/terrain/scenario.hpp>

namespace strata::terrain {
namespace {

// A complete, valid scenario; the bad-input tests change one thing each.
constexpr const char* kGood = R"(name = "canyon flood"
[terrain]
dem = "dem.tif"
[[terrain.layer]]
material = "sand"
thickness = "2 m"
[region]
bbox_lonlat = [-112.9, 36.0, -112.1, 36.5]
[model]
kind = "flood"
manning_n = 0.035
boundary = { west = "closed", east = "open" }
[[water.inflow]]
name = "Colorado River"
at_lonlat = [-112.2, 36.2]
hydrograph = [[0, 0], [1, 5000], [3, 5000], [4, 0]]
hydrograph_units = ["h", "m3/s"]
[water.rain]
rate = "12 mm/h"
end = "2 h"
[time]
duration = "6 h"
output_interval = "30 min"
)";

Result<Scenario> parse(const std::string& text) { return parseScenario(text, "/data/runs/gc.toml"); }

std::string replaced(std::string text, const std::string& from, const std::string& to) {
  const auto at = text.find(from);
  EXPECT_NE(at, std::string::npos) << from;
  return text.replace(at, from.size(), to);
}

TEST(Scenario, ReadsAValidFileWithUnits) {
  auto s = parse(kGood);
  ASSERT_TRUE(s) << s.message();
  EXPECT_EQ(s->name, "canyon flood");
  EXPECT_EQ(s->terrain.dems, (std::vector<std::string>{"/data/runs/dem.tif"}));  // relative to the file
  ASSERT_EQ(s->terrain.layers.size(), 1u);
  EXPECT_DOUBLE_EQ(s->terrain.layers[0].thicknessM, 2.0);
  EXPECT_EQ(s->region.kind, decltype(s->region)::BBox);
  EXPECT_EQ(s->region.place.points[1][0], -112.1);
  EXPECT_EQ(s->model.boundaries[0], Boundary::Closed);
  EXPECT_EQ(s->model.boundaries[1], Boundary::Open);
  ASSERT_EQ(s->water.inflows.size(), 1u);
  const auto& h = s->water.inflows[0].hydrograph;
  EXPECT_DOUBLE_EQ(h.at(1800), 2500.0);
  // Volume: ramp up (0.5 h at mean 2500) + 2 h at 5000 + ramp down: 5000 m3/s * 3 h * 3600 s/h.
  EXPECT_DOUBLE_EQ(h.volume(0, 4 * 3600), 5000.0 * 3 * 3600);
  EXPECT_DOUBLE_EQ(h.volume(0, 3600), 2500.0 * 3600);
  EXPECT_DOUBLE_EQ(s->water.rain->rateMPerS, 0.012 / 3600);
  EXPECT_DOUBLE_EQ(s->water.rain->endS, 7200);
  EXPECT_DOUBLE_EQ(s->durationS, 21600);
  EXPECT_DOUBLE_EQ(s->outputIntervalS, 1800);
}

TEST(Scenario, Quantities) {
  EXPECT_DOUBLE_EQ(*parseQuantity("6 h", "time"), 21600);
  EXPECT_DOUBLE_EQ(*parseQuantity("2.5km", "length"), 2500);
  EXPECT_DOUBLE_EQ(*parseQuantity(" 36 mm/h ", "rate"), 1e-5);
  EXPECT_EQ(parseQuantity("6 parsecs", "time").message(), "unknown unit 'parsecs' (use one of s, min, h, d)");
  EXPECT_EQ(parseQuantity("6 m", "time").message(), "unit 'm' is a length, not a time (use one of s, min, h, d)");
  EXPECT_EQ(parseQuantity("6", "time").message(), "\"6\" has no unit (use one of s, min, h, d)");
  EXPECT_EQ(parseQuantity("fast", "speed").message(), "\"fast\" does not start with a number");
}

struct BadCase {
  const char* what;
  std::string from, to;
  std::string message;
};

void PrintTo(const BadCase& c, std::ostream* os) { *os << c.what; }

class ScenarioBadInput : public ::testing::TestWithParam<BadCase> {};

TEST_P(ScenarioBadInput, IsRefusedWithLineAndKey) {
  const auto& c = GetParam();
  auto s = parse(replaced(kGood, c.from, c.to));
  ASSERT_FALSE(s) << c.what;
  EXPECT_EQ(s.message(), c.message) << c.what;
}

INSTANTIATE_TEST_SUITE_P(
    Cases, ScenarioBadInput,
    ::testing::Values(
        BadCase{"unknown key", "duration = \"6 h\"", "duraton = \"6 h\"",
                "/data/runs/gc.toml:22: key 'time.duraton': unknown key (expected one of: duration, output_interval)"},
        BadCase{
            "wrong unit", "duration = \"6 h\"", "duration = \"6 m\"",
            "/data/runs/gc.toml:22: key 'time.duration': unit 'm' is a length, not a time (use one of s, min, h, d)"},
        BadCase{"negative duration", "duration = \"6 h\"", "duration = \"-6 h\"",
                "/data/runs/gc.toml:22: key 'time.duration': must be positive"},
        BadCase{"interval longer than the run", "output_interval = \"30 min\"", "output_interval = \"7 h\"",
                "/data/runs/gc.toml:23: key 'time.output_interval': longer than the duration"},
        BadCase{"unknown model", "kind = \"flood\"", "kind = \"lake\"",
                "/data/runs/gc.toml:10: key 'model.kind': expected \"flood\" or \"pipe\", got \"lake\""},
        BadCase{"hydrograph time going back", "[3, 5000], [4, 0]", "[3, 5000], [2, 0]",
                "/data/runs/gc.toml:16: key 'water.inflow[0].hydrograph': times must increase strictly"},
        BadCase{"negative discharge", "[4, 0]]", "[4, -1]]",
                "/data/runs/gc.toml:16: key 'water.inflow[0].hydrograph': negative discharge -1.000000 m3/s"},
        BadCase{"latitude out of range", "at_lonlat = [-112.2, 36.2]", "at_lonlat = [-112.2, 96.2]",
                "/data/runs/gc.toml:15: key 'water.inflow[0].at_lonlat': longitude/latitude out of range: "
                "[-112.200000, 96.200000]"},
        BadCase{"inverted bbox", "[-112.9, 36.0, -112.1, 36.5]", "[-112.1, 36.0, -112.9, 36.5]",
                "/data/runs/gc.toml:8: key 'region.bbox_lonlat': west must be < east and south < north"},
        BadCase{"rain ends before it starts", "end = \"2 h\"", "start = \"3 h\"\nend = \"2 h\"",
                "/data/runs/gc.toml:21: key 'water.rain.end': must be after start"},
        BadCase{"negative thickness", "thickness = \"2 m\"", "thickness = \"-2 m\"",
                "/data/runs/gc.toml:6: key 'terrain.layer[0].thickness': negative thickness"},
        BadCase{"TOML syntax error", "manning_n = 0.035", "manning_n = = 0.035",
                "/data/runs/gc.toml:11: Error while parsing value: could not determine value type"},
        BadCase{"terrain change without erosion", "[time]", "[outputs]\nmaps = [\"terrain_change\"]\n[time]",
                "/data/runs/gc.toml: outputs.maps asks for terrain_change but erosion is not enabled"}));

TEST(Scenario, NeedsASource) {
  std::string text = kGood;
  text = text.substr(0, text.find("[[water.inflow]]")) + text.substr(text.find("[time]"));
  auto s = parse(text);
  ASSERT_FALSE(s);
  EXPECT_EQ(s.message(), "/data/runs/gc.toml: [water] has no source: add an inflow, rain, a dam_break or a level");
}

TEST(Scenario, MissingFile) {
  auto s = loadScenario("/nonexistent/flood.toml");
  ASSERT_FALSE(s);
  EXPECT_EQ(s.message(), "/nonexistent/flood.toml: no such scenario file");
}

}  // namespace
}  // namespace strata::terrain
