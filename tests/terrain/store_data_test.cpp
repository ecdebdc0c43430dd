// The store on real DEMs (Grand Canyon, Mount Rainier) and a synthetic scene: resolution maps,
// memory saved against dense storage, exact reads in complex tiles, and ingest memory bounded by
// the tile size rather than the input size.
#include <gtest/gtest.h>

#include <OpenImageIO/imagebuf.h>
#include <OpenImageIO/imageio.h>

#include <cmath>
#include <fstream>
#include <set>

#include <strata/terrain/ingest.hpp>
#include <strata/terrain/synthetic.hpp>
#include <strata/terrain/tile_store.hpp>

#include "strata_test.hpp"

namespace strata::terrain {
namespace {

namespace fs = std::filesystem;
using gis::Grid;

// Pixel values of a single-band GeoTIFF (through OpenImageIO, which ignores the georeference;
// the values are all these tests need). int16 nodata -32768 becomes NaN.
Grid<float> readPixels(const std::string& path) {
  auto in = OIIO::ImageInput::open(path);
  STRATA_CHECK(in) << path << ": " << OIIO::geterror();
  const auto& spec = in->spec();
  Grid<float> g(spec.width, spec.height);
  if (spec.format == OIIO::TypeDesc::INT16) {
    std::vector<int16_t> raw(g.size());
    STRATA_CHECK(in->read_image(0, 0, 0, 1, OIIO::TypeDesc::INT16, raw.data())) << path;
    for (size_t i = 0; i < raw.size(); ++i) g.data[i] = raw[i] == -32768 ? gis::kNoData : float(raw[i]);
  } else {
    STRATA_CHECK(in->read_image(0, 0, 0, 1, OIIO::TypeDesc::FLOAT, g.data.data())) << path;
  }
  return g;
}

WindowReader gridReader(const Grid<float>& src) {
  return [&src](int x0, int y0, int w, int h) -> Result<Grid<float>> {
    Grid<float> g(w, h);
    for (int y = 0; y < h; ++y) std::copy_n(&src.data[src.index(x0, y0 + y)], w, &g.data[g.index(0, y)]);
    return g;
  };
}

gis::Georef gridGeoref(int w, int h) {
  gis::Georef g;
  g.epsg = 4326;
  g.crsName = "WGS 84";
  g.geographic = true;
  g.width = w;
  g.height = h;
  return g;
}

// Writes the tile exponents as a PNG: one `scale`-pixel block per tile, grey from black (2^min)
// to white (2^max), red where the tile is absent.
void writeResolutionMap(const TileStore& store, const fs::path& png, int scale) {
  const auto map = store.resolutionMap();
  const int lo = store.desc().metric.minExp, hi = store.desc().metric.maxExp;
  OIIO::ImageSpec spec(map.width * scale, map.height * scale, 3, OIIO::TypeDesc::UINT8);
  std::vector<uint8_t> px(size_t(spec.width) * size_t(spec.height) * 3);
  for (int y = 0; y < spec.height; ++y) {
    for (int x = 0; x < spec.width; ++x) {
      const float e = map.at(x / scale, y / scale);
      uint8_t* p = &px[(size_t(y) * size_t(spec.width) + size_t(x)) * 3];
      if (std::isnan(e)) {
        p[0] = 200, p[1] = 30, p[2] = 30;
      } else {
        const auto v = uint8_t(std::lround(255.0 * (e - lo) / std::max(1, hi - lo)));
        p[0] = p[1] = p[2] = v;
      }
    }
  }
  auto out = OIIO::ImageOutput::create(png.string());
  STRATA_CHECK(out && out->open(png.string(), spec)) << png;
  STRATA_CHECK(out->write_image(OIIO::TypeDesc::UINT8, px.data())) << png;
  out->close();
}

// The same number of metric bins as the seed's 2^5..2^10 (six), on tiles small enough that a
// 512 x 512 DEM has 8 x 8 of them.
IngestOptions realDataOptions() {
  IngestOptions o;
  o.metric = {1, 6};
  o.cache.prefetch = false;
  return o;
}

void report(const std::string& name, const TileStore& store) {
  const auto fp = store.footprintStats();
  std::ofstream(test::outputDir("terrain") / "memory_saved.txt", std::ios::app)
      << name << ": " << store.width() << "x" << store.height() << " cells, tiles of " << store.footprint() << ", 2^"
      << store.desc().metric.minExp << "..2^" << store.desc().metric.maxExp << ": stored " << fp.storedSamples << " of "
      << fp.denseSamples << " samples, " << 100.0 * fp.savedFraction() << "% saved; with mips "
      << 100.0 * (1.0 - double(fp.storedWithMips) / double(fp.denseSamples)) << "% saved; files " << fp.fileBytes
      << " B vs " << fp.denseSamples * 4 << " B dense float32\n";
  std::cout << name << ": " << 100.0 * fp.savedFraction() << "% saved against dense\n";
}

TEST(StoreOnRealData, GrandCanyonResolutionFollowsTheCanyon) {
  const auto dem = readPixels(test::dataPath("grand_canyon/grand_canyon_512.tif"));
  ASSERT_EQ(dem.width, 512);
  const auto dir = test::tempDir("gc");
  auto rep = ingest(dir, gridGeoref(dem.width, dem.height), {{{"bedrock", LayerKind::Bedrock, ""}, gridReader(dem)}},
                    realDataOptions());
  ASSERT_TRUE(rep) << rep.message();
  auto store = TileStore::open(dir, realDataOptions().cache);
  ASSERT_TRUE(store);
  writeResolutionMap(*store, test::outputDir("terrain") / "grand_canyon_resolution.png", 32);
  report("grand_canyon_512", *store);
  // The tile with the largest relief gets a high exponent and the flattest the lowest, and the
  // map uses several levels (a canyon cut into plateaus is not uniform).
  std::set<int> exps;
  float maxRange = -1, minRange = 1e9f;
  int expAtMax = 0, expAtMin = 0;
  for (int ty = 0; ty < store->tilesY(); ++ty) {
    for (int tx = 0; tx < store->tilesX(); ++tx) {
      const auto& t = store->tile(tx, ty);
      exps.insert(t.exp);
      const float r = t.maxV[0] - t.minV[0];
      if (r > maxRange) maxRange = r, expAtMax = t.exp;
      if (r < minRange) minRange = r, expAtMin = t.exp;
    }
  }
  EXPECT_GE(exps.size(), 3u);
  EXPECT_GT(expAtMax, expAtMin);
  const auto [lo, hi] = store->globalRange(0);
  EXPECT_EQ(expAtMax, chooseTileExp({maxRange}, {hi - lo}, 1, 6));
  // Full-resolution reads give each tile's box means of the source, replicated: no tile of the
  // Grand Canyon spans 5/6 of its 2265 m range, so none is stored at 2^6.
  auto all = store->readWindow(0, {0, 0, 512, 512}, 0);
  ASSERT_TRUE(all);
  for (int ty = 0; ty < 8; ++ty) {
    for (int tx = 0; tx < 8; ++tx) {
      const int k = 64 >> store->tile(tx, ty).exp;
      for (int y = ty * 64; y < ty * 64 + 64; y += k) {
        for (int x = tx * 64; x < tx * 64 + 64; x += k) {
          double sum = 0;
          for (int yy = 0; yy < k; ++yy) {
            for (int xx = 0; xx < k; ++xx) sum += dem.at(x + xx, y + yy);
          }
          // float32 mean of up to 1024 values near 2000 m: within 1e-3 m of the double mean
          // (the sum is accumulated in double; one final rounding of ~1e-4 m).
          ASSERT_NEAR(all->at(x + k - 1, y + k - 1), sum / (k * k), 1e-3) << x << "," << y;
        }
      }
    }
  }
}

TEST(StoreOnRealData, RainierAndASyntheticSceneSaveMemory) {
  const auto dem = readPixels(test::dataPath("rainier/mt_rainier_90m.tif"));
  ASSERT_EQ(dem.width, 1201);
  const auto dir = test::tempDir("rainier");
  ASSERT_TRUE(ingest(dir, gridGeoref(dem.width, dem.height), {{{"bedrock", LayerKind::Bedrock, ""}, gridReader(dem)}},
                     realDataOptions()));
  auto store = TileStore::open(dir, realDataOptions().cache);
  ASSERT_TRUE(store);
  writeResolutionMap(*store, test::outputDir("terrain") / "rainier_resolution.png", 16);
  report("rainier_90m", *store);
  // Rainier's edge tiles reach past the 1201-cell grid: those cells must read as no data.
  auto edge = store->readWindow(0, {1199, 1199, 4, 4}, 0);
  ASSERT_TRUE(edge);
  EXPECT_FALSE(std::isnan(edge->at(1, 1)));
  EXPECT_TRUE(std::isnan(edge->at(2, 1)));
  EXPECT_TRUE(std::isnan(edge->at(1, 2)));

  SyntheticScene s;  // the benchmark's scene at 2048^2: 20% rough, 30% ramps, 50% flat blocks
  s.blockCells = 64;
  const auto sdir = test::tempDir("synthetic");
  ASSERT_TRUE(ingest(sdir, gridGeoref(2048, 2048), {{{"bedrock", LayerKind::Bedrock, ""}, syntheticReader(s)}},
                     realDataOptions()));
  auto syn = TileStore::open(sdir, realDataOptions().cache);
  ASSERT_TRUE(syn);
  report("synthetic_2048", *syn);
  // Rough blocks stay at 2^6 (4096 samples), ramps at 2^2 (16: 30% of the amplitude is bin 1 of
  // 6), flat blocks at 2^1 (4): the saving is 1 - E[samples]/4096 over the block mix.
  double expect = 0;
  for (int by = 0; by < 32; ++by) {
    for (int bx = 0; bx < 32; ++bx) {
      const auto k = syntheticBlockKind(s, bx, by);
      expect += k == SyntheticBlock::Rough ? 4096 : k == SyntheticBlock::Ramp ? 16 : 4;
    }
  }
  EXPECT_DOUBLE_EQ(syn->footprintStats().savedFraction(), 1.0 - expect / (2048.0 * 2048.0));
}

TEST(StoreOnRealData, EtopoAsAGlobalLayoutWrapsAtTheDateLine) {
  // ETOPO 20': 1080 x 540, -180..180 x -90..90; tiles of 64 cells leave a partial tile column
  // at the seam, which reads must cross seamlessly.
  const auto dem = readPixels(test::dataPath("earth/etopo20.tif"));
  ASSERT_EQ(dem.width, 1080);
  gis::Georef g = gridGeoref(dem.width, dem.height);
  g.transform = {{-180.0, 1.0 / 3.0, 0.0, 90.0, 0.0, -1.0 / 3.0}};
  auto opts = realDataOptions();
  opts.layout = TileLayout::Global;
  opts.metric = {6, 6};  // full resolution everywhere: reads compare exactly
  const auto dir = test::tempDir("etopo");
  ASSERT_TRUE(ingest(dir, g, {{{"bedrock", LayerKind::Bedrock, ""}, gridReader(dem)}}, opts));
  auto store = TileStore::open(dir, opts.cache);
  ASSERT_TRUE(store);
  auto seam = store->readWindow(0, {1070, 200, 20, 4}, 0);
  ASSERT_TRUE(seam);
  for (int y = 0; y < 4; ++y) {
    for (int x = 0; x < 20; ++x) ASSERT_EQ(seam->at(x, y), dem.at((1070 + x) % 1080, 200 + y)) << x << "," << y;
  }
  // Two rows beyond the north pole at 0 E: rows 1 and 0 at 180 E.
  auto pole = store->readWindow(0, {540, -2, 1, 3}, 0);
  ASSERT_TRUE(pole);
  EXPECT_EQ(pole->at(0, 0), dem.at(0, 1));
  EXPECT_EQ(pole->at(0, 1), dem.at(0, 0));
  EXPECT_EQ(pole->at(0, 2), dem.at(540, 0));

  // The same grid under the metric (bins as for the other real DEMs) for the memory figures.
  const auto mdir = test::tempDir("etopo-metric");
  opts.metric = realDataOptions().metric;
  ASSERT_TRUE(ingest(mdir, g, {{{"bedrock", LayerKind::Bedrock, ""}, gridReader(dem)}}, opts));
  auto metric = TileStore::open(mdir, opts.cache);
  ASSERT_TRUE(metric);
  writeResolutionMap(*metric, test::outputDir("terrain") / "etopo20_resolution.png", 16);
  report("etopo20_global", *metric);
}

}  // namespace
}  // namespace strata::terrain
