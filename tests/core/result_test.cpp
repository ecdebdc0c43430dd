#include <gtest/gtest.h>

#include <strata/core/result.hpp>

namespace strata {
namespace {

Result<int> parsePositive(int v) {
  if (v <= 0) return fail("value " + std::to_string(v) + " is not positive");
  return v;
}

Result<int> doubled(int v) {
  STRATA_TRY(int x, parsePositive(v));
  return 2 * x;
}

Status check(int v) {
  STRATA_TRY_STATUS(parsePositive(v));
  return {};
}

TEST(Result, CarriesValueOrMessage) {
  auto ok = parsePositive(3);
  ASSERT_TRUE(ok);
  EXPECT_EQ(*ok, 3);
  auto bad = parsePositive(-1);
  ASSERT_FALSE(bad);
  EXPECT_EQ(bad.message(), "value -1 is not positive");
}

TEST(Result, TryPropagatesTheFirstError) {
  EXPECT_EQ(*doubled(4), 8);
  EXPECT_EQ(doubled(0).message(), "value 0 is not positive");
  EXPECT_TRUE(check(1));
  EXPECT_EQ(check(-2).message(), "value -2 is not positive");
}

TEST(ResultDeathTest, ValueOfAnErrorAborts) {
  auto bad = parsePositive(-5);
  EXPECT_DEATH((void)bad.value(), "check failed: ok\\(\\): Result::value\\(\\) on an error: value -5");
}

TEST(CheckDeathTest, NamesConditionAndMessage) {
  const int n = 3;
  EXPECT_DEATH(STRATA_CHECK(n == 4) << "n was " << n, "check failed: n == 4: n was 3");
}

}  // namespace
}  // namespace strata
