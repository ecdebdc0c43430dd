// The scale bar's arithmetic (no GL context): round lengths and their labels. The bar drawn on a
// view is checked in terrain_render_test.cpp (GlTest.AScaleBarMeasuresTheGroundAtItsTrueScale).
#include <gtest/gtest.h>

#include <limits>

#include <strata/render/overlay.hpp>

namespace strata::render {
namespace {

TEST(ScaleBar, LengthsRoundDownToOneTwoOrFiveTimesAPowerOfTen) {
  EXPECT_DOUBLE_EQ(roundScaleLength(214.4), 200);
  EXPECT_DOUBLE_EQ(roundScaleLength(199.9), 100);
  EXPECT_DOUBLE_EQ(roundScaleLength(500), 500);
  EXPECT_DOUBLE_EQ(roundScaleLength(999), 500);
  EXPECT_DOUBLE_EQ(roundScaleLength(1000), 1000);
  EXPECT_DOUBLE_EQ(roundScaleLength(0.37), 0.2);
  EXPECT_DOUBLE_EQ(roundScaleLength(4.9e6), 2e6);
  EXPECT_EQ(roundScaleLength(0), 0);
  EXPECT_EQ(roundScaleLength(-3), 0);
  EXPECT_EQ(roundScaleLength(std::numeric_limits<double>::infinity()), 0);
}

TEST(ScaleBar, LabelsUseMetresBelowAKilometre) {
  EXPECT_EQ(formatDistance(200), "200 m");
  EXPECT_EQ(formatDistance(0.5), "0.5 m");
  EXPECT_EQ(formatDistance(1000), "1 km");
  EXPECT_EQ(formatDistance(5000), "5 km");
  EXPECT_EQ(formatDistance(2e7), "20000 km");
}

}  // namespace
}  // namespace strata::render
