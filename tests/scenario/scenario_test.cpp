#include <gtest/gtest.h>

#include <strata/scenario/report.hpp>
#include <strata/scenario/scenario.hpp>

namespace strata::scenario {
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
  EXPECT_DOUBLE_EQ(h.integral(0, 4 * 3600), 5000.0 * 3 * 3600);
  EXPECT_DOUBLE_EQ(h.integral(0, 3600), 2500.0 * 3600);
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
                "/data/runs/gc.toml:22: key 'time.duraton': unknown key (expected one of: duration, output_interval, "
                "spin_up, spin_up_tolerance); did you mean 'duration'?"},
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
        BadCase{"unknown slope limiter", "manning_n = 0.035", "manning_n = 0.035\nslopes = \"superbee\"",
                "/data/runs/gc.toml:12: key 'model.slopes': expected \"minmod\" or \"mc\", got \"superbee\""},
        BadCase{"unknown flood scheme", "manning_n = 0.035", "manning_n = 0.035\nscheme = \"diffusive\"",
                "/data/runs/gc.toml:12: key 'model.scheme': expected \"finite_volume\" or \"inertial\", got "
                "\"diffusive\""},
        BadCase{"a scheme for the pipe model", "kind = \"flood\"", "kind = \"pipe\"\nscheme = \"inertial\"",
                "/data/runs/gc.toml:11: key 'model.scheme': is flood mode's choice; kind = \"pipe\" has no scheme"},
        BadCase{"local steps with finite volumes", "manning_n = 0.035", "manning_n = 0.035\nlocal_steps = true",
                "/data/runs/gc.toml:12: key 'model.local_steps': local time steps need scheme = \"inertial\""},
        BadCase{"local steps on the GPU", "manning_n = 0.035",
                "manning_n = 0.035\nscheme = \"inertial\"\nbackend = \"gpu\"\nlocal_steps = true",
                "/data/runs/gc.toml:14: key 'model.local_steps': local time steps run on the CPU backend; backend = "
                "\"gpu\" takes one step for the whole grid"},
        BadCase{"finite volumes above CFL 0.5", "manning_n = 0.035", "manning_n = 0.035\ncfl = 0.7",
                "/data/runs/gc.toml:12: key 'model.cfl': flood mode needs cfl <= 0.5 (positivity of the "
                "finite-volume scheme)"},
        BadCase{"terrain change without erosion", "[time]", "[outputs]\nmaps = [\"terrain_change\"]\n[time]",
                "/data/runs/gc.toml: outputs.maps asks for terrain_change but erosion is not enabled"},
        BadCase{"unknown erosion law", "[time]", "[erosion]\nlaw = \"stream power\"\n[time]",
                "/data/runs/gc.toml:22: key 'erosion.law': \"stream power\" is not \"shear\" or \"force-based\""},
        BadCase{"force-based constants with the shear law", "[time]", "[erosion]\ncapacity = 0.05\n[time]",
                "/data/runs/gc.toml:22: key 'erosion.capacity': belongs to law = \"force-based\"; the shear-stress "
                "law takes its constants from the materials ([materials.NAME], docs/scenario.md)"},
        BadCase{"dissolution is a material's", "[time]", "[erosion]\ndissolution_rate = 1e-6\n[time]",
                "/data/runs/gc.toml:22: key 'erosion.dissolution_rate': dissolution is a material's constant: set "
                "dissolution_rate in [materials.NAME] (docs/scenario.md)"},
        BadCase{"a stress in metres", "[time]", "[materials.sand]\ncritical_shear = \"2 m\"\n[time]",
                "/data/runs/gc.toml:22: key 'materials.sand.critical_shear': unit 'm' is a length, not a stress "
                "(use one of Pa, kPa, MPa)"},
        BadCase{"a friction angle of 90 degrees", "[time]", "[materials.sand]\nfriction_angle = 90\n[time]",
                "/data/runs/gc.toml:22: key 'materials.sand.friction_angle': must be at most 89.9 degrees"},
        BadCase{"an unknown material constant", "[time]", "[materials.sand]\nhardness = 3\n[time]",
                "/data/runs/gc.toml:22: key 'materials.sand.hardness': unknown key (expected one of: critical_shear, "
                "shear_erodibility, settling_velocity, friction_angle, cohesion, talus_angle, weathering_rate, "
                "dissolution_rate, erodibility)"},
        // Issue 33: a name that is not a string is refused, not read as "".
        BadCase{"a number for a name", "name = \"Colorado River\"", "name = 5",
                "/data/runs/gc.toml:14: key 'water.inflow[0].name': expected a string"}));

