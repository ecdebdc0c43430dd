// The sun's place (against the equinox, the solstice and the equation of time) and cast shadows
// against the length a wall's shadow must have.
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

#include <strata/render/sun.hpp>

namespace strata::render {
namespace {

using namespace std::chrono;

sys_seconds utc(const char* text) {
  auto t = parseUtc(text);
  EXPECT_TRUE(t) << t.message();
  return t ? *t : sys_seconds{};
}

TEST(Sun, SubsolarPointAtTheEquinoxSolsticeAndByTheEquationOfTime) {
  // March equinox 2026-03-20 14:46 UTC: declination 0; June solstice 2026-06-21 08:24 UTC: the
  // obliquity, 23.436 degrees (IMCCE/USNO times).
  EXPECT_NEAR(earthSubsolarPoint(utc("2026-03-20T14:46:00Z")).y, 0.0, 0.02);
  EXPECT_NEAR(earthSubsolarPoint(utc("2026-06-21T08:24:00Z")).y, 23.436, 0.02);
  EXPECT_NEAR(earthSubsolarPoint(utc("2026-12-21T20:50:00Z")).y, -23.436, 0.02);
  // The equation of time: the sun crosses Greenwich 16.4 min before 12:00 UTC on 3 November
  // and 14.2 min after on 11 February, so at noon UTC it stands 4.1 degrees west / 3.55 east.
  EXPECT_NEAR(earthSubsolarPoint(utc("2026-11-03T12:00:00Z")).x, -16.4 / 4.0, 0.06);
  EXPECT_NEAR(earthSubsolarPoint(utc("2026-02-11T12:00:00Z")).x, 14.2 / 4.0, 0.06);
  // Six hours later it is further west by the Earth's turn in 6 h (90.246 degrees at the sidereal
  // rate) less the sun's own eastward motion in right ascension (0.26 degree at the solstice).
  const double a = earthSubsolarPoint(utc("2026-06-21T06:00:00Z")).x;
  const double b = earthSubsolarPoint(utc("2026-06-21T12:00Z")).x;
  EXPECT_NEAR(std::remainder(a - b, 360.0), 90.246 - 0.26, 0.01);
}

TEST(Sun, TimesAreUtcAndBadOnesAreNamed) {
  EXPECT_EQ(utc("1970-01-01T00:00:00Z").time_since_epoch().count(), 0);
  EXPECT_EQ(utc("2000-01-01T12:00:00+00:00").time_since_epoch().count(), 946728000);
  for (const char* bad : {"2026-06-21", "2026-06-21T18:30:00", "2026-06-21T18:30:00+02:00", "2026-02-30T00:00Z",
                          "2026-06-21T25:00Z", "noon", "2026-06-21T18:30:00Zjunk"}) {
    auto t = parseUtc(bad);
    ASSERT_FALSE(t) << bad;
    EXPECT_NE(t.message().find(std::string("'") + bad + "'"), std::string::npos) << t.message();
    EXPECT_NE(t.message().find("2026-06-21T18:30:00Z"), std::string::npos) << t.message();
  }
}

TEST(Sun, DirectionsInThePlacesFrame) {
  // Overhead at the subsolar point, on the horizon 90 degrees away, from the east at dawn.
  const glm::dvec3 over = sunDirectionEnu(glm::dvec2(30, 20), 30, 20);
  EXPECT_NEAR(over.z, 1.0, 1e-12);
  const glm::dvec3 dawn = sunDirectionEnu(glm::dvec2(90, 0), 0, 0);
  EXPECT_NEAR(dawn.x, 1.0, 1e-12);
  EXPECT_NEAR(dawn.z, 0.0, 1e-12);
  const glm::dvec3 south = sunDirectionEnu(glm::dvec2(0, -23.44), 0, 40);  // noon, December, 40 N
  EXPECT_NEAR(std::asin(south.z) * 180 / std::numbers::pi, 90 - 40 - 23.44, 1e-9);
  EXPECT_LT(south.y, 0);
  const glm::dvec3 az = sunDirectionEnu(135.0, 30.0);
  EXPECT_NEAR(az.x, std::cos(std::numbers::pi / 6) * std::sqrt(0.5), 1e-12);
  EXPECT_NEAR(az.y, -std::cos(std::numbers::pi / 6) * std::sqrt(0.5), 1e-12);
}

// A flat 10 m grid (local metres) with a north-south wall 100 m high on columns 50-52.
gis::Grid<float> wallGrid(gis::Georef& g) {
  g.width = 200;
  g.height = 40;
  g.geographic = false;
  g.transform = gis::GeoTransform{{0, 10, 0, 400, 0, -10}};
  gis::Grid<float> h(200, 40, 0.0f);
  for (int y = 0; y < 40; ++y) {
    for (int x = 50; x <= 52; ++x) h.at(x, y) = 100.0f;
  }
  return h;
}

TEST(Sun, AWallsShadowIsItsHeightOverTheTangentOfTheSunsElevation) {
  gis::Georef g;
  const auto heights = wallGrid(g);
  for (double elev : {15.0, 30.0, 60.0}) {
    SunSpec sun;
    sun.dirEnu = sunDirectionEnu(270.0, elev);  // from the west
    const auto lit = castShadows(heights, g, sun, 1.0f);
    // The shadow runs east from the wall's top edge, at the centre of column 52 (bilinear
    // heights fall from 100 m there to 0 at column 53's centre).
    const double topEdgeM = 52.5 * 10, length = 100 / std::tan(elev * std::numbers::pi / 180);
    for (int x = 0; x < 200; ++x) {
      const double centreM = (x + 0.5) * 10;
      const float v = lit.at(x, 20);
      if (x <= 52) {
        EXPECT_EQ(v, 1.0f) << elev << " column " << x;  // west of and on the wall: in the sun
      } else if (centreM < topEdgeM + length - 15) {
        EXPECT_LT(v, 0.05f) << elev << " column " << x;
      } else if (centreM > topEdgeM + length + 15) {
        EXPECT_EQ(v, 1.0f) << elev << " column " << x;
      }
    }
    // Twice the exaggeration, twice the shadow.
    const auto lit2 = castShadows(heights, g, sun, 2.0f);
    const int x2 = int((topEdgeM + 1.8 * length) / 10);
    if (x2 < 200) {
      EXPECT_LT(lit2.at(x2, 20), 0.05f) << elev;
    }
  }
  // From the east the wall shades the west side instead; the sun below the horizon lights nothing.
  SunSpec east;
  east.dirEnu = sunDirectionEnu(90.0, 45.0);
  const auto litEast = castShadows(heights, g, east, 1.0f);
  EXPECT_LT(litEast.at(45, 20), 0.05f);
  EXPECT_EQ(litEast.at(60, 20), 1.0f);
  SunSpec night;
  night.dirEnu = sunDirectionEnu(90.0, -5.0);
  for (float v : castShadows(heights, g, night, 1.0f).data) ASSERT_EQ(v, 0.0f);
}

TEST(Sun, ASubsolarPointLightsEachCellOfAGlobalGridFromItsOwnSky) {
  // A flat lon/lat grid of the whole Earth, the sun over (0, 0): cells within 90 degrees of it
  // are lit, the others are not (a 0.53 degree disc blurs the terminator, 2-degree cells).
  gis::Georef g;
  g.width = 180;
  g.height = 90;
  g.geographic = true;
  g.body = gis::Body::wgs84();
  g.transform = gis::GeoTransform{{-180, 2, 0, 90, 0, -2}};
  const gis::Grid<float> heights(180, 90, 0.0f);
  SunSpec sun;
  sun.subsolarLonLat = glm::dvec2(0, 0);
  const auto lit = castShadows(heights, g, sun, 1.0f);
  for (int y = 0; y < 90; ++y) {
    for (int x = 0; x < 180; ++x) {
      const double lon = -180 + 2 * (x + 0.5), lat = 90 - 2 * (y + 0.5);
      const double cosAngle = std::cos(lon * std::numbers::pi / 180) * std::cos(lat * std::numbers::pi / 180);
      if (cosAngle > 0.02) {
        EXPECT_EQ(lit.at(x, y), 1.0f) << lon << " " << lat;
      } else if (cosAngle < -0.02) {
        EXPECT_EQ(lit.at(x, y), 0.0f) << lon << " " << lat;
      }
    }
  }
}

}  // namespace
}  // namespace strata::render
