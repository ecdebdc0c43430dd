// The GPU tile cache and elevation streamed from a tile store (docs/render-rings.md,
// "Streaming"), on a small store ingested from the Grand Canyon DEM: page contents equal the
// store's reads, the byte budget and LRU order hold, a streamed render matches the whole-DEM
// render, moving refills only the exposed pages, and a frame with no upload budget has no hole.
#include <gtest/gtest.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstring>
#include <fstream>
#include <set>
#include <tuple>

#include <strata/gis/dem_io.hpp>
#include <strata/render/drape.hpp>
#include <strata/render/gpu_tile_cache.hpp>
#include <strata/render/image_io.hpp>
#include <strata/render/screen_error.hpp>
#include <strata/render/sliding_grid.hpp>
#include <strata/render/streamed_elevation.hpp>
#include <strata/render/terrain_renderer.hpp>
#include <strata/terrain/dem_sources.hpp>
#include <strata/terrain/ingest.hpp>
#include <strata/terrain/tile_store.hpp>

#include "drape_raster.hpp"
#include "gl_fixture.hpp"
#include "strata_test.hpp"
#include "terrain_fixture.hpp"

namespace strata::render {
namespace {

using strata::terrain::TileStore;
using test::GlTest;

// Tiles of 128 cells (4 x 4 over the 512^2 DEM), exponents 2^4..2^7: the flat plateaus are
// stored coarser than the canyon, so level-0 reads are not the DEM itself everywhere.
const std::filesystem::path& canyonStore() {
  static const std::filesystem::path dir = [] {
    const auto d = test::tempDir("canyon_store") / "store";
    const std::string path = test::dataPath("grand_canyon/grand_canyon_512.tif");
    auto dem = gis::readDem(path);
    EXPECT_TRUE(dem) << dem.message();
    strata::terrain::IngestOptions o;
    o.metric = {.minExp = 4, .maxExp = 7};
    o.cache.prefetch = false;
    auto rep = strata::terrain::ingest(
        d, dem->georef, {{{"bedrock", strata::terrain::LayerKind::Bedrock, ""}, strata::terrain::demReader(path)}}, o);
    EXPECT_TRUE(rep) << rep.message();
    return d;
  }();
  return dir;
}

TileStore openStore() {
  auto s = TileStore::open(canyonStore(), {.budgetBytes = size_t(16) << 20, .prefetch = false});
  STRATA_CHECK(bool(s)) << s.message();
  return std::move(s).value();
}

GpuCacheOptions pageOptions(size_t budgetBytes) {
  GpuCacheOptions o;
  o.pageSize = 32;
  o.budgetBytes = budgetBytes;
  return o;
}

bool sameFloat(float a, float b) { return (std::isnan(a) && std::isnan(b)) || std::memcmp(&a, &b, 4) == 0; }

TEST_F(GlTest, GpuTileCachePagesEqualTheStoresReads) {
  auto store = openStore();
  auto cache = GpuTileCache::create(store, pageOptions(64 * 32 * 32 * 4));
  ASSERT_TRUE(cache) << cache.message();
  // Pages at four levels, including the last row and column of each level and a page that
  // gathers several tiles (level 3: a page of 32 cells spans 2 x 2 tiles of 16).
  std::vector<PageKey> keys;
  for (int lod = 0; lod <= 3; ++lod) {
    const int last = (store.levelWidth(lod) + 31) / 32 - 1;
    keys.push_back({0, 0, 0, lod});
    keys.push_back({0, last, last, lod});
    keys.push_back({0, last / 2, 0, lod});
  }
  std::vector<int> layers;
  std::vector<std::tuple<int, int, int>> distinct;
  for (const auto& k : keys) {
    distinct.emplace_back(k.x, k.y, k.lod);
    auto layer = cache->acquire(k);
    ASSERT_TRUE(layer) << layer.message();
    layers.push_back(*layer);
  }
  const auto gpu = cache->pages().read<float>();
  for (size_t i = 0; i < keys.size(); ++i) {
    const auto& k = keys[i];
    auto cpu = store.readWindow(k.field, {k.x * 32, k.y * 32, 32, 32}, k.lod);
    ASSERT_TRUE(cpu) << cpu.message();
    const float* page = gpu.data() + size_t(layers[i]) * 32 * 32;
    int mismatches = 0;
    for (size_t j = 0; j < cpu->data.size(); ++j) mismatches += sameFloat(page[j], cpu->data[j]) ? 0 : 1;
    // Bit for bit: the page is the store's float samples, copied.
    EXPECT_EQ(mismatches, 0) << "page " << k.x << "," << k.y << " of level " << k.lod;
  }
  // Each distinct page is uploaded once (level 3 has 2 x 2 pages: some keys repeat).
  const std::set<std::tuple<int, int, int>> unique(distinct.begin(), distinct.end());
  EXPECT_EQ(cache->stats().uploads, unique.size());
}

TEST_F(GlTest, GpuTileCacheHoldsItsBudgetOverAWalk) {
  auto store = openStore();
  const size_t page = 32 * 32 * 4;
  const size_t budget = 5 * page + page / 2;  // room for 5 pages, not 6
  auto cache = GpuTileCache::create(store, pageOptions(budget));
  ASSERT_TRUE(cache) << cache.message();
  EXPECT_EQ(cache->capacity(), 5);
  // A serpentine walk over all 16 x 16 level-0 pages: 1 MiB of elevation through 20 KiB.
  int steps = 0;
  for (int y = 0; y < 16; ++y) {
    for (int i = 0; i < 16; ++i) {
      const int x = y % 2 ? 15 - i : i;
      ASSERT_TRUE(cache->acquire({0, x, y, 0}));
      const auto s = cache->stats();
      ASSERT_LE(s.bytesResident, budget);
      ASSERT_LE(s.bytesAllocated, budget);
      ++steps;
    }
  }
  auto s = cache->stats();
  EXPECT_EQ(s.misses, uint64_t(steps));
  EXPECT_EQ(s.uploads, uint64_t(steps));
  EXPECT_EQ(s.evictions, uint64_t(steps - 5));
  EXPECT_EQ(s.bytesResident, 5 * page);
  // The last five pages of the walk are the ones resident: touching them again uploads nothing.
  cache->resetStats();
  for (int x = 0; x < 5; ++x) ASSERT_TRUE(cache->acquire({0, x, 15, 0}));
  EXPECT_EQ(cache->stats().hits, 5u);
  EXPECT_EQ(cache->stats().uploads, 0u);
}

TEST_F(GlTest, GpuTileCacheEvictsTheLeastRecentlyUsed) {
  auto store = openStore();
  auto cache = GpuTileCache::create(store, pageOptions(3 * 32 * 32 * 4));
  ASSERT_TRUE(cache) << cache.message();
  const PageKey a{0, 0, 0, 0}, b{0, 1, 0, 0}, c{0, 2, 0, 0}, d{0, 3, 0, 0};
  for (const auto& k : {a, b, c}) ASSERT_TRUE(cache->acquire(k));
  const int layerB = cache->find(b);
  ASSERT_TRUE(cache->acquire(a));  // a becomes the most recent: b is now the oldest
  ASSERT_TRUE(cache->acquire(d));
  EXPECT_EQ(cache->find(b), -1);
  EXPECT_EQ(cache->find(d), layerB);
  EXPECT_EQ(cache->lruOrder(), (std::vector<PageKey>{d, a, c}));
  EXPECT_EQ(cache->stats().evictions, 1u);
  EXPECT_EQ(cache->stats().hits, 1u);
}

// ---- Streaming -----------------------------------------------------------------------------

using test::kCanyonCamera;  // the golden test's oblique view of the canyon

// The store's level-0 read as a whole-DEM scene: what streaming must reproduce.
Result<TerrainScene> storeAsWholeScene() {
  auto store = openStore();
  STRATA_TRY(auto grid, store.readWindow(0, {0, 0, store.width(), store.height()}, 0));
  return TerrainScene::create(gis::Raster{store.desc().georef, std::move(grid)});
}

struct Diff {
  double colourFraction = 0;  // pixels with a channel off by more than the threshold
  int maxChannel = 0;
  double elevMeanM = 0, elevP99M = 0, elevMaxM = 0;
  size_t terrainMismatch = 0;  // terrain in one image, sky in the other
};

Diff compare(const OffscreenTarget& a, const OffscreenTarget& b, int threshold) {
  const auto ca = a.colour(), cb = b.colour();
  const auto ea = a.elevation(), eb = b.elevation();
  Diff d;
  size_t off = 0;
  std::vector<double> de;
  for (size_t p = 0; p < ea.size(); ++p) {
    int m = 0;
    for (int c = 0; c < 3; ++c) m = std::max(m, std::abs(int(ca[p * 4 + size_t(c)]) - int(cb[p * 4 + size_t(c)])));
    d.maxChannel = std::max(d.maxChannel, m);
    off += m > threshold ? 1 : 0;
    if (std::isnan(ea[p]) != std::isnan(eb[p])) ++d.terrainMismatch;
    if (!std::isnan(ea[p]) && !std::isnan(eb[p])) de.push_back(std::abs(double(ea[p]) - double(eb[p])));
  }
  d.colourFraction = double(off) / double(ea.size());
  if (!de.empty()) {
    double sum = 0;
    for (double v : de) sum += v;
    d.elevMeanM = sum / double(de.size());
    std::sort(de.begin(), de.end());
    d.elevP99M = de[std::min(de.size() - 1, size_t(0.99 * double(de.size())))];
    d.elevMaxM = de.back();
  }
  return d;
}

// The whole-DEM and the streamed scene drawn from the canyon camera (64 circles, 256 x 160, fog,
// the whole scene's tint range) and compared with a colour threshold of 8; the streamed picture
// into `picture` when given. 64 circles: the ring wants, at distance r, texels about as large as
// its tangential spacing 2 pi r / 6i, which a window of N texels holds out to where that is its
// level: N >= 2n (docs/render-rings.md, "Streaming"). With 128 circles: 3.1 m mean, 33 m 99th
// percentile.
constexpr int kMatchW = 256, kMatchH = 160;
Result<Diff> drawBothAndCompare(const TerrainScene& whole, const TerrainScene& streamed,
                                std::vector<uint8_t>* picture = nullptr) {
  STRATA_TRY(auto ring, RingRenderer::create({.circles = 64}));
  STRATA_TRY(auto t1, OffscreenTarget::create(kMatchW, kMatchH));
  STRATA_TRY(auto t2, OffscreenTarget::create(kMatchW, kMatchH));
  Shading shading;
  shading.fogM = 150000;
  shading.tintRangeM = glm::vec2(whole.minElevationM(), whole.maxElevationM());
  STRATA_TRY_STATUS(ring->draw(whole, kCanyonCamera, shading, t1));
  STRATA_TRY_STATUS(ring->draw(streamed, kCanyonCamera, shading, t2));
  if (picture) *picture = t2.colour();
  return compare(t1, t2, 8);
}

TEST_F(GlTest, StreamedWithTheWholeTerrainResidentIsTheWholeDemRender) {
  // clipSize 512 >= the grid: level 0 is the coarse level, the stack is empty, and the streamed
  // path samples the same texture as the whole-DEM path: the images must be identical.
  auto whole = storeAsWholeScene();
  ASSERT_TRUE(whole) << whole.message();
  auto streamed = TerrainScene::createStreamed(openStore(), {.clipSize = 512, .pageSize = 64});
  ASSERT_TRUE(streamed) << streamed.message();
  EXPECT_EQ(streamed->streamed()->coarseLevel(), 0);
  auto ring = RingRenderer::create({.circles = 96});
  ASSERT_TRUE(ring) << ring.message();
  auto t1 = OffscreenTarget::create(192, 120), t2 = OffscreenTarget::create(192, 120);
  ASSERT_TRUE(t1 && t2);
  // The tint range: the store's global range (its base cells) is wider than the range of its
  // level-0 read (coarse tiles are block means), so both use the same explicit one.
  Shading shading;
  shading.tintRangeM = glm::vec2(whole->minElevationM(), whole->maxElevationM());
  ASSERT_TRUE((*ring)->draw(*whole, kCanyonCamera, shading, *t1));
  ASSERT_TRUE((*ring)->draw(*streamed, kCanyonCamera, shading, *t2));
  const Diff d = compare(*t1, *t2, 0);
  EXPECT_EQ(d.maxChannel, 0);
  EXPECT_EQ(d.elevMaxM, 0.0);
  EXPECT_EQ(d.terrainMismatch, 0u);
}

TEST_F(GlTest, StreamedRenderMatchesTheWholeDemRender) {
  auto whole = storeAsWholeScene();
  ASSERT_TRUE(whole) << whole.message();
  // Windows of 128 texels at levels 0 and 1, level 2 (128^2) the coarse texture.
  const StreamParams params{.clipSize = 128, .pageSize = 32, .uploadPagesPerFrame = 1000};
  auto streamed = TerrainScene::createStreamed(openStore(), params);
  ASSERT_TRUE(streamed) << streamed.message();
  ASSERT_EQ(streamed->streamed()->coarseLevel(), 2);
  auto diff = drawBothAndCompare(*whole, *streamed);
  ASSERT_TRUE(diff) << diff.message();
  EXPECT_EQ(streamed->streamed()->stats().pending, 0);
  const Diff d = *diff;
  const int w = kMatchW, h = kMatchH;
  std::ofstream(test::outputDir("render") / "streaming_match.txt")
      << "# streamed (N=128, P=32, levels 0-1 streamed, 2 coarse) vs whole-DEM ring render, Grand Canyon store, " << w
      << "x" << h << "\ncolour_fraction_over_8 " << d.colourFraction << "\nmax_channel " << d.maxChannel
      << "\nelev_mean_m " << d.elevMeanM << "\nelev_p99_m " << d.elevP99M << "\nelev_max_m " << d.elevMaxM
      << "\nterrain_mismatch_px " << d.terrainMismatch << "\n";
  // Where the windows hold the wanted level the two sample the same values; outside them the
  // ring's wanted level below 1 (resp. 2) is served by level 1 (resp. 2), a smoother surface.
  // Measured on llvmpipe: see streaming_match.txt and docs/render-rings.md.
  EXPECT_LT(d.elevMeanM, 1.0);
  EXPECT_LT(d.elevP99M, 15.0);
  EXPECT_LT(d.colourFraction, 0.02);
  EXPECT_LT(d.terrainMismatch, size_t(w * h / 100));
}

// Issue 33: voids in a streamed store were drawn as shafts down to its lowest elevation (a page
// has no neighbours to fill from), where the whole-DEM render fills them from the cells around.
// Three voids of 6 x 6 cells in the view (5, 10 and 20 km ahead of the camera, on the canyon's
// rims and slopes) now take the filled coarse level's surface: the streamed render matches the
// whole-DEM render of the same voided DEM up to the two fills' difference over the voids.
TEST_F(GlTest, StreamedVoidsAreDrawnAsTheWholeDemDrawsThem) {
  const std::string path = test::dataPath("grand_canyon/grand_canyon_512.tif");
  auto dem = gis::readDem(path);
  ASSERT_TRUE(dem) << dem.message();
  for (const auto& [cx, cy] : {std::pair{445, 471}, std::pair{419, 461}, std::pair{367, 442}}) {
    for (int y = cy - 3; y < cy + 3; ++y) {
      for (int x = cx - 3; x < cx + 3; ++x) dem->values.at(x, y) = gis::kNoData;
    }
  }
  const auto dir = test::tempDir("void_store") / "store";
  strata::terrain::IngestOptions o;
  o.metric = {.minExp = 4, .maxExp = 7};
  o.cache.prefetch = false;
  const gis::Grid<float> voided = dem->values;
  auto reader = [&voided](int x, int y, int w, int h) -> Result<gis::Grid<float>> {
    gis::Grid<float> g(w, h, gis::kNoData);
    for (int j = 0; j < h; ++j) {
      for (int i = 0; i < w; ++i) {
        if (x + i < voided.width && y + j < voided.height) g.at(i, j) = voided.at(x + i, y + j);
      }
    }
    return g;
  };
  auto rep =
      strata::terrain::ingest(dir, dem->georef, {{{"bedrock", strata::terrain::LayerKind::Bedrock, ""}, reader}}, o);
  ASSERT_TRUE(rep) << rep.message();
  auto store = TileStore::open(dir, {.budgetBytes = size_t(16) << 20, .prefetch = false});
  ASSERT_TRUE(store) << store.message();
  // The whole-DEM render of the store's level 0 (voids and all), voids filled (the default).
  auto grid = store->readWindow(0, {0, 0, store->width(), store->height()}, 0);
  ASSERT_TRUE(grid) << grid.message();
  auto whole = TerrainScene::create(gis::Raster{store->desc().georef, std::move(*grid)});
  ASSERT_TRUE(whole) << whole.message();
  EXPECT_EQ(whole->voidCount(), 108u);
  auto streamed =
      TerrainScene::createStreamed(std::move(*store), {.clipSize = 128, .pageSize = 32, .uploadPagesPerFrame = 1000});
  ASSERT_TRUE(streamed) << streamed.message();
  std::vector<uint8_t> picture;
  auto diff = drawBothAndCompare(*whole, *streamed, &picture);
  ASSERT_TRUE(diff) << diff.message();
  const Diff d = *diff;
  const int w = kMatchW, h = kMatchH;
  std::ofstream(test::outputDir("render") / "streaming_voids.txt")
      << "# streamed vs whole-DEM ring render of the canyon with three 6 x 6-cell voids, " << w << "x" << h
      << "\ncolour_fraction_over_8 " << d.colourFraction << "\nelev_mean_m " << d.elevMeanM << "\nelev_p99_m "
      << d.elevP99M << "\nelev_max_m " << d.elevMaxM << "\n";
  ASSERT_TRUE(render::writeImage8((test::outputDir("render") / "streaming_voids.png").string(), w, h, 4, picture));
  // Measured on llvmpipe: 0.29 % of pixels off by more than 8, elevation mean 0.69 m, 99th
  // percentile 17 m (a streamed page's voids filled by GDAL from the page and a page-wide margin,
  // as the whole-DEM render fills its grid; the rest is the levels' box means over the voids'
  // edges). With the coarse level's surface over a page's voids: 1.1 %, 1.3 m and 36 m; with the
  // lowest elevation before that: 5.0 %, 13.5 m and 362 m, a pit in the picture. Issue 33 asks
  // for under 1 % of pixels.
  EXPECT_LT(d.colourFraction, 0.01);
  EXPECT_LT(d.elevMeanM, 1.0);
  EXPECT_LT(d.elevP99M, 25.0);
}

// A drape, cast shadows and a graticule on a streamed scene (the drape over the whole terrain,
// shadows and lon/lat on the overview level: here level 0, the store's 512^2) look as on the
// whole-DEM scene, up to the streamed elevation's own difference (the test above); and they
// are drawn (the picture differs from the one without them).
TEST_F(GlTest, DrapeShadowsAndGraticuleOnAStreamedSceneMatchTheWholeDem) {
  auto whole = storeAsWholeScene();
  ASSERT_TRUE(whole) << whole.message();
  const StreamParams params{.clipSize = 128, .pageSize = 32, .uploadPagesPerFrame = 1000};
  auto streamed = TerrainScene::createStreamed(openStore(), params);
  ASSERT_TRUE(streamed) << streamed.message();
  auto plain = TerrainScene::createStreamed(openStore(), params);
  ASSERT_TRUE(plain) << plain.message();
  // The UTM marker raster of the drape tests (blue, a red square), reprojected onto each scene.
  const std::string drapePath = (test::tempDir("streamed-drape") / "utm_marker.tif").string();
  ASSERT_TRUE(test::writeUtmMarker(drapePath));
  SunSpec sun;
  sun.dirEnu = glm::normalize(glm::dvec3(-1.0, 0.3, 0.35));  // low in the west
  for (TerrainScene* scene : {&*whole, &*streamed}) {
    auto drape = loadDrape(drapePath, scene->georef());
    ASSERT_TRUE(drape) << drape.message();
    ASSERT_TRUE(scene->setDrape(*drape));
    ASSERT_TRUE(scene->castShadows(sun, 1.0f));
    ASSERT_TRUE(scene->enableGraticule());
    EXPECT_EQ(scene->overviewUvScale(), glm::vec2(1.0f, 1.0f));
  }
  // A store wider than the overview's side gives a coarser level with its own cells.
  auto over = streamed->streamed()->overview(100);
  ASSERT_TRUE(over) << over.message();
  EXPECT_EQ(over->georef.width, 64);  // level 3 of 512
  EXPECT_EQ(streamed->streamed()->overviewGrid(100).transform.c[1], over->georef.transform.c[1]);
  EXPECT_EQ(over->georef.transform.c[1], 8 * whole->georef().transform.c[1]);
  auto level3 = openStore().readWindow(0, {0, 0, 64, 64}, 3);
  ASSERT_TRUE(level3) << level3.message();
  EXPECT_EQ(over->values.data, level3->data);
  auto ring = RingRenderer::create({.circles = 64});
  ASSERT_TRUE(ring) << ring.message();
  const int w = 256, h = 160;
  auto t1 = OffscreenTarget::create(w, h), t2 = OffscreenTarget::create(w, h), t3 = OffscreenTarget::create(w, h);
  ASSERT_TRUE(t1 && t2 && t3);
  Shading shading;
  shading.fogM = 150000;
  shading.tintRangeM = glm::vec2(whole->minElevationM(), whole->maxElevationM());
  shading.sunDir = glm::vec3(glm::normalize(glm::dvec3(-1.0, 0.3, 0.35)));
  shading.drapeOpacity = 0.6f;
  shading.graticuleDeg = 0.05;
  ASSERT_TRUE((*ring)->draw(*whole, kCanyonCamera, shading, *t1));
  ASSERT_TRUE((*ring)->draw(*streamed, kCanyonCamera, shading, *t2));
  ASSERT_TRUE((*ring)->draw(*plain, kCanyonCamera, shading, *t3));
  ASSERT_TRUE(writeImage8((test::outputDir("render") / "streamed_drape_shadows_graticule.png").string(), w, h, 4,
                          t2->colour()));
  const Diff same = compare(*t1, *t2, 8);
  const Diff without = compare(*t3, *t2, 8);
  std::printf(
      "streamed vs whole, both with drape, shadows, graticule: %.4f of pixels over 8, max %d; "
      "vs streamed without them: %.4f\n",
      same.colourFraction, same.maxChannel, without.colourFraction);
  EXPECT_LT(same.colourFraction, 0.03);
  EXPECT_GT(without.colourFraction, 0.3) << "the drape, shadows and graticule are drawn";
}

TEST_F(GlTest, SlidingGridDrawsAStreamedScene) {
  // The sliding grid's levels (+-32 texels at level 0, +-64 at 1, +-128 at 2) lie inside the
  // windows (+-64 texels at levels 0 and 1, level 2 coarse), and each vertex samples its level at
  // an integer MIP level: the streamed render samples the same values as the whole-DEM one.
  auto whole = storeAsWholeScene();
  ASSERT_TRUE(whole) << whole.message();
  auto streamed =
      TerrainScene::createStreamed(openStore(), {.clipSize = 128, .pageSize = 32, .uploadPagesPerFrame = 1000});
  ASSERT_TRUE(streamed) << streamed.message();
  auto grid = SlidingGridRenderer::create({.halfCells = 32, .levels = 3});
  ASSERT_TRUE(grid) << grid.message();
  const int w = 192, h = 120;
  auto t1 = OffscreenTarget::create(w, h), t2 = OffscreenTarget::create(w, h);
  ASSERT_TRUE(t1 && t2);
  Shading shading;
  shading.tintRangeM = glm::vec2(whole->minElevationM(), whole->maxElevationM());
  const auto& c = whole->georef().transform.c;
  CameraPose cam{
      .lon = c[0] + 256.4 * c[1], .lat = c[3] + 250.2 * c[5], .heightM = 0, .headingDeg = 30, .pitchDeg = -30};
  cam.heightM = whole->heightAt(cam.lon, cam.lat) + 3000;
  ASSERT_TRUE((*grid)->draw(*whole, cam, shading, *t1));
  ASSERT_TRUE((*grid)->draw(*streamed, cam, shading, *t2));
  EXPECT_EQ(streamed->streamed()->stats().pending, 0);
  const Diff d = compare(*t1, *t2, 8);
  std::ofstream(test::outputDir("render") / "streaming_sliding.txt")
      << "# sliding grid (3 levels of +-32), streamed vs whole-DEM\nelev_mean_m " << d.elevMeanM << "\nelev_max_m "
      << d.elevMaxM << "\nmax_channel " << d.maxChannel << "\nterrain_mismatch_px " << d.terrainMismatch << "\n";
  // The store's level-l reads and GL's mips of its level 0 are both 2x2 box means: identical on
  // llvmpipe (measured 0 m); another driver's mip generation may round differently, hence 5 cm.
  EXPECT_LT(d.elevMaxM, 0.05);
  EXPECT_EQ(d.colourFraction, 0.0);
  EXPECT_EQ(d.terrainMismatch, 0u);
}

// Pages of the current windows (level, x, y), inside each level's cells.
std::set<std::tuple<int, int, int>> windowPages(const StreamedElevation& s) {
  std::set<std::tuple<int, int, int>> out;
  const int p = s.params().pageSize, k = s.params().clipSize / p;
  for (int l = 0; l < s.coarseLevel(); ++l) {
    const glm::ivec2 o = s.windowOrigin(l) / p, ext = s.levelSize(l);
    for (int y = o.y; y < o.y + k; ++y) {
      for (int x = o.x; x < o.x + k; ++x) {
        if (x >= 0 && y >= 0 && x * p < ext.x && y * p < ext.y) out.insert({l, x, y});
      }
    }
  }
  return out;
}

TEST_F(GlTest, MovingTheViewerRefillsOnlyTheExposedPages) {
  const StreamParams params{
      .clipSize = 128, .pageSize = 32, .uploadPagesPerFrame = 1000, .gpuBudgetBytes = size_t(2) << 20};
  auto scene = TerrainScene::createStreamed(openStore(), params);
  ASSERT_TRUE(scene) << scene.message();
  auto* s = scene->streamed();
  auto ring = RingRenderer::create({.circles = 32});
  ASSERT_TRUE(ring) << ring.message();
  auto target = OffscreenTarget::create(64, 40);
  ASSERT_TRUE(target);
  const auto& c = scene->georef().transform.c;
  // Cell (200.3, 250.7), then 32 cells (one page of level 0, half a page of level 1) east.
  CameraPose cam{.lon = c[0] + 200.3 * c[1], .lat = c[3] + 250.7 * c[5], .heightM = 4000, .pitchDeg = -20};
  ASSERT_TRUE((*ring)->draw(*scene, cam, {}, *target));
  const auto first = windowPages(*s);
  EXPECT_EQ(s->stats().lastFramePagesCopied, int(first.size()));
  EXPECT_EQ(s->stats().pending, 0);
  std::ofstream report(test::outputDir("render") / "streaming_refill.txt");
  report << "# pages copied per step, Grand Canyon store, N=128, P=32, levels 0-1 streamed\nfirst_frame "
         << first.size() << "\n";
  auto previous = first;
  for (const double dx : {32.0, 32.0, -64.0}) {
    cam.lon += dx * c[1];
    const auto before = s->stats();
    ASSERT_TRUE((*ring)->draw(*scene, cam, {}, *target));
    const auto now = windowPages(*s);
    size_t exposed = 0;
    for (const auto& page : now) exposed += previous.count(page) ? 0 : 1;
    const auto after = s->stats();
    // Exactly the pages that entered a window are copied, and nothing else.
    EXPECT_EQ(after.lastFramePagesCopied, int(exposed)) << "step " << dx;
    EXPECT_GT(exposed, 0u);
    // At most the columns the move crossed, per level (4 pages a column).
    EXPECT_LE(exposed, 4u * size_t(std::abs(dx) / 32 + 1));
    EXPECT_LE(after.gpuBytes, params.gpuBudgetBytes);
    report << "move_" << dx << "_cells copied " << after.lastFramePagesCopied << " uploaded_from_ram "
           << after.cache.uploads - before.cache.uploads << "\n";
    if (dx < 0) {
      // Back where it started: every page comes from the GPU cache, none from RAM.
      EXPECT_EQ(after.cache.uploads, before.cache.uploads);
    } else {
      EXPECT_EQ(after.cache.uploads - before.cache.uploads, exposed);
    }
    previous = now;
  }
}

// Every pixel whose ray must meet the terrain (it drops below the lowest elevation within
// `reachM` of the viewer) is not the magenta background. Returns how many pixels were checked.
long expectNoHole(const TerrainScene& scene, const CameraPose& cam, const OffscreenTarget& target, double reachM) {
  const int w = target.width(), h = target.height();
  const auto px = target.colour();
  const auto f = frameGeometry(scene, cam, {}, w, h);
  const double drop = cam.heightM - scene.minElevationM();
  long checked = 0;
  for (int y = 0; y < h; ++y) {
    for (int x = 0; x < w; ++x) {
      const glm::dvec3 ray = pixelRay(f, cam, x, y, w, h);
      if (ray.z >= 0 || drop / -ray.z * glm::length(glm::dvec2(ray)) > reachM) continue;
      ++checked;
      const uint8_t* p = &px[(size_t(y) * size_t(w) + size_t(x)) * 4];
      EXPECT_FALSE(p[0] == 255 && p[1] == 0 && p[2] == 255) << "hole: magenta at pixel " << x << "," << y;
      if (p[0] == 255 && p[1] == 0 && p[2] == 255) return checked;
    }
  }
  return checked;
}

// The oblique view of the convergence tests: a 96-circle ring whose disc reaches 30 km from the
// DEM's centre (inside the 90 x 111 km grid in every direction), two 160 x 100 targets (the
// streamed render and the reference), a magenta sky, and a camera 300 m above cell (256, 256) of
// `heights` looking SSW.
struct ObliqueRig {
  static constexpr int kW = 160, kH = 100;
  std::unique_ptr<RingRenderer> ring;
  OffscreenTarget target, ref;
  Shading magenta;
  CameraPose cam;
};

void makeObliqueRig(const TerrainScene& heights, ObliqueRig& rig) {
  auto ring = RingRenderer::create({.circles = 96, .rangeM = 30000});
  ASSERT_TRUE(ring) << ring.message();
  rig.ring = std::move(ring).value();
  auto target = OffscreenTarget::create(ObliqueRig::kW, ObliqueRig::kH);
  auto ref = OffscreenTarget::create(ObliqueRig::kW, ObliqueRig::kH);
  ASSERT_TRUE(target && ref);
  rig.target = std::move(target).value();
  rig.ref = std::move(ref).value();
  rig.magenta.sky = {1, 0, 1, 1};
  const auto& c = heights.georef().transform.c;
  rig.cam = {.lon = c[0] + 256 * c[1], .lat = c[3] + 256 * c[5], .heightM = 0, .headingDeg = 200, .pitchDeg = -25};
  rig.cam.heightM = heights.heightAt(rig.cam.lon, rig.cam.lat) + 300;
}

TEST_F(GlTest, ZeroUploadBudgetDrawsFromCoarserLevelsAndThenConverges) {
  const size_t budget = size_t(1) << 20;
  const StreamParams params{.clipSize = 128, .pageSize = 32, .uploadPagesPerFrame = 0, .gpuBudgetBytes = budget};
  auto scene = TerrainScene::createStreamed(openStore(), params);
  ASSERT_TRUE(scene) << scene.message();
  auto full = TerrainScene::createStreamed(openStore(), {.clipSize = 128, .pageSize = 32, .uploadPagesPerFrame = 1000});
  ASSERT_TRUE(full) << full.message();
  ObliqueRig rig;
  ASSERT_NO_FATAL_FAILURE(makeObliqueRig(*scene, rig));
  auto& [ring, target, ref, magenta, cam] = rig;
  const int w = ObliqueRig::kW, h = ObliqueRig::kH;
  ASSERT_TRUE(ring->draw(*scene, cam, magenta, target));
  auto* s = scene->streamed();
  EXPECT_EQ(s->stats().pagesCopied, 0u);
  const int total = s->stats().pending;
  EXPECT_GT(total, 0);
  // A third of the image must be terrain, and none of it is a hole.
  EXPECT_GT(expectNoHole(*scene, cam, target, 0.95 * 30000), long(w * h / 3));
  ASSERT_TRUE(ring->draw(*full, cam, magenta, ref));
  const Diff coarseOnly = compare(target, ref, 0);
  EXPECT_GT(coarseOnly.elevMaxM, 0.0);  // the coarse stand-in is not the full render

  // Four pages a frame: the stack fills in ceil(total / 4) frames, every one of them complete,
  // and ends identical to the render that had everything at once.
  s->setUploadPagesPerFrame(4);
  int frames = 0;
  while (s->stats().pending > 0 && frames < 100) {
    ASSERT_TRUE(ring->draw(*scene, cam, magenta, target));
    ++frames;
    EXPECT_LE(s->stats().lastFramePagesCopied, 4);
    EXPECT_LE(s->stats().gpuBytes, budget);
    expectNoHole(*scene, cam, target, 0.95 * 30000);
  }
  EXPECT_EQ(frames, (total + 3) / 4);
  const Diff converged = compare(target, ref, 0);
  EXPECT_EQ(converged.maxChannel, 0);
  EXPECT_EQ(converged.elevMaxM, 0.0);
  std::ofstream(test::outputDir("render") / "streaming_budget.txt")
      << "# upload budget 0, then 4 pages per frame; Grand Canyon store, N=128, P=32\npages_pending_at_start " << total
      << "\nframes_to_converge " << frames << "\ncoarse_only_vs_full elev_mean_m " << coarseOnly.elevMeanM
      << " elev_max_m " << coarseOnly.elevMaxM << "\nconverged_vs_full max_channel " << converged.maxChannel
      << " elev_max_m " << converged.elevMaxM << "\ngpu_bytes " << s->stats().gpuBytes << " budget " << budget << "\n";
}

double msSince(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
}

TEST_F(GlTest, ALateTileNeverStallsAFrameAndTheRenderConverges) {
  // Every tile decode sleeps kDelayMs (a slow disk). With waitForDisk off, draw() decodes
  // nothing on its own thread: pages whose tiles are not in RAM are requested from the store's
  // loader and coarser levels stand in; once the loader has caught up the render is exactly the
  // one with everything resident. The same scene with waitForDisk on waits for every decode.
  // The delay, longer than a quiet frame, keeps the loader's first decodes from competing with
  // the cold frame for the CPU.
  constexpr double kDelayMs = 250;
  auto slowStore = [&] {
    auto s =
        TileStore::open(canyonStore(), {.budgetBytes = size_t(16) << 20, .prefetch = false, .loadDelayMs = kDelayMs});
    STRATA_CHECK(bool(s)) << s.message();
    return std::move(s).value();
  };
  StreamParams params{.clipSize = 128, .pageSize = 32, .uploadPagesPerFrame = 1000, .waitForDisk = false};
  auto scene = TerrainScene::createStreamed(slowStore(), params);
  ASSERT_TRUE(scene) << scene.message();
  auto full = TerrainScene::createStreamed(openStore(), {.clipSize = 128, .pageSize = 32, .uploadPagesPerFrame = 1000});
  ASSERT_TRUE(full) << full.message();
  ObliqueRig rig;
  ASSERT_NO_FATAL_FAILURE(makeObliqueRig(*full, rig));
  auto& [ring, target, ref, magenta, cam] = rig;
  const int w = ObliqueRig::kW, h = ObliqueRig::kH;
  // Warm-up (programs compiled, both targets drawn once), then a frame with nothing to load.
  ASSERT_TRUE(ring->draw(*full, cam, magenta, target));
  auto t0 = std::chrono::steady_clock::now();
  ASSERT_TRUE(ring->draw(*full, cam, magenta, ref));
  const double residentMs = msSince(t0);

  // A cold RAM cache: every page of the windows needs a decode.
  auto* s = scene->streamed();
  s->store().clearCache();
  s->store().resetCacheStats();
  t0 = std::chrono::steady_clock::now();
  ASSERT_TRUE(ring->draw(*scene, cam, magenta, target));
  const double firstMs = msSince(t0);
  EXPECT_EQ(s->store().cacheStats().syncLoads, 0u);
  EXPECT_EQ(s->stats().lastFramePagesCopied, 0);
  const int total = s->stats().pending;
  EXPECT_EQ(s->stats().lastFramePagesWaiting, total);
  EXPECT_GT(total, 0);
  EXPECT_GT(s->store().requestsPending(), 0);
  // The cold frame costs less than one decode, or one resident frame, more than a frame with
  // everything resident, where the blocking frame below costs kDelayMs per tile level it decodes
  // (8 here: 2 s). The margin absorbs llvmpipe's frame-time noise on a loaded machine and the
  // loader's decodes competing for the same 2 cores: a resident frame measured ~470 ms under a
  // full ctest -j2 with a cold one at 500 ms beside it, and under the sanitizers 214 ms resident
  // against 409 ms cold (CI, stop 38), which failed the earlier margin of half a frame.
  EXPECT_LT(firstMs, residentMs + std::max(kDelayMs, residentMs));
  EXPECT_GT(expectNoHole(*scene, cam, target, 0.95 * 30000), long(w * h / 3));

  // Frames go on while the loader works: none decodes, none has a hole.
  int frames = 1;
  double worstMs = firstMs;
  const auto until = std::chrono::steady_clock::now() + std::chrono::seconds(30);
  while (s->stats().pending > 0 && std::chrono::steady_clock::now() < until) {
    t0 = std::chrono::steady_clock::now();
    ASSERT_TRUE(ring->draw(*scene, cam, magenta, target));
    worstMs = std::max(worstMs, msSince(t0));
    ++frames;
    expectNoHole(*scene, cam, target, 0.95 * 30000);
  }
  ASSERT_EQ(s->stats().pending, 0) << "the loader did not catch up in 30 s";
  const auto st = s->store().cacheStats();
  EXPECT_EQ(st.syncLoads, 0u);
  EXPECT_GT(st.requestLoads, 0u);
  const Diff converged = compare(target, ref, 0);
  EXPECT_EQ(converged.maxChannel, 0);
  EXPECT_EQ(converged.elevMaxM, 0.0);

  // The blocking mode on the same cold cache: one frame, full resolution, waiting for each decode.
  params.waitForDisk = true;
  auto blocking = TerrainScene::createStreamed(slowStore(), params);
  ASSERT_TRUE(blocking) << blocking.message();
  blocking->streamed()->store().clearCache();
  blocking->streamed()->store().resetCacheStats();
  t0 = std::chrono::steady_clock::now();
  ASSERT_TRUE(ring->draw(*blocking, cam, magenta, target));
  const double blockingMs = msSince(t0);
  const uint64_t decodes = blocking->streamed()->store().cacheStats().syncLoads;
  EXPECT_EQ(blocking->streamed()->stats().pending, 0);
  EXPECT_EQ(decodes, st.requestLoads);  // the same tile levels, decoded on the caller's thread
  EXPECT_GE(blockingMs, double(decodes) * kDelayMs);
  EXPECT_GE(decodes, 2u);  // so that the contrast with the asynchronous frame is at least 2 decodes
  const Diff same = compare(target, ref, 0);
  EXPECT_EQ(same.maxChannel, 0);
  EXPECT_EQ(same.elevMaxM, 0.0);
  std::ofstream(test::outputDir("render") / "streaming_async.txt")
      << "# cold RAM cache, every tile decode delayed " << kDelayMs
      << " ms; Grand Canyon store, N=128, P=32, ring 160x100\nresident_frame_ms " << residentMs
      << "\npages_pending_at_start " << total << "\nasync_first_frame_ms " << firstMs << "\nasync_worst_frame_ms "
      << worstMs << "\nasync_frames_to_converge " << frames << "\ntile_levels_decoded_by_loader " << st.requestLoads
      << "\nblocking_first_frame_ms " << blockingMs << "\nblocking_decodes_on_caller " << decodes << "\n";
}

// ETOPO20 (1080 x 540 cells of 20 arc-minutes) as a global store: tiles of 128 cells, 2^4..2^7.
const std::filesystem::path& earthStore() {
  static const std::filesystem::path dir = [] {
    const auto d = test::tempDir("earth_store") / "store";
    const std::string path = test::dataPath("earth/etopo20.tif");
    auto dem = gis::readDem(path);
    EXPECT_TRUE(dem) << dem.message();
    strata::terrain::IngestOptions o;
    o.layout = strata::terrain::TileLayout::Global;
    o.metric = {.minExp = 4, .maxExp = 7};
    o.cache.prefetch = false;
    auto rep = strata::terrain::ingest(
        d, dem->georef, {{{"bedrock", strata::terrain::LayerKind::Bedrock, ""}, strata::terrain::demReader(path)}}, o);
    EXPECT_TRUE(rep) << rep.message();
    return d;
  }();
  return dir;
}

TEST_F(GlTest, GlobalStoreStreamsAcrossTheSeamInPlanetaryMode) {
  auto open = [] {
    auto s = TileStore::open(earthStore(), {.budgetBytes = size_t(16) << 20, .prefetch = false});
    STRATA_CHECK(bool(s)) << s.message();
    return std::move(s).value();
  };
  auto store = open();
  auto grid = store.readWindow(0, {0, 0, store.width(), store.height()}, 0);
  ASSERT_TRUE(grid) << grid.message();
  auto whole = TerrainScene::create(gis::Raster{store.desc().georef, std::move(grid).value()}, {.planetary = true});
  ASSERT_TRUE(whole) << whole.message();
  // N = 160: level 3 (135 x 68) is the coarse level; 2^3 divides the 1080 columns, so the
  // coarse texture wraps exactly at the seam.
  auto streamed = TerrainScene::createStreamed(open(), {.clipSize = 160, .pageSize = 32, .uploadPagesPerFrame = 1000},
                                               {.planetary = true});
  ASSERT_TRUE(streamed) << streamed.message();
  auto* s = streamed->streamed();
  ASSERT_EQ(s->coarseLevel(), 3);
  // The rings spread to the horizon of the softened viewpoint (a range beyond it): the default
  // range (the viewer's horizon plus the highest summit's, 4,900 km here) packs the 96 circles
  // closer, and they then want level 0 beyond the level-0 window, where a coarser level stands in
  // (measured 4.1 m mean with the default, 0.08 m with this).
  auto ring = RingRenderer::create({.circles = 96, .rangeM = 2e7});
  ASSERT_TRUE(ring) << ring.message();
  const int w = 192, h = 120;
  auto t1 = OffscreenTarget::create(w, h), t2 = OffscreenTarget::create(w, h);
  ASSERT_TRUE(t1 && t2);
  Shading shading;
  shading.sky = {0, 0, 0, 1};
  shading.exaggeration = 20;
  shading.tintRangeM = glm::vec2(whole->minElevationM(), whole->maxElevationM());
  // Over the Pacific half a degree west of the antimeridian, looking east across it.
  const CameraPose cam{.lon = 179.5, .lat = 30, .heightM = 1.5e6, .headingDeg = 90, .pitchDeg = -40};
  ASSERT_TRUE((*ring)->draw(*whole, cam, shading, *t1));
  ASSERT_TRUE((*ring)->draw(*streamed, cam, shading, *t2));
  EXPECT_EQ(s->stats().pending, 0);
  // The level-0 window runs past the last column: it holds pages from both sides of the seam.
  EXPECT_GT(s->windowOrigin(0).x + 160, store.width());
  const Diff d = compare(*t1, *t2, 8);
  std::ofstream(test::outputDir("render") / "streaming_global.txt")
      << "# streamed global store (ETOPO20, N=160, P=32, levels 0-2 streamed, 3 coarse) vs whole-DEM, planetary, "
      << "across the antimeridian, " << w << "x" << h << "\ncolour_fraction_over_8 " << d.colourFraction
      << "\nmax_channel " << d.maxChannel << "\nelev_mean_m " << d.elevMeanM << "\nelev_p99_m " << d.elevP99M
      << "\nelev_max_m " << d.elevMaxM << "\nterrain_mismatch_px " << d.terrainMismatch << "\n";
  // Not vacuous: from the coarse level alone (no page uploaded) the same view is much further off.
  auto coarseOnly = TerrainScene::createStreamed(open(), {.clipSize = 160, .pageSize = 32, .uploadPagesPerFrame = 0},
                                                 {.planetary = true});
  ASSERT_TRUE(coarseOnly) << coarseOnly.message();
  ASSERT_TRUE((*ring)->draw(*coarseOnly, cam, shading, *t2));
  const Diff c = compare(*t1, *t2, 8);
  std::ofstream(test::outputDir("render") / "streaming_global.txt", std::ios::app)
      << "coarse_only elev_mean_m " << c.elevMeanM << " colour_fraction_over_8 " << c.colourFraction << "\n";
  // Streamed: what the whole-DEM render samples, up to filtering order (measured 0.08 m mean,
  // no pixel more than 3/255 off); the coarse level alone: at least ten times further off.
  EXPECT_LT(d.elevMeanM, 1.0);
  EXPECT_LT(d.colourFraction, 0.01);
  EXPECT_LT(d.terrainMismatch, size_t(w * h / 100));
  EXPECT_GT(c.elevMeanM, 10 * d.elevMeanM);
}

}  // namespace
}  // namespace strata::render
