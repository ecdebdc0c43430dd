#include <gtest/gtest.h>

#include <chrono>
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

// Issue 34: the ETA follows the rate of the last seconds, not the mean since the start; log
// lines come every logEverySeconds of wall time (the run calls update() after every step and
// due() decides), STRATA_PROGRESS_EVERY overriding it.
TEST_F(LogTest, ProgressEtaFollowsTheRecentRate) {
  log::setLevel(log::Level::Info);
  setenv("STRATA_PROGRESS", "0", 1);
  auto t = std::chrono::steady_clock::time_point{};
  auto clock = [&] { return t; };
  {
    Progress p("spin-up", 1000.0, 10.0, clock);
    // 20 s at 1 unit/s (a slow start: the river still dry), then 5 units/s.
    for (int s = 1; s <= 20; ++s) {
      t += std::chrono::seconds(1);
      p.update(s);
    }
    EXPECT_NEAR(p.rate(), 1.0, 1e-9);
    for (int s = 1; s <= 20; ++s) {
      t += std::chrono::seconds(1);
      p.update(20 + 5.0 * s);
    }
    // 120 done in 40 s: the mean rate says 880 / 3 = 293 s left, the recent rate 880 / 5 = 176 s.
    EXPECT_NEAR(p.rate(), 5.0, 0.01);
    EXPECT_NEAR(p.etaSeconds(), 176.0, 1.0);
    EXPECT_FALSE(p.due());  // the last line was at 40 s
    t += std::chrono::seconds(9);
    EXPECT_FALSE(p.due());
    t += std::chrono::seconds(1);
    EXPECT_TRUE(p.due());
  }
  setenv("STRATA_PROGRESS_EVERY", "2", 1);
  {
    Progress p("run", 100.0, 10.0, clock);
    t += std::chrono::seconds(2);
    EXPECT_TRUE(p.due());
  }
  unsetenv("STRATA_PROGRESS_EVERY");
  unsetenv("STRATA_PROGRESS");
  // A line every 10 s of the 40: at 10, 20, 30 and 40 s.
  EXPECT_EQ(lines_.size(), 4u);
}

TEST(FormatDuration, ReadableUnits) {
  EXPECT_EQ(formatDuration(4.25), "4.2 s");
  EXPECT_EQ(formatDuration(190), "3 min 10 s");
  EXPECT_EQ(formatDuration(3720), "1 h 02 min");
  EXPECT_EQ(formatDuration(-1), "?");
}

}  // namespace
}  // namespace strata