// Issue 31: report volumes in the unit that fits.
TEST(Report, VolumesAreWrittenInTheUnitThatFits) {
  EXPECT_EQ(volumeText(740.4), "740 m³");
  EXPECT_EQ(volumeText(9999), "9999 m³");
  EXPECT_EQ(volumeText(69300), "69.3 thousand m³");
  EXPECT_EQ(volumeText(4.24e6), "4.2 million m³");
  EXPECT_EQ(volumeText(-2.5e4), "-25.0 thousand m³");
}

// Issue 33: a UTF-8 byte-order mark (some editors write one) is skipped, not refused.
TEST(Scenario, AByteOrderMarkIsSkipped) {
  auto s = parse("\xEF\xBB\xBF" + std::string(kGood));
  ASSERT_TRUE(s) << s.message();
  EXPECT_EQ(s->water.inflows.at(0).name, "Colorado River");
}

// Issue 30: the erosion law and the materials' constants in physical units, with units.
TEST(Scenario, ReadsTheErosionLawAndMaterialConstants) {
  auto s = parse(replaced(kGood, "[time]",
                          "[erosion]\nenabled = true\n[materials.sand]\ncritical_shear = \"0.4 Pa\"\n"
                          "settling_velocity = \"50 mm/s\"\ncohesion = \"2 kPa\"\nfriction_angle = 33\n[time]"));
  ASSERT_TRUE(s) << s.message();
  EXPECT_EQ(s->erosion.law, sim::ErosionLaw::kShearStress);  // the default
  ASSERT_EQ(s->materials.size(), 1u);
  EXPECT_EQ(s->materials[0].name, "sand");
  EXPECT_DOUBLE_EQ(*s->materials[0].criticalShearPa, 0.4);
  EXPECT_DOUBLE_EQ(*s->materials[0].settlingVelocityMS, 0.05);
  EXPECT_DOUBLE_EQ(*s->materials[0].cohesionPa, 2000.0);
  EXPECT_DOUBLE_EQ(*s->materials[0].frictionAngleDeg, 33.0);
  EXPECT_FALSE(s->materials[0].shearErodibility);
  s = parse(replaced(kGood, "[time]", "[erosion]\nlaw = \"force-based\"\ncapacity = 0.1\n[time]"));
  ASSERT_TRUE(s) << s.message();
  EXPECT_EQ(s->erosion.law, sim::ErosionLaw::kForceBased);
  EXPECT_DOUBLE_EQ(s->erosion.capacity, 0.1);
}

TEST(Scenario, SlopeLimiterIsMinmodUnlessAskedForMc) {
  auto s = parse(kGood);
  ASSERT_TRUE(s) << s.message();
  EXPECT_FALSE(s->model.sharpSlopes);
  s = parse(replaced(kGood, "manning_n = 0.035", "manning_n = 0.035\nslopes = \"mc\""));
  ASSERT_TRUE(s) << s.message();
  EXPECT_TRUE(s->model.sharpSlopes);
}

TEST(Scenario, TheInertialSchemeTakesItsOwnCflUnlessGiven) {
  auto s = parse(kGood);
  ASSERT_TRUE(s) << s.message();
  EXPECT_FALSE(s->model.inertial);
  s = parse(replaced(kGood, "manning_n = 0.035", "manning_n = 0.035\nscheme = \"inertial\""));
  ASSERT_TRUE(s) << s.message();
  EXPECT_TRUE(s->model.inertial);
  EXPECT_DOUBLE_EQ(s->model.cfl, 0.7);
  EXPECT_EQ(modelParams(*s).floodScheme, sim::FloodScheme::kLocalInertial);
  s = parse(replaced(kGood, "manning_n = 0.035", "manning_n = 0.035\nscheme = \"inertial\"\ncfl = 0.9"));
  ASSERT_TRUE(s) << s.message();
  EXPECT_DOUBLE_EQ(s->model.cfl, 0.9);
  s = parse(replaced(kGood, "manning_n = 0.035", "cfl = 0.3\nscheme = \"finite_volume\""));
  ASSERT_TRUE(s) << s.message();
  EXPECT_DOUBLE_EQ(s->model.cfl, 0.3);
}

