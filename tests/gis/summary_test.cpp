// `strata info`'s numbers (summarizeDem) against gdalinfo -stats, and the command itself.
#include <cpl_json.h>
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>

#include <strata/gis/dem_summary.hpp>

#include "gis_test_util.hpp"
#include "strata_test.hpp"

namespace strata::gis {
namespace {

using test::runCommand;

CPLJSONObject gdalinfoStats(const std::string& path) {
  // PAM off: gdalinfo must not try to write .aux.xml next to the read-only shared data.
  const auto r = runCommand({"gdalinfo", "--config", "GDAL_PAM_ENABLED", "NO", "-json", "-stats", path});
  EXPECT_EQ(r.status, 0);
  CPLJSONDocument doc;
  EXPECT_TRUE(doc.LoadMemory(r.out));
  return doc.GetRoot();
}

TEST(Summary, StatisticsMatchGdalinfo) {
  for (const char* f : {"grand_canyon/grandcanyon_srtm_3857.tif", "rainier/mt_rainier_90m.tif", "earth/etopo20.tif",
                        "mars/mola_megdr_4ppd.vrt"}) {
    const std::string path = test::dataFile(f);
    auto s = summarizeDem(path);
    ASSERT_TRUE(s.ok()) << s.message();
    const CPLJSONObject band = gdalinfoStats(path).GetArray("bands")[0];
    // These files have scale 1, offset 0: GDAL's raw statistics are metres. gdalinfo prints
    // min, max and mean rounded to 3 decimals (half a unit: 5e-4, plus 1e-9 for the text to
    // double conversion of a tie such as 6228.8125 -> "6228.812") and the valid share to 2
    // decimals of a percent.
    const double printed = 5e-4 + 1e-9;
    EXPECT_NEAR(s->minM, band.GetDouble("minimum"), printed) << f;
    EXPECT_NEAR(s->maxM, band.GetDouble("maximum"), printed) << f;
    EXPECT_NEAR(s->meanM, band.GetDouble("mean"), printed) << f;
    double validPercent = 100;
    for (const CPLJSONObject& domain : band.GetObj("metadata").GetChildren()) {
      const std::string v = domain.GetString("STATISTICS_VALID_PERCENT");
      if (!v.empty()) validPercent = std::stod(v);
    }
    EXPECT_NEAR(100.0 * (1 - s->noDataFraction), validPercent, 0.005 + 1e-9) << f;
  }
}

TEST(Summary, ExtentAndResolution) {
  const std::string path = test::dataFile("grand_canyon/grandcanyon_srtm_3857.tif");
  auto s = summarizeDem(path);
  ASSERT_TRUE(s.ok()) << s.message();
  const auto r = runCommand({"gdalinfo", "-json", path});
  CPLJSONDocument doc;
  ASSERT_TRUE(doc.LoadMemory(r.out));
  // gdalinfo's WGS84 extent polygon (printed to 7 decimals): Mercator edges are straight in
  // lon/lat, so the corners bound it.
  const CPLJSONArray ring = doc.GetRoot().GetArray("wgs84Extent/coordinates")[0].ToArray();
  double minLon = 1e9, maxLon = -1e9, minLat = 1e9, maxLat = -1e9;
  for (int i = 0; i < ring.Size(); ++i) {
    const CPLJSONArray p = ring[i].ToArray();
    minLon = std::min(minLon, p[0].ToDouble());
    maxLon = std::max(maxLon, p[0].ToDouble());
    minLat = std::min(minLat, p[1].ToDouble());
    maxLat = std::max(maxLat, p[1].ToDouble());
  }
  EXPECT_NEAR(s->minLon, minLon, 1e-7);
  EXPECT_NEAR(s->maxLon, maxLon, 1e-7);
  EXPECT_NEAR(s->minLat, minLat, 1e-7);
  EXPECT_NEAR(s->maxLat, maxLat, 1e-7);
  // Web Mercator pixels are 76.437 m * cos(lat) on the ground (spherical scale; the ellipsoid
  // changes it by < 0.5 %).
  const double c = std::cos((s->minLat + s->maxLat) / 2 * M_PI / 180);
  EXPECT_NEAR(s->pixelWidthM / (76.437028 * c), 1, 0.005);
  EXPECT_NEAR(s->pixelHeightM / (76.437028 * c), 1, 0.005);
  // The Moon grid runs 0..360 E around 180 E: reported unwrapped, not as -180..180.
  auto moon = summarizeDem(test::dataFile("moon/LDEM_4.LBL"));
  ASSERT_TRUE(moon.ok()) << moon.message();
  EXPECT_NEAR(moon->minLon, 0, 1e-3);
  EXPECT_NEAR(moon->maxLon, 360, 1e-3);
  // 4 pixels per degree on a 1737.4 km sphere: 7580.8 m at the equator.
  EXPECT_NEAR(moon->pixelWidthM, 2 * M_PI * 1737400 / 1440, 5);
}

TEST(Summary, StrataInfoCommand) {
  const std::string exe = (std::filesystem::path(STRATA_TEST_OUTPUT_DIR).parent_path() / "apps/strata").string();
  ASSERT_TRUE(std::filesystem::exists(exe)) << exe;
  const auto ok = runCommand(
      {exe, "info", test::dataFile("grand_canyon/grandcanyon_srtm_3857.tif"), test::dataFile("moon/LDEM_4.LBL")});
  EXPECT_EQ(ok.status, 0) << ok.out;
  for (const char* line :
       {"driver      GTiff", "CRS         WGS 84 / Pseudo-Mercator (EPSG:3857)",
        "size        512 x 512, Int16, nodata -32768", "lon/lat     lon -113.203125 .. -112.851562",
        "values      min 479.000, max 2347.000", "nodata      0.000 % of 262144 cells",
        "body        Moon (a = 1737400.0 m, sphere)", "CRS         SIMPLE_CYLINDRICAL MOON (no EPSG code)"}) {
    EXPECT_NE(ok.out.find(line), std::string::npos) << "missing '" << line << "' in\n" << ok.out;
  }
  const auto bad = runCommand({exe, "info", "/nonexistent/dem.tif"}, true);
  EXPECT_NE(bad.status, 0);
  EXPECT_EQ(bad.out, "strata info: /nonexistent/dem.tif: no such file\n");
}

}  // namespace
}  // namespace strata::gis
