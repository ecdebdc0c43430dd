#include <gtest/gtest.h>

#include <strata/terrain/material.hpp>

namespace strata::terrain {
namespace {

TEST(Material, DefaultsAreOrderedByStrength) {
  const auto m = defaultMaterials();
  const int rock = findMaterial(m, "rock"), soil = findMaterial(m, "soil"), sand = findMaterial(m, "sand");
  ASSERT_GE(rock, 0);
  ASSERT_GE(soil, 0);
  ASSERT_GE(sand, 0);
  EXPECT_EQ(findMaterial(m, "cheese"), -1);
  // Rock erodes least and stands steepest; sand erodes most and rests at its angle of repose.
  EXPECT_LT(m[rock].erodibility, m[soil].erodibility);
  EXPECT_LT(m[soil].erodibility, m[sand].erodibility);
  EXPECT_GT(m[rock].talusAngleDeg, m[soil].talusAngleDeg);
  EXPECT_GT(m[soil].talusAngleDeg, m[sand].talusAngleDeg);
  EXPECT_NEAR(m[sand].talusAngleDeg, 32.0f, 3.0f);
}

}  // namespace
}  // namespace strata::terrain