TEST(Scenario, NeedsASource) {
  std::string text = kGood;
  text = text.substr(0, text.find("[[water.inflow]]")) + text.substr(text.find("[time]"));
  auto s = parse(text);
  ASSERT_FALSE(s);
  EXPECT_EQ(s.message(), "/data/runs/gc.toml: [water] has no source: add an inflow, rain, a dam_break or a level");
}

// A fixed level on a line, its stage in hours and metres (lines 1-5 of the text).
constexpr const char* kLevel = R"([terrain]
dem = "dem.tif"
[[water.level]]
name = "lake"
line_lonlat = [[-112.2, 36.2], [-112.2, 36.3]]
stage = [[0, 700], [1, 730.5], [3, 730.5]]
stage_units = ["h", "m"]
[time]
duration = "6 h"
)";

TEST(Scenario, ReadsAFixedLevel) {
  auto s = parse(kLevel);
  ASSERT_TRUE(s) << s.message();
  ASSERT_EQ(s->water.levels.size(), 1u);
  const auto& l = s->water.levels[0];
  EXPECT_EQ(l.name, "lake");
  EXPECT_FALSE(l.polygon);
  EXPECT_EQ(l.place.points.size(), 2u);
  EXPECT_EQ(l.stageLine, 6);
  ASSERT_EQ(l.stage.samples().size(), 3u);
  EXPECT_EQ(l.stage.samples()[1][0], 3600.0);
  EXPECT_EQ(l.stage.samples()[1][1], 730.5);
  // A polygon, and the stage in centimetres (any length unit).
  auto p = parse(replaced(
      replaced(kLevel, "line_lonlat = [[-112.2, 36.2], [-112.2, 36.3]]", "polygon_xy = [[0, 0], [10, 0], [10, 10]]"),
      "[\"h\", \"m\"]", "[\"min\", \"cm\"]"));
  ASSERT_TRUE(p) << p.message();
  EXPECT_TRUE(p->water.levels[0].polygon);
  EXPECT_EQ(p->water.levels[0].place.frame, CoordFrame::DemCrs);
  EXPECT_EQ(p->water.levels[0].stage.samples()[1][0], 60.0);
  EXPECT_DOUBLE_EQ(p->water.levels[0].stage.samples()[1][1], 7.305);
}

