// The tile store: the seed metric, the on-disk format, windowed reads at any level, writes with
// re-evaluation, absent tiles, global layouts, the cache, crash safety and corruption.
#include <gtest/gtest.h>

#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cmath>
#include <fstream>
#include <map>
#include <set>
#include <thread>

#include <strata/terrain/ingest.hpp>
#include <strata/terrain/synthetic.hpp>
#include <strata/terrain/tile_store.hpp>

#include "store_support.hpp"
#include "strata_test.hpp"

namespace strata::terrain {
namespace {

using test::bedrock;
using test::problemsOf;

namespace fs = std::filesystem;
using gis::Grid;

// Small stores: tiles of 2^6 = 64 cells, resolutions 2^3..2^6 (four bins of the metric).
constexpr int kMinExp = 3, kMaxExp = 6, kFootprint = 1 << kMaxExp;

gis::Georef planarGeoref(int w, int h) {
  gis::Georef g;
  g.epsg = 32612;
  g.crsName = "WGS 84 / UTM zone 12N";
  g.transform = {{500000.0, 30.0, 0.0, 4000000.0, 0.0, -30.0}};
  g.width = w;
  g.height = h;
  return g;
}

SyntheticScene smallScene() {
  SyntheticScene s;
  s.blockCells = kFootprint;
  s.rampFraction = 0.3f;
  s.roughFraction = 0.3f;
  return s;
}

// The seed's relief metric (what most tests here pin down) unless told otherwise.
IngestOptions smallOptions(bool prefetch = false, TileMetric metric = TileMetric::Range) {
  IngestOptions o;
  o.metric = {kMinExp, kMaxExp};
  o.metric.kind = metric;
  o.cache.prefetch = prefetch;
  return o;
}

TileStore ingestScene(const fs::path& dir, int w, int h, const SyntheticScene& s, bool prefetch = false) {
  auto rep = ingest(dir, planarGeoref(w, h), {bedrock(syntheticReader(s))}, smallOptions(prefetch));
  STRATA_CHECK(rep.ok()) << rep.message();
  auto store = TileStore::open(dir, smallOptions(prefetch).cache);
  STRATA_CHECK(store.ok()) << store.message();
  return std::move(*store);
}

TEST(TileMetric, MapsTheRangeRatioLinearlyOntoTheExponents) {
  // 4 bins over [0,1]: [0,.25) -> 3, [.25,.5) -> 4, [.5,.75) -> 5, [.75,1] -> 6.
  EXPECT_EQ(chooseTileExp({0.0f}, {100.0f}, 3, 6), 3);
  EXPECT_EQ(chooseTileExp({24.0f}, {100.0f}, 3, 6), 3);
  EXPECT_EQ(chooseTileExp({26.0f}, {100.0f}, 3, 6), 4);
  EXPECT_EQ(chooseTileExp({60.0f}, {100.0f}, 3, 6), 5);
  EXPECT_EQ(chooseTileExp({100.0f}, {100.0f}, 3, 6), 6);
  EXPECT_EQ(chooseTileExp({250.0f}, {100.0f}, 3, 6), 6);  // beyond the range (before re-evaluation)
  // The most complex field decides; a field with no range or no data does not count.
  EXPECT_EQ(chooseTileExp({1.0f, 5.0f}, {100.0f, 5.0f}, 3, 6), 6);
  EXPECT_EQ(chooseTileExp({gis::kNoData, 5.0f}, {100.0f, 0.0f}, 3, 6), 3);
  EXPECT_EQ(chooseTileExp({50.0f}, {100.0f}, 5, 10), 8);  // the seed's defaults: 6 bins
}

TEST(Resampling, BoxMeanIgnoresNoDataAndInvertsReplication) {
  Grid<float> g(4, 2, 1.0f);
  g.at(0, 0) = 3.0f;
  g.at(2, 0) = gis::kNoData;
  g.at(2, 1) = gis::kNoData;
  g.at(3, 0) = gis::kNoData;
  g.at(3, 1) = gis::kNoData;
  const auto d = boxDownsample(g, 2);
  ASSERT_EQ(d.width, 2);
  EXPECT_EQ(d.at(0, 0), 1.5f);  // (3+1+1+1)/4, exact in float
  EXPECT_TRUE(std::isnan(d.at(1, 0)));
  const auto u = replicateUpsample(d, 4);
  EXPECT_EQ(boxDownsample(u, 4).at(0, 0), 1.5f);
  EXPECT_EQ(u.at(3, 3), 1.5f);
}

TEST(TileStore, FlatTilesGetMinRoughTilesGetMaxAndReadsAreExact) {
  const auto dir = test::tempDir("store");
  const auto s = smallScene();
  const int w = 5 * kFootprint, h = 4 * kFootprint;
  auto store = ingestScene(dir, w, h, s);
  ASSERT_EQ(store.tilesX(), 5);
  ASSERT_EQ(store.tilesY(), 4);
  std::map<SyntheticBlock, int> seen;
  for (int ty = 0; ty < 4; ++ty) {
    for (int tx = 0; tx < 5; ++tx) {
      const auto kind = syntheticBlockKind(s, tx, ty);
      ++seen[kind];
      const auto& t = store.tile(tx, ty);
      ASSERT_TRUE(t.present);
      // Flat: range 0 -> 2^min. Ramp: 30% of the amplitude -> the second bin. Rough: white noise
      // over the whole amplitude -> 2^max.
      const int want = kind == SyntheticBlock::Flat ? kMinExp : kind == SyntheticBlock::Ramp ? kMinExp + 1 : kMaxExp;
      EXPECT_EQ(t.exp, want) << "tile " << tx << "," << ty;
    }
  }
  ASSERT_GT(seen[SyntheticBlock::Flat], 0);
  ASSERT_GT(seen[SyntheticBlock::Ramp], 0);
  ASSERT_GT(seen[SyntheticBlock::Rough], 0);
  // Full-resolution window across several tiles: rough tiles equal the source bit for bit, flat
  // tiles too (a constant survives box means exactly).
  auto win = store.readWindow(0, {40, 30, 3 * kFootprint, 2 * kFootprint}, 0);
  ASSERT_TRUE(win) << win.message();
  int exact = 0;
  for (int y = 0; y < win->height; ++y) {
    for (int x = 0; x < win->width; ++x) {
      const int gx = 40 + x, gy = 30 + y;
      const auto kind = syntheticBlockKind(s, gx / kFootprint, gy / kFootprint);
      if (kind == SyntheticBlock::Ramp) continue;
      ASSERT_EQ(win->at(x, y), syntheticElevation(s, gx, gy)) << gx << "," << gy;
      ++exact;
    }
  }
  EXPECT_GT(exact, 0);
  // Ramps are stored at 2^4 = 16 samples for 64 cells: each sample is the mean of 4 columns, so
  // a read is off by at most 1.5 column steps of 0.3 * 1000 / 63 m (4.8 m per column).
  auto ramp = store.readWindow(0, {0, 0, w, h}, 0);
  ASSERT_TRUE(ramp);
  for (int y = 0; y < h; y += 7) {
    for (int x = 0; x < w; ++x) {
      if (syntheticBlockKind(s, x / kFootprint, y / kFootprint) != SyntheticBlock::Ramp) continue;
      EXPECT_NEAR(ramp->at(x, y), syntheticElevation(s, x, y), 1.5 * 300.0 / 63 + 1e-3);
    }
  }
  const auto fp = store.footprintStats();
  EXPECT_EQ(fp.denseSamples, uint64_t(w) * h);
  EXPECT_LT(fp.storedSamples, fp.denseSamples);
}

TEST(TileStore, ManifestRoundTripsGeoreferenceAndRecords) {
  const auto dir = test::tempDir("store");
  auto a = ingestScene(dir, 3 * kFootprint, 2 * kFootprint, smallScene());
  auto b = TileStore::open(dir);
  ASSERT_TRUE(b) << b.message();
  const auto& ga = a.desc().georef;
  const auto& gb = b->desc().georef;
  for (int i = 0; i < 6; ++i) EXPECT_EQ(ga.transform.c[i], gb.transform.c[i]);  // exact: shortest round-trip text
  EXPECT_EQ(gb.epsg, 32612);
  EXPECT_EQ(gb.crsWkt, ga.crsWkt);
  EXPECT_EQ(b->desc().materials.size(), defaultMaterials().size());
  EXPECT_EQ(b->desc().materials[2].talusAngleDeg, defaultMaterials()[2].talusAngleDeg);
  EXPECT_EQ(b->globalRange(0), a.globalRange(0));
  for (int ty = 0; ty < 2; ++ty) {
    for (int tx = 0; tx < 3; ++tx) {
      EXPECT_EQ(a.tile(tx, ty).crc32, b->tile(tx, ty).crc32);
      EXPECT_EQ(a.tile(tx, ty).exp, b->tile(tx, ty).exp);
      EXPECT_EQ(a.tile(tx, ty).maxV, b->tile(tx, ty).maxV);
    }
  }
  EXPECT_EQ(problemsOf(*b), "");
}

TEST(TileStore, BadManifestsAreRefusedNamingTheField) {
  const auto dir = test::tempDir("store");
  ingestScene(dir, kFootprint, kFootprint, smallScene());
  const auto path = dir / "manifest.toml";
  std::ifstream in(path);
  std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  auto with = [&](const std::string& from, const std::string& to) {
    auto t = text;
    const auto at = t.find(from);
    STRATA_CHECK(at != std::string::npos) << from;
    t.replace(at, from.size(), to);
    std::ofstream(path) << t;
    return TileStore::open(dir);
  };
  auto r1 = with("max_exp = 6", "max_exp = 7");
  ASSERT_FALSE(r1);
  EXPECT_NE(r1.message().find("footprint_cells"), std::string::npos) << r1.message();
  auto r2 = with("kind = \"planar\"", "kind = \"cubic\"");
  ASSERT_FALSE(r2);
  EXPECT_NE(r2.message().find("layout.kind"), std::string::npos) << r2.message();
  auto r3 = with("talus_angle_deg = 70.0", "talus_angle_deg = 170.0");
  ASSERT_FALSE(r3);
  EXPECT_NE(r3.message().find("talus_angle_deg"), std::string::npos) << r3.message();
  auto r4 = with("format = ", "formt = ");
  ASSERT_FALSE(r4);
  EXPECT_NE(r4.message().find("'format'"), std::string::npos) << r4.message();
  EXPECT_FALSE(TileStore::open(dir / "nowhere"));
}

TEST(TileStore, CoarseLevelsAreBoxMeansOfTheSource) {
  const auto dir = test::tempDir("store");
  const auto s = smallScene();
  const int w = 4 * kFootprint, h = 2 * kFootprint;
  auto store = ingestScene(dir, w, h, s);
  for (int lod : {1, 3, kMaxExp}) {
    const int n = 1 << lod;
    auto g = store.readWindow(0, {0, 0, store.levelWidth(lod), store.levelHeight(lod)}, lod);
    ASSERT_TRUE(g);
    for (int y = 0; y < g->height; ++y) {
      for (int x = 0; x < g->width; ++x) {
        if (syntheticBlockKind(s, x * n / kFootprint, y * n / kFootprint) == SyntheticBlock::Ramp) continue;
        double sum = 0;
        for (int yy = 0; yy < n; ++yy) {
          for (int xx = 0; xx < n; ++xx) sum += syntheticElevation(s, x * n + xx, y * n + yy);
        }
        // Mips are means of means in float32: 6 halvings of values < 1100 m, each rounding by
        // at most half an ulp (6e-5 m): 1e-3 m is a safe bound.
        ASSERT_NEAR(g->at(x, y), sum / (n * n), 1e-3) << "lod " << lod << " at " << x << "," << y;
      }
    }
  }
}

TEST(TileStore, WindowReadsTouchOnlyTheTilesTheyCover) {
  const auto dir = test::tempDir("store");
  auto store = ingestScene(dir, 4 * kFootprint, 3 * kFootprint, smallScene());
  // Delete every tile file but (1,1)'s: a read inside tile (1,1) must not need them.
  const std::string keep = fs::path(store.tile(1, 1).file).filename().string();
  for (const auto& e : fs::directory_iterator(dir / "tiles")) {
    if (e.path().filename() != keep) fs::remove(e.path());
  }
  auto inside = store.readWindow(0, {kFootprint + 3, kFootprint + 5, 50, 40}, 0);
  ASSERT_TRUE(inside) << inside.message();
  const auto st = store.cacheStats();
  EXPECT_EQ(st.misses, 1u);
  auto coarse = store.readWindow(0, {4, 4, 3, 3}, 4);  // level 4: tile (1,1) is cells [4,8)
  ASSERT_TRUE(coarse) << coarse.message();
  auto outside = store.readWindow(0, {kFootprint - 1, kFootprint, 2, 2}, 0);
  ASSERT_FALSE(outside);
  EXPECT_NE(outside.message().find("x0_y1_g"), std::string::npos) << outside.message();
}

TEST(TileStore, NonRectangularDomainsLeaveTilesAbsent) {
  const auto dir = test::tempDir("store");
  constexpr int n = 4 * kFootprint;
  // A disc of data (radius 0.35 n < the 0.354 n to the corner tiles' nearest point): the corner
  // tiles lie wholly outside it.
  auto disc = [](int x0, int y0, int w, int h) -> Result<Grid<float>> {
    Grid<float> g(w, h, gis::kNoData);
    for (int y = 0; y < h; ++y) {
      for (int x = 0; x < w; ++x) {
        const double dx = x0 + x + 0.5 - n / 2.0, dy = y0 + y + 0.5 - n / 2.0;
        if (dx * dx + dy * dy < 0.35 * 0.35 * n * n) g.at(x, y) = float(x0 + x);
      }
    }
    return g;
  };
  auto rep = ingest(dir, planarGeoref(n, n), {bedrock(disc)}, smallOptions());
  ASSERT_TRUE(rep) << rep.message();
  EXPECT_EQ(rep->tilesAbsent, 4);
  EXPECT_EQ(rep->tilesPresent, 12);
  auto store = TileStore::open(dir);
  ASSERT_TRUE(store);
  EXPECT_FALSE(store->tile(0, 0).present);
  EXPECT_FALSE(store->tile(3, 3).present);
  EXPECT_TRUE(store->tile(1, 0).present);
  auto g = store->readWindow(0, {0, 0, n, n}, 0);
  ASSERT_TRUE(g);
  EXPECT_TRUE(std::isnan(g->at(5, 5)));
  EXPECT_TRUE(std::isnan(g->at(kFootprint + 1, 0)));  // present tile, outside the disc
  // Outside the grid of a planar store is no data too.
  auto off = store->readWindow(0, {-4, n - 2, 8, 8}, 0);
  ASSERT_TRUE(off);
  EXPECT_TRUE(std::isnan(off->at(0, 0)));
  const auto map = store->resolutionMap();
  EXPECT_EQ(std::count_if(map.data.begin(), map.data.end(), [](float e) { return std::isnan(e); }), 4);
}

TEST(TileStore, WritesReevaluateTheTileAndTheGlobalRange) {
  const auto dir = test::tempDir("store");
  SyntheticScene s = smallScene();
  s.roughFraction = 0;
  s.rampFraction = 0;  // all flat at 100 m
  auto store = ingestScene(dir, 3 * kFootprint, 2 * kFootprint, s);
  for (int i = 0; i < 6; ++i) EXPECT_EQ(store.tile(i % 3, i / 3).exp, kMinExp);
  // A rough patch (0..500 m) into tile (1,0): the global range becomes [0, 500], the patch's tile
  // spans all of it -> 2^max; its cells read back exactly.
  Grid<float> patch(20, 20);
  for (int i = 0; i < 400; ++i) patch.data[size_t(i)] = float((i * 37) % 501);
  ASSERT_TRUE(store.writeWindow(0, kFootprint + 10, 10, patch));
  EXPECT_EQ(store.tile(1, 0).exp, kMaxExp);
  EXPECT_EQ(store.tile(0, 0).exp, kMinExp);
  EXPECT_EQ(store.globalRange(0), std::make_pair(0.0f, 500.0f));
  auto back = store.readWindow(0, {kFootprint + 10, 10, 20, 20}, 0);
  ASSERT_TRUE(back);
  EXPECT_EQ(back->data, patch.data);
  // A 5000 m spike in tile (2,1) stretches the global range tenfold: (1,0)'s ratio drops from 1
  // to ~0.1 -> resampled down to 2^min; the spike's tile goes to 2^max.
  ASSERT_TRUE(store.writeWindow(0, 2 * kFootprint + 5, kFootprint + 5, Grid<float>(1, 1, 5000.0f)));
  EXPECT_EQ(store.globalRange(0), std::make_pair(0.0f, 5000.0f));
  EXPECT_EQ(store.tile(2, 1).exp, kMaxExp);
  EXPECT_EQ(store.tile(1, 0).exp, kMinExp);
  // Flattening the spike shrinks the range back: (1,0) goes up again (its stored detail is gone,
  // the stats it was evaluated on are kept), (2,1) down.
  ASSERT_TRUE(store.writeWindow(0, 2 * kFootprint + 5, kFootprint + 5, Grid<float>(1, 1, 100.0f)));
  EXPECT_EQ(store.tile(2, 1).exp, kMinExp);
  EXPECT_EQ(store.tile(1, 0).exp, kMaxExp);
  // Nothing is on disk for other readers before commit; after it, a reopen sees the writes.
  EXPECT_EQ(TileStore::open(dir)->tile(1, 0).exp, kMinExp);
  ASSERT_TRUE(store.commit());
  auto again = TileStore::open(dir);
  EXPECT_EQ(again->tile(1, 0).exp, kMaxExp);
  EXPECT_EQ(problemsOf(*again), "");
  // Superseded files are gone after the commit: one file per present tile.
  EXPECT_EQ(std::distance(fs::directory_iterator(dir / "tiles"), fs::directory_iterator()), 6);
  EXPECT_FALSE(store.writeWindow(0, 3 * kFootprint - 1, 0, Grid<float>(2, 1, 0.0f)));
}

TEST(TileStore, GlobalLayoutWrapsTheSeamAndFoldsThePoles) {
  const auto dir = test::tempDir("store");
  gis::Georef g;
  g.epsg = 4326;
  g.crsName = "WGS 84";
  g.geographic = true;
  const int w = 256, h = 128;  // 1.40625 degree cells, 4 x 2 tiles of 64
  g.transform = {{-180.0, 360.0 / w, 0.0, 90.0, 0.0, -180.0 / h}};
  g.width = w;
  g.height = h;
  auto value = [](int x, int y) { return float(x * 1000 + y); };  // exact in float32 (< 2^24)
  auto reader = [&](int x0, int y0, int ww, int hh) -> Result<Grid<float>> {
    Grid<float> out(ww, hh);
    for (int y = 0; y < hh; ++y) {
      for (int x = 0; x < ww; ++x) out.at(x, y) = value(x0 + x, y0 + y);
    }
    return out;
  };
  auto opts = smallOptions();
  opts.layout = TileLayout::Global;
  opts.metric = {kMaxExp, kMaxExp};  // every tile at full resolution: reads are exact
  ASSERT_TRUE(ingest(dir, g, {bedrock(reader)}, opts));
  auto store = TileStore::open(dir);
  ASSERT_TRUE(store);
  // Across the seam: columns 250..255 then 0..5.
  auto seam = store->readWindow(0, {250, 40, 12, 3}, 0);
  ASSERT_TRUE(seam);
  EXPECT_EQ(seam->at(0, 0), value(250, 40));
  EXPECT_EQ(seam->at(6, 2), value(0, 42));
  EXPECT_EQ(seam->at(11, 1), value(5, 41));
  // Over the north pole: row -1 is row 0 half a turn away, row -3 is row 2.
  auto pole = store->readWindow(0, {10, -3, 4, 5}, 0);
  ASSERT_TRUE(pole);
  EXPECT_EQ(pole->at(0, 0), value(10 + w / 2, 2));
  EXPECT_EQ(pole->at(1, 2), value(11 + w / 2, 0));
  EXPECT_EQ(pole->at(3, 3), value(13, 0));
  // Over the south pole near the seam: both at once.
  auto south = store->readWindow(0, {w / 2 - 1, h - 1, 2, 2}, 0);
  ASSERT_TRUE(south);
  EXPECT_EQ(south->at(0, 0), value(w / 2 - 1, h - 1));
  EXPECT_EQ(south->at(0, 1), value(w - 1, h - 1));
  EXPECT_EQ(south->at(1, 1), value(0, h - 1));
  // A global layout needs a whole-globe geographic grid.
  g.transform.c[1] = 1.0;
  EXPECT_FALSE(ingest(test::tempDir("bad"), g, {bedrock(reader)}, opts));
}

TEST(TileCache, KeepsItsBudgetAndHitsOnRereads) {
  const auto dir = test::tempDir("store");
  SyntheticScene s = smallScene();
  s.roughFraction = 1.0f;  // every tile at 2^6: 16 KiB decoded per tile level
  ingestScene(dir, 4 * kFootprint, 4 * kFootprint, s);
  const size_t tileBytes = size_t(kFootprint) * kFootprint * sizeof(float);
  auto store = TileStore::open(dir, {.budgetBytes = 3 * tileBytes, .prefetch = false});
  ASSERT_TRUE(store);
  for (int i = 0; i < 16; ++i) ASSERT_TRUE(store->readWindow(0, {(i % 4) * kFootprint, (i / 4) * kFootprint, 8, 8}));
  auto st = store->cacheStats();
  EXPECT_EQ(st.misses, 16u);
  EXPECT_EQ(st.evictions, 13u);
  EXPECT_LE(st.bytes, 3 * tileBytes);
  // The three most recent tiles hit; an older one missed again.
  for (int i = 13; i < 16; ++i) ASSERT_TRUE(store->readWindow(0, {(i % 4) * kFootprint, (i / 4) * kFootprint, 8, 8}));
  ASSERT_TRUE(store->readWindow(0, {0, 0, 8, 8}));
  st = store->cacheStats();
  EXPECT_EQ(st.hits, 3u);
  EXPECT_EQ(st.misses, 17u);
}

TEST(TileCache, PrefetchesTheNeighboursOfAMiss) {
  const auto dir = test::tempDir("store");
  SyntheticScene s = smallScene();
  s.roughFraction = 1.0f;
  ingestScene(dir, 3 * kFootprint, 3 * kFootprint, s);
  auto store = TileStore::open(dir, {.budgetBytes = size_t(64) << 20, .prefetch = true});
  ASSERT_TRUE(store);
  ASSERT_TRUE(store->readWindow(0, {kFootprint, kFootprint, 4, 4}));  // the centre tile
  // The 8 neighbours load in the background; 5 s is ample for 8 small tiles on a loaded machine.
  const auto until = std::chrono::steady_clock::now() + std::chrono::seconds(5);
  while (store->cacheStats().prefetchLoads < 8 && std::chrono::steady_clock::now() < until) {
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
  }
  ASSERT_EQ(store->cacheStats().prefetchLoads, 8u);
  ASSERT_TRUE(store->readWindow(0, {0, 0, 3 * kFootprint, 3 * kFootprint}));
  const auto st = store->cacheStats();
  EXPECT_EQ(st.prefetchHits, 8u);
  EXPECT_EQ(st.misses, 1u);
  EXPECT_EQ(st.hits, 9u);  // the 8 prefetched neighbours and the centre tile read first
}

// Waits (5 s at most: ample for a few small tiles on a loaded machine) until `store` has no
// request left.
void waitForLoader(TileStore& store) {
  const auto until = std::chrono::steady_clock::now() + std::chrono::seconds(5);
  while (store.requestsPending() > 0 && std::chrono::steady_clock::now() < until) {
    std::this_thread::sleep_for(std::chrono::milliseconds(2));
  }
}

TEST(TileCache, TryReadWindowNeverReadsAFileOnTheCallersThread) {
  const auto dir = test::tempDir("store");
  SyntheticScene s = smallScene();
  s.roughFraction = 1.0f;
  ingestScene(dir, 3 * kFootprint, 2 * kFootprint, s);
  // Every decode sleeps 50 ms: a caller that waited for one would take at least that long.
  const double delayMs = 50;
  auto store = TileStore::open(dir, {.budgetBytes = size_t(64) << 20, .prefetch = false, .loadDelayMs = delayMs});
  ASSERT_TRUE(store);
  const gis::CellRect w{kFootprint / 2, kFootprint / 2, 2 * kFootprint, kFootprint};  // over 3 x 2 tiles
  const auto t0 = std::chrono::steady_clock::now();
  auto first = store->tryReadWindow(0, w, 0);
  const double ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
  ASSERT_TRUE(first) << first.message();
  EXPECT_FALSE(first->has_value());
  EXPECT_LT(ms, delayMs);                  // no decode on this thread (measured: well under 1 ms)
  EXPECT_EQ(store->requestsPending(), 6);  // every missing tile level is asked for at once
  // Asking again while the loader works queues nothing twice.
  ASSERT_TRUE(store->tryReadWindow(0, w, 0));
  EXPECT_LE(store->requestsPending(), 6);
  waitForLoader(*store);
  ASSERT_EQ(store->requestsPending(), 0);
  auto ready = store->tryReadWindow(0, w, 0);
  ASSERT_TRUE(ready && ready->has_value());
  auto blocking = store->readWindow(0, w, 0);
  ASSERT_TRUE(blocking);
  EXPECT_EQ((*ready)->data, blocking->data);
  const auto st = store->cacheStats();
  EXPECT_EQ(st.syncLoads, 0u);     // nothing decoded on the caller's thread
  EXPECT_EQ(st.requestLoads, 6u);  // each tile level decoded once, by the loader
  // clearRequests drops what the loader has not started.
  store->clearCache();
  ASSERT_TRUE(store->tryReadWindow(0, {0, 0, 3 * kFootprint, 2 * kFootprint}, 0));
  store->clearRequests();
  EXPECT_LE(store->requestsPending(), 1);  // at most the one being decoded
}

TEST(TileStore, TryReadWindowReportsACorruptTileOnceTheLoaderFoundIt) {
  const auto dir = test::tempDir("store");
  auto store = ingestScene(dir, 2 * kFootprint, kFootprint, smallScene());
  const auto file = dir / store.tile(1, 0).file;
  fs::resize_file(file, fs::file_size(file) / 2);
  auto reopened = TileStore::open(dir, {.prefetch = false});
  ASSERT_TRUE(reopened);
  auto first = reopened->tryReadWindow(0, {kFootprint, 0, 4, 4}, 0);
  ASSERT_TRUE(first) << first.message();
  EXPECT_FALSE(first->has_value());
  waitForLoader(*reopened);
  auto bad = reopened->tryReadWindow(0, {kFootprint, 0, 4, 4}, 0);
  ASSERT_FALSE(bad);
  EXPECT_NE(bad.message().find(store.tile(1, 0).file), std::string::npos) << bad.message();
}

// Cell values of field 0 over the whole store.
std::vector<float> allCells(TileStore& s) {
  auto g = s.readWindow(0, {0, 0, s.width(), s.height()}, 0);
  STRATA_CHECK(g.ok()) << g.message();
  return g->data;
}

TEST(TileStore, AWriterKilledBeforeItsCommitLeavesTheEarlierStore) {
  const auto dir = test::tempDir("store");
  std::vector<float> before;
  fs::path newFile;
  {
    auto store = ingestScene(dir, 3 * kFootprint, 2 * kFootprint, smallScene());
    before = allCells(store);
    // Writes whose tile files land on disk, then a "crash" before commit (the writer goes away,
    // releasing its lock): one new tile file is truncated, a manifest temporary and a tile
    // temporary are left half written.
    Grid<float> patch(2 * kFootprint, kFootprint, 7.0f);
    ASSERT_TRUE(store.writeWindow(0, 10, 10, patch));
    newFile = dir / store.tile(1, 0).file;
  }
  fs::resize_file(newFile, fs::file_size(newFile) / 2);
  std::ofstream(dir / "manifest.toml.tmp") << "format = \"strata-tile-st";
  std::ofstream(dir / "tiles" / "x9_y9_g999.exr.tmp") << "partial";
  auto reopened = TileStore::open(dir, {.prefetch = false});
  ASSERT_TRUE(reopened) << reopened.message();
  EXPECT_EQ(problemsOf(*reopened), "");
  EXPECT_EQ(allCells(*reopened), before);
  // The next commit sweeps the leftovers.
  ASSERT_TRUE(reopened->commit());
  EXPECT_FALSE(fs::exists(dir / "tiles" / "x9_y9_g999.exr.tmp"));
  EXPECT_FALSE(fs::exists(newFile));
}

// Issue 33: a commit sweeps the manifest temporaries a killed writer left (writeFileAtomic's
// manifest.toml.tmp-PID-N) and nothing else: a user's file named alike stays.
TEST(TileStore, ACommitRemovesOnlyItsOwnTemporaries) {
  const auto dir = test::tempDir("store");
  auto store = ingestScene(dir, 2 * kFootprint, kFootprint, smallScene());
  std::ofstream(dir / "manifest.toml.tmp-4242-0") << "format = \"strata-tile-st";
  std::ofstream(dir / "manifest.toml.tmp-mydraft") << "my notes";
  std::ofstream(dir / "manifest.toml.tmp-1-2-3") << "mine too";
  ASSERT_TRUE(store.commit());
  EXPECT_FALSE(fs::exists(dir / "manifest.toml.tmp-4242-0"));
  EXPECT_TRUE(fs::exists(dir / "manifest.toml.tmp-mydraft"));
  EXPECT_TRUE(fs::exists(dir / "manifest.toml.tmp-1-2-3"));
}

TEST(TileStore, AWriterKilledMidStreamLeavesACommittedVersion) {
  const auto dir = test::tempDir("store");
  SyntheticScene s = smallScene();
  s.roughFraction = s.rampFraction = 0;
  { ingestScene(dir, 4 * kFootprint, 2 * kFootprint, s); }
  // The child rewrites the whole field with value k and commits, for k = 1, 2, ...; SIGKILL hits
  // it at some point of that loop. Every commit is a consistent version.
  const pid_t child = fork();
  ASSERT_GE(child, 0);
  if (child == 0) {
    auto st = TileStore::open(dir, {.prefetch = false});
    for (int k = 1;; ++k) {
      Grid<float> all(st->width(), st->height(), float(k));
      all.at(k % st->width(), 0) = float(k + 1000);  // some tiles go rough, then back
      if (!st->writeWindow(0, 0, 0, all) || !st->commit()) _exit(3);
    }
  }
  std::this_thread::sleep_for(std::chrono::milliseconds(700));
  ASSERT_EQ(kill(child, SIGKILL), 0);
  int status = 0;
  waitpid(child, &status, 0);
  ASSERT_TRUE(WIFSIGNALED(status)) << "the writer stopped on its own (status " << status << ")";
  auto st = TileStore::open(dir, {.prefetch = false});
  ASSERT_TRUE(st) << st.message();
  EXPECT_EQ(problemsOf(*st), "");
  const auto cells = allCells(*st);
  std::set<float> values;
  for (float v : cells) {
    if (v < 1000) values.insert(v);
  }
  // One version throughout: the base (100) or a single k.
  ASSERT_EQ(values.size(), 1u);
  std::cout << "writer killed at version " << *values.begin() << "\n";
}

TEST(TileStore, AFlippedByteIsReportedAndNeverUsed) {
  const auto dir = test::tempDir("store");
  auto store = ingestScene(dir, 2 * kFootprint, kFootprint, smallScene());
  const auto file = dir / store.tile(1, 0).file;
  {
    std::fstream f(file, std::ios::in | std::ios::out | std::ios::binary);
    f.seekg(std::streamoff(fs::file_size(file) / 2));
    char c = 0;
    f.read(&c, 1);
    c = char(c ^ 0x10);
    f.seekp(std::streamoff(fs::file_size(file) / 2));
    f.write(&c, 1);
  }
  auto reopened = TileStore::open(dir, {.prefetch = false});
  ASSERT_TRUE(reopened);
  const auto problems = reopened->verify();
  ASSERT_EQ(problems.size(), 1u);
  EXPECT_EQ(problems[0].file, store.tile(1, 0).file);
  EXPECT_NE(problems[0].message.find("checksum mismatch"), std::string::npos) << problems[0].message;
  auto bad = reopened->readWindow(0, {kFootprint, 0, 4, 4}, 0);
  ASSERT_FALSE(bad);
  EXPECT_NE(bad.message().find(store.tile(1, 0).file), std::string::npos) << bad.message();
  EXPECT_TRUE(reopened->readWindow(0, {0, 0, 4, 4}, 0));
}

TEST(TileStore, LayeredStoresKeepEveryField) {
  const auto dir = test::tempDir("store");
  const int w = 2 * kFootprint, h = kFootprint;
  auto constant = [](float v) {
    return [v](int, int, int ww, int hh) -> Result<Grid<float>> { return Grid<float>(ww, hh, v); };
  };
  std::vector<IngestSource> src = {bedrock(syntheticReader(smallScene())),
                                   {{"soil", LayerKind::Material, "soil"}, constant(2.0f)},
                                   {{"sand", LayerKind::Material, "sand"}, constant(0.5f)},
                                   {{"water", LayerKind::Water, ""}, constant(0.0f)}};
  ASSERT_TRUE(ingest(dir, planarGeoref(w, h), src, smallOptions()));
  auto store = TileStore::open(dir);
  ASSERT_TRUE(store);
  EXPECT_EQ(store->fieldIndex("sand"), 2);
  auto t = store->readTerrain({0, 0, w, h});
  ASSERT_TRUE(t) << t.message();
  ASSERT_EQ(t->layers.size(), 2u);
  EXPECT_EQ(t->materials[size_t(t->layers[1].material)].name, "sand");
  const auto s = smallScene();
  for (int x = 0; x < w; x += 9) {
    if (syntheticBlockKind(s, x / kFootprint, 0) == SyntheticBlock::Ramp) continue;
    EXPECT_EQ(t->surfaceAt(x, 3), syntheticElevation(s, x, 3) + 2.5f);  // + 2 + 0.5 m, exact
  }
  EXPECT_FALSE(ingest(test::tempDir("dup"), planarGeoref(w, h), {src[0], src[0]}, smallOptions()));
}

}  // namespace
}  // namespace strata::terrain
