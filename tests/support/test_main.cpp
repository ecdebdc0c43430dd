#include "strata_test.hpp"

#include <gtest/gtest.h>

#include <unistd.h>

#include <cstdlib>
#include <vector>

#include <strata/core/log.hpp>

#ifndef STRATA_DATA_DIR
#define STRATA_DATA_DIR "../shared/data"
#endif

namespace strata::test {
namespace {
std::vector<std::filesystem::path>& tempDirs() {
  static std::vector<std::filesystem::path> dirs;
  return dirs;
}
}  // namespace

std::string dataPath(const std::string& relative) { return std::string(STRATA_DATA_DIR) + "/" + relative; }

std::filesystem::path outputDir(const std::string& suite) {
  auto dir = std::filesystem::path(STRATA_TEST_OUTPUT_DIR) / suite;
  std::filesystem::create_directories(dir);
  return dir;
}

std::filesystem::path tempDir(const std::string& name) {
  const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
  std::string tag = info ? std::string(info->test_suite_name()) + "." + info->name() : "strata";
  for (char& c : tag) {
    if (c == '/') c = '_';
  }
  auto dir =
      std::filesystem::temp_directory_path() / ("strata-test-" + tag + "-" + name + "-" + std::to_string(::getpid()));
  std::filesystem::remove_all(dir);
  std::filesystem::create_directories(dir);
  tempDirs().push_back(dir);
  return dir;
}

}  // namespace strata::test

int main(int argc, char** argv) {
  ::testing::InitGoogleTest(&argc, argv);
  if (!std::getenv("STRATA_LOG")) strata::log::setLevel(strata::log::Level::Warn);
  const int rc = RUN_ALL_TESTS();
  const char* keep = std::getenv("STRATA_KEEP_TMP");
  if (!keep || std::string(keep) != "1") {
    std::error_code ec;
    for (const auto& d : strata::test::tempDirs()) std::filesystem::remove_all(d, ec);
  }
  return rc;
}
