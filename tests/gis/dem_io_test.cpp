// Reading every shared DEM and comparing with what GDAL's own tools report; windowed reads;
// GeoTIFF / COG writing read back by gdalinfo.
#include <cpl_json.h>
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <random>
#include <sstream>

#include <strata/gis/dem_io.hpp>
#include <strata/gis/geodesy.hpp>

#include "gis_test_util.hpp"
#include "strata_test.hpp"

namespace strata::gis {
namespace {

using test::runCommand;

CPLJSONObject gdalinfoJson(const std::string& path) {
  const auto r = runCommand({"gdalinfo", "-json", path});
  EXPECT_EQ(r.status, 0) << "gdalinfo -json " << path;
  CPLJSONDocument doc;
  EXPECT_TRUE(doc.LoadMemory(r.out)) << r.out.substr(0, 200);
  return doc.GetRoot();
}

// Raw band values at pixel centres (x + 0.5, y + 0.5) from gdallocationinfo -valonly (one run,
// points on stdin).
std::vector<double> gdalValues(const std::string& path, const std::vector<std::pair<int, int>>& pixels) {
  std::ostringstream coords;
  for (auto [x, y] : pixels) coords << x << " " << y << "\n";
  const auto r = runCommand({"gdallocationinfo", "-valonly", path}, false, coords.str());
  EXPECT_EQ(r.status, 0);
  std::vector<double> v;
  std::istringstream in(r.out);
  std::string line;
  while (std::getline(in, line)) v.push_back(line.empty() ? std::nan("") : std::stod(line));
  return v;
}

// gdalinfo's EPSG code: stac "proj:epsg" (absent or null when the CRS has none).
std::optional<int> gdalEpsg(const CPLJSONObject& info) {
  const CPLJSONObject e = info.GetObj("stac/proj:epsg");
  if (!e.IsValid() || e.GetType() != CPLJSONObject::Type::Integer) return std::nullopt;
  return e.ToInteger();
}

struct DataFile {
  const char* relative;
  const char* driver;
  int width, height;
  const char* bodyName;
  bool geographic;
};

class SharedData : public ::testing::TestWithParam<DataFile> {};

TEST_P(SharedData, MatchesGdalToolsAtSampledPoints) {
  const DataFile& d = GetParam();
  const std::string path = test::dataFile(d.relative);
  auto dem = readDem(path);
  ASSERT_TRUE(dem.ok()) << dem.message();
  auto info = probeDem(path);
  ASSERT_TRUE(info.ok()) << info.message();
  const Georef& g = dem->georef;
  EXPECT_EQ(info->driver, d.driver);
  EXPECT_EQ(g.width, d.width);
  EXPECT_EQ(g.height, d.height);
  EXPECT_EQ(g.body.name, d.bodyName);
  EXPECT_EQ(g.geographic, d.geographic);

  const CPLJSONObject j = gdalinfoJson(path);
  EXPECT_EQ(j.GetString("driverShortName"), d.driver);
  const CPLJSONArray size = j.GetArray("size");
  EXPECT_EQ(size[0].ToInteger(), g.width);
  EXPECT_EQ(size[1].ToInteger(), g.height);
  EXPECT_EQ(gdalEpsg(j), g.epsg);
  const CPLJSONArray gt = j.GetArray("geoTransform");
  ASSERT_EQ(gt.Size(), 6);
  for (int i = 0; i < 6; ++i) {
    // gdalinfo prints 16+ significant digits: the text round trip is within an ulp or two.
    EXPECT_NEAR(gt[i].ToDouble(), g.transform.c[i], 1e-12 * std::max(1.0, std::abs(g.transform.c[i]))) << i;
  }
  const CPLJSONObject band = j.GetArray("bands")[0];
  EXPECT_EQ(band.GetString("type"), info->bandType);
  const double scale = band.GetDouble("scale", 1.0), offset = band.GetDouble("offset", 0.0);
  EXPECT_EQ(scale, info->scale);
  EXPECT_EQ(offset, info->offset);
  const CPLJSONObject nd = band.GetObj("noDataValue");
  EXPECT_EQ(nd.IsValid(), info->nodata.has_value());
  if (nd.IsValid() && info->nodata) {
    EXPECT_EQ(nd.ToDouble(), *info->nodata);
  }
  // Radius products (the Moon's LDEM: offset = 1737.4 km) come back as heights above the sphere.
  const double datum = info->offsetIsBodyRadius ? g.body.semiMajorM : 0.0;
  EXPECT_EQ(info->offsetIsBodyRadius, std::string(d.driver) == "PDS");

  std::mt19937 rng(42);
  std::vector<std::pair<int, int>> px = {{0, 0}, {g.width - 1, 0}, {0, g.height - 1}, {g.width - 1, g.height - 1}};
  for (int i = 0; i < 60; ++i) px.emplace_back(int(rng() % g.width), int(rng() % g.height));
  const auto raw = gdalValues(path, px);
  ASSERT_EQ(raw.size(), px.size());
  int nodataSeen = 0;
  for (size_t i = 0; i < px.size(); ++i) {
    const float v = dem->values.at(px[i].first, px[i].second);
    if (info->nodata && raw[i] == *info->nodata) {
      EXPECT_TRUE(std::isnan(v)) << "nodata at " << px[i].first << "," << px[i].second << " read as " << v;
      ++nodataSeen;
      continue;
    }
    const double expected = raw[i] * scale + offset - datum;
    // gdallocationinfo prints float32 values with enough digits to round-trip (int16 exactly);
    // the remaining difference is float32 rounding of our metres: half an ulp, < 1e-7 relative.
    EXPECT_NEAR(v, expected, 1e-7 * std::max(1.0, std::abs(expected)))
        << d.relative << " pixel " << px[i].first << "," << px[i].second;
  }
  EXPECT_LT(nodataSeen, int(px.size()));
}

INSTANTIATE_TEST_SUITE_P(
    Gis, SharedData,
    ::testing::Values(DataFile{"grand_canyon/grand_canyon_512.tif", "GTiff", 512, 512, "Earth (WGS84)", true},
                      DataFile{"grand_canyon/grandcanyon_srtm_3857.tif", "GTiff", 512, 512, "Earth (WGS84)", false},
                      DataFile{"rainier/mt_rainier_90m.tif", "GTiff", 1201, 1201, "Earth (WGS84)", true},
                      DataFile{"earth/etopo20.tif", "GTiff", 1080, 540, "Earth (WGS84)", true},
                      DataFile{"moon/LDEM_4.LBL", "PDS", 1440, 720, "Moon", false},
                      DataFile{"mars/mola_megdr_4ppd.vrt", "VRT", 1440, 720, "Mars", true}),
    [](const auto& p) {
      std::string n = std::filesystem::path(p.param.relative).stem().string();
      for (char& c : n)
        if (!std::isalnum(static_cast<unsigned char>(c))) c = '_';
      return n;
    });

TEST(DemIo, GeorefFieldsOfTheSharedData) {
  auto gc = probeDem(test::dataFile("grand_canyon/grandcanyon_srtm_3857.tif"));
  ASSERT_TRUE(gc.ok()) << gc.message();
  EXPECT_EQ(gc->georef.epsg, 3857);
  EXPECT_EQ(gc->georef.crsName, "WGS 84 / Pseudo-Mercator");
  EXPECT_EQ(gc->bandType, "Int16");
  EXPECT_EQ(gc->nodata, -32768.0);
  auto moon = probeDem(test::dataFile("moon/LDEM_4.LBL"));
  ASSERT_TRUE(moon.ok()) << moon.message();
  EXPECT_FALSE(moon->georef.epsg.has_value());
  EXPECT_EQ(moon->georef.body.semiMajorM, 1737400.0);
  EXPECT_TRUE(moon->georef.body.isSphere());
  auto mars = probeDem(test::dataFile("mars/mola_megdr_4ppd.vrt"));
  ASSERT_TRUE(mars.ok()) << mars.message();
  EXPECT_EQ(mars->georef.body.semiMajorM, 3396190.0);
  // Mars' grid runs 0..360 E: kept as the file says, not re-centred.
  EXPECT_EQ(mars->georef.transform.c[0], 0.0);
  EXPECT_EQ(mars->georef.transform.x(mars->georef.width, 0), 360.0);
}

TEST(DemIo, WindowEqualsTheSameCellsOfAFullRead) {
  const std::string path = test::dataFile("grand_canyon/grandcanyon_srtm_3857.tif");
  auto full = readDem(path);
  ASSERT_TRUE(full.ok()) << full.message();
  ReadOptions o;
  o.window = CellRect{300, 100, 64, 32};
  auto win = readDem(path, o);
  ASSERT_TRUE(win.ok()) << win.message();
  ASSERT_EQ(win->values.width, 64);
  ASSERT_EQ(win->values.height, 32);
  for (int y = 0; y < 32; ++y)
    for (int x = 0; x < 64; ++x) ASSERT_EQ(win->values.at(x, y), full->values.at(300 + x, 100 + y));
  EXPECT_DOUBLE_EQ(win->georef.transform.c[0], full->georef.transform.x(300, 100));
  EXPECT_DOUBLE_EQ(win->georef.transform.c[3], full->georef.transform.y(300, 100));
  EXPECT_EQ(win->georef.transform.c[1], full->georef.transform.c[1]);
  o.window = CellRect{500, 0, 64, 32};
  auto outside = readDem(path, o);
  ASSERT_FALSE(outside.ok());
  EXPECT_NE(outside.message().find("window 64x32+500+0 is outside the 512x512 raster"), std::string::npos)
      << outside.message();
}

// A window read decodes only the tiles it touches: with every other tile's data destroyed, the
// window still reads, and the whole raster does not.
TEST(DemIo, WindowReadsOnlyItsTiles) {
  const auto dir = strata::test::tempDir("window");
  const std::string path = (dir / "tiled.tif").string();
  test::SyntheticRaster s;
  s.width = s.height = 1024;
  s.crs = "EPSG:32612";
  s.gt = std::array<double, 6>{400000, 30, 0, 4000000, 0, -30};
  s.creationOptions = {"TILED=YES", "BLOCKXSIZE=256", "BLOCKYSIZE=256", "COMPRESS=DEFLATE"};
  ASSERT_TRUE(test::writeSynthetic(path, s));
  std::vector<std::pair<long, long>> damaged;  // offset, size of each tile but (0, 0)
  {
    GDALDataset* ds = GDALDataset::Open(path.c_str(), GDAL_OF_RASTER);
    ASSERT_NE(ds, nullptr);
    for (int ty = 0; ty < 4; ++ty)
      for (int tx = 0; tx < 4; ++tx) {
        if (tx == 0 && ty == 0) continue;
        const std::string key = std::to_string(tx) + "_" + std::to_string(ty);
        const char* off = ds->GetRasterBand(1)->GetMetadataItem(("BLOCK_OFFSET_" + key).c_str(), "TIFF");
        const char* sz = ds->GetRasterBand(1)->GetMetadataItem(("BLOCK_SIZE_" + key).c_str(), "TIFF");
        ASSERT_TRUE(off && sz) << key;
        damaged.emplace_back(std::atol(off), std::atol(sz));
      }
    GDALClose(ds);
  }
  {
    std::fstream f(path, std::ios::in | std::ios::out | std::ios::binary);
    for (auto [off, sz] : damaged) {
      f.seekp(off);
      const std::string junk(size_t(sz), '\x5a');
      f.write(junk.data(), std::streamsize(junk.size()));
    }
  }
  ReadOptions o;
  o.window = CellRect{10, 20, 200, 100};
  auto win = readDem(path, o);
  ASSERT_TRUE(win.ok()) << win.message();
  EXPECT_EQ(win->values.at(0, 0), 10 + 10 * 20);
  EXPECT_EQ(win->values.at(199, 99), 209 + 10 * 119);
  auto full = readDem(path);
  ASSERT_FALSE(full.ok());
  EXPECT_NE(full.message().find(path + ": read failed (truncated or corrupt file?)"), std::string::npos)
      << full.message();
}

TEST(DemIo, WrittenGeoTiffReadsBackInGdalinfo) {
  const auto dir = strata::test::tempDir("write");
  ReadOptions o;
  o.window = CellRect{100, 50, 96, 80};
  auto src = readDem(test::dataFile("grand_canyon/grandcanyon_srtm_3857.tif"), o);
  ASSERT_TRUE(src.ok()) << src.message();
  src->values.at(3, 4) = kNoData;  // a hole must come back as nodata
  for (bool cog : {false, true}) {
    const std::string path = (dir / (cog ? "out_cog.tif" : "out.tif")).string();
    WriteOptions w;
    w.cog = cog;
    w.blockSize = 64;
    ASSERT_TRUE(writeGeoTiff(path, *src, w).ok());
    EXPECT_FALSE(std::filesystem::exists(path + ".tmp" + std::to_string(::getpid())));
    const CPLJSONObject j = gdalinfoJson(path);
    EXPECT_EQ(gdalEpsg(j), 3857);
    const CPLJSONArray gt = j.GetArray("geoTransform");
    for (int i = 0; i < 6; ++i) EXPECT_NEAR(gt[i].ToDouble(), src->georef.transform.c[i], 1e-12 * 1.3e7) << i;
    const CPLJSONObject band = j.GetArray("bands")[0];
    EXPECT_EQ(band.GetString("type"), "Float32");
    EXPECT_EQ(band.GetDouble("noDataValue"), -32768.0);
    EXPECT_EQ(band.GetArray("block")[0].ToInteger(), 64);
    EXPECT_EQ(j.GetString("metadata/IMAGE_STRUCTURE/COMPRESSION"), "DEFLATE");
    if (cog) {
      EXPECT_EQ(j.GetString("metadata/IMAGE_STRUCTURE/LAYOUT"), "COG");
    }
    auto back = readDem(path);
    ASSERT_TRUE(back.ok()) << back.message();
    for (size_t i = 0; i < back->values.size(); ++i) {
      const float a = src->values.data[i], b = back->values.data[i];
      ASSERT_TRUE(a == b || (std::isnan(a) && std::isnan(b))) << i;
    }
  }
  // A CRS without an EPSG code (the Moon's) survives the round trip.
  o.window = CellRect{0, 0, 64, 32};
  auto moon = readDem(test::dataFile("moon/LDEM_4.LBL"), o);
  ASSERT_TRUE(moon.ok()) << moon.message();
  const std::string moonPath = (dir / "moon.tif").string();
  ASSERT_TRUE(writeGeoTiff(moonPath, *moon).ok());
  auto moonBack = probeDem(moonPath);
  ASSERT_TRUE(moonBack.ok()) << moonBack.message();
  EXPECT_EQ(moonBack->georef.body.name, "Moon");
  OGRSpatialReference a, b;
  a.importFromWkt(moon->georef.crsWkt.c_str());
  b.importFromWkt(moonBack->georef.crsWkt.c_str());
  EXPECT_TRUE(a.IsSame(&b)) << moonBack->georef.crsWkt;
}

// A GeoTIFF written window by window (what each MPI rank does with its blocks of a map) holds
// the same cells, CRS and geotransform as one written whole; cells no window wrote read as
// nodata; a window outside the raster or holding the nodata value is refused, naming the file.
TEST(DemIo, GeoTiffWrittenByWindowsEqualsOneWrittenWhole) {
  const auto dir = strata::test::tempDir("windows");
  ReadOptions o;
  o.window = CellRect{100, 50, 150, 90};
  auto src = readDem(test::dataFile("grand_canyon/grandcanyon_srtm_3857.tif"), o);
  ASSERT_TRUE(src.ok()) << src.message();
  src->values.at(7, 9) = kNoData;
  WriteOptions w;
  w.blockSize = 64;  // windows below cut tiles, so some tiles are written by two windows
  w.metadata = {{"STRATA_TEST", "windows"}};
  const std::string whole = (dir / "whole.tif").string(), parts = (dir / "parts.tif").string();
  ASSERT_TRUE(writeGeoTiff(whole, *src, w).ok());
  ASSERT_TRUE(createGeoTiff(parts, src->georef, w).ok());
  auto window = [&](int x, int y, int width, int height) {
    Grid<float> g(width, height);
    for (int r = 0; r < height; ++r) {
      for (int c = 0; c < width; ++c) g.at(c, r) = src->values.at(x + c, y + r);
    }
    return g;
  };
  // Three of four quadrants, in an order that revisits tiles.
  ASSERT_TRUE(writeGeoTiffWindows(parts, {{70, 40, window(70, 40, 80, 50)}, {0, 0, window(0, 0, 70, 40)}}).ok());
  ASSERT_TRUE(writeGeoTiffWindows(parts, {{70, 0, window(70, 0, 80, 40)}}).ok());
  auto partial = readDem(parts, [] {
    ReadOptions r;
    r.allowAllNoData = true;
    return r;
  }());
  ASSERT_TRUE(partial.ok()) << partial.message();
  for (int y = 0; y < 90; ++y) {
    for (int x = 0; x < 150; ++x) {
      const float a = src->values.at(x, y), b = partial->values.at(x, y);
      if (x < 70 && y >= 40) {
        ASSERT_TRUE(std::isnan(b)) << x << ", " << y << ": never written, reads " << b;
      } else {
        ASSERT_TRUE(a == b || (std::isnan(a) && std::isnan(b))) << x << ", " << y;
      }
    }
  }
  ASSERT_TRUE(writeGeoTiffWindows(parts, {{0, 40, window(0, 40, 70, 50)}}).ok());
  const CPLJSONObject a = gdalinfoJson(whole), b = gdalinfoJson(parts);
  EXPECT_EQ(gdalEpsg(b), 3857);
  for (int i = 0; i < 6; ++i)
    EXPECT_EQ(a.GetArray("geoTransform")[i].ToDouble(), b.GetArray("geoTransform")[i].ToDouble());
  EXPECT_EQ(b.GetString("metadata/IMAGE_STRUCTURE/COMPRESSION"), "DEFLATE");
  EXPECT_EQ(b.GetArray("bands")[0].GetDouble("noDataValue"), -32768.0);
  EXPECT_NE(runCommand({"gdalinfo", parts}).out.find("STRATA_TEST=windows"), std::string::npos);
  auto x = readDem(whole), y = readDem(parts);
  ASSERT_TRUE(x.ok() && y.ok());
  for (size_t i = 0; i < x->values.size(); ++i) {
    const float p = x->values.data[i], q = y->values.data[i];
    ASSERT_TRUE(p == q || (std::isnan(p) && std::isnan(q))) << i;
  }
  auto outside = writeGeoTiffWindows(parts, {{100, 50, window(0, 0, 60, 41)}});
  ASSERT_FALSE(outside.ok());
  EXPECT_NE(outside.message().find(parts + ": the window (100, 50) 60x41 is not inside its 150x90 cells"),
            std::string::npos)
      << outside.message();
  Grid<float> clash(2, 2, 1.0f);
  clash.at(1, 0) = -32768.0f;
  auto refused = writeGeoTiffWindows(parts, {{0, 0, clash}});
  ASSERT_FALSE(refused.ok());
  EXPECT_NE(refused.message().find(parts + ": cannot write: the value -32768"), std::string::npos);
  auto missing = writeGeoTiffWindows((dir / "none.tif").string(), {{0, 0, Grid<float>(2, 2, 1.0f)}});
  EXPECT_FALSE(missing.ok());
}

TEST(DemIo, WriteRefusesAValueEqualToNodata) {
  Raster r;
  r.georef.width = r.georef.height = 2;
  r.georef.crsWkt = "EPSG:4326";
  r.georef.transform = GeoTransform{{0, 1, 0, 0, 0, -1}};
  r.values = Grid<float>(2, 2, 5.0f);
  r.values.at(1, 1) = -32768.0f;
  const auto dir = strata::test::tempDir("nd");
  const std::string path = (dir / "x.tif").string();
  auto s = writeGeoTiff(path, r);
  ASSERT_FALSE(s.ok());
  EXPECT_NE(s.message().find(path + ": cannot write: the value -32768"), std::string::npos) << s.message();
  EXPECT_FALSE(std::filesystem::exists(path));
}

// readDemLonLat: the Moon's LDEM (equirectangular on the 1737.4 km sphere, central meridian
// 180) relabelled in degrees gives, at every probed cell corner, the lon/lat PROJ computes from
// its projected georeference, and the same cells; a geographic DEM comes back unchanged.
TEST(DemIo, ReadDemLonLatRelabelsTheMoonsEquirectangularGrid) {
  const std::string path = test::dataFile("moon/LDEM_4.LBL");
  auto projected = readDem(path);
  ASSERT_TRUE(projected) << projected.message();
  auto ll = readDemLonLat(path);
  ASSERT_TRUE(ll) << ll.message();
  EXPECT_TRUE(ll->georef.geographic);
  EXPECT_EQ(ll->georef.body.name, projected->georef.body.name);
  EXPECT_EQ(ll->values.data, projected->values.data);  // relabelled, not resampled
  // 4 pixels per degree, up to the label's map scale rounded to the metre (7581.9 m: 0.25000008).
  EXPECT_NEAR(ll->georef.transform.c[1], 0.25, 1e-6);
  EXPECT_NEAR(ll->georef.transform.c[5], -0.25, 1e-6);
  for (auto [col, row] : {std::pair{0.0, 0.0}, std::pair{100.5, 300.25}, std::pair{1439.0, 719.0}}) {
    auto expect = pixelToLonLat(projected->georef, col, row);
    ASSERT_TRUE(expect) << expect.message();
    double lon = ll->georef.transform.x(col, row), lat = ll->georef.transform.y(col, row);
    while (lon - expect->lonDeg > 180) lon -= 360;  // PROJ answers in -180..180
    while (expect->lonDeg - lon > 180) lon += 360;
    // 1e-9 degree: the relabelling is exact up to rounding of the geotransform.
    EXPECT_NEAR(lon, expect->lonDeg, 1e-9) << col << ", " << row;
    EXPECT_NEAR(lat, expect->latDeg, 1e-9) << col << ", " << row;
  }
  auto gc = readDemLonLat(test::dataFile("grand_canyon/grand_canyon_512.tif"));
  auto gcDirect = readDem(test::dataFile("grand_canyon/grand_canyon_512.tif"));
  ASSERT_TRUE(gc && gcDirect);
  for (int k = 0; k < 6; ++k) EXPECT_EQ(gc->georef.transform.c[k], gcDirect->georef.transform.c[k]);
}

}  // namespace
}  // namespace strata::gis
