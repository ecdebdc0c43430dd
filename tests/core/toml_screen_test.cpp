// The one screen every TOML text passes before toml++ (scenarios and manifests): its options. The
// inputs that trip toml++ are tested through each reader (tests/scenario/scenario_test.cpp,
// tests/terrain/store_safety_test.cpp) and fuzzed (scripts/fuzz.sh).
#include <gtest/gtest.h>

#include <string>

#include <strata/core/toml_screen.hpp>

namespace strata {
namespace {

TEST(TomlScreen, AsciiOnlyRefusesNonAsciiInStringsAndComments) {
  const std::string text = "name = \"R\xC3\xA9seau\"  # \xE2\x80\x94\n";
  EXPECT_TRUE(screenToml(text, "a.toml"));
  TomlScreenOptions ascii;
  ascii.asciiOnly = true;
  ascii.kind = "manifest";
  auto s = screenToml(text, "m.toml", ascii);
  ASSERT_FALSE(s);
  EXPECT_EQ(s.message(),
            "m.toml:1: U+00E9: not ASCII (a manifest is ASCII; its strings write other characters as \\uXXXX escapes)");
  // Outside strings and comments TOML allows none, in either mode.
  auto outside = screenToml("a = 1\n\xC3\xA9 = 2\n", "a.toml");
  ASSERT_FALSE(outside);
  EXPECT_EQ(outside.message(), "a.toml:2: U+00E9 outside a string or a comment (TOML allows ASCII only there)");
}

TEST(TomlScreen, DatesAreRefusedNamingTheKindAndTheHint) {
  TomlScreenOptions o;
  o.kind = "scenario";
  o.dateHint = "durations are quantities such as \"3 h\"";
  auto s = screenToml("a = 1\nstart = 2026-11-24\n", "s.toml", o);
  ASSERT_FALSE(s);
  EXPECT_EQ(s.message(),
            "s.toml:2: '-' inside a value: a date or a time of day, which no scenario key takes (durations are "
            "quantities such as \"3 h\")");
  // Signs and exponents are not dates; strings may hold anything.
  EXPECT_TRUE(screenToml("a = -1.5e-3\nb = [-2, +3]\nc = \"2026-11-24 12:00\"\n", "s.toml", o));
}

TEST(TomlScreen, SizeAndNestingAreBounded) {
  TomlScreenOptions o;
  o.maxBytes = std::size_t(1) << 20;
  o.kind = "manifest";
  auto big = screenToml(std::string((std::size_t(1) << 20) + 1, ' '), "m.toml", o);
  ASSERT_FALSE(big);
  EXPECT_EQ(big.message(), "m.toml: larger than 1 MiB: not a manifest");
  o.maxNesting = 3;
  EXPECT_TRUE(screenToml("a = [[[1]]]\n", "m.toml", o));
  auto deep = screenToml("a = [[[[1]]]]\n", "m.toml", o);
  ASSERT_FALSE(deep);
  EXPECT_EQ(deep.message(), "m.toml:1: arrays and inline tables nested deeper than 3");
}

TEST(TomlScreen, MismatchedBracketsAreRefusedWithTheirLine) {
  auto a = screenToml("x = 1\nu = [1, }\n", "a.toml");
  ASSERT_FALSE(a);
  EXPECT_EQ(a.message(), "a.toml:2: '}' inside an array (no inline table to close)");
  auto b = screenToml("t = { k = ]\n", "a.toml");
  ASSERT_FALSE(b);
  EXPECT_EQ(b.message(), "a.toml:1: ']' inside an inline table (no array to close)");
  EXPECT_TRUE(screenToml("t = { k = [1, { m = 2 }] }\n[[layer]]\nname = 'x'\n", "a.toml"));
}

}  // namespace
}  // namespace strata
