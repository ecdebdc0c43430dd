// Mosaics: synthetic inputs in EPSG:4326 and EPSG:32612 warped onto one grid and blended; every
// mode checked cell by cell against values computed here from the inputs' own pixels.
#include <gtest/gtest.h>

#include <cmath>

#include <strata/gis/dem_io.hpp>
#include <strata/gis/geodesy.hpp>
#include <strata/gis/mosaic.hpp>

#include "gis_test_util.hpp"
#include "strata_test.hpp"

namespace strata::gis {
namespace {

// Input A: EPSG:4326, 0.005 degree pixels, float32 values 100 + x + 1000 y.
constexpr double kAx0 = -113.2537, kAy0 = 36.3463, kAd = 0.005;
constexpr int kAw = 60, kAh = 50;
double aValue(int x, int y) { return 100 + x + 1000.0 * y; }

// Input B: EPSG:32612 (UTM 12N), 500 m pixels, int16 raw x + 3 y + 1 with scale 0.5, offset 10;
// raw -32768 is nodata on the diagonal x == y.
constexpr int kBw = 30, kBh = 30;
constexpr double kBd = 500;
double bRaw(int x, int y) { return x == y ? -32768 : x + 3 * y + 1; }

// Target: EPSG:4326, 0.01 degree cells, larger than both inputs, so some cells stay uncovered.
Georef targetGrid() {
  Georef g;
  g.crsWkt = "EPSG:4326";
  g.epsg = 4326;
  g.geographic = true;
  g.width = 50;
  g.height = 40;
  g.transform = GeoTransform{{-113.3013, 0.01, 0, 36.4027, 0, -0.01}};
  return g;
}

struct Inputs {
  std::string a, b;
  double bx0 = 0, by0 = 0;
};

Inputs writeInputs(const std::filesystem::path& dir) {
  Inputs in;
  in.a = (dir / "a_4326.tif").string();
  in.b = (dir / "b_32612.tif").string();
  test::SyntheticRaster a;
  a.width = kAw;
  a.height = kAh;
  a.crs = "EPSG:4326";
  a.gt = std::array<double, 6>{kAx0, kAd, 0, kAy0, 0, -kAd};
  for (int y = 0; y < kAh; ++y)
    for (int x = 0; x < kAw; ++x) a.values.push_back(aValue(x, y));
  EXPECT_TRUE(test::writeSynthetic(in.a, a));
  // B's top-left corner at (-113.06, 36.33), moved off round numbers.
  auto utm = toUtm(LonLat{-113.06, 36.33, 0}, 12);
  EXPECT_TRUE(utm.ok());
  in.bx0 = std::floor(utm->eastingM) + 0.37;
  in.by0 = std::floor(utm->northingM) + 0.61;
  test::SyntheticRaster b;
  b.width = kBw;
  b.height = kBh;
  b.type = GDT_Int16;
  b.nodata = -32768;
  b.crs = "EPSG:32612";
  b.gt = std::array<double, 6>{in.bx0, kBd, 0, in.by0, 0, -kBd};
  for (int y = 0; y < kBh; ++y)
    for (int x = 0; x < kBw; ++x) b.values.push_back(bRaw(x, y));
  EXPECT_TRUE(test::writeSynthetic(in.b, b));
  // Scale and offset on B's band.
  GDALDataset* ds = GDALDataset::Open(in.b.c_str(), GDAL_OF_RASTER | GDAL_OF_UPDATE);
  EXPECT_NE(ds, nullptr);
  ds->GetRasterBand(1)->SetScale(0.5);
  ds->GetRasterBand(1)->SetOffset(10);
  GDALClose(ds);
  return in;
}

// What nearest-neighbour resampling must give at each target cell centre: the value of the
// input pixel containing it (NaN outside or on nodata). Pixel positions within 1e-6 pixel of an
// edge would be ties: counted, and the test requires none.
struct Expected {
  Grid<float> a, b;
  int ties = 0;
};

Expected expected(const Inputs& in, const Georef& t) {
  Expected e{Grid<float>(t.width, t.height, kNoData), Grid<float>(t.width, t.height, kNoData)};
  auto toUtm12 = CrsTransform::create("EPSG:4326", "EPSG:32612");
  EXPECT_TRUE(toUtm12.ok());
  auto tie = [](double p) { return std::abs(p - std::round(p)) < 1e-6; };
  for (int r = 0; r < t.height; ++r) {
    for (int c = 0; c < t.width; ++c) {
      const double lon = t.transform.x(c + 0.5, r + 0.5), lat = t.transform.y(c + 0.5, r + 0.5);
      const double ax = (lon - kAx0) / kAd, ay = (kAy0 - lat) / kAd;
      e.ties += tie(ax) + tie(ay);
      if (ax >= 0 && ay >= 0 && ax < kAw && ay < kAh) e.a.at(c, r) = float(aValue(int(ax), int(ay)));
      double x = lon, y = lat;
      EXPECT_TRUE(toUtm12->transform(1, &x, &y));
      const double bx = (x - in.bx0) / kBd, by = (in.by0 - y) / kBd;
      e.ties += tie(bx) + tie(by);
      if (bx >= 0 && by >= 0 && bx < kBw && by < kBh && bRaw(int(bx), int(by)) != -32768) {
        e.b.at(c, r) = float(bRaw(int(bx), int(by)) * 0.5 + 10);
      }
    }
  }
  return e;
}

float blendExpected(float layer, float src, BlendMode m, bool fill = false) {
  if (std::isnan(src)) return layer;
  // Corrections (add, subtract, multiply) leave no data where the layer has none, unless filling.
  const bool corrects = m == BlendMode::Add || m == BlendMode::Subtract || m == BlendMode::Multiply;
  if (std::isnan(layer)) return corrects && !fill ? kNoData : src;
  switch (m) {
    case BlendMode::Replace: return src;
    case BlendMode::Add: return layer + src;
    case BlendMode::Subtract: return layer - src;
    case BlendMode::Multiply: return layer * src;
    case BlendMode::Max: return std::max(layer, src);
    case BlendMode::Min: return std::min(layer, src);
  }
  return kNoData;
}

TEST(Mosaic, EveryBlendModeCellByCellAcrossTwoCrs) {
  const auto dir = strata::test::tempDir("mosaic");
  const Inputs in = writeInputs(dir);
  const Georef t = targetGrid();
  const Expected e = expected(in, t);
  ASSERT_EQ(e.ties, 0) << "a target cell centre lies on an input pixel edge: move the grids";
  int onlyA = 0, onlyB = 0, both = 0, neither = 0;
  for (size_t i = 0; i < e.a.size(); ++i) {
    const bool a = !std::isnan(e.a.data[i]), b = !std::isnan(e.b.data[i]);
    onlyA += a && !b;
    onlyB += b && !a;
    both += a && b;
    neither += !a && !b;
  }
  // The setup must exercise every case (and B's nodata diagonal inside the overlap).
  ASSERT_GT(onlyA, 50);
  ASSERT_GT(onlyB, 50);
  ASSERT_GT(both, 50);
  ASSERT_GT(neither, 50);

  for (BlendMode m :
       {BlendMode::Replace, BlendMode::Add, BlendMode::Subtract, BlendMode::Multiply, BlendMode::Max, BlendMode::Min}) {
    for (int order = 0; order < 4; ++order) {
      const bool aFirst = order % 2 == 0, fill = order >= 2;
      MosaicInput first{aFirst ? in.a : in.b, std::nullopt, BlendMode::Replace, Resampling::Nearest};
      MosaicInput second{aFirst ? in.b : in.a, std::nullopt, m, Resampling::Nearest};
      second.fillNoData = fill;
      const MosaicInput inputs[] = {first, second};
      auto layer = buildMosaic("bedrock", t, inputs);
      ASSERT_TRUE(layer.ok()) << layer.message();
      EXPECT_EQ(layer->name, "bedrock");
      const Grid<float>& x = aFirst ? e.a : e.b;
      const Grid<float>& y = aFirst ? e.b : e.a;
      int mismatches = 0;
      for (int r = 0; r < t.height; ++r) {
        for (int c = 0; c < t.width; ++c) {
          const float want = blendExpected(blendExpected(kNoData, x.at(c, r), BlendMode::Replace), y.at(c, r), m, fill);
          const float got = layer->raster.values.at(c, r);
          // Same float operations on the same float inputs: exactly equal.
          const bool same = (std::isnan(want) && std::isnan(got)) || want == got;
          if (!same && ++mismatches <= 5) {
            ADD_FAILURE() << toString(m) << (fill ? "+fill" : "") << (aFirst ? " A then B" : " B then A") << " cell "
                          << c << "," << r << ": " << got << " want " << want;
          }
        }
      }
      EXPECT_EQ(mismatches, 0) << toString(m);
    }
  }
}

TEST(Mosaic, BilinearKeepsConstantsAndLeavesUncoveredCellsNoData) {
  const auto dir = strata::test::tempDir("bilinear");
  const Georef t = targetGrid();
  const std::string a = (dir / "a.tif").string(), b = (dir / "b.tif").string();
  test::SyntheticRaster sa;
  sa.width = kAw;
  sa.height = kAh;
  sa.crs = "EPSG:4326";
  sa.gt = std::array<double, 6>{kAx0, kAd, 0, kAy0, 0, -kAd};
  sa.values.assign(size_t(kAw) * kAh, 250.0);
  ASSERT_TRUE(test::writeSynthetic(a, sa));
  auto utm = toUtm(LonLat{-113.06, 36.33, 0}, 12);
  ASSERT_TRUE(utm.ok());
  test::SyntheticRaster sb;
  sb.width = kBw;
  sb.height = kBh;
  sb.type = GDT_Int16;
  sb.nodata = -32768;
  sb.crs = "EPSG:32612";
  sb.gt = std::array<double, 6>{utm->eastingM, kBd, 0, utm->northingM, 0, -kBd};
  sb.values.assign(size_t(kBw) * kBh, 40.0);
  for (int i = 0; i < kBw; ++i) sb.values[size_t(i) * kBw + i] = -32768;  // nodata is never blended in
  ASSERT_TRUE(test::writeSynthetic(b, sb));
  for (Resampling rs : {Resampling::Bilinear, Resampling::Cubic}) {
    // B fills the cells where A has no data (add+fill), so B-only cells read 40.
    const MosaicInput inputs[] = {{a, std::nullopt, BlendMode::Replace, rs},
                                  {b, std::nullopt, BlendMode::Add, rs, 1, true}};
    auto layer = buildMosaic("sum", t, inputs);
    ASSERT_TRUE(layer.ok()) << layer.message();
    int n250 = 0, n290 = 0, n40 = 0, nan = 0;
    for (float v : layer->raster.values.data) {
      if (std::isnan(v)) {
        ++nan;
      } else if (v == 250.0f) {
        ++n250;
      } else if (v == 290.0f) {
        ++n290;
      } else if (v == 40.0f) {
        ++n40;
      } else {
        // Kernels renormalised over valid pixels keep a constant constant: anything else means
        // nodata (-32768) leaked into an interpolation.
        ADD_FAILURE() << "value " << v;
      }
    }
    EXPECT_GT(n250, 50);
    EXPECT_GT(n290, 50);
    EXPECT_GT(n40, 50);
    EXPECT_GT(nan, 50);
    // The target's top-left and bottom-right corners are outside both inputs.
    EXPECT_TRUE(std::isnan(layer->raster.values.at(0, 0)));
    EXPECT_TRUE(std::isnan(layer->raster.values.at(t.width - 1, t.height - 1)));
  }
}

TEST(Mosaic, InMemoryRasterEqualsItsFile) {
  const auto dir = strata::test::tempDir("mem");
  const Inputs in = writeInputs(dir);
  const Georef t = targetGrid();
  auto b = readDem(in.b);
  ASSERT_TRUE(b.ok()) << b.message();
  MosaicInput fromFile{in.b, std::nullopt, BlendMode::Replace, Resampling::Nearest};
  MosaicInput fromMemory{"", *b, BlendMode::Replace, Resampling::Nearest};
  auto x = warpToGrid(fromFile, t), y = warpToGrid(fromMemory, t);
  ASSERT_TRUE(x.ok() && y.ok());
  for (size_t i = 0; i < x->values.size(); ++i) {
    const float p = x->values.data[i], q = y->values.data[i];
    ASSERT_TRUE(p == q || (std::isnan(p) && std::isnan(q))) << i;
  }
}

TEST(Mosaic, ZeroTo360SourceOntoMinus180Grid) {
  // Mars' MEGDR runs 0..360 E; a -180..180 target must still be covered everywhere, with the
  // western hemisphere taken from 180..360 of the file.
  const std::string path = test::dataFile("mars/mola_megdr_4ppd.vrt");
  auto info = probeDem(path);
  ASSERT_TRUE(info.ok()) << info.message();
  Georef t = info->georef;
  t.width = 360;
  t.height = 180;
  // Cell centres at x.4 / x.6 degrees: never on a 0.25 degree source pixel edge.
  t.transform = GeoTransform{{-180.1, 1, 0, 90.1, 0, -1}};
  MosaicInput in;
  in.path = path;
  in.resampling = Resampling::Nearest;
  auto w = warpToGrid(in, t);
  ASSERT_TRUE(w.ok()) << w.message();
  auto src = readDem(path);
  ASSERT_TRUE(src.ok()) << src.message();
  int nan = 0;
  for (float v : w->values.data) nan += std::isnan(v);
  EXPECT_EQ(nan, 0);
  for (int r : {0, 79, 100, 179}) {
    for (int c : {0, 89, 180, 270, 359}) {
      double lon = t.transform.x(c + 0.5, r + 0.5);
      const double lat = t.transform.y(c + 0.5, r + 0.5);
      if (lon < 0) lon += 360;
      const int sx = int(lon / 0.25), sy = int((90 - lat) / 0.25);
      EXPECT_EQ(w->values.at(c, r), src->values.at(sx, sy)) << "lon " << lon << " lat " << lat;
    }
  }
}

TEST(Mosaic, Errors) {
  const Georef t = targetGrid();
  MosaicInput moon[1];
  moon[0].path = test::dataFile("moon/LDEM_4.LBL");
  auto r = buildMosaic("m", t, moon);
  ASSERT_FALSE(r.ok());
  EXPECT_NE(r.message().find("mosaic 'm': " + test::dataFile("moon/LDEM_4.LBL") +
                             ": lives on Moon, the mosaic "
                             "target on Earth (WGS84)"),
            std::string::npos)
      << r.message();
  MosaicInput missing[1];
  missing[0].path = "/nonexistent/x.tif";
  auto m = buildMosaic("m", t, missing);
  ASSERT_FALSE(m.ok());
  EXPECT_EQ(m.message(), "mosaic 'm': /nonexistent/x.tif: no such file");
  auto mode = parseBlendMode("screen");
  ASSERT_FALSE(mode.ok());
  EXPECT_EQ(mode.message(), "blend mode 'screen' is not one of replace, add, subtract, multiply, max, min");
  EXPECT_EQ(*parseBlendMode("multiply"), BlendMode::Multiply);
}

}  // namespace
}  // namespace strata::gis
