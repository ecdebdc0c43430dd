// 8-bit images through GDAL (gis/image8.hpp): PNGs that round-trip every byte for 1-4 channels,
// read back by gdalinfo with the right bands, no sidecar files; bad sizes and non-8-bit rasters
// refused naming the file.
#include <gtest/gtest.h>

#include <cpl_json.h>

#include <filesystem>
#include <fstream>
#include <random>

#include <strata/gis/dem_io.hpp>
#include <strata/gis/image8.hpp>

#include "gis_test_util.hpp"
#include "strata_test.hpp"

namespace strata::gis {
namespace {

namespace fs = std::filesystem;

TEST(Image8, PngRoundTripsEveryByteWithOneToFourChannels) {
  const auto dir = strata::test::tempDir("image8");
  std::mt19937 rng(7);
  for (int channels = 1; channels <= 4; ++channels) {
    SCOPED_TRACE(channels);
    const int w = 37, h = 23;  // odd sizes: no row padding hides a stride error
    std::vector<uint8_t> pixels(size_t(w) * h * channels);
    for (auto& p : pixels) p = uint8_t(rng());
    const std::string path = (dir / ("c" + std::to_string(channels) + ".png")).string();
    ASSERT_TRUE(writeImage8(path, w, h, channels, pixels));
    {
      std::ifstream f(path, std::ios::binary);
      char sig[8] = {};
      f.read(sig, 8);
      EXPECT_EQ(std::string(sig + 1, 3), "PNG");
    }
    auto back = readImage8(path);
    ASSERT_TRUE(back) << back.message();
    EXPECT_EQ(back->width, w);
    EXPECT_EQ(back->height, h);
    EXPECT_EQ(back->channels, channels);
    EXPECT_EQ(back->pixels, pixels);
    // Another reader: gdalinfo sees the size, the bands and (2 and 4 channels) the alpha band.
    const auto r = test::runCommand({"gdalinfo", "--config", "GDAL_PAM_ENABLED", "NO", "-json", path});
    ASSERT_EQ(r.status, 0);
    CPLJSONDocument doc;
    ASSERT_TRUE(doc.LoadMemory(r.out));
    const auto bands = doc.GetRoot().GetArray("bands");
    ASSERT_EQ(bands.Size(), channels);
    EXPECT_EQ(doc.GetRoot().GetArray("size")[0].ToInteger(), w);
    EXPECT_EQ(bands[channels - 1].GetString("colorInterpretation") == "Alpha", channels == 2 || channels == 4);
  }
  // Nothing but the four pictures: no .aux.xml or world file beside them.
  int files = 0;
  for ([[maybe_unused]] const auto& e : fs::directory_iterator(dir)) ++files;
  EXPECT_EQ(files, 4);
}

TEST(Image8, BadSizesAndNonByteRastersAreRefusedNamingTheFile) {
  const auto dir = strata::test::tempDir("image8-bad");
  const std::string png = (dir / "x.png").string();
  const std::vector<uint8_t> three(3);
  auto st = writeImage8(png, 2, 2, 1, three);  // 3 bytes for 4 pixels
  ASSERT_FALSE(st);
  EXPECT_NE(st.message().find("x.png: 3 bytes for a 2x2x1 image"), std::string::npos) << st.message();
  EXPECT_FALSE(writeImage8(png, 1, 1, 5, std::vector<uint8_t>(5)));
  EXPECT_FALSE(fs::exists(png));
  // A float DEM is not an image: refused naming its sample type (the viewer's stamp then reads
  // it as heights).
  auto dem = readImage8(test::dataFile("grand_canyon/grand_canyon_512.tif"));
  ASSERT_FALSE(dem);
  EXPECT_NE(dem.message().find("not an 8-bit image (its samples are"), std::string::npos) << dem.message();
  auto missing = readImage8((dir / "none.png").string());
  ASSERT_FALSE(missing);
  EXPECT_NE(missing.message().find("none.png"), std::string::npos) << missing.message();
  std::ofstream(dir / "junk.png") << "not a picture";
  auto junk = readImage8((dir / "junk.png").string());
  ASSERT_FALSE(junk);
  EXPECT_NE(junk.message().find("junk.png"), std::string::npos) << junk.message();
}

}  // namespace
}  // namespace strata::gis
