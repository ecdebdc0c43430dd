// Issue 31: a run folder a GIS user opens as it is. The flood outline (maps/flood_outline.gpkg)
// has the maps' CRS and, feature by feature, the area of the cells the max_depth map shows wet;
// its polygons' own geodesic area agrees; the hazard rating map is FD2321's formula of the
// max_depth and max_speed maps; and headless QGIS applies the .qml style beside every map.
#include <gtest/gtest.h>
#include <ogrsf_frmts.h>

#include <cmath>
#include <fstream>
#include <sstream>

#include <strata/gis/geodesy.hpp>
#include <strata/scenario/compare.hpp>
#include <strata/scenario/domain.hpp>
#include <strata/scenario/hazard.hpp>
#include <strata/scenario/run.hpp>

#include "scenario_fixture.hpp"
#include "strata_test.hpp"

namespace strata::scenario {
namespace {

using namespace test_support;

// The area of an OGR polygon in lon/lat on the body's ellipsoid (rings: the first adds, the others
// subtract). Cells are bounded by parallels, which are not geodesics: the edges are cut into
// 1e-4 degree pieces first (a geodesic that short strays from its parallel by nothing measurable).
double ellipsoidArea(const OGRPolygon& polygon, const gis::Body& body) {
  OGRPolygon p(polygon);
  p.segmentize(1e-4);
  double area = 0;
  for (int r = 0; r <= p.getNumInteriorRings(); ++r) {
    const OGRLinearRing* ring = r == 0 ? p.getExteriorRing() : p.getInteriorRing(r - 1);
    std::vector<gis::LonLat> pts;
    for (int i = 0; i + 1 < ring->getNumPoints(); ++i) pts.push_back({ring->getX(i), ring->getY(i)});
    const double a = std::abs(gis::geodesicPolygonAreaM2(pts, body));
    area += r == 0 ? a : -a;
  }
  return area;
}

// `text` run as dir/name.toml into dir/name on the CPU backend, without pictures and plots.
void cpuRun(const std::filesystem::path& dir, const std::string& name, const std::string& text) {
  std::ofstream(dir / (name + ".toml")) << text;
  auto s = loadScenario(dir / (name + ".toml"));
  ASSERT_TRUE(s) << s.message();
  auto summary = runScenario(*s, cpuOptions(dir / name));
  ASSERT_TRUE(summary) << summary.message();
}

TEST(ScenarioOutputs, OutlineHazardAndStylesAreWhatAGisUserOpens) {
  const auto dir = strata::test::tempDir("outputs");
  cpuRun(dir, "run", damBreakText());
  auto s = loadScenario(dir / "run.toml");
  ASSERT_TRUE(s) << s.message();
  const std::filesystem::path outDir = dir / "run";
  auto d = buildDomain(*s);
  ASSERT_TRUE(d) << d.message();
  auto maxDepth = gis::readDem((outDir / "maps" / "max_depth.tif").string(), allowEmpty());
  auto maxSpeed = gis::readDem((outDir / "maps" / "max_speed.tif").string(), allowEmpty());
  auto hazard = gis::readDem((outDir / "maps" / "hazard_rating.tif").string(), allowEmpty());
  ASSERT_TRUE(maxDepth && maxSpeed && hazard);

  // The wet area the map shows, in the model's cell areas (row dx x its float32 dy, as the
  // solver's totals and the report's).
  const double wet = s->outputs.wetThresholdM;
  double wetArea = 0;
  int wetCells = 0, rated = 0;
  for (int y = 0; y < maxDepth->georef.height; ++y) {
    for (int x = 0; x < maxDepth->georef.width; ++x) {
      const float depth = maxDepth->values.at(x, y), rating = hazard->values.at(x, y);
      if (!(depth > wet)) {
        EXPECT_TRUE(std::isnan(rating)) << "no rating where it was never wet: " << x << ", " << y;
        continue;
      }
      wetArea += d->input.rowDxM[size_t(y)] * double(float(d->input.dyM));
      ++wetCells;
      const double expected = hazardRating(depth, maxSpeed->values.at(x, y), HazardLandUse::kUrban);
      EXPECT_NEAR(rating, expected, 1e-5 * expected) << x << ", " << y;  // float32 map against double
      rated += hazardClass(rating) == 3;
    }
  }
  ASSERT_GT(wetCells, 20);
  EXPECT_GT(rated, 0) << "a 100 m dam break has extreme hazard somewhere";

  GDALDatasetH ds =
      GDALOpenEx((outDir / "maps" / "flood_outline.gpkg").string().c_str(), GDAL_OF_VECTOR, nullptr, nullptr, nullptr);
  ASSERT_NE(ds, nullptr);
  OGRLayer* layer = GDALDataset::FromHandle(ds)->GetLayerByName("flood_outline");
  ASSERT_NE(layer, nullptr);
  OGRSpatialReference mapCrs(maxDepth->georef.crsWkt.c_str());
  mapCrs.SetAxisMappingStrategy(OAMS_TRADITIONAL_GIS_ORDER);
  ASSERT_NE(layer->GetSpatialRef(), nullptr);
  EXPECT_TRUE(layer->GetSpatialRef()->IsSame(&mapCrs));
  double attributeArea = 0, polygonArea = 0;
  for (auto& f : *layer) {
    attributeArea += f->GetFieldAsDouble("area_m2");
    EXPECT_GT(f->GetFieldAsDouble("max_depth_m"), wet);
    const auto* g = f->GetGeometryRef()->toMultiPolygon();
    for (const auto* p : *g) polygonArea += ellipsoidArea(*p, maxDepth->georef.body);
  }
  GDALClose(ds);
  EXPECT_NEAR(attributeArea, wetArea, 1e-9 * wetArea);
  // The traced polygons themselves: the same area on the ellipsoid (the model's rows take the
  // middle column's cell area; on a lon/lat grid every column's is the same; its dy is float32).
  EXPECT_NEAR(polygonArea, wetArea, 1e-6 * wetArea);

  // QGIS (python3-qgis, installed by scripts/setup.sh) loads every style and the outline.
  const auto qgis =
      strata::test::runProgram({"/usr/bin/python3", STRATA_SOURCE_DIR "/tests/scenario/qgis/check_styles.py",
                                outDir.string(), std::to_string(wetArea)});
  EXPECT_EQ(qgis.status, 0) << qgis.output;
  for (const char* m : {"max_depth", "hazard_rating", "elevation", "flood_outline"}) {
    EXPECT_NE(qgis.output.find(m), std::string::npos) << qgis.output;
  }
}

// Issue 31: the report warns. The fixture's flood on the raw DEM ends with most of its water in
// the DEM's pits: said, with the keys that address it, and gone once they are set; a 50,000 m3/s
// inflow line of 4 cells makes the fastest water, and the warning says so.
TEST(ScenarioOutputs, TheReportWarnsOfPondedWaterAndOfInflowSpeeds) {
  const auto dir = strata::test::tempDir("warnings");
  auto run = [&](const std::string& name, const std::string& text) {
    cpuRun(dir, name, text);
    return slurp(dir / name / "report.md");
  };
  const std::string raw = run("raw", scenarioText());
  const size_t at = raw.find("% of the water in the region at the end) stands in closed depressions of the bed");
  ASSERT_NE(at, std::string::npos) << raw;
  EXPECT_GT(std::stoi(raw.substr(raw.rfind('(', at) + 1)), 50) << raw;
  EXPECT_NE(raw.find("`[terrain] fill_depressions = true`"), std::string::npos);

  std::string conditioned = scenarioText();
  conditioned.replace(conditioned.find("[terrain]\n"), 10,
                      "[terrain]\nbreach_inflows = true\nfill_depressions = true\n");
  for (size_t p = conditioned.find("20000"); p != std::string::npos; p = conditioned.find("20000", p)) {
    conditioned.replace(p, 5, "50000");
  }
  const std::string report = run("conditioned", conditioned);
  EXPECT_EQ(report.find("closed depressions"), std::string::npos) << report;
  EXPECT_FALSE(std::filesystem::exists(dir / "raw" / "maps" / "conditioning.tif"));
  // Where conditioning changed the DEM, as a map: its volume is what the report says was cut and
  // raised (breach_inflows, then fill_depressions).
  std::ofstream(dir / "c.toml") << conditioned;
  auto d = buildDomain(*loadScenario(dir / "c.toml"));
  ASSERT_TRUE(d) << d.message();
  auto change = gis::readDem((dir / "conditioned" / "maps" / "conditioning.tif").string(), allowEmpty());
  ASSERT_TRUE(change) << change.message();
  double net = 0;
  for (int y = 0; y < change->georef.height; ++y) {
    for (int x = 0; x < change->georef.width; ++x) {
      if (std::isfinite(change->values.at(x, y))) net += change->values.at(x, y) * d->cellAreaM2.at(x, y);
    }
  }
  const double expected = d->breach.fillM3 + d->filled.volumeM3 - d->breach.cutM3;
  EXPECT_GT(d->breach.cutM3 + d->filled.volumeM3, 1e6);
  // 1e-5: the map holds float32 differences of beds of ~1000 m (a ulp is 6e-5 m).
  EXPECT_NEAR(net, expected, 1e-5 * (d->breach.cutM3 + d->breach.fillM3 + d->filled.volumeM3));
  EXPECT_NE(report.find("`maps/conditioning.tif`"), std::string::npos) << report;
  EXPECT_NE(report.find("is next to the inflow \"Colorado\", which puts up to 50000 m³/s into 4 cell(s)"),
            std::string::npos)
      << report;
}

// Issue 35: the local-inertial scheme leaves out advection. The fixture's 20,000 m3/s down the
// canyon on it races down chutes at a Froude number well above 1: the report names the scheme,
// says where the flow was supercritical and sends the user to the finite-volume scheme; the same
// run on the finite-volume scheme has no such warning. Erosion is refused with the scheme.
TEST(ScenarioOutputs, TheInertialSchemeWarnsWhereTheFlowWasSupercritical) {
  const auto dir = strata::test::tempDir("inertial_warning");
  std::string text = scenarioText();
  text.replace(text.find("kind = \"flood\"\n"), 15, "kind = \"flood\"\nscheme = \"inertial\"\n");
  cpuRun(dir, "inertial", text);
  const std::string report = slurp(dir / "inertial" / "report.md");
  EXPECT_NE(report.find("local-inertial shallow water, Bates et al. 2010"), std::string::npos) << report;
  EXPECT_NE(report.find("CFL 0.70"), std::string::npos) << report;
  const size_t at = report.find("The flow was supercritical on ");
  ASSERT_NE(at, std::string::npos) << report;
  EXPECT_NE(report.find("`[model] scheme = \"finite_volume\"`", at), std::string::npos) << report;
  cpuRun(dir, "finite_volume", scenarioText());
  EXPECT_EQ(slurp(dir / "finite_volume" / "report.md").find("supercritical"), std::string::npos);

  std::ofstream(dir / "eroding.toml") << text << "[erosion]\nenabled = true\n";
  const auto refused = loadScenario(dir / "eroding.toml");
  ASSERT_FALSE(refused);
  EXPECT_NE(refused.message().find("model.scheme"), std::string::npos) << refused.message();
  EXPECT_NE(refused.message().find("erosion needs scheme = \"finite_volume\""), std::string::npos) << refused.message();
}

// Issue 31: strata compare. The fixture's flood with Manning n 0.04 against 0.08: every map's
// difference is B - A cell by cell (never-wet cells count as 0 depth), the headline table has
// both runs and the change, and a folder that holds anything, or runs of other grids, are refused.
// Issue 31: "voids filled under the flood". Rainier's SRTM has 1,501 void cells in this region
// (ScenarioDomain.VoidsAreRefusedFilledWallsOrHoles); filled, and rained on, some of them get wet:
// the report says how many, where the deepest is, and that the ground there is made up. Without
// voids (a region of the same DEM that has none) it says nothing.
TEST(ScenarioOutputs, TheReportWarnsOfWaterOverFilledVoids) {
  const auto dir = strata::test::tempDir("voids_warning");
  auto text = [](const std::string& bbox) {
    return "[terrain]\ndem = \"" + strata::test::dataPath("rainier/mt_rainier_90m.tif") +
           "\"\nvoids = \"fill\"\n[region]\nbbox_lonlat = " + bbox +
           "\n[model]\nkind = \"flood\"\nboundary = \"open\"\n[water.rain]\nrate = \"100 mm/h\"\n"
           "[time]\nduration = \"10 min\"\n[outputs]\nwet_threshold = \"0.005 m\"\nmaps = [\"max_depth\"]\n";
  };
  cpuRun(dir, "voids", text("[-121.82, 46.82, -121.70, 46.89]"));
  const std::string report = slurp(dir / "voids" / "report.md");
  const size_t at = report.find(" of the 1501 cells the DEM had no data for (");
  ASSERT_NE(at, std::string::npos) << report;
  const int wet = std::stoi(report.substr(report.rfind("reached ", at) + 8));
  EXPECT_GT(wet, 0);
  EXPECT_LE(wet, 1501);
  EXPECT_NE(report.find("stands on ground the DEM does not have"), std::string::npos) << report;
  cpuRun(dir, "none", text("[-121.39, 46.77, -121.31, 46.83]"));
  const std::string clean = slurp(dir / "none" / "report.md");
  EXPECT_EQ(clean.find("| voids |"), std::string::npos) << "this region has voids: pick one without";
  EXPECT_EQ(clean.find("the DEM had no data for"), std::string::npos) << clean;
}

TEST(ScenarioOutputs, CompareGivesDifferenceMapsAndTheHeadlineNumbers) {
  const auto dir = strata::test::tempDir("compare");
  auto run = [&](const std::string& name, const std::string& text) { cpuRun(dir, name, text); };
  std::string rough = scenarioText();
  rough.replace(rough.find("manning_n = 0.04"), 16, "manning_n = 0.08");
  run("smooth", scenarioText());
  run("rough", rough);
  CompareOptions o{dir / "smooth", dir / "rough", dir / "what-changed", true};
  auto written = compareRuns(o);
  ASSERT_TRUE(written) << written.message();
  for (const char* f : {"compare.md", "maps/max_depth_difference.tif", "maps/max_depth_difference.qml",
                        "plots/max_depth_difference.png", "maps/arrival_time_difference.tif"}) {
    EXPECT_TRUE(std::filesystem::exists(o.outDir / f)) << f;
  }
  auto a = gis::readDem((o.runA / "maps" / "max_depth.tif").string(), allowEmpty());
  auto b = gis::readDem((o.runB / "maps" / "max_depth.tif").string(), allowEmpty());
  auto d = gis::readDem((o.outDir / "maps" / "max_depth_difference.tif").string(), allowEmpty());
  ASSERT_TRUE(a && b && d);
  int changed = 0;
  for (size_t i = 0; i < d->values.size(); ++i) {
    const float x = std::isfinite(a->values.data[i]) ? a->values.data[i] : 0.0f;
    const float y = std::isfinite(b->values.data[i]) ? b->values.data[i] : 0.0f;
    if (!std::isfinite(a->values.data[i]) && !std::isfinite(b->values.data[i])) continue;
    EXPECT_EQ(d->values.data[i], y - x) << i;
    changed += y != x;
  }
  EXPECT_GT(changed, 10) << "a rougher bed changes the depths";
  const std::string md = slurp(o.outDir / "compare.md");
  EXPECT_NE(md.find("| largest flooded area | "), std::string::npos) << md;
  EXPECT_NE(md.find("![max_depth_difference](plots/max_depth_difference.png)"), std::string::npos);
  // Friction changes the water, not the bed: no map of zeros, said instead.
  EXPECT_FALSE(std::filesystem::exists(o.outDir / "maps" / "elevation_difference.tif"));
  EXPECT_NE(md.find("The same in both runs, cell for cell (no difference map): `elevation`"), std::string::npos) << md;

  // Refusals: the output folder holds something; a run of other cells.
  auto again = compareRuns(o);
  ASSERT_FALSE(again);
  EXPECT_EQ(again.message(), o.outDir.string() + ": exists and is not empty (choose a new folder)");
  std::string coarse = scenarioText();
  coarse.replace(coarse.find("cell_size = \"600 m\""), 19, "cell_size = \"900 m\"");
  run("coarse", coarse);
  auto other = compareRuns({dir / "smooth", dir / "coarse", dir / "other", false});
  ASSERT_FALSE(other);
  EXPECT_NE(other.message().find("not on the grid of"), std::string::npos) << other.message();
}

}  // namespace
}  // namespace strata::scenario