TEST(Scenario, FixedLevelBadInput) {
  const std::pair<std::pair<const char*, const char*>, const char*> cases[] = {
      {{"[1, 730.5], [3, 730.5]", "[1, 730.5], [0.5, 730.5]"},
       "/data/runs/gc.toml:6: key 'water.level[0].stage': times must increase strictly"},
      {{"[\"h\", \"m\"]", "[\"h\", \"m3/s\"]"},
       "/data/runs/gc.toml:7: key 'water.level[0].stage_units': unit 'm3/s' is a discharge, not a length (use one "
       "of m, km, mm, cm)"},
      {{"stage = [[0, 700], [1, 730.5], [3, 730.5]]", "stage = [[0, \"700 m\"]]"},
       "/data/runs/gc.toml:6: key 'water.level[0].stage': expected a pair [time, water surface elevation] of numbers"},
      {{"stage = [[0, 700], [1, 730.5], [3, 730.5]]\n", ""},
       "/data/runs/gc.toml:3: key 'water.level[0].stage': missing (pairs [time, water surface elevation])"},
      {{"line_lonlat = [[-112.2, 36.2], [-112.2, 36.3]]", "line_lonlat = [[-112.2, 36.2]]"},
       "/data/runs/gc.toml:5: key 'water.level[0].line_lonlat': a line needs at least 2 points"},
      {{"line_lonlat = [[-112.2, 36.2], [-112.2, 36.3]]", "at_lonlat = [-112.2, 36.2]"},
       "/data/runs/gc.toml:5: key 'water.level[0].at_lonlat': unknown key (expected one of: name, line_lonlat, "
       "line_xy, polygon_lonlat, polygon_xy, stage, stage_units)"},
      {{"line_lonlat = [[-112.2, 36.2], [-112.2, 36.3]]", "name2 = 1"},
       "/data/runs/gc.toml:5: key 'water.level[0].name2': unknown key (expected one of: name, line_lonlat, line_xy, "
       "polygon_lonlat, polygon_xy, stage, stage_units)"},
  };
  for (const auto& [edit, message] : cases) {
    auto s = parse(replaced(kLevel, edit.first, edit.second));
    ASSERT_FALSE(s) << edit.second;
    EXPECT_EQ(s.message(), message) << edit.second;
  }
  // Neither a line nor a polygon.
  auto none = parse(replaced(kLevel, "line_lonlat = [[-112.2, 36.2], [-112.2, 36.3]]\n", ""));
  ASSERT_FALSE(none);
  EXPECT_EQ(none.message(),
            "/data/runs/gc.toml:3: key 'water.level[0]': missing line_lonlat / line_xy / polygon_lonlat / polygon_xy");
}

