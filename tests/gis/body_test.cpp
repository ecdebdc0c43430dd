#include <gtest/gtest.h>

#include <strata/gis/body.hpp>

namespace strata::gis {
namespace {

TEST(Body, RecognisedFromEllipsoidParameters) {
  EXPECT_EQ(Body::fromEllipsoid(6378137.0, 1 / 298.257223563).name, "Earth (WGS84)");
  EXPECT_EQ(Body::fromEllipsoid(1737400.0, 0.0).name, "Moon");
  EXPECT_EQ(Body::fromEllipsoid(3396190.0, 0.0).name, "Mars");
  // GRS80 differs from WGS84 in f by 1.6e-11 only, but a sphere of Earth radius is not WGS84.
  const Body sphere = Body::fromEllipsoid(6371000.0, 0.0, "Normal Sphere");
  EXPECT_EQ(sphere.name, "Normal Sphere");
  EXPECT_TRUE(sphere.isSphere());
  EXPECT_NEAR(Body::wgs84().semiMinorM(), 6356752.314245, 1e-6);
}

}  // namespace
}  // namespace strata::gis
