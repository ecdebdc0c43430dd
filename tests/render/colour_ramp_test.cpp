// A user's colour ramp in gdaldem color-relief's format colours each elevation as gdaldem does
// (run side by side on Rainier), and bad files are refused naming file and line.
#include <gdal_priv.h>
#include <gtest/gtest.h>

#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>

#include <strata/core/process.hpp>
#include <strata/gis/dem_io.hpp>
#include <strata/render/colour_ramp.hpp>

#include "strata_test.hpp"

namespace strata::render {
namespace {

// (test::tempDir empties its folder on each call: one call a test.)
std::string writeRamp(const std::filesystem::path& dir, const std::string& name, const std::string& text) {
  const auto path = dir / name;
  std::ofstream(path) << text;
  return path.string();
}

TEST(ColourRamp, ColoursEveryCellAsGdaldemColorReliefDoes) {
  // Rainier (90 m SRTM, 263-4388 m): absolute stops, a percentage, a comment, commas, a
  // no-data colour and the stops out of order, the colours gdaldem writes for each valid cell
  // against ColourRamp::at, rounded as gdaldem rounds.
  const std::string dem = test::dataPath("rainier/mt_rainier_90m.tif");
  auto raster = gis::readDem(dem);
  ASSERT_TRUE(raster) << raster.message();
  float lo = INFINITY, hi = -INFINITY;
  for (float v : raster->values.data) {
    if (!gis::isNoData(v)) lo = std::min(lo, v), hi = std::max(hi, v);
  }
  const auto dir = test::tempDir("colour_ramp");
  const std::string ramp = writeRamp(dir, "rainier.txt",
                                     "# elevation red green blue\n"
                                     "500 30 90 40\n"
                                     "1500,160,150,90\n"
                                     "90% 240 240 250\n"
                                     "\t1000\t90 120 60   # out of order\n"
                                     "2500 120 100 90\n"
                                     "nv 0 0 0 0\n");
  auto r = loadColourRamp(ramp, lo, hi);
  ASSERT_TRUE(r) << r.message();
  ASSERT_EQ(r->elevationsM.size(), 5u);
  EXPECT_FLOAT_EQ(r->elevationsM[3], 2500);
  EXPECT_NEAR(r->elevationsM[4], lo + 0.9 * (hi - lo), 1e-3);
  const auto out = dir / "gdaldem.tif";
  // gdaldem computes the DEM's statistics for the percentages and GDAL would keep them in a
  // .aux.xml beside the shared DEM: not there (the child inherits this environment).
  ::setenv("GDAL_PAM_ENABLED", "NO", 1);
  const auto run = runProcess({"/usr/bin/gdaldem", "color-relief", "-q", dem, ramp, out.string()});
  ::unsetenv("GDAL_PAM_ENABLED");
  ASSERT_TRUE(run) << run.message();
  GDALAllRegister();
  GDALDataset* ds = GDALDataset::Open(out.string().c_str(), GDAL_OF_RASTER | GDAL_OF_READONLY);
  ASSERT_NE(ds, nullptr);
  const int w = raster->values.width, h = raster->values.height;
  std::vector<uint8_t> band(size_t(w) * size_t(h));
  int compared = 0, off = 0;
  for (int b = 0; b < 3; ++b) {
    ASSERT_EQ(ds->GetRasterBand(b + 1)->RasterIO(GF_Read, 0, 0, w, h, band.data(), w, h, GDT_Byte, 0, 0), CE_None);
    for (int i = 0; i < w * h; ++i) {
      const float e = raster->values.data[size_t(i)];
      if (gis::isNoData(e)) continue;
      const int ours = int(std::lround(255.0f * r->at(e)[b]));
      ++compared;
      if (std::abs(ours - int(band[size_t(i)])) > 1 && ++off < 4) {
        ADD_FAILURE() << "cell " << i << " band " << b << ": " << e << " m, ours " << ours << ", gdaldem "
                      << int(band[size_t(i)]);
      }
    }
  }
  GDALClose(ds);
  EXPECT_GT(compared, 3 * 1000000);
  EXPECT_EQ(off, 0) << "of " << compared << " colour values";
  // Beyond the ends, the end colours.
  EXPECT_EQ(r->at(-100.0f), r->colours.front());
  EXPECT_EQ(r->at(9000.0f), r->colours.back());
}

TEST(ColourRamp, BadFilesAreRefusedNamingFileAndLine) {
  const struct {
    const char* text;
    const char* message;
  } cases[] = {
      {"100 1 2 3\n200 1 2\n", ":2: expected ELEVATION R G B [A] (e.g. 1500 120 200 80), found 3 fields"},
      {"100 1 2 300\n", ":1: colour '300': expected a whole number 0-255"},
      {"100 white\n100 red green blue\n", ":1: expected ELEVATION R G B"},
      {"1e400 1 2 3\n", ":1: elevation '1e400': expected a number of metres, a percentage such as 50%, or nv"},
      {"low 1 2 3\n", ":1: elevation 'low': expected a number"},
      // Issue 33: a stop beyond any relief (1e308 m became inf and drew every cell black).
      {"0 1 2 3\n1e308 4 5 6\n", ":2: elevation '1e308': outside +-1000 km of the datum"},
      {"-1e39 1 2 3\n", ":1: elevation '-1e39': outside +-1000 km of the datum"},
      {"0 1 2 3\n1e12% 4 5 6\n", ":2: elevation '1e12%': outside +-1000 km of the datum"},
      {"# nothing\n\n", ": no colour stops (lines of ELEVATION R G B)"},
  };
  const auto dir = test::tempDir("colour_ramp");
  for (const auto& c : cases) {
    const std::string path = writeRamp(dir, "bad.txt", c.text);
    auto r = loadColourRamp(path, 0, 100);
    ASSERT_FALSE(r) << c.text;
    EXPECT_NE(r.message().find(path + c.message), std::string::npos) << r.message();
  }
  std::string many;
  for (int i = 0; i < 65; ++i) many += std::to_string(i) + " 1 2 3\n";
  auto r = loadColourRamp(writeRamp(dir, "many.txt", many), 0, 100);
  ASSERT_FALSE(r);
  EXPECT_NE(r.message().find("65 colour stops; at most 64 are drawn"), std::string::npos) << r.message();
  EXPECT_FALSE(loadColourRamp("/nonexistent/ramp.txt", 0, 1));
}

}  // namespace
}  // namespace strata::render