// Debian's toml++ 3.3.0 reaches __builtin_unreachable() (undefined behaviour; UBSan aborts) on
// some non-ASCII characters where it looks for whitespace (upstream issue 190: a line-ending
// backslash in a multi-line string followed by U+00A7), and fails assertions on a table header
// starting with a character a key cannot start with, a date-time with no time after its 'T' and
// a '}' where an array's value is expected (found by scripts/fuzz.sh). The
// scenario parser checks the text first: each is a one-line error with the line.
TEST(Scenario, TextTheTomlReaderMishandlesIsRefusedFirst) {
  const std::pair<std::string, std::string> cases[] = {
      {"name = \"x\"\ns = \"\"\"\\\n\xc2\xa7\"\"\"\n",
       "/data/runs/gc.toml:3: U+00A7 first after a line-ending backslash: the TOML reader (toml++ 3.3.0) cannot read "
       "it there; start the line with an ASCII character or join the lines"},
      {"s = \"\"\"a \\  \r\n\n   \xe3\x81\x82\"\"\"\n",
       "/data/runs/gc.toml:3: U+3042 first after a line-ending backslash: the TOML reader (toml++ 3.3.0) cannot read "
       "it there; start the line with an ASCII character or join the lines"},
      {"s = \"\"\"L\\\xc2\xa7\"\"\"\n",
       "/data/runs/gc.toml:1: U+00A7 after a backslash in a multi-line string (not an escape TOML knows)"},
      {"s = \"\"\"L\\  \xc2\xa7\"\"\"\n",
       "/data/runs/gc.toml:1: U+00A7 after a backslash in a multi-line string (not an escape TOML knows)"},
      {"[ \xc3\xa9]\n", "/data/runs/gc.toml:1: U+00E9 outside a string or a comment (TOML allows ASCII only there)"},
      {"a = 1\nb = 2 \xc2\xa7\n",
       "/data/runs/gc.toml:2: U+00A7 outside a string or a comment (TOML allows ASCII only there)"},
      {"[!]\n",
       "/data/runs/gc.toml:1: '!' starts a table name (TOML allows ASCII letters, digits, _ and -, or a quoted "
       "name)"},
      {"a = [[-112.2'\xc2\xa7\n",
       "/data/runs/gc.toml:1: U+00A7 outside a string or a comment (TOML allows ASCII only there)"},
      {"f = 1;979-25-['\xc2\xa7\n",
       "/data/runs/gc.toml:1: '-' inside a value: a date or a time of day, which no scenario key takes (durations "
       "are quantities such as \"3 h\")"},
      {"a = {b = [[1],\n }]}\n", "/data/runs/gc.toml:2: '}' inside an array (no inline table to close)"},
      {"[\n[\nu|at\"[[\n", "/data/runs/gc.toml:1: a table name is missing after '['"},
      {"a = 1\n [[ =]]\n",
       "/data/runs/gc.toml:2: '=' starts a table name (TOML allows ASCII letters, digits, _ and -, "
       "or a quoted name)"},
      // Dates and times: toml++'s scanning of malformed ones fails assertions (the last two were
      // found by fuzzing on 2026-11-24); no scenario key takes one.
      {"a = 1\nd = 1979-05-27T:32:00\n",
       "/data/runs/gc.toml:2: '-' inside a value: a date or a time of day, which no scenario key takes (durations are "
       "quantities such as \"3 h\")"},
      {"a = [1979-05-27t+07]\n",
       "/data/runs/gc.toml:1: '-' inside a value: a date or a time of day, which no scenario key takes (durations are "
       "quantities such as \"3 h\")"},
      {"f =1979-05-27 1]]]]\n",
       "/data/runs/gc.toml:1: '-' inside a value: a date or a time of day, which no scenario key takes (durations are "
       "quantities such as \"3 h\")"},
      {"s = 1908-05-\\6 7 = 1908-05-\\6 =\n",
       "/data/runs/gc.toml:1: '-' inside a value: a date or a time of day, which no scenario key takes (durations are "
       "quantities such as \"3 h\")"},
      {"t = 07:32:00\n",
       "/data/runs/gc.toml:1: ':' inside a value: a date or a time of day, which no scenario key takes (durations are "
       "quantities such as \"3 h\")"},
      {std::string("[\0]\n", 4),
       "/data/runs/gc.toml:1: U+0000: a control character (TOML allows tab and line breaks only)"},
      {"# a comment \x1b[31m\n",
       "/data/runs/gc.toml:1: U+001B: a control character (TOML allows tab and line breaks only)"},
      {"a = 1\rb = 2\n", "/data/runs/gc.toml:1: U+000D: a control character (TOML allows tab and line breaks only)"},
      // toml++ quotes the character it saw: a line break stays escaped in the one-line message.
      {"material =i\n", "/data/runs/gc.toml:1: Error while parsing floating-point: expected 'inf', saw 'i\\n'"},
  };
  for (const auto& [text, message] : cases) {
    auto s = parse(text);
    ASSERT_FALSE(s) << text;
    EXPECT_EQ(s.message(), message);
  }
  // What is valid TOML passes: non-ASCII in strings and comments, nested arrays starting a line,
  // a line-ending backslash followed by ASCII, quoted table names.
  auto ok = parse(std::string(kGood) + "# crue de l'Is\xc3\xa8re \xc2\xa7\n" +
                  "[outputs]\nmaps = [\n[\"max_depth\"][0],\n]\n");
  EXPECT_FALSE(ok);  // (an index is not TOML: the check above only must not be what refuses it)
  EXPECT_EQ(ok.message().find("starts a table name"), std::string::npos) << ok.message();
  auto good = parse(replaced(kGood, "name = \"canyon flood\"",
                             "name = \"Crue de l'Is\xc3\xa8re \xc2\xa7\"\ndescription = \"\"\"\xc3\xa9t\xc3\xa9 \\\n"
                             "  2023 \xe2\x80\x94 \"\"\"\n\"x\" = '\xc3\xa9'\n"));
  ASSERT_FALSE(good);  // the key "x" is unknown, which is the only complaint
  EXPECT_EQ(good.message(),
            "/data/runs/gc.toml:4: key 'x': unknown key (expected one of: name, description, terrain, "
            "region, model, erosion, materials, water, time, outputs)");
  auto named = parse(replaced(kGood, "name = \"canyon flood\"", "name = \"Crue de l'Is\xc3\xa8re\" # \xc2\xa7"));
  ASSERT_TRUE(named) << named.message();
  EXPECT_EQ(named->name, "Crue de l'Is\xc3\xa8re");
}

TEST(Scenario, MissingFile) {
  auto s = loadScenario("/nonexistent/flood.toml");
  ASSERT_FALSE(s);
  EXPECT_EQ(s.message(), "/nonexistent/flood.toml: no such scenario file");
}

}  // namespace
}  // namespace strata::scenario
