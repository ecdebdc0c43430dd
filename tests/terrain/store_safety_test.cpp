// The store as something to trust: the error-bounded metric (and voids kept void), one writer at
// a time, nothing touched that the store did not create, ingests that survive kill -9, Ctrl-C and
// failed reads (and resume to the same bytes), and `verify` / the manifest reader catching edits
// and bad numbers. Real data are crops of the shared DEMs.
#include <gtest/gtest.h>

#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <fstream>
#include <map>
#include <thread>

#include <strata/core/interrupt.hpp>
#include <strata/gis/dem_io.hpp>
#include <strata/terrain/dem_sources.hpp>
#include <strata/terrain/ingest.hpp>
#include <strata/terrain/synthetic.hpp>
#include <strata/terrain/tile_store.hpp>

#include "store_support.hpp"
#include "strata_test.hpp"

namespace strata::terrain {
namespace {

using test::bedrock;
using test::gridReader;
using test::problemsOf;

namespace fs = std::filesystem;
using gis::Grid;

constexpr int kFinestExp = 6, kF = 1 << kFinestExp;

gis::Georef utmGeoref(int w, int h) {
  gis::Georef g;
  g.epsg = 32612;
  g.crsName = "WGS 84 / UTM zone 12N";
  g.transform = {{500000.0, 30.0, 0.0, 4000000.0, 0.0, -30.0}};
  g.width = w;
  g.height = h;
  return g;
}

std::string slurp(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  return std::string((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
}

// Every file of a store but its lock, name -> bytes.
std::map<std::string, std::string> storeFiles(const fs::path& dir) {
  std::map<std::string, std::string> files;
  for (const auto& e : fs::recursive_directory_iterator(dir)) {
    if (!e.is_regular_file() || e.path().filename() == "writer.lock") continue;
    files[fs::relative(e.path(), dir).string()] = slurp(e.path());
  }
  return files;
}

// A real DEM crop: rows and columns of the Rainier SRTM tile (int16 metres, with voids).
gis::Raster rainier(int x, int y, int w, int h) {
  gis::ReadOptions o;
  o.window = gis::CellRect{x, y, w, h};
  auto r = gis::readDem(test::dataPath("rainier/mt_rainier_90m.tif"), o);
  STRATA_CHECK(r.ok()) << r.message();
  return std::move(*r);
}

TEST(MaxErrorMetric, EachTileIsTheCoarsestWithinTheTolerance) {
  SyntheticScene s;
  s.blockCells = kF;
  s.rampFraction = 0.3f;
  s.roughFraction = 0.3f;
  const int w = 5 * kF, h = 4 * kF;
  const auto dir = test::tempDir("maxerr");
  IngestOptions o;
  o.metric = {2, kFinestExp};
  o.metric.maxErrorM = 10.0;
  ASSERT_TRUE(ingest(dir, utmGeoref(w, h), {bedrock(syntheticReader(s))}, o));
  auto store = TileStore::open(dir);
  ASSERT_TRUE(store) << store.message();
  auto all = store->readWindow(0, {0, 0, w, h});
  ASSERT_TRUE(all);
  std::map<SyntheticBlock, int> seen;
  for (int ty = 0; ty < 4; ++ty) {
    for (int tx = 0; tx < 5; ++tx) {
      const auto kind = syntheticBlockKind(s, tx, ty);
      ++seen[kind];
      const auto& t = store->tile(tx, ty);
      // Flat: exact at the coarsest. Ramp: 0.3 * 1000 m over 63 columns (4.76 m a column); a
      // block of b columns errs by (b - 1) / 2 columns at its ends: b = 4 gives 7.1 m <= 10, b = 8
      // gives 16.7 m: 2^4 samples. Rough (white noise over 1000 m): full resolution.
      const int want = kind == SyntheticBlock::Flat ? 2 : kind == SyntheticBlock::Ramp ? 4 : kFinestExp;
      EXPECT_EQ(t.exp, want) << tx << "," << ty;
      double maxE = 0;
      for (int y = ty * kF; y < (ty + 1) * kF; ++y) {
        for (int x = tx * kF; x < (tx + 1) * kF; ++x) {
          maxE = std::max(maxE, std::abs(double(all->at(x, y)) - double(syntheticElevation(s, x, y))));
        }
      }
      EXPECT_LE(maxE, 10.0);
      EXPECT_EQ(t.maxErrorM[0], float(maxE)) << tx << "," << ty;  // the record is the measured error
    }
  }
  EXPECT_GT(seen[SyntheticBlock::Flat] * seen[SyntheticBlock::Ramp] * seen[SyntheticBlock::Rough], 0);
  // The seed's relief metric is still there: a ramp spans 30% of the range, the second of four bins.
  const auto rdir = test::tempDir("range");
  o.metric.kind = TileMetric::Range;
  ASSERT_TRUE(ingest(rdir, utmGeoref(w, h), {bedrock(syntheticReader(s))}, o));
  auto range = TileStore::open(rdir);
  ASSERT_TRUE(range);
  for (int ty = 0; ty < 4; ++ty) {
    for (int tx = 0; tx < 5; ++tx) {
      if (syntheticBlockKind(s, tx, ty) == SyntheticBlock::Ramp) {
        EXPECT_EQ(range->tile(tx, ty).exp, 3);
      }
    }
  }
}

TEST(MaxErrorMetric, VoidsStayVoidUnderEitherMetric) {
  // Rainier's SRTM voids: a 256 x 192 crop where 9 of its 12 tiles of 64 hold some (3 to 180
  // void cells each). Whatever a tile's relief, a block mixing data and void is never stored:
  // the mask is the source's exactly, and only the void-free tiles coarsen.
  const auto crop = rainier(512, 512, 256, 192);
  for (TileMetric m : {TileMetric::MaxError, TileMetric::Range}) {
    IngestOptions o;
    o.metric = {0, kFinestExp};
    o.metric.kind = m;
    o.metric.maxErrorM = 1000;  // anything goes, but voids
    const auto dir = test::tempDir(m == TileMetric::Range ? "voids_range" : "voids_err");
    ASSERT_TRUE(ingest(dir, crop.georef, {bedrock(gridReader(crop.values))}, o));
    auto store = TileStore::open(dir);
    ASSERT_TRUE(store);
    auto back = store->readWindow(0, {0, 0, 256, 192});
    ASSERT_TRUE(back);
    int coarse = 0, voidFree = 0;
    for (int ty = 0; ty < 3; ++ty) {
      for (int tx = 0; tx < 4; ++tx) {
        bool voids = false;
        for (int y = 0; y < kF; ++y) {
          for (int x = 0; x < kF; ++x) voids |= std::isnan(crop.values.at(tx * kF + x, ty * kF + y));
        }
        voidFree += !voids;
        coarse += store->tile(tx, ty).exp < kFinestExp;
      }
    }
    EXPECT_GT(voidFree, 0);
    EXPECT_EQ(coarse, voidFree);  // 1000 m coarsens every void-free tile
    for (size_t i = 0; i < back->data.size(); ++i) {
      ASSERT_EQ(std::isnan(back->data[i]), std::isnan(crop.values.data[i])) << i;
    }
    EXPECT_EQ(problemsOf(*store), "");
  }
}

TEST(StoreWriters, OneAtATimeAcrossObjectsAndProcesses) {
  const auto crop = rainier(300, 300, 192, 128);
  const auto dir = test::tempDir("lock");
  IngestOptions o;
  o.metric = {2, kFinestExp};
  ASSERT_TRUE(ingest(dir, crop.georef, {bedrock(gridReader(crop.values))}, o));
  auto a = TileStore::open(dir);
  auto b = TileStore::open(dir);
  ASSERT_TRUE(a && b);
  ASSERT_TRUE(a->writeWindow(0, 5, 5, Grid<float>(3, 3, 1000.0f)));
  // The second writer is refused, naming the holder; reading is never blocked.
  auto refused = b->writeWindow(0, 5, 5, Grid<float>(3, 3, 2000.0f));
  ASSERT_FALSE(refused);
  EXPECT_EQ(refused.message(), dir.string() + ": another writer holds this store (pid " + std::to_string(getpid()) +
                                   "); one writer at a time: wait for it to finish, or stop it");
  EXPECT_FALSE(b->commit());
  EXPECT_TRUE(b->readWindow(0, {0, 0, 10, 10}));
  ASSERT_TRUE(a->commit());

  // Two ingests into one folder from two processes: the second is refused while the first runs,
  // and the first completes a sound store.
  const auto two = test::tempDir("two");
  auto slow = [&](int x, int y, int w, int h) {
    std::this_thread::sleep_for(std::chrono::milliseconds(40));
    return gridReader(crop.values)(x, y, w, h);
  };
  const pid_t child = fork();
  ASSERT_GE(child, 0);
  if (child == 0) _exit(ingest(two, crop.georef, {bedrock(slow)}, o) ? 0 : 3);
  const auto until = std::chrono::steady_clock::now() + std::chrono::seconds(10);
  while (!fs::exists(two / "manifest.toml") && std::chrono::steady_clock::now() < until) {
    std::this_thread::sleep_for(std::chrono::milliseconds(2));
  }
  auto second = ingest(two, crop.georef, {bedrock(gridReader(crop.values))}, o);
  ASSERT_FALSE(second);
  EXPECT_NE(second.message().find("another writer holds this store (pid " + std::to_string(child) + ")"),
            std::string::npos)
      << second.message();
  int status = 0;
  waitpid(child, &status, 0);
  ASSERT_TRUE(WIFEXITED(status) && WEXITSTATUS(status) == 0) << status;
  auto done = TileStore::open(two);
  ASSERT_TRUE(done) << done.message();
  EXPECT_EQ(problemsOf(*done), "");
  EXPECT_EQ(done->readWindow(0, {0, 0, 192, 128})->data.size(), crop.values.data.size());
}

TEST(StoreWriters, TouchOnlyTheFilesTheyCreated) {
  const auto crop = rainier(300, 300, 192, 128);
  const auto dir = test::tempDir("hygiene");
  fs::create_directories(dir / "tiles");
  std::ofstream(dir / "notes.txt") << "mine";
  std::ofstream(dir / "tiles" / "README") << "mine too";
  std::ofstream(dir / "tiles" / "x0_y0_g1.exr.bak") << "a backup";
  IngestOptions o;
  o.metric = {2, kFinestExp};
  o.commitEveryTiles = 1;  // a commit (and its sweep of superseded files) after every tile
  ASSERT_TRUE(ingest(dir, crop.georef, {bedrock(gridReader(crop.values))}, o));
  {
    auto s = TileStore::open(dir);
    ASSERT_TRUE(s);
    ASSERT_TRUE(s->writeWindow(0, 0, 0, Grid<float>(100, 100, 7.0f)));
    ASSERT_TRUE(s->commit());
  }
  EXPECT_EQ(slurp(dir / "notes.txt"), "mine");
  EXPECT_EQ(slurp(dir / "tiles" / "README"), "mine too");
  EXPECT_EQ(slurp(dir / "tiles" / "x0_y0_g1.exr.bak"), "a backup");
  // A folder whose tiles/ holds tile files but no manifest is not this ingest's: refused.
  const auto foreign = test::tempDir("foreign");
  fs::create_directories(foreign / "tiles");
  std::ofstream(foreign / "tiles" / "x0_y0_g3.exr") << "someone's tile";
  auto r = ingest(foreign, crop.georef, {bedrock(gridReader(crop.values))}, o);
  ASSERT_FALSE(r);
  EXPECT_NE(r.message().find("tiles/ holds tile files (x0_y0_g3.exr) but there is no manifest"), std::string::npos)
      << r.message();
  EXPECT_EQ(slurp(foreign / "tiles" / "x0_y0_g3.exr"), "someone's tile");
}

// The interruption tests' ingest: a 384 x 256 Rainier crop (voids included) in 64-cell tiles,
// 6 x 4 = 24 tiles, a checkpoint every 5.
struct Interrupted {
  gis::Raster crop = rainier(500, 420, 384, 256);
  IngestOptions options() const {
    IngestOptions o;
    o.metric = {1, kFinestExp};
    o.metric.maxErrorM = 5;  // some tiles coarse, some not
    o.commitEveryTiles = 5;
    return o;
  }
  fs::path reference() const {
    const auto dir = test::tempDir("reference");
    auto r = ingest(dir, crop.georef, {bedrock(gridReader(crop.values))}, options());
    STRATA_CHECK(r.ok()) << r.message();
    return dir;
  }
};

TEST(Ingest, KilledAtSeveralPointsThenResumedGivesTheSameBytes) {
  const Interrupted in;
  const auto ref = in.reference();
  const auto want = storeFiles(ref);
  int checked = 0;
  // Kill -9 once the manifest exists (no tile), after 3 tile files (before the first
  // checkpoint), after 12 and after 22 (between checkpoints).
  for (int tiles : {0, 3, 12, 22}) {
    const auto dir = test::tempDir("killed_" + std::to_string(tiles));
    const pid_t child = fork();
    ASSERT_GE(child, 0);
    if (child == 0) {
      auto slow = [&](int x, int y, int w, int h) {
        std::this_thread::sleep_for(std::chrono::milliseconds(30));
        return gridReader(in.crop.values)(x, y, w, h);
      };
      _exit(ingest(dir, in.crop.georef, {bedrock(slow)}, in.options()) ? 0 : 3);
    }
    const auto until = std::chrono::steady_clock::now() + std::chrono::seconds(20);
    auto count = [&] {
      std::error_code ec;
      int n = 0;
      for (const auto& e : fs::directory_iterator(dir / "tiles", ec)) n += e.path().extension() == ".exr";
      return n;
    };
    while ((!fs::exists(dir / "manifest.toml") || count() < tiles) && std::chrono::steady_clock::now() < until) {
      std::this_thread::sleep_for(std::chrono::milliseconds(1));
    }
    ASSERT_EQ(kill(child, SIGKILL), 0);
    int status = 0;
    waitpid(child, &status, 0);
    ASSERT_TRUE(WIFSIGNALED(status)) << "the ingest finished before the kill (" << tiles << " tiles)";
    // Not a store anyone may use yet, but a consistent one.
    auto refused = TileStore::open(dir);
    ASSERT_FALSE(refused);
    EXPECT_NE(refused.message().find("incomplete store"), std::string::npos) << refused.message();
    auto partial = TileStore::open(dir, {}, {.allowIncomplete = true});
    ASSERT_TRUE(partial) << partial.message();
    EXPECT_FALSE(partial->buildState().complete);
    EXPECT_EQ(problemsOf(*partial), "");
    std::cout << "killed after " << count() << " tile files; the checkpoint says " << partial->buildState().tilesDone
              << " tiles done\n";
    // Resumed: the same bytes as the uninterrupted ingest.
    auto o = in.options();
    o.resume = true;
    auto rep = ingest(dir, in.crop.georef, {bedrock(gridReader(in.crop.values))}, o);
    ASSERT_TRUE(rep) << rep.message();
    EXPECT_EQ(rep->resumedAt, partial->buildState().tilesDone);
    const auto got = storeFiles(dir);
    EXPECT_EQ(got.size(), want.size());
    for (const auto& [name, bytes] : want) {
      ASSERT_TRUE(got.count(name)) << name;
      EXPECT_TRUE(got.at(name) == bytes) << name << " differs";
    }
    ++checked;
  }
  EXPECT_EQ(checked, 4);
}

TEST(Ingest, CtrlCStopsAtATileBoundaryAndResumes) {
  const Interrupted in;
  const auto want = storeFiles(in.reference());
  const auto dir = test::tempDir("sigint");
  int reads = 0;
  auto interrupting = [&](int x, int y, int w, int h) {
    if (++reads == 8) setInterrupted(true);  // as the SIGINT handler does, during tile 8
    return gridReader(in.crop.values)(x, y, w, h);
  };
  auto r = ingest(dir, in.crop.georef, {bedrock(interrupting)}, in.options());
  setInterrupted(false);
  ASSERT_FALSE(r);
  EXPECT_NE(r.message().find("ingest: interrupted; " + dir.string() + " is left incomplete after 8 of 24 tiles"),
            std::string::npos)
      << r.message();
  auto partial = TileStore::open(dir, {}, {.allowIncomplete = true});
  ASSERT_TRUE(partial);
  EXPECT_EQ(partial->buildState().tilesDone, 8);  // the tile it was reading was finished and recorded
  EXPECT_EQ(problemsOf(*partial), "");
  auto o = in.options();
  o.resume = true;
  ASSERT_TRUE(ingest(dir, in.crop.georef, {bedrock(gridReader(in.crop.values))}, o));
  EXPECT_TRUE(storeFiles(dir) == want);
  // Resuming a complete store does nothing.
  auto again = ingest(dir, in.crop.georef, {bedrock(gridReader(in.crop.values))}, o);
  ASSERT_TRUE(again);
  EXPECT_TRUE(again->alreadyComplete);
}

TEST(Ingest, AFailedReadLeavesNoStoreThatLooksValid) {
  const Interrupted in;
  const auto want = storeFiles(in.reference());
  // A truncated GeoTIFF (striped, cut in its pixel data): the read of some tile fails.
  const auto dir = test::tempDir("truncated");
  const auto tif = dir / "crop.tif";
  gis::WriteOptions wo;
  ASSERT_TRUE(gis::writeGeoTiff(tif.string(), in.crop, wo));
  fs::resize_file(tif, fs::file_size(tif) * 6 / 10);
  auto r = ingest(dir / "store", in.crop.georef, {bedrock(demReader(tif.string()))}, in.options());
  ASSERT_FALSE(r);
  EXPECT_NE(r.message().find("read failed (truncated or corrupt file?)"), std::string::npos) << r.message();
  EXPECT_NE(r.message().find("is left incomplete"), std::string::npos) << r.message();
  auto refused = TileStore::open(dir / "store");
  ASSERT_FALSE(refused);
  EXPECT_NE(refused.message().find("incomplete store"), std::string::npos);
  // Fixed (the good data), the resume completes it to the same bytes as an uninterrupted ingest.
  auto o = in.options();
  o.resume = true;
  ASSERT_TRUE(ingest(dir / "store", in.crop.georef, {bedrock(gridReader(in.crop.values))}, o));
  EXPECT_TRUE(storeFiles(dir / "store") == want);
}

TEST(Ingest, ResumeRefusesOtherSourcesOrOptions) {
  const Interrupted in;
  const auto dir = test::tempDir("mismatch");
  int reads = 0;
  std::vector<IngestSource> src{bedrock([&](int x, int y, int w, int h) {
    if (++reads == 4) setInterrupted(true);
    return gridReader(in.crop.values)(x, y, w, h);
  })};
  src[0].identity = "crop.tif (1234 B)";
  ASSERT_FALSE(ingest(dir, in.crop.georef, src, in.options()));
  setInterrupted(false);
  auto o = in.options();
  o.resume = true;
  src[0].identity = "crop.tif (999 B)";
  auto r = ingest(dir, in.crop.georef, src, o);
  ASSERT_FALSE(r);
  EXPECT_EQ(
      r.message(),
      dir.string() + ": cannot resume: field 'bedrock' was read from crop.tif (1234 B), now from crop.tif (999 B)");
  src[0].identity = "crop.tif (1234 B)";
  o.metric.maxErrorM = 1;
  r = ingest(dir, in.crop.georef, src, o);
  ASSERT_FALSE(r);
  EXPECT_EQ(r.message(),
            dir.string() + ": cannot resume: the metric (--metric, --min-exp, --max-exp, --max-error) differs");
  o.metric.maxErrorM = 5;
  EXPECT_TRUE(ingest(dir, in.crop.georef, src, o));
}

TEST(Ingest, InputWithoutDataIsAnErrorAndLeavesNothing) {
  const auto dir = test::tempDir("empty") / "store";
  auto r = ingest(dir, utmGeoref(100, 70), {bedrock(gridReader(Grid<float>(100, 70, gis::kNoData)))});
  ASSERT_FALSE(r);
  EXPECT_EQ(r.message(), "ingest: no data: every cell of the 100x70 grid is nodata in every field (nothing stored)");
  EXPECT_FALSE(fs::exists(dir));
}

// A store of a real DEM crop (EPSG:4326) whose manifest the tests edit.
struct Edited {
  fs::path dir;
  std::string text;
  explicit Edited(const std::string& name) : dir(test::tempDir(name)) {
    const auto crop = rainier(700, 200, 192, 128);
    IngestOptions o;
    o.metric = {2, kFinestExp};
    o.metric.maxErrorM = 20;
    auto r = ingest(dir, crop.georef, {bedrock(gridReader(crop.values))}, o);
    STRATA_CHECK(r.ok()) << r.message();
    text = slurp(dir / "manifest.toml");
  }
  // The manifest with the first `from` replaced by `to`, written; the store reopened.
  Result<TileStore> with(const std::string& from, const std::string& to) const {
    auto t = text;
    const auto at = t.find(from);
    STRATA_CHECK(at != std::string::npos) << from;
    t.replace(at, from.size(), to);
    std::ofstream(dir / "manifest.toml", std::ios::binary) << t;
    return TileStore::open(dir);
  }
  std::string problems(const std::string& from, const std::string& to) const {
    auto s = with(from, to);
    return s ? problemsOf(*s) : "open failed: " + s.message();
  }
};

TEST(StoreVerify, FindsWhatAnEditedManifestHides) {
  const Edited e("verify");
  EXPECT_EQ(e.problems("x = 0", "x = 0"), "");
  // A deleted tile entry: its file is an orphan (52,358 cells lost in the issue's case).
  const auto first = e.text.find("[[tiles]]"), second = e.text.find("[[tiles]]", first + 1);
  auto s = e.with(e.text.substr(first, second - first), "");
  ASSERT_TRUE(s);
  EXPECT_NE(problemsOf(*s).find("tiles/x0_y0_g1.exr: a tile file for a tile the manifest lists as absent"),
            std::string::npos)
      << problemsOf(*s);
  // A geotransform shifted by a tenth of a degree: every tile says it was made for another place.
  const auto gt = e.text.find("geotransform = [") + 16, comma = e.text.find(',', gt);
  const std::string x0 = e.text.substr(gt, comma - gt);
  EXPECT_NE(e.problems("[" + x0 + ",", "[" + std::to_string(std::stod(x0) + 0.1) + ",").find("made for another place"),
            std::string::npos);
  // A wrong EPSG code, a CRS that does not parse, another body.
  EXPECT_NE(e.problems("epsg = 4326", "epsg = 32612").find("georef.epsg = 32612 but crs_wkt says 4326"),
            std::string::npos);
  EXPECT_NE(e.problems("crs_wkt = \"GEOGCRS", "crs_wkt = \"garbage GEOGCRS").find("georef.crs_wkt does not parse"),
            std::string::npos);
  EXPECT_NE(e.problems("body_semi_major_m = 6378137.0", "body_semi_major_m = 3396190.0").find("body_semi_major_m"),
            std::string::npos);
  // A field range that is not the tiles'.
  EXPECT_NE(e.problems("range_max = ", "range_max = 1").find("field 'bedrock': range"), std::string::npos);
}

TEST(StoreManifest, EveryNumberIsCheckedFiniteAndInRange) {
  const Edited e("numbers");
  struct Case {
    std::string from, to, want;
  };
  const std::vector<Case> cases = {
      {"max_error_m = 20.0", "max_error_m = nan", "key 'metric.max_error_m': is nan (not a number)"},
      {"max_error_m = 20.0", "max_error_m = inf", "key 'metric.max_error_m': is infinite"},
      {"max_error_m = 20.0", "max_error_m = -1.0", "key 'metric.max_error_m': -1 outside [0, 1e+06]"},
      {e.text.substr(e.text.find("geotransform = ["),
                     e.text.find(',', e.text.find("geotransform = [")) - e.text.find("geotransform = [")),
       "geotransform = [inf", "key 'georef.geotransform[0]': is infinite"},
      {"body_semi_major_m = 6378137.0", "body_semi_major_m = 0.0", "key 'georef.body_semi_major_m': 0 outside"},
      {"body_flattening = ", "body_flattening = -", "key 'georef.body_flattening': -0.00335"},
      {"next_generation = ", "next_generation = 0#", "key 'next_generation': 0 outside"},
      {"width = 192", "width = 0", "key 'georef.width': 0 outside [1, 1073741824]"},
      {"width = 192", "width = 1e30", "key 'georef.width': is not an integer"},
      {"tiles_done = ", "tiles_done = -", "key 'build.tiles_done': -"},
      {"\nexp = ", "\nexp = 1", "key 'tiles[0].exp': "},
      {"bytes = ", "bytes = -", "key 'tiles[0].bytes': -"},
      {"max_error = [", "max_error = [nan, ", "key 'tiles[0].max_error': has 2 values, expected 1"},
      {"max_error = [", "max_error = [nan] #", "key 'tiles[0].max_error[0]': is nan (not a number)"},
      {"rms_error = [", "rms_error = [1e9] #", "key 'tiles[0].rms_error[0]': 1e+09 outside"},
      {"file = \"tiles/x0_y0_g1.exr\"", "file = \"../../etc/passwd\"", "is not this tile's file name"},
      {"format = ", "format = 1\nx = ", "key 'format': is not a string"},
  };
  for (const auto& c : cases) {
    auto s = e.with(c.from, c.to);
    ASSERT_FALSE(s) << c.to;
    EXPECT_NE(s.message().find(c.want), std::string::npos) << c.to << ": " << s.message();
    // file:line: key '...': what
    EXPECT_EQ(s.message().rfind((e.dir / "manifest.toml").string() + ":", 0), 0u) << s.message();
  }
}

TEST(StoreManifest, TextThatTripsTomlPlusPlusIsRefusedBeforeItReachesIt) {
  // The inputs scripts/fuzz.sh found reaching an assertion or TOML_UNREACHABLE in toml++ 3.3.0
  // (undefined behaviour in release builds), each refused by the screen with a line number.
  const auto dir = test::tempDir("screen");
  fs::create_directories(dir);
  struct Case {
    std::string text, want;
  };
  const std::vector<Case> cases = {
      {"[\x19", ":1: U+0019: a control character (TOML allows tab and line breaks only)"},
      {"a = \"\x19\"", ":1: U+0019: a control character"},
      {"format = 1\n[&", ":2: '&' starts a table name (TOML allows ASCII letters, digits, _ and -, or a quoted name)"},
      {"u=[}", ":1: '}' inside an array (no inline table to close)"},
      {"x = 1\n\xEF\xBB\xA2",
       ":2: U+FEE2: not ASCII (a manifest is ASCII; its strings write other characters as "
       "\\uXXXX escapes)"},
      {"nte= 0e-'xbo\xEF\xBB\xAF", ":1: U+FEEF: not ASCII"},
      {"solcoln= 5301-04-0s 3, 0o darat",
       ":1: '-' inside a value: a date or a time of day, which no manifest key takes"},
      {"a = [" + std::string(100, '['), ":1: arrays and inline tables nested deeper than 64"},
      {"a = {b = ]", ":1: ']' inside an inline table (no array to close)"},
  };
  for (const auto& c : cases) {
    std::ofstream(dir / "manifest.toml", std::ios::binary) << c.text;
    auto s = TileStore::open(dir);
    ASSERT_FALSE(s) << c.text;
    EXPECT_EQ(s.message().rfind((dir / "manifest.toml").string() + c.want, 0), 0u) << c.text << ": " << s.message();
  }
  // What the writer writes passes: names with non-ASCII characters are escaped, read back whole.
  auto g = utmGeoref(64, 64);
  g.epsg.reset();
  g.crsName = "R\xC3\xA9seau \xE2\x80\x94 \xF0\x9F\x97\xBA";  // "Réseau — 🗺"
  const auto store = test::tempDir("ascii");
  ASSERT_TRUE(ingest(store, g, {bedrock(gridReader(Grid<float>(64, 64, 5.0f)))}));
  const std::string text = slurp(store / "manifest.toml");
  EXPECT_TRUE(std::all_of(text.begin(), text.end(), [](char ch) { return static_cast<unsigned char>(ch) < 0x80; }));
  EXPECT_NE(text.find("crs_name = \"R\\u00E9seau \\u2014 \\U0001F5FA\""), std::string::npos) << text;
  auto back = TileStore::open(store);
  ASSERT_TRUE(back) << back.message();
  EXPECT_EQ(back->desc().georef.crsName, g.crsName);
}

}  // namespace
}  // namespace strata::terrain
