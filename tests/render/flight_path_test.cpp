// Flight-path keyframes: parsing, errors that name the line, interpolation.
#include <gtest/gtest.h>

#include <strata/render/flight_path.hpp>

namespace strata::render {
namespace {

TEST(FlightPath, ParsesAndInterpolates) {
  auto path = FlightPath::parse(
      "# lon lat height heading pitch [fov]\n"
      "-112.1 36.1 3000 350 -20\n"
      "\n"
      "-112.0 36.2 5000 10 -40 60\n"
      "-111.9 36.2 5000 10 -40\n",
      "keys.txt");
  ASSERT_TRUE(path) << path.message();
  ASSERT_EQ(path->keys.size(), 3u);
  EXPECT_EQ(path->keys[1].fovYDeg, 60);
  const CameraPose mid = path->at(0.25);  // halfway between keys 0 and 1
  EXPECT_DOUBLE_EQ(mid.lon, -112.05);
  EXPECT_DOUBLE_EQ(mid.heightM, 4000);
  EXPECT_DOUBLE_EQ(mid.pitchDeg, -30);
  EXPECT_DOUBLE_EQ(mid.fovYDeg, 52.5);
  // 350 -> 10 turns through north (20 degrees), not back through south.
  EXPECT_NEAR(std::remainder(mid.headingDeg, 360.0), 0.0, 1e-12);
  EXPECT_DOUBLE_EQ(path->at(1.0).lon, -111.9);
  EXPECT_DOUBLE_EQ(path->at(0.0).lat, 36.1);
}

TEST(FlightPath, ErrorsNameTheLine) {
  auto bad = FlightPath::parse("1 2 3 4 5\n1 2 three 4 5\n", "keys.txt");
  ASSERT_FALSE(bad);
  EXPECT_NE(bad.message().find("keys.txt:2"), std::string::npos) << bad.message();
  auto one = FlightPath::parse("1 2 3 4 5\n", "keys.txt");
  ASSERT_FALSE(one);
  EXPECT_NE(one.message().find("need at least 2"), std::string::npos) << one.message();
  auto pitch = FlightPath::parse("1 2 3 4 5\n1 2 3 4 -95\n", "keys.txt");
  ASSERT_FALSE(pitch);
  EXPECT_NE(pitch.message().find("keys.txt:2: pitch"), std::string::npos) << pitch.message();
  auto extra = FlightPath::parse("1 2 3 4 5 45 x\n1 2 3 4 5\n", "keys.txt");
  ASSERT_FALSE(extra);
  EXPECT_NE(extra.message().find("keys.txt:1: unexpected 'x'"), std::string::npos) << extra.message();
  EXPECT_FALSE(FlightPath::load("/nonexistent/keys.txt"));
}

}  // namespace
}  // namespace strata::render
