// CPU reference of the CDF 5/3 transform, histogram matching and the KS distance.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>

#include <strata/procgen/wavelet.hpp>

#include "procgen_test_support.hpp"
#include "strata_test.hpp"

namespace strata::procgen {
namespace {

float maxAbsDiff(const Grid<float>& a, const Grid<float>& b) {
  float worst = 0;
  for (size_t i = 0; i < a.size(); ++i) worst = std::max(worst, std::abs(a.data[i] - b.data[i]));
  return worst;
}

TEST(Wavelet53, LinearRampHasZeroInteriorDetailAndKeepsSamples) {
  // CDF 5/3 has two vanishing moments: the detail of a linear ramp is 0 away from the right
  // end (where the mirror breaks linearity), and the coarse samples are the even ones.
  std::vector<float> x(20), c(20);
  for (int i = 0; i < 20; ++i) x[size_t(i)] = 3.0f + 0.5f * float(i);
  forward53(x, c);
  for (int i = 0; i < 9; ++i) EXPECT_EQ(c[size_t(10 + i)], 0.0f) << "d[" << i << "]";
  for (int i = 1; i < 9; ++i) EXPECT_EQ(c[size_t(i)], x[size_t(2 * i)]) << "s[" << i << "]";
  EXPECT_EQ(c[19], 0.5f);  // x[19] - x[18]: the mirrored end
}

TEST(Wavelet53, OneDimensionalRoundTripOfEveryLength) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<float> u(-100, 100);
  for (int n = 2; n <= 33; ++n) {
    std::vector<float> x(static_cast<size_t>(n)), c(static_cast<size_t>(n)), y(static_cast<size_t>(n));
    for (auto& v : x) v = u(rng);
    forward53(x, c);
    inverse53(c, y);
    // Values of magnitude 100: float ulp 7.6e-6; lifting adds a few roundings per sample.
    for (int i = 0; i < n; ++i) EXPECT_NEAR(y[size_t(i)], x[size_t(i)], 1e-4) << "n=" << n << " i=" << i;
  }
}

TEST(Wavelet97, CubicHasZeroInteriorDetailAndConstantsKeepTheirValue) {
  // CDF 9/7 analysis has four vanishing moments: a cubic has zero detail away from the ends (up
  // to float rounding of values ~1e3: ulp 6e-5, a few roundings per lifting step), and the
  // low-pass has DC gain 1 (s = the constant, to the rounding of the 1/K scaling).
  const int n = 40;
  std::vector<float> x(n), c(n), k(n, 7.0f), ck(n);
  for (int i = 0; i < n; ++i) x[size_t(i)] = 0.01f * float(i * i * i) - 0.3f * float(i * i) + 2.0f * float(i);
  forward97(x, c);
  for (int i = 2; i < n / 2 - 2; ++i) EXPECT_NEAR(c[size_t(n / 2 + i)], 0.0f, 2e-3f) << "d[" << i << "]";
  forward97(k, ck);
  for (int i = 0; i < n / 2; ++i) EXPECT_NEAR(ck[size_t(i)], 7.0f, 1e-5f) << "s[" << i << "]";
  for (int i = n / 2; i < n; ++i) EXPECT_NEAR(ck[size_t(i)], 0.0f, 1e-5f) << "d[" << i - n / 2 << "]";
}

TEST(Wavelet97, OneDimensionalRoundTripOfEveryLength) {
  std::mt19937 rng(8);
  std::uniform_real_distribution<float> u(-100, 100);
  for (int n = 2; n <= 33; ++n) {
    std::vector<float> x(static_cast<size_t>(n)), c(static_cast<size_t>(n)), y(static_cast<size_t>(n));
    for (auto& v : x) v = u(rng);
    forward97(x, c);
    inverse97(c, y);
    // Values of magnitude 100 (ulp 7.6e-6) through four lifting steps and a scaling each way,
    // with weights up to 1.6: a few tens of ulps at most.
    for (int i = 0; i < n; ++i) EXPECT_NEAR(y[size_t(i)], x[size_t(i)], 5e-4) << "n=" << n << " i=" << i;
  }
}

TEST(Wavelet97, GrandCanyonRoundTrip) {
  const auto dem = test::readDemForTest(test::dataPath("grand_canyon/grand_canyon_512.tif"));
  const int levels = maxLevels(dem.width, dem.height);
  const auto back = inverseTransform(forwardTransform(dem, levels, Wavelet::Cdf97), levels, Wavelet::Cdf97);
  const float err = maxAbsDiff(back, dem);
  // Irrational weights round every product too (5/3's are exact) and K, 1/K rescale each level:
  // measured 7.1 mm (~30 ulps at 2800 m) against 1.2 mm for 5/3. 2 cm leaves margin for
  // another compiler's rounding and is still far below any lifting slip (metres).
  EXPECT_LT(err, 2e-2f) << "max |inverse(forward(dem)) - dem| = " << err << " m";
  std::printf("grand canyon 512^2, CDF 9/7, %d levels: max round-trip error %.3g m\n", levels, double(err));
}

TEST(Wavelet53, BandsTileTheGridForOddSizes) {
  const PyramidShape shape{37, 23, maxLevels(37, 23)};
  EXPECT_EQ(shape.levels, 5);  // regions 37x23, 19x12, 10x6, 5x3, 3x2 (the next, 2x1, is too small)
  std::vector<int> hits(37 * 23, 0);
  auto mark = [&](BandRect r) {
    for (int y = r.y0; y < r.y0 + r.height; ++y) {
      for (int x = r.x0; x < r.x0 + r.width; ++x) ++hits[size_t(y * 37 + x)];
    }
  };
  for (int l = 0; l < shape.levels; ++l) {
    for (Band b : {Band::HL, Band::LH, Band::HH}) mark(shape.band(l, b));
  }
  mark(shape.band(shape.levels, Band::LL));
  for (int h : hits) ASSERT_EQ(h, 1);
  EXPECT_FALSE(validateLevels(37, 23, 6).ok());
  EXPECT_FALSE(validateLevels(37, 23, 0).ok());
}

TEST(Wavelet53, RoundTripOfOddSizedRandomGrid) {
  Grid<float> g(37, 23);
  std::mt19937 rng(3);
  std::uniform_real_distribution<float> u(0, 1000);
  for (auto& v : g.data) v = u(rng);
  const auto back = inverseTransform(forwardTransform(g, 4), 4);
  // Magnitudes up to 1000 (ulp 6.1e-5) through 4 levels of two lifting steps each way.
  EXPECT_LT(maxAbsDiff(back, g), 2e-3f);
}

TEST(Wavelet53, GrandCanyonRoundTripIsExactToFloatTolerance) {
  const auto dem = test::readDemForTest(test::dataPath("grand_canyon/grand_canyon_512.tif"));
  ASSERT_EQ(dem.width, 512);
  const int levels = maxLevels(dem.width, dem.height);
  EXPECT_EQ(levels, 9);
  const auto coeffs = forwardTransform(dem, levels);
  const auto back = inverseTransform(coeffs, levels);
  const float err = maxAbsDiff(back, dem);
  // Heights 541..2806 m: float ulp there is 1.2e-4..2.4e-4 m. Each level's inverse re-rounds
  // the samples it rebuilds (s - (d0 + d1) / 4 does not undo s = x + (d0 + d1) / 4 exactly in
  // float), so the error grows by ~1-2 ulps per level: measured 1.2 mm (5 ulps) over 9 levels.
  // 4 mm (~17 ulps) leaves margin and still catches any lifting slip (a wrong weight or
  // index moves heights by metres).
  EXPECT_LT(err, 4e-3f) << "max |inverse(forward(dem)) - dem| = " << err << " m";
  std::printf("grand canyon 512^2, %d levels: max round-trip error %.3g m\n", levels, double(err));
  // The coarse 1x1 LL is close to the mean height (5/3 low-pass has DC gain 1).
  double mean = 0;
  for (float v : dem.data) mean += v;
  mean /= double(dem.size());
  EXPECT_NEAR(coeffs.at(0, 0), mean, 150.0);  // the boundary weights differ from a plain mean
}

TEST(HistogramMatching, TakesTheReferenceValuesInTheInputsRankOrder) {
  std::vector<float> values = {5, 1, 4, 2, 3};
  const std::vector<float> reference = {100, 300, 200, 500, 400};
  matchHistogram(values, reference);
  EXPECT_EQ(values, (std::vector<float>{500, 100, 400, 200, 300}));
  // Different sizes: the reference quantiles, interpolated.
  std::vector<float> three = {0, 10, 5};
  matchHistogram(three, reference);
  EXPECT_EQ(three, (std::vector<float>{100, 500, 300}));
}

TEST(HistogramMatching, KsDistanceOfKnownSamples) {
  const std::vector<float> a = {1, 2, 3, 4}, b = {3, 4, 5, 6};
  EXPECT_DOUBLE_EQ(ksDistance(a, a), 0.0);
  EXPECT_DOUBLE_EQ(ksDistance(a, b), 0.5);
  const std::vector<float> c = {10, 11};
  EXPECT_DOUBLE_EQ(ksDistance(a, c), 1.0);
}

TEST(Resample, BilinearKeepsCornersAndPlanes) {
  Grid<float> g(5, 4);
  for (int y = 0; y < 4; ++y) {
    for (int x = 0; x < 5; ++x) g.at(x, y) = float(2 * x + 3 * y);
  }
  const auto r = resampleBilinear(g, 9, 7);
  EXPECT_FLOAT_EQ(r.at(0, 0), 0.0f);
  EXPECT_FLOAT_EQ(r.at(8, 6), 17.0f);
  EXPECT_FLOAT_EQ(r.at(4, 3), 8.5f);  // plane at (2, 1.5)
  // A void takes the heights around it: a 3-cell hole in a row between 10 and 40 fills from
  // both ends inwards (10, then the mean of its neighbours in the middle, 40).
  Grid<float> holes(5, 1);
  holes.data = {10.0f, gis::kNoData, gis::kNoData, gis::kNoData, 40.0f};
  auto filled = fillNoData(holes, "x");
  ASSERT_TRUE(filled);
  EXPECT_EQ(filled->data, (std::vector<float>{10, 10, 25, 40, 40}));
  EXPECT_FALSE(fillNoData(Grid<float>(2, 2, gis::kNoData), "x").ok());
}

}  // namespace
}  // namespace strata::procgen
