#include <gtest/gtest.h>

#include <string>
#include <vector>

#include <strata/core/log.hpp>
#include <strata/core/progress.hpp>

namespace strata {
namespace {

struct Captured {
  log::Level level;
  std::string category, message;
};

class LogTest : public ::testing::Test {
 protected:
  void SetUp() override {
    saved_ = log::level();
    log::setSink([this](log::Level l, std::string_view c, std::string_view m) {
      lines_.push_back({l, std::string(c), std::string(m)});
    });
  }
  void TearDown() override {
    log::resetSink();
    log::setLevel(saved_);
  }
  std::vector<Captured> lines_;
  log::Level saved_{};
};

TEST_F(LogTest, LinesCarryCategoryAndRespectLevel) {
  log::setLevel(log::Level::Info);
  log::info("gis") << "reading "
                   << "dem.tif"
                   << ": " << 512 << " x " << 512;
  log::debug("gis") << "hidden";
  log::error("gl") << "bad";
  ASSERT_EQ(lines_.size(), 2u);
  EXPECT_EQ(lines_[0].category, "gis");
  EXPECT_EQ(lines_[0].message, "reading dem.tif: 512 x 512");
  EXPECT_EQ(lines_[1].level, log::Level::Error);
}

TEST_F(LogTest, ProgressLogsPlainLinesWhenNotATerminal) {
  log::setLevel(log::Level::Info);
  setenv("STRATA_PROGRESS", "0", 1);
  {
    Progress p("flood", 100.0, 0.0);
    EXPECT_FALSE(p.interactive());
    p.update(50, "12 steps/s");
    EXPECT_DOUBLE_EQ(p.fraction(), 0.5);
    p.finish();
  }
  unsetenv("STRATA_PROGRESS");
  ASSERT_GE(lines_.size(), 2u);
  EXPECT_EQ(lines_[0].category, "progress");
  EXPECT_NE(lines_[0].message.find("flood: 50%"), std::string::npos) << lines_[0].message;
  EXPECT_NE(lines_[0].message.find("12 steps/s"), std::string::npos);
  EXPECT_NE(lines_.back().message.find("100%"), std::string::npos);
}

TEST(FormatDuration, ReadableUnits) {
  EXPECT_EQ(formatDuration(4.25), "4.2 s");
  EXPECT_EQ(formatDuration(190), "3 min 10 s");
  EXPECT_EQ(formatDuration(3720), "1 h 02 min");
  EXPECT_EQ(formatDuration(-1), "?");
}

}  // namespace
}  // namespace strata
