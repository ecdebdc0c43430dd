// A solver's state as bytes (what moves blocks between ranks and what a rank's part of a
// distributed checkpoint is), and the clock-only step runners use for idle blocks.
#include <gtest/gtest.h>

#include <cstring>

#include <strata/sim/cpu_solver.hpp>
#include <strata/sim/state_codec.hpp>

#include "sim_scenes.hpp"

namespace strata::sim {
namespace {

TEST(SimState, EncodedStateRestoresBitForBit) {
  auto in = test::erodingValley(24);
  auto p = test::erosionParams();
  auto a = CpuSolver::create(in, p);
  ASSERT_TRUE(a) << a.message();
  ASSERT_TRUE(a->addSource(test::valleySpring(24)));
  a->enableFloodStats(0.01f);
  a->step(30);
  SolverState saved = a->saveState();
  saved.parts = {saved, saved};  // nested parts (a runner's), carried too
  saved.tags = {3, 1, 4};
  saved.numbers = {2.5};
  const std::string bytes = encodeState(saved);
  auto back = decodeState(bytes);
  ASSERT_TRUE(back) << back.message();
  EXPECT_EQ(encodeState(*back), bytes);
  ASSERT_EQ(back->parts.size(), 2u);
  EXPECT_EQ(back->tags, saved.tags);

  auto b = CpuSolver::create(in, p);
  ASSERT_TRUE(b) << b.message();
  ASSERT_TRUE(b->addSource(test::valleySpring(24)));
  back->parts.clear();
  ASSERT_TRUE(b->restoreState(*back));
  a->step(10);
  b->step(10);
  const auto sa = a->saveState(), sb = b->saveState();
  EXPECT_EQ(encodeState(sa), encodeState(sb));

  // Anything but a whole encoded state is refused.
  EXPECT_FALSE(decodeState(bytes.substr(0, bytes.size() - 1)));
  EXPECT_FALSE(decodeState(bytes + "x"));
  EXPECT_FALSE(decodeState("STRATAS1"));
  EXPECT_FALSE(decodeState("not a state"));
  std::string huge = bytes;
  const uint64_t n = ~0ull;
  std::memcpy(&huge[8 + sizeof(SolverCounters) + 4], &n, 8);  // the length of `state`: beyond what is left
  EXPECT_FALSE(decodeState(huge));
}

TEST(SimState, SkipStepAdvancesTheClockOnly) {
  auto in = test::sloshingBox(16);
  auto a = CpuSolver::create(in, test::floodParams());
  ASSERT_TRUE(a) << a.message();
  const CellBlock before = a->readBlock(0, 0, 16, 16, kBlockAll);
  a->skipStep(2.5);
  a->skipStep(1.5);
  const CellBlock after = a->readBlock(0, 0, 16, 16, kBlockAll);
  EXPECT_EQ(a->timeS(), 4.0);
  EXPECT_EQ(a->counterStats().steps, 2);
  EXPECT_EQ(a->counterStats().lastDtS, 1.5);
  EXPECT_EQ(before.state, after.state);
  EXPECT_EQ(before.accum, after.accum);
}

}  // namespace
}  // namespace strata::sim
