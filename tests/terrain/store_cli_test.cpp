// The store's command-line verbs, run as the real `strata` binary.
#include <gtest/gtest.h>

#include <sys/wait.h>

#include <cstdio>
#include <cstdlib>
#include <fstream>

#include <strata/gis/dem_io.hpp>
#include <strata/terrain/dem_sources.hpp>
#include <strata/terrain/ingest.hpp>
#include <strata/terrain/synthetic.hpp>
#include <strata/terrain/tile_store.hpp>

#include "strata_test.hpp"

namespace strata::terrain {
namespace {

namespace fs = std::filesystem;

struct Run {
  int status = -1;
  std::string output;  // stdout and stderr together
};

Run runCli(const std::string& args) {
  Run r;
  const std::string cmd = std::string(STRATA_CLI) + " " + args + " 2>&1";
  FILE* p = popen(cmd.c_str(), "r");
  STRATA_CHECK(p) << cmd;
  char buf[4096];
  size_t n = 0;
  while ((n = fread(buf, 1, sizeof buf, p)) > 0) r.output.append(buf, n);
  const int st = pclose(p);
  r.status = WIFEXITED(st) ? WEXITSTATUS(st) : -1;
  return r;
}

fs::path smallStore() {
  const auto dir = test::tempDir("store");
  gis::Georef g;
  g.width = 128;
  g.height = 64;
  SyntheticScene s;
  s.blockCells = 32;
  IngestOptions o;
  o.metric = {2, 5};
  auto rep = ingest(dir, g, {{{"bedrock", LayerKind::Bedrock, ""}, syntheticReader(s)}}, o);
  STRATA_CHECK(rep.ok()) << rep.message();
  return dir;
}

TEST(StrataCheck, PassesASoundStoreAndNamesACorruptTile) {
  const auto dir = smallStore();
  const auto ok = runCli("check " + dir.string());
  EXPECT_EQ(ok.status, 0) << ok.output;
  EXPECT_NE(ok.output.find("result    OK"), std::string::npos) << ok.output;
  EXPECT_NE(ok.output.find("4 x 2 of 32 cells"), std::string::npos) << ok.output;

  // Flip one byte in the middle of one tile file.
  fs::path victim;
  for (const auto& e : fs::directory_iterator(dir / "tiles")) victim = e.path();
  {
    std::fstream f(victim, std::ios::in | std::ios::out | std::ios::binary);
    const auto at = std::streamoff(fs::file_size(victim) / 2);
    f.seekg(at);
    char c = 0;
    f.read(&c, 1);
    c = char(~c);
    f.seekp(at);
    f.write(&c, 1);
  }
  const auto bad = runCli("check " + dir.string());
  EXPECT_EQ(bad.status, 1) << bad.output;
  EXPECT_NE(bad.output.find(victim.filename().string() + ": checksum mismatch"), std::string::npos) << bad.output;
  EXPECT_NE(bad.output.find("1 corrupt tile"), std::string::npos) << bad.output;

  const auto missing = runCli("check " + (dir / "nothing").string());
  EXPECT_EQ(missing.status, 1);
  EXPECT_NE(missing.output.find("manifest.toml: cannot read"), std::string::npos) << missing.output;
}

// `gdalinfo -json FILE`'s geotransform and CRS WKT.
struct GdalInfo {
  std::vector<double> geoTransform;
  std::string wkt;
};
GdalInfo gdalInfo(const std::string& path) {
  FILE* p = popen(("gdalinfo -json " + path + " 2>&1").c_str(), "r");
  STRATA_CHECK(p) << path;
  std::string out;
  char buf[4096];
  size_t n = 0;
  while ((n = fread(buf, 1, sizeof buf, p)) > 0) out.append(buf, n);
  pclose(p);
  GdalInfo info;
  const auto gt = out.find("\"geoTransform\":");
  STRATA_CHECK(gt != std::string::npos) << out;
  const char* c = out.c_str() + out.find('[', gt) + 1;
  for (int i = 0; i < 6; ++i) {
    char* end = nullptr;
    info.geoTransform.push_back(std::strtod(c, &end));
    c = end + 1;  // past the comma
  }
  const auto wkt = out.find("\"wkt\":");
  STRATA_CHECK(wkt != std::string::npos) << out;
  size_t q = out.find('"', wkt + 6) + 1;
  for (; q < out.size() && out[q] != '"'; ++q) {  // up to the closing (unescaped) quote
    if (out[q] == '\\') ++q;
    info.wkt += out[q];
  }
  return info;
}

TEST(StrataExport, AWindowKeepsTheSourcesCrsAndGeotransform) {
  const std::string dem = test::dataPath("grand_canyon/grand_canyon_512.tif");
  const auto dir = test::tempDir("gc");
  const auto ing = runCli("ingest " + (dir / "store").string() + " --dem " + dem + " --min-exp 1 --max-exp 6");
  ASSERT_EQ(ing.status, 0) << ing.output;
  const auto out = (dir / "window.tif").string();
  const auto ex = runCli("export " + (dir / "store").string() + " " + out + " --window 64 128 100 50");
  ASSERT_EQ(ex.status, 0) << ex.output;
  const auto src = gdalInfo(dem), got = gdalInfo(out);
  EXPECT_GT(src.wkt.size(), 100u);  // the whole WKT, not a prefix
  EXPECT_EQ(got.wkt, src.wkt);
  ASSERT_EQ(got.geoTransform.size(), 6u);
  // Shifted by 64 columns and 128 rows of the source's pixel size; gdalinfo prints 17 significant
  // digits, so the comparison is to 1e-12 degrees.
  EXPECT_NEAR(got.geoTransform[0], src.geoTransform[0] + 64 * src.geoTransform[1], 1e-12);
  EXPECT_NEAR(got.geoTransform[3], src.geoTransform[3] + 128 * src.geoTransform[5], 1e-12);
  EXPECT_EQ(got.geoTransform[1], src.geoTransform[1]);
  EXPECT_EQ(got.geoTransform[5], src.geoTransform[5]);
  // The exported cells are the store's.
  auto store = TileStore::open(dir / "store");
  ASSERT_TRUE(store);
  auto fromStore = store->readWindow(0, {64, 128, 100, 50}, 0);
  auto fromFile = gis::readDem(out);
  ASSERT_TRUE(fromStore && fromFile) << (fromFile ? "" : fromFile.message());
  EXPECT_EQ(fromFile->values.data, fromStore->data);
  // A coarser level: pixels twice as wide, same origin.
  const auto lod1 = runCli("export " + (dir / "store").string() + " " + (dir / "lod1.tif").string() + " --lod 1");
  ASSERT_EQ(lod1.status, 0) << lod1.output;
  const auto half = gdalInfo((dir / "lod1.tif").string());
  EXPECT_EQ(half.geoTransform[1], 2 * src.geoTransform[1]);
  EXPECT_EQ(half.geoTransform[0], src.geoTransform[0]);
}

TEST(DemSources, MosaicWindowsMatchTheSource) {
  const std::string dem = test::dataPath("grand_canyon/grand_canyon_512.tif");
  auto info = gis::probeDem(dem);
  ASSERT_TRUE(info) << info.message();
  gis::ReadOptions window;
  window.window = gis::PixelWindow{100, 200, 64, 32};
  auto ref = gis::readDem(dem, window);
  ASSERT_TRUE(ref) << ref.message();
  // One input on the store's own grid: read directly, bit for bit.
  gis::MosaicInput first, second;
  first.path = second.path = dem;
  second.mode = gis::BlendMode::Add;
  auto direct = mosaicReader({first}, info->georef);
  ASSERT_TRUE(direct) << direct.message();
  auto a = (*direct)(100, 200, 64, 32);
  ASSERT_TRUE(a) << a.message();
  EXPECT_EQ(a->data, ref->values.data);
  // The same DEM twice, the second added: warped per window onto the same grid, doubled.
  auto twice = mosaicReader({first, second}, info->georef);
  ASSERT_TRUE(twice) << twice.message();
  auto b = (*twice)(100, 200, 64, 32);
  ASSERT_TRUE(b) << b.message();
  for (size_t i = 0; i < b->data.size(); ++i) {
    // Warping onto identical pixel centres reproduces each value up to float32 rounding of
    // ~2000 m (1.2e-4 m) in the interpolation weights: 1e-2 m is a safe bound for the sum.
    ASSERT_NEAR(b->data[i], 2.0f * ref->values.data[i], 1e-2f) << i;
  }
}

}  // namespace
}  // namespace strata::terrain
