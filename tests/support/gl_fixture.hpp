#pragma once
// Fixture for tests that need a real GL 4.5 context (ctest label `gpu`): llvmpipe where there
// is no GPU, the GPU where there is one. A test that cannot get a context FAILS with the reason,
// unless the run says explicitly that there is no GL (STRATA_NO_GL=1): then it is skipped, and
// reported as skipped, never as passed.
#include <gtest/gtest.h>

#include <strata/render/gl/context.hpp>

namespace strata::test {

class GlTest : public ::testing::Test {
 protected:
  void SetUp() override;
  void TearDown() override;
  /// The process-wide headless context (created on first use).
  static render::gl::HeadlessContext& context();

 private:
  long errorsBefore_ = 0;
};

}  // namespace strata::test
