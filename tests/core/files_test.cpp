#include <gtest/gtest.h>

#include <fstream>
#include <sstream>

#include <strata/core/files.hpp>

#include "strata_test.hpp"

namespace strata {
namespace {

std::string slurp(const std::filesystem::path& p) {
  std::ifstream f(p);
  std::stringstream s;
  s << f.rdbuf();
  return s.str();
}

TEST(Files, AtomicWriteReplacesWholeAndLeavesNoTemporary) {
  const auto dir = test::tempDir("atomic");
  const auto target = dir / "series.csv";
  ASSERT_TRUE(writeFileAtomic(target, "old\n"));
  ASSERT_TRUE(writeFileAtomic(target, "new content\n"));
  EXPECT_EQ(slurp(target), "new content\n");
  int entries = 0;
  for ([[maybe_unused]] const auto& e : std::filesystem::directory_iterator(dir)) ++entries;
  EXPECT_EQ(entries, 1) << "a temporary was left behind";
}

TEST(Files, AnInterruptedWriteLeavesTheOldFile) {
  // A writer killed before commitTemporary: the target keeps its earlier content.
  const auto dir = test::tempDir("atomic");
  const auto target = dir / "max_depth.tif";
  ASSERT_TRUE(writeFileAtomic(target, "complete"));
  const auto tmp = temporaryPathFor(target);
  std::ofstream(tmp) << "half";
  EXPECT_EQ(slurp(target), "complete");
  EXPECT_TRUE(commitTemporary(tmp, target));
  EXPECT_EQ(slurp(target), "half");
}

TEST(Files, UnwritableTargetIsAnError) {
  auto s = writeFileAtomic("/nonexistent-dir/x.csv", "x");
  ASSERT_FALSE(s);
  EXPECT_EQ(s.message(), "/nonexistent-dir/x.csv: cannot write: No such file or directory");
}

}  // namespace
}  // namespace strata
