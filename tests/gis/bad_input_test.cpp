// Every kind of bad input gets a one-line error naming the file and the problem, never a crash
// or a huge allocation.
#include <gtest/gtest.h>

#include <cstring>
#include <filesystem>
#include <fstream>
#include <limits>

#include <strata/gis/dem_io.hpp>

#include "gis_test_util.hpp"
#include "strata_test.hpp"

namespace strata::gis {
namespace {

namespace fs = std::filesystem;

// The error of reading `path`, asserting it is one line that names the file.
std::string readError(const std::string& path, const ReadOptions& o = {}) {
  auto r = readDem(path, o);
  EXPECT_FALSE(r.ok()) << path << " read without error";
  if (r.ok()) return {};
  const std::string& m = r.message();
  EXPECT_EQ(m.rfind(path + ": ", 0), 0u) << "message does not start with the file: " << m;
  EXPECT_EQ(m.find('\n'), std::string::npos) << "message is not one line: " << m;
  return m;
}

#define EXPECT_CONTAINS(haystack, needle)                          \
  EXPECT_NE(std::string(haystack).find(needle), std::string::npos) \
      << "'" << (haystack) << "' lacks '" << (needle) << "'"

test::SyntheticRaster geoRaster() {
  test::SyntheticRaster s;
  s.width = 32;
  s.height = 16;
  s.crs = "EPSG:4326";
  s.gt = std::array<double, 6>{-113, 1.0 / 32, 0, 37, 0, -1.0 / 32};
  return s;
}

std::string readAll(const std::string& path) {
  std::ifstream f(path, std::ios::binary);
  return {std::istreambuf_iterator<char>(f), std::istreambuf_iterator<char>()};
}
void writeAll(const std::string& path, const std::string& bytes) {
  std::ofstream f(path, std::ios::binary | std::ios::trunc);
  f.write(bytes.data(), std::streamsize(bytes.size()));
}

TEST(BadInput, MissingFile) {
  const std::string path = (strata::test::tempDir("missing") / "nope.tif").string();
  EXPECT_CONTAINS(readError(path), "no such file");
  auto p = probeDem(path);
  ASSERT_FALSE(p.ok());
  EXPECT_EQ(p.message(), path + ": no such file");
}

TEST(BadInput, NotARaster) {
  const auto dir = strata::test::tempDir("notraster");
  const std::string text = (dir / "notes.tif").string();
  writeAll(text, "elevation 1200 m\n");
  EXPECT_CONTAINS(readError(text), "not a raster GDAL can read");
  // A vector dataset GDAL knows is not a raster either.
  const std::string json = (dir / "points.geojson").string();
  writeAll(json, R"({"type":"FeatureCollection","features":[{"type":"Feature","properties":{},)"
                 R"("geometry":{"type":"Point","coordinates":[1,2]}}]})");
  EXPECT_CONTAINS(readError(json), "not a raster GDAL can read");
  EXPECT_CONTAINS(readError(dir.string()), "is a directory, not a raster file");
}

TEST(BadInput, TruncatedTiff) {
  const auto dir = strata::test::tempDir("truncated");
  const std::string path = (dir / "t.tif").string();
  auto s = geoRaster();
  s.width = s.height = 128;
  ASSERT_TRUE(test::writeSynthetic(path, s));
  const std::string bytes = readAll(path);
  // Cut inside the pixel data: the header opens, the read fails.
  writeAll(path, bytes.substr(0, bytes.size() / 2));
  EXPECT_CONTAINS(readError(path), "read failed (truncated or corrupt file?)");
  // Cut inside the header.
  writeAll(path, bytes.substr(0, 12));
  EXPECT_CONTAINS(readError(path), "cannot open as a raster (corrupt or truncated?): TIFFFetchDirectory");
}

TEST(BadInput, CorruptTiff) {
  const auto dir = strata::test::tempDir("corrupt");
  const std::string path = (dir / "c.tif").string();
  std::string junk("II*\0", 4);
  junk += std::string("\x08\x00\x00\x00\xff\xff", 6);  // IFD at 8 claiming 65535 entries
  junk += std::string(200, '\x07');
  writeAll(path, junk);
  EXPECT_CONTAINS(readError(path), "cannot open as a raster (corrupt or truncated?)");
}

// Rewrites the TIFF's ImageWidth/ImageLength/RowsPerStrip (tags 256, 257, 278) as LONG values:
// one strip covering the claimed size, so the header is consistent and only the size is absurd.
void patchTiffSize(std::string& b, uint32_t width, uint32_t height) {
  ASSERT_EQ(b.substr(0, 4), std::string("II*\0", 4));  // classic little-endian TIFF, as GDAL writes
  uint32_t ifd = 0;
  std::memcpy(&ifd, b.data() + 4, 4);
  uint16_t n = 0;
  std::memcpy(&n, b.data() + ifd, 2);
  for (int i = 0; i < n; ++i) {
    char* e = b.data() + ifd + 2 + 12 * i;
    uint16_t tag = 0;
    std::memcpy(&tag, e, 2);
    if (tag != 256 && tag != 257 && tag != 278) continue;
    const uint16_t type = 4;  // LONG
    const uint32_t count = 1, value = tag == 256 ? width : height;
    std::memcpy(e + 2, &type, 2);
    std::memcpy(e + 4, &count, 4);
    std::memcpy(e + 8, &value, 4);
  }
}

TEST(BadInput, AbsurdHeaderSizeIsRefusedBeforeAllocating) {
  const auto dir = strata::test::tempDir("absurd");
  const std::string path = (dir / "huge.tif").string();
  ASSERT_TRUE(test::writeSynthetic(path, geoRaster()));
  std::string bytes = readAll(path);
  patchTiffSize(bytes, 4000000, 3000000);
  writeAll(path, bytes);
  // 4e6 x 3e6 float32 is 44 TiB: refused from the header, before any allocation.
  const std::string m = readError(path);
  EXPECT_CONTAINS(m, "4000000x3000000 pixels");
  EXPECT_CONTAINS(m, "exceed the read budget");
  // The budget applies to ordinary files too.
  const std::string small = (dir / "small.tif").string();
  ASSERT_TRUE(test::writeSynthetic(small, geoRaster()));
  ReadOptions o;
  o.maxBytes = 1000;
  EXPECT_CONTAINS(readError(small, o), "32x16 pixels (0.00195312 MiB as float32) exceed the read budget");
}

TEST(BadInput, NoGeoreferenceUnlessGivenExplicitly) {
  const auto dir = strata::test::tempDir("nogeo");
  const std::string path = (dir / "plain.tif").string();
  test::SyntheticRaster s;
  ASSERT_TRUE(test::writeSynthetic(path, s));
  EXPECT_CONTAINS(readError(path), "no georeference (no CRS and no geotransform); assign one (strata: --assign-crs");
  ReadOptions half;
  half.crs = "EPSG:32612";
  EXPECT_CONTAINS(readError(path, half), "no georeference (no geotransform); assign one");
  ReadOptions o = half;
  o.transform = GeoTransform{{400000, 30, 0, 4000000, 0, -30}};
  auto r = readDem(path, o);
  ASSERT_TRUE(r.ok()) << r.message();
  EXPECT_EQ(r->georef.epsg, 32612);
  EXPECT_EQ(r->georef.transform.c[0], 400000);
  EXPECT_EQ(r->values.at(3, 2), 23.0f);
  // A geotransform without a CRS is not enough.
  const std::string gtOnly = (dir / "gt_only.tif").string();
  s.gt = std::array<double, 6>{0, 1, 0, 0, 0, -1};
  ASSERT_TRUE(test::writeSynthetic(gtOnly, s));
  EXPECT_CONTAINS(readError(gtOnly), "no georeference (no CRS)");
}

TEST(BadInput, AllNoData) {
  const auto dir = strata::test::tempDir("allnodata");
  const std::string path = (dir / "empty.tif").string();
  auto s = geoRaster();
  s.type = GDT_Int16;
  s.nodata = -32768;
  s.values.assign(size_t(s.width) * s.height, -32768);
  ASSERT_TRUE(test::writeSynthetic(path, s));
  EXPECT_CONTAINS(readError(path), "no data: all 32x16 cells are nodata");
  ReadOptions o;
  o.allowAllNoData = true;
  auto r = readDem(path, o);
  ASSERT_TRUE(r.ok()) << r.message();
  EXPECT_TRUE(std::isnan(r->values.at(5, 5)));
}

TEST(BadInput, NaNValues) {
  const auto dir = strata::test::tempDir("nan");
  const std::string path = (dir / "nan.tif").string();
  auto s = geoRaster();
  s.values.assign(size_t(s.width) * s.height, 100.0);
  s.values[size_t(7) * s.width + 11] = std::numeric_limits<double>::quiet_NaN();
  ASSERT_TRUE(test::writeSynthetic(path, s));
  EXPECT_CONTAINS(readError(path), "NaN value at pixel (11, 7) and no NaN nodata value");
  // With NaN declared as the nodata value, NaN cells are simply nodata.
  s.nodata = std::numeric_limits<double>::quiet_NaN();
  const std::string declared = (dir / "nan_nodata.tif").string();
  ASSERT_TRUE(test::writeSynthetic(declared, s));
  auto r = readDem(declared);
  ASSERT_TRUE(r.ok()) << r.message();
  EXPECT_TRUE(std::isnan(r->values.at(11, 7)));
  EXPECT_EQ(r->values.at(0, 0), 100.0f);
}

TEST(BadInput, UnknownCrs) {
  const auto dir = strata::test::tempDir("crs");
  const std::string path = (dir / "plain.tif").string();
  ASSERT_TRUE(test::writeSynthetic(path, test::SyntheticRaster{}));
  ReadOptions o;
  o.crs = "EPSG:999999";
  o.transform = GeoTransform{};
  EXPECT_CONTAINS(readError(path, o), "unknown CRS 'EPSG:999999'");
  o.crs = "not a crs at all";
  EXPECT_CONTAINS(readError(path, o), "unknown CRS 'not a crs at all'");
  // A file whose CRS is an engineering (local) one: neither geographic nor projected.
  const std::string local = (dir / "local.tif").string();
  test::SyntheticRaster s;
  s.crs = R"(LOCAL_CS["site grid",UNIT["metre",1],AXIS["X",EAST],AXIS["Y",NORTH]])";
  s.gt = std::array<double, 6>{0, 1, 0, 0, 0, -1};
  ASSERT_TRUE(test::writeSynthetic(local, s));
  EXPECT_CONTAINS(readError(local), "unknown CRS 'site grid' (neither geographic nor projected)");
}

TEST(BadInput, AGridBeyondAnyBodyIsRefused) {
  // The fuzzer's input: a Web Mercator grid 1e20 m from the origin (GDAL 3.6 spins for hours
  // taking such a corner to lon/lat). Refused at the probe, naming the corner.
  const auto dir = strata::test::tempDir("far");
  const std::string path = (dir / "far.tif").string();
  auto s = geoRaster();
  s.crs = "EPSG:3857";
  s.gt = std::array<double, 6>{-1e20, 5e18, 0, 1e20, 0, -5e18};
  ASSERT_TRUE(test::writeSynthetic(path, s));
  EXPECT_CONTAINS(readError(path), "geotransform puts corner (0, 0) at (-1e+20, 1e+20), beyond any body");
  // 1e4 km off the origin is unusual but possible (a false easting): read.
  const std::string near = (dir / "near.tif").string();
  s.gt = std::array<double, 6>{1e7, 30, 0, 1e7, 0, -30};
  ASSERT_TRUE(test::writeSynthetic(near, s));
  EXPECT_TRUE(readDem(near).ok());
}

TEST(BadInput, WindowAndBandOutOfRange) {
  const auto dir = strata::test::tempDir("range");
  const std::string path = (dir / "g.tif").string();
  ASSERT_TRUE(test::writeSynthetic(path, geoRaster()));
  ReadOptions o;
  o.band = 2;
  EXPECT_CONTAINS(readError(path, o), "band 2 requested, the file has 1");
  o.band = 1;
  o.window = CellRect{-1, 0, 4, 4};
  EXPECT_CONTAINS(readError(path, o), "window 4x4+-1+0 is outside the 32x16 raster");
}

}  // namespace
}  // namespace strata::gis
