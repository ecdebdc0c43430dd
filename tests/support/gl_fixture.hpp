#pragma once
// Fixture for tests that need a real GL 4.5 context (ctest label `gpu`): llvmpipe where there
// is no GPU, the GPU where there is one. A test that cannot get a context FAILS with the reason,
// unless the run says explicitly that there is no GL (STRATA_NO_GL=1): then it is skipped, and
// reported as skipped, never as passed.
#include <gtest/gtest.h>

#include <optional>
#include <span>
#include <string>
#include <utility>
#include <vector>

#include <strata/gl/context.hpp>
#include <strata/gl/objects.hpp>

namespace strata::test {

/// The run says it has no GL (STRATA_NO_GL=1): GL tests skip, and say so, instead of failing.
/// Tests that reach GL through another program (strata-view under Xvfb) ask this too.
bool noGlRequested();

class GlTest : public ::testing::Test {
 protected:
  void SetUp() override;
  void TearDown() override;
  /// The process-wide headless context (created on first use).
  static gl::HeadlessContext& context();

 private:
  long errorsBefore_ = 0;
};

/// A program to check against a binding table: one compute shader or a vertex + fragment pair
/// (names of embedded shaders), or already-preprocessed compute source.
struct SlotProgram {
  std::vector<std::string> shaders;                       ///< {comp} or {vert, frag}
  std::optional<gl::ShaderSource> source = std::nullopt;  ///< instead of `shaders`: a compute source (e.g. spliced)
  bool bindsNothing = false;  ///< the program has no block, sampler or image (uniforms only): checked to have none
};

/// The binding-slot check of one library (docs/architecture.md, "The GL layer"): every program
/// compiles with the table's #defines, every block, sampler and image it has is declared in the
/// table with the binding the program got (gl::checkBindings), every table entry is used by some
/// program, and every program file under `folder` (e.g. "render/shaders/") is in some program.
/// `defines`: what the library compiles its programs with, when more than the table's slots.
void expectProgramsMatchSlots(const std::string& folder, std::span<const gl::Binding> slots,
                              const std::vector<SlotProgram>& programs, std::vector<gl::ShaderDefine> defines = {});

}  // namespace strata::test
