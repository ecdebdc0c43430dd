// The store on real DEMs: every shared DEM within its error bound with its nodata mask exactly
// and the recorded error equal to the measured one (the default max-error metric); the seed's
// relief metric on the Grand Canyon, Rainier and a synthetic scene (resolution maps, memory saved
// against dense storage).
#include <gtest/gtest.h>

#include <OpenImageIO/imagebuf.h>
#include <OpenImageIO/imageio.h>

#include <gdal.h>

#include <cmath>
#include <cstring>
#include <fstream>
#include <limits>
#include <random>
#include <set>

#include <strata/gis/dem_io.hpp>
#include <strata/terrain/dem_sources.hpp>
#include <strata/terrain/ingest.hpp>
#include <strata/terrain/synthetic.hpp>
#include <strata/terrain/tile_store.hpp>

#include "store_support.hpp"
#include "strata_test.hpp"

namespace strata::terrain {
namespace {

using test::gridReader;

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

// The seed's relief metric with the same number of bins as its 2^5..2^10 (six), on tiles small
// enough that a 512 x 512 DEM has 8 x 8 of them.
IngestOptions realDataOptions() {
  IngestOptions o;
  o.metric = {1, 6};
  o.metric.kind = TileMetric::Range;
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

// One shared DEM and how to store it.
struct SharedDem {
  const char* file;
  bool global;
};

class EveryDem : public ::testing::TestWithParam<SharedDem> {};

// Each shared DEM, read through GDAL (demReader: scale, offset, nodata as the file says), at the
// default tolerance and at a lossy one: every cell read back is within the tolerance, the nodata
// mask is the source's exactly, and the store's recorded error is the measured one.
TEST_P(EveryDem, StaysWithinItsToleranceWithItsNodataMask) {
  const std::string path = test::dataPath(GetParam().file);
  auto src = gis::readDem(path);
  ASSERT_TRUE(src) << src.message();
  const auto& ref = src->values;
  const std::string name = fs::path(GetParam().file).stem().string();
  for (double tol : {kDefaultMaxErrorM, 20.0, 100.0}) {
    IngestOptions o;
    o.metric = {1, 7};  // tiles of 128 cells, stored at 2^1..2^7 samples
    o.metric.maxErrorM = tol;
    o.layout = GetParam().global ? TileLayout::Global : TileLayout::Planar;
    o.cache.prefetch = false;
    const auto dir = test::tempDir(name + "_" + std::to_string(int(tol * 10)));
    auto rep = ingest(dir, src->georef, {{{"bedrock", LayerKind::Bedrock, ""}, demReader(path)}}, o);
    ASSERT_TRUE(rep) << rep.message();
    auto store = TileStore::open(dir, o.cache);
    ASSERT_TRUE(store) << store.message();
    auto back = store->readWindow(0, {0, 0, ref.width, ref.height}, 0);
    ASSERT_TRUE(back) << back.message();
    double maxErr = 0, sumSq = 0;
    uint64_t cells = 0, maskDiffers = 0;
    for (size_t i = 0; i < ref.data.size(); ++i) {
      const bool a = std::isnan(ref.data[i]), b = std::isnan(back->data[i]);
      if (a != b) {
        ++maskDiffers;
        continue;
      }
      if (a) continue;
      const double e = std::abs(double(back->data[i]) - double(ref.data[i]));
      maxErr = std::max(maxErr, e);
      sumSq += e * e;
      ++cells;
    }
    EXPECT_EQ(maskDiffers, 0u);
    EXPECT_LE(maxErr, tol);
    const auto rec = store->errorSummary(0);
    EXPECT_EQ(rec.cells, cells);
    // Both are max |sample - cell| over the same float32 values, in double: equal once rounded
    // to the float32 the manifest keeps.
    EXPECT_EQ(float(rec.maxM), float(maxErr));
    // RMS: per-tile float32 RMS combined; 1e-5 relative covers the float rounding.
    EXPECT_NEAR(rec.rmsM, std::sqrt(sumSq / double(cells)), 1e-5 * rec.rmsM + 1e-9);
    EXPECT_EQ(store->verify().size(), 0u);
    const auto fp = store->footprintStats();
    std::ofstream(test::outputDir("terrain") / "memory_saved_max_error.txt", std::ios::app)
        << name << " tolerance " << tol << " m: " << store->width() << "x" << store->height() << ", tiles of "
        << store->footprint() << ", 2^1..2^7: " << 100.0 * fp.savedFraction() << "% saved (with mips "
        << 100.0 * (1.0 - double(fp.storedWithMips) / double(fp.denseSamples)) << "%), max error " << rec.maxM
        << " m, RMS " << rec.rmsM << " m over " << rec.cells << " cells\n";
    std::cout << name << " at " << tol << " m: " << 100.0 * fp.savedFraction() << "% saved, max " << rec.maxM
              << " m, RMS " << rec.rmsM << " m\n";
  }
}

INSTANTIATE_TEST_SUITE_P(Shared, EveryDem,
                         ::testing::Values(SharedDem{"grand_canyon/grand_canyon_512.tif", false},
                                           SharedDem{"grand_canyon/grandcanyon_srtm_3857.tif", false},
                                           SharedDem{"rainier/mt_rainier_90m.tif", false},
                                           SharedDem{"earth/etopo20.tif", true}, SharedDem{"moon/LDEM_4.LBL", false},
                                           SharedDem{"mars/mola_megdr_4ppd.vrt", true}),
                         [](const auto& p) {
                           std::string n = fs::path(p.param.file).stem().string();
                           for (char& c : n) c = std::isalnum(static_cast<unsigned char>(c)) ? c : '_';
                           return n;
                         });

TEST(StoreOnRealData, AOneCellDemSavesNothingRatherThanANegativeAmount) {
  // A 1 x 1 piece of Rainier: one 1024-cell tile whose samples beyond the grid hold nothing.
  gis::ReadOptions o;
  o.window = gis::CellRect{600, 600, 1, 1};
  auto one = gis::readDem(test::dataPath("rainier/mt_rainier_90m.tif"), o);
  ASSERT_TRUE(one);
  const auto dir = test::tempDir("one");
  auto values = one->values;
  auto rep = ingest(dir, one->georef, {{{"bedrock", LayerKind::Bedrock, ""}, gridReader(values)}});
  ASSERT_TRUE(rep) << rep.message();
  EXPECT_EQ(rep->footprint.denseSamples, 1u);
  EXPECT_EQ(rep->footprint.storedSamples, 1u);
  EXPECT_EQ(rep->footprint.savedFraction(), 0.0);
  auto store = TileStore::open(dir);
  ASSERT_TRUE(store);
  EXPECT_EQ(store->readWindow(0, {0, 0, 1, 1})->data[0], values.data[0]);
}

}  // namespace
}  // namespace strata::terrain

namespace strata::terrain {
namespace {

using gis::Grid;
namespace fs = std::filesystem;

// The window as a tiled DEFLATE GeoTIFF (GDAL's defaults otherwise), of `type` (int16: NaN as
// -32768); returns its size in bytes.
uint64_t deflateGeoTiffBytes(const Grid<float>& g, GDALDataType type, const fs::path& path) {
  GDALAllRegister();
  const char* options[] = {"TILED=YES", "COMPRESS=DEFLATE", nullptr};
  GDALDatasetH ds =
      GDALCreate(GDALGetDriverByName("GTiff"), path.c_str(), g.width, g.height, 1, type, const_cast<char**>(options));
  STRATA_CHECK(ds) << path;
  GDALRasterBandH band = GDALGetRasterBand(ds, 1);
  std::vector<float> values = g.data;
  if (type == GDT_Int16) {
    GDALSetRasterNoDataValue(band, -32768);
    for (float& v : values) v = std::isnan(v) ? -32768.0f : v;
  }
  STRATA_CHECK(GDALRasterIO(band, GF_Write, 0, 0, g.width, g.height, values.data(), g.width, g.height, GDT_Float32, 0,
                            0) == CE_None);
  GDALClose(ds);
  return fs::file_size(path);
}

// A lossless store of `g` (max error 0, one tile of 2^exp): its tile files' bytes, after checking
// that the full-resolution read gives back every sample's bits.
uint64_t losslessStoreBytes(const Grid<float>& g, int exp, const std::string& name) {
  IngestOptions o;
  o.metric = {exp, exp};
  o.metric.kind = TileMetric::MaxError;
  o.metric.maxErrorM = 0;
  o.cache.prefetch = false;
  const auto dir = test::tempDir(name);
  STRATA_CHECK(ingest(dir, gridGeoref(g.width, g.height), {{{"bedrock", LayerKind::Bedrock, ""}, gridReader(g)}}, o));
  auto store = TileStore::open(dir, o.cache);
  STRATA_CHECK(store) << store.message();
  auto back = store->readWindow(0, {0, 0, g.width, g.height}, 0);
  STRATA_CHECK(back) << back.message();
  for (size_t i = 0; i < g.size(); ++i) {
    const bool bothVoid = std::isnan(g.data[i]) && std::isnan(back->data[i]);
    EXPECT_TRUE(bothVoid || std::memcmp(&g.data[i], &back->data[i], sizeof(float)) == 0)
        << name << ": sample " << i << " " << g.data[i] << " read back as " << back->data[i];
  }
  return store->footprintStats().fileBytes;
}

// The window (x0, y0, n, n) of the file's first band resampled to `size` x `size` by GDAL's
// cubic kernel into int16 (NaN where the result is GDAL's nodata): a DEM upsampled as
// `gdalwarp -r cubic -ot Int16` makes it, smooth, its differences a few units.
Grid<float> cubicUpsampledInt16(const std::string& path, int x0, int y0, int n, int size) {
  GDALAllRegister();
  GDALDatasetH ds = GDALOpen(path.c_str(), GA_ReadOnly);
  STRATA_CHECK(ds) << path;
  GDALRasterIOExtraArg extra;
  INIT_RASTERIO_EXTRA_ARG(extra);
  extra.eResampleAlg = GRIORA_Cubic;
  std::vector<int16_t> raw(size_t(size) * size_t(size));
  STRATA_CHECK(GDALRasterIOEx(GDALGetRasterBand(ds, 1), GF_Read, x0, y0, n, n, raw.data(), size, size, GDT_Int16, 0, 0,
                              &extra) == CE_None);
  GDALClose(ds);
  Grid<float> g(size, size);
  for (size_t i = 0; i < raw.size(); ++i) g.data[i] = raw[i] == -32768 ? gis::kNoData : float(raw[i]);
  return g;
}

}  // namespace

// Issue 33: an int16 DEM was stored as ZIP float32 tiles, 1.9x the DEFLATE GeoTIFF of the same
// cells (3.5x at 16384^2), then (PXR24 float layout) 1.43x on native SRTM and 2.01x at 16384^2,
// where the mips cost 87 % of level 0. Whole numbers are now stored as integers (predicted,
// zigzagged residuals: terrain/src/exr_codec.cpp) and their mips rounded to whole numbers
// (tile_store.cpp): with every mip level a tile stays within the GeoTIFF, which has none.
// Rainier's SRTM (int16, with voids), the same relief upsampled 13.6x as the 16384^2 DEM
// was (smooth: the case the float layout stored worst), and the Grand Canyon (float32).
TEST(StoreOnRealData, ATileStoresWithinTheDeflateGeoTiffAndExactly) {
  const auto rainier = readPixels(test::dataPath("rainier/mt_rainier_90m.tif"));
  Grid<float> window(1024, 1024);
  for (int y = 0; y < 1024; ++y)
    std::copy_n(&rainier.data[rainier.index(0, y)], 1024, &window.data[window.index(0, y)]);
  const auto out = test::tempDir("store-size");
  const double tif = double(deflateGeoTiffBytes(window, GDT_Int16, out / "rainier.tif"));
  const double store = double(losslessStoreBytes(window, 10, "store-size-rainier"));
  std::cout << "Rainier 1024^2 int16: store " << store << " B, DEFLATE GeoTIFF " << tif << " B, " << store / tif
            << "x\n";
  EXPECT_LE(store, tif);  // 0.76x measured; 1.43x in the float layout

  const auto smooth = cubicUpsampledInt16(test::dataPath("rainier/mt_rainier_90m.tif"), 450, 450, 75, 1024);
  const double tif1 = double(deflateGeoTiffBytes(smooth, GDT_Int16, out / "smooth.tif"));
  const double store1 = double(losslessStoreBytes(smooth, 10, "store-size-smooth"));
  std::cout << "Rainier upsampled 13.6x to 1024^2 int16: store " << store1 << " B, DEFLATE GeoTIFF " << tif1 << " B, "
            << store1 / tif1 << "x\n";
  EXPECT_LE(store1, tif1);  // 1.85x in the float layout

  const auto canyon = readPixels(test::dataPath("grand_canyon/grand_canyon_512.tif"));
  const double tif2 = double(deflateGeoTiffBytes(canyon, GDT_Float32, out / "canyon.tif"));
  const double store2 = double(losslessStoreBytes(canyon, 9, "store-size-canyon"));
  std::cout << "Grand Canyon 512^2 float32: store " << store2 << " B, DEFLATE GeoTIFF " << tif2 << " B, "
            << store2 / tif2 << "x\n";
  EXPECT_LE(store2, 1.5 * tif2);

  // Any float32 bit pattern comes back: random signs, mantissas and exponents (magnitudes below
  // 2^23, the manifest's range is +-1e7 m), -0, denormals.
  Grid<float> noise(64, 64);
  std::mt19937 rng(7);
  for (auto& v : noise.data) {
    const uint32_t bits = (rng() & 0x807fffffu) | ((rng() % 150u) << 23);
    std::memcpy(&v, &bits, sizeof v);
  }
  noise.at(0, 0) = -0.0f;
  noise.at(1, 0) = std::numeric_limits<float>::denorm_min();
  losslessStoreBytes(noise, 6, "store-size-noise");

  // Whole numbers over the manifest's whole range, of either sign, next to each other and to
  // voids: the integer layout gives each back.
  Grid<float> whole(64, 64);
  for (auto& v : whole.data) {
    const int kind = int(rng() % 5u);
    v = kind == 0   ? gis::kNoData
        : kind == 1 ? float(int32_t(rng() % 2001u) - 1000)
        : kind == 2 ? float(int32_t(rng() % 20000001u) - 10000000)
        : kind == 3 ? 1e7f
                    : -1e7f;
  }
  losslessStoreBytes(whole, 6, "store-size-whole");
}

// An integer DEM's coarse levels are its box means (of the level before's 2 x 2 blocks, voids
// ignored) rounded to whole numbers, as GDAL's overviews of an integer raster are; a float DEM's
// stay exact (checked by
// TileStore.CoarseLevelsAreBoxMeansOfTheSource). Rainier's SRTM, with its voids.
TEST(StoreOnRealData, AnIntegerDemsCoarseLevelsAreItsRoundedBoxMeans) {
  const auto rainier = readPixels(test::dataPath("rainier/mt_rainier_90m.tif"));
  Grid<float> window(256, 256);
  for (int y = 0; y < 256; ++y)
    std::copy_n(&rainier.data[rainier.index(0, 500 + y)], 256, &window.data[window.index(0, y)]);
  ASSERT_GT(std::count_if(window.data.begin(), window.data.end(), [](float v) { return std::isnan(v); }), 0);
  IngestOptions o;
  o.metric = {8, 8};  // one tile of 2^8: level L is its mip L
  o.metric.maxErrorM = 0;
  o.cache.prefetch = false;
  const auto dir = test::tempDir("integer-mips");
  ASSERT_TRUE(ingest(dir, gridGeoref(256, 256), {{{"bedrock", LayerKind::Bedrock, ""}, gridReader(window)}}, o));
  auto store = TileStore::open(dir, o.cache);
  ASSERT_TRUE(store) << store.message();
  // The exact chain: each level the means of the level before's 2 x 2 blocks, voids ignored.
  std::vector<double> chain(window.data.begin(), window.data.end());
  int fractional = 0;  // cells whose exact mean is not whole: rounding had to move them
  for (int lod = 1; lod <= 8; ++lod) {
    const int side = 256 >> lod;
    std::vector<double> next(size_t(side) * size_t(side));
    for (int y = 0; y < side; ++y) {
      for (int x = 0; x < side; ++x) {
        double sum = 0;
        int count = 0;
        for (int k = 0; k < 4; ++k) {
          const double v = chain[size_t(2 * y + k / 2) * size_t(2 * side) + size_t(2 * x + k % 2)];
          if (!std::isnan(v)) sum += v, ++count;
        }
        next[size_t(y) * size_t(side) + size_t(x)] = count ? sum / count : std::nan("");
      }
    }
    chain = std::move(next);
    auto g = store->readWindow(0, {0, 0, side, side}, lod);
    ASSERT_TRUE(g) << g.message();
    for (int y = 0; y < side; ++y) {
      for (int x = 0; x < side; ++x) {
        const double mean = chain[size_t(y) * size_t(side) + size_t(x)];
        const float stored = g->at(x, y);
        if (std::isnan(mean)) {
          EXPECT_TRUE(std::isnan(stored)) << "lod " << lod << " at " << x << "," << y;
          continue;
        }
        fractional += mean != std::floor(mean);
        ASSERT_EQ(stored, std::nearbyint(stored)) << "lod " << lod << " at " << x << "," << y;
        // Float32 means of means, then rounded: within half a unit and the float's error.
        ASSERT_LE(std::abs(stored - mean), 0.5 + 1e-3) << "lod " << lod << " at " << x << "," << y;
      }
    }
  }
  EXPECT_GT(fractional, 1000);
}

}  // namespace strata::terrain
