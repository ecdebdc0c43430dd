// The store's command-line verbs, run as the real `strata` binary.
#include <gtest/gtest.h>

#include <fcntl.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <map>
#include <thread>

#include <strata/core/interrupt.hpp>
#include <strata/gis/dem_io.hpp>
#include <strata/terrain/dem_sources.hpp>
#include <strata/terrain/ingest.hpp>
#include <strata/terrain/synthetic.hpp>
#include <strata/terrain/tile_store.hpp>

#include "strata_test.hpp"

namespace strata::terrain {
namespace {

namespace fs = std::filesystem;

// `strata ARGS...`, no shell between (file names are arguments, never command text).
test::ProgramRun runCli(std::vector<std::string> args) {
  args.insert(args.begin(), STRATA_CLI);
  return test::runProgram(args);
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
  const auto ok = runCli({"check", dir.string()});
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
  const auto bad = runCli({"check", dir.string()});
  EXPECT_EQ(bad.status, 1) << bad.output;
  EXPECT_NE(bad.output.find(victim.filename().string() + ": checksum mismatch"), std::string::npos) << bad.output;
  EXPECT_NE(bad.output.find("result    1 problem(s)"), std::string::npos) << bad.output;

  const auto missing = runCli({"check", (dir / "nothing").string()});
  EXPECT_EQ(missing.status, 1);
  EXPECT_NE(missing.output.find("manifest.toml: cannot read"), std::string::npos) << missing.output;
}

// `gdalinfo -json FILE`'s geotransform and CRS WKT.
struct GdalInfo {
  std::vector<double> geoTransform;
  std::string wkt;
};
GdalInfo gdalInfo(const std::string& path) {
  const std::string out = test::runProgram({"gdalinfo", "-json", path}).output;
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
  const auto ing = runCli({"ingest", (dir / "store").string(), "--dem", dem, "--min-exp", "1", "--max-exp", "6"});
  ASSERT_EQ(ing.status, 0) << ing.output;
  const auto out = (dir / "window.tif").string();
  const auto ex = runCli({"export", (dir / "store").string(), out, "--window", "64", "128", "100", "50"});
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
  const auto lod1 = runCli({"export", (dir / "store").string(), (dir / "lod1.tif").string(), "--lod", "1"});
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
  window.window = gis::CellRect{100, 200, 64, 32};
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

// gdal_translate SRC -> DST with extra arguments.
fs::path crop(const fs::path& dst, std::vector<std::string> args,
              const std::string& src = "rainier/mt_rainier_90m.tif") {
  args.insert(args.begin(), {"gdal_translate", "-q"});
  args.push_back(test::dataPath(src));
  args.push_back(dst);
  const auto r = test::runProgram(args);
  STRATA_CHECK(r.status == 0) << "gdal_translate: " << r.output;
  return dst;
}

std::vector<std::string> operator+(std::vector<std::string> a, const std::vector<std::string>& b) {
  a.insert(a.end(), b.begin(), b.end());
  return a;
}

std::string slurp(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  return std::string((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
}

std::map<std::string, std::string> storeFiles(const fs::path& dir) {
  std::map<std::string, std::string> files;
  for (const auto& e : fs::recursive_directory_iterator(dir)) {
    if (e.is_regular_file() && e.path().filename() != "writer.lock") {
      files[fs::relative(e.path(), dir).string()] = slurp(e.path());
    }
  }
  return files;
}

bool sameCells(const gis::Grid<float>& a, const gis::Grid<float>& b) {
  if (a.width != b.width || a.height != b.height) return false;
  for (size_t i = 0; i < a.data.size(); ++i) {
    if (std::isnan(a.data[i]) != std::isnan(b.data[i])) return false;
    if (!std::isnan(a.data[i]) && a.data[i] != b.data[i]) return false;
  }
  return true;
}

TEST(StrataIngest, TwoHalvesMosaicToTheWholeAndPathsWithAnAtWork) {
  const auto dir = test::tempDir("halves");
  const auto west = crop(dir / "we@st.tif", {"-srcwin", "600", "500", "128", "160"});  // '@' in the name
  const auto east = crop(dir / "east.tif", {"-srcwin", "728", "500", "128", "160"});
  const auto whole = crop(dir / "whole.tif", {"-srcwin", "600", "500", "256", "160"});
  auto ing =
      runCli({"ingest", dir / "halves", "--dem", west, "--blend", "replace", east, "--min-exp", "1", "--max-exp", "6"});
  ASSERT_EQ(ing.status, 0) << ing.output;
  ASSERT_EQ(runCli({"ingest", dir / "whole", "--dem", whole, "--min-exp", "1", "--max-exp", "6"}).status, 0);
  ASSERT_EQ(runCli({"export", dir / "halves", dir / "halves.tif"}).status, 0);
  auto ex = runCli({"export", dir / "whole", dir / "whole_out.tif"});
  ASSERT_EQ(ex.status, 0) << ex.output;
  EXPECT_NE(ex.output.find("167 of 40960 cells are nodata"), std::string::npos) << ex.output;
  auto a = gis::readDem((dir / "halves.tif").string()), b = gis::readDem((dir / "whole_out.tif").string()),
       src = gis::readDem(whole.string());
  ASSERT_TRUE(a && b && src);
  EXPECT_TRUE(sameCells(a->values, b->values));
  // Exact at the default tolerance, with the source's voids as nodata, and it says so.
  EXPECT_TRUE(sameCells(a->values, src->values));
  const std::string out = test::runProgram({"gdalinfo", dir / "halves.tif"}).output;
  EXPECT_NE(out.find("STRATA_MAX_ERROR_M=0"), std::string::npos) << out;
  EXPECT_NE(out.find("STRATA_ERROR_TOLERANCE_M=0.5"), std::string::npos) << out;
  // The older PATH@MODE form still works where it is unambiguous.
  auto legacy = runCli({"ingest", dir / "legacy", "--dem", whole, "--dem", east.string() + "@max", "--max-exp", "6"});
  EXPECT_EQ(legacy.status, 0) << legacy.output;
}

TEST(StrataExport, NeverOverwritesOrWritesInsideAStore) {
  const auto dir = test::tempDir("export");
  const auto dem = crop(dir / "dem.tif", {"-srcwin", "600", "500", "128", "96"});
  const auto store = dir / "store";
  ASSERT_EQ(runCli({"ingest", store, "--dem", dem, "--max-exp", "6"}).status, 0);
  const auto manifest = slurp(store / "manifest.toml");
  auto onManifest = runCli({"export", store, store / "manifest.toml"});
  EXPECT_EQ(onManifest.status, 1);
  EXPECT_NE(onManifest.output.find("inside the tile store"), std::string::npos) << onManifest.output;
  EXPECT_EQ(slurp(store / "manifest.toml"), manifest);
  EXPECT_EQ(runCli({"export", store, store / "tiles" / "x.tif"}).status, 1);
  EXPECT_EQ(runCli({"check", store}).status, 0);
  std::ofstream(dir / "mine.tif") << "not to be replaced";
  auto existing = runCli({"export", store, dir / "mine.tif"});
  EXPECT_EQ(existing.status, 1);
  EXPECT_NE(existing.output.find("mine.tif: already exists (pass --overwrite to replace it)"), std::string::npos);
  EXPECT_EQ(slurp(dir / "mine.tif"), "not to be replaced");
  EXPECT_EQ(runCli({"export", store, dir / "mine.tif", "--overwrite"}).status, 0);
  auto outside = runCli({"export", store, dir / "w.tif", "--window", "100", "0", "64", "8"});
  EXPECT_EQ(outside.status, 1);
  EXPECT_NE(outside.output.find("reaches outside level 0's 128 x 96 cells"), std::string::npos) << outside.output;
}

TEST(StrataCheck, FailsOnAnIncompleteStoreAndOnAMissingTile) {
  const auto dir = test::tempDir("incomplete");
  auto dem = gis::readDem(crop(dir / "dem.tif", {"-srcwin", "600", "500", "256", "128"}).string());
  ASSERT_TRUE(dem);
  int reads = 0;
  auto values = dem->values;
  IngestOptions o;
  o.metric = {1, 6};
  auto r = ingest(dir / "store", dem->georef,
                  {{{"bedrock", LayerKind::Bedrock, ""},
                    [&](int x, int y, int w, int h) -> Result<gis::Grid<float>> {
                      if (++reads == 3) setInterrupted(true);
                      gis::Grid<float> g(w, h);
                      for (int j = 0; j < h; ++j)
                        std::copy_n(&values.data[values.index(x, y + j)], w, &g.data[g.index(0, j)]);
                      return g;
                    }}},
                  o);
  setInterrupted(false);
  ASSERT_FALSE(r);
  auto check = runCli({"check", dir / "store"});
  EXPECT_EQ(check.status, 1) << check.output;
  EXPECT_NE(check.output.find("INCOMPLETE: ingest stopped in pass 2 after 3 of 8 tiles"), std::string::npos)
      << check.output;
  auto ex = runCli({"export", dir / "store", dir / "out.tif"});
  EXPECT_EQ(ex.status, 1);
  EXPECT_NE(ex.output.find("incomplete store"), std::string::npos) << ex.output;
  EXPECT_FALSE(fs::exists(dir / "out.tif"));
  // A complete store whose tile file is gone: check fails naming it, export of it fails.
  ASSERT_EQ(runCli({"ingest", dir / "done", "--dem", dir / "dem.tif", "--max-exp", "6"}).status, 0);
  fs::remove(dir / "done" / "tiles" / "x1_y0_g2.exr");
  auto missing = runCli({"check", dir / "done"});
  EXPECT_EQ(missing.status, 1);
  EXPECT_NE(missing.output.find("tiles/x1_y0_g2.exr: missing or unreadable"), std::string::npos) << missing.output;
  EXPECT_EQ(runCli({"export", dir / "done", dir / "o.tif", "--window", "64", "0", "8", "8"}).status, 1);
}

TEST(StrataIngest, CtrlCStopsCleanlyAndResumeGivesTheSameBytes) {
  const auto dir = test::tempDir("ctrlc");
  const std::vector<std::string> args = {"--synthetic", "2048", "--max-exp", "6", "--min-exp", "2"};
  ASSERT_EQ(runCli(std::vector<std::string>{"ingest", dir / "reference"} + args).status, 0);
  // The same ingest, SIGINT once it has written some tiles.
  const std::string store = (dir / "store").string();
  const pid_t child = fork();
  ASSERT_GE(child, 0);
  if (child == 0) {
    const int devnull = ::open("/dev/null", O_WRONLY);
    dup2(devnull, 1);
    dup2(devnull, 2);
    execl(STRATA_CLI, STRATA_CLI, "ingest", store.c_str(), "--synthetic", "2048", "--max-exp", "6", "--min-exp", "2",
          static_cast<char*>(nullptr));
    _exit(127);
  }
  const auto until = std::chrono::steady_clock::now() + std::chrono::seconds(30);
  auto tiles = [&] {
    std::error_code ec;
    return std::distance(fs::directory_iterator(dir / "store" / "tiles", ec), fs::directory_iterator());
  };
  while (tiles() < 50 && std::chrono::steady_clock::now() < until)
    std::this_thread::sleep_for(std::chrono::milliseconds(1));
  ASSERT_EQ(kill(child, SIGINT), 0);
  int status = 0;
  waitpid(child, &status, 0);
  ASSERT_TRUE(WIFEXITED(status)) << "killed by the signal instead of stopping: " << status;
  ASSERT_EQ(WEXITSTATUS(status), 1) << "finished before the interrupt";
  auto check = runCli({"check", dir / "store"});
  EXPECT_EQ(check.status, 1);
  EXPECT_NE(check.output.find("INCOMPLETE"), std::string::npos) << check.output;
  EXPECT_NE(check.output.find("result    0 problem(s), store incomplete"), std::string::npos) << check.output;
  auto resumed =
      runCli(std::vector<std::string>{"ingest", dir / "store"} + args + std::vector<std::string>{"--resume"});
  ASSERT_EQ(resumed.status, 0) << resumed.output;
  EXPECT_NE(resumed.output.find("(resumed at tile "), std::string::npos) << resumed.output;
  EXPECT_TRUE(storeFiles(dir / "store") == storeFiles(dir / "reference"));
  EXPECT_EQ(runCli({"check", dir / "store"}).status, 0);
}

TEST(StrataIngest, RefusesBadNumbersEmptyInputAndNeverReportsNegativeSavings) {
  const auto dir = test::tempDir("numbers");
  const auto dem = crop(dir / "dem.tif", {"-srcwin", "600", "500", "64", "64"});
  struct Case {
    std::vector<std::string> args;
    std::string want;
  };
  const std::vector<Case> cases = {
      {{"--max-error", "nan"}, "--max-error nan: expected a finite number in [0, 1e+06]"},
      {{"--max-error", "inf"}, "--max-error inf: expected a finite number"},
      {{"--max-error", "-1"}, "--max-error -1: expected a finite number"},
      {{"--max-exp", "20"}, "--min-exp 5 / --max-exp 20: need 0 <= min-exp <= max-exp <= 14"},
      {{"--resolution", "0"}, "--resolution: cell sizes must be finite and positive"},
      {{"--resolution", "nan"}, "--resolution: cell sizes must be finite and positive"},
      {{"--extent", "0", "0", "nan", "1"}, "--extent: coordinates must be finite"},
      {{"--extent", "1", "0", "0", "1"}, "--extent: needs xmin < xmax and ymin < ymax"},
      {{"--metric", "fast"}, "--metric 'fast': expected max-error or range"},
      {{"--resampling", "lanczos"}, "--resampling 'lanczos': expected nearest, bilinear, cubic, min or min-if-coarser"},
  };
  for (const auto& c : cases) {
    auto r = runCli(std::vector<std::string>{"ingest", dir / "s", "--dem", dem} + c.args);
    EXPECT_EQ(r.status, 1) << c.want;
    EXPECT_NE(r.output.find("strata ingest: " + c.want), std::string::npos) << r.output;
    EXPECT_FALSE(fs::exists(dir / "s" / "manifest.toml")) << c.want;
  }
  auto synth = runCli({"ingest", dir / "s", "--synthetic", "16", "--cell-size", "nan"});
  EXPECT_NE(synth.output.find("--cell-size nan: expected a finite number"), std::string::npos) << synth.output;
  // All nodata: an error, and no store left behind.
  const auto empty =
      crop(dir / "empty.tif", {"-srcwin", "0", "0", "32", "32", "-a_nodata", "0", "-scale", "0", "5000", "0", "0"});
  auto none = runCli({"ingest", dir / "none", "--dem", empty});
  EXPECT_EQ(none.status, 1);
  EXPECT_NE(none.output.find("no data: every cell of the 32x32 grid is nodata"), std::string::npos) << none.output;
  EXPECT_FALSE(fs::exists(dir / "none"));
  // A 1 x 1 DEM: nothing saved, nothing negative.
  const auto one = crop(dir / "one.tif", {"-srcwin", "600", "600", "1", "1"});
  auto r = runCli({"ingest", dir / "one_store", "--dem", one});
  EXPECT_EQ(r.status, 0) << r.output;
  EXPECT_NE(r.output.find("0.0% saved against dense"), std::string::npos) << r.output;
}

TEST(StrataInfo, DescribesAStoreAndAssignsAMissingGeoreference) {
  const auto dir = test::tempDir("info");
  const auto dem = crop(dir / "dem.tif", {"-srcwin", "600", "500", "64", "64"});
  ASSERT_EQ(runCli({"ingest", dir / "store", "--dem", dem, "--max-exp", "6", "--max-error", "20"}).status, 0);
  auto store = runCli({"info", dir / "store"});
  EXPECT_EQ(store.status, 0) << store.output;
  EXPECT_NE(store.output.find("metric    max-error: each tile the coarsest within 20 m of every source cell"),
            std::string::npos)
      << store.output;
  EXPECT_NE(store.output.find("error     bedrock      max "), std::string::npos) << store.output;
  // A DEM without a georeference: refused, then described with one assigned.
  const auto bare = crop(dir / "bare.tif", {"-srcwin", "600", "500", "64", "64", "-co", "PROFILE=BASELINE"});
  // Its side file keeps only the nodata value (the SRTM voids), not the CRS and geotransform.
  std::ofstream(bare.string() + ".aux.xml")
      << "<PAMDataset><PAMRasterBand band=\"1\"><NoDataValue>-32768</NoDataValue></PAMRasterBand></PAMDataset>\n";
  auto refused = runCli({"info", bare});
  EXPECT_EQ(refused.status, 1);
  EXPECT_NE(refused.output.find("no georeference (no CRS and no geotransform)"), std::string::npos) << refused.output;
  auto dinfo = gis::probeDem(dem.string());
  ASSERT_TRUE(dinfo);
  std::string gt;
  for (double c : dinfo->georef.transform.c) {
    char b[40];
    std::snprintf(b, sizeof b, "%.17g,", c);
    gt += b;
  }
  gt.pop_back();
  auto assigned = runCli({"info", bare, "--assign-crs", "EPSG:4326", "--assign-geotransform", gt});
  EXPECT_EQ(assigned.status, 0) << assigned.output;
  EXPECT_NE(assigned.output.find("CRS         WGS 84 (EPSG:4326)"), std::string::npos) << assigned.output;
  // And ingested with one: the same cells as the georeferenced file.
  auto ing = runCli({"ingest", dir / "bare_store", "--dem", bare, "--assign-crs", "EPSG:4326", "--assign-geotransform",
                     gt, "--max-exp", "6"});
  ASSERT_EQ(ing.status, 0) << ing.output;
  ASSERT_EQ(runCli({"export", dir / "bare_store", dir / "bare_out.tif"}).status, 0);
  auto a = gis::readDem((dir / "bare_out.tif").string()), b = gis::readDem(dem.string());
  ASSERT_TRUE(a && b);
  EXPECT_TRUE(sameCells(a->values, b->values));
  EXPECT_EQ(a->georef.transform.c[0], b->georef.transform.c[0]);
}

}  // namespace
}  // namespace strata::terrain
