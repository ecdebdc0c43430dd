// Compute shaders on whatever GL the machine has (llvmpipe in CI), checked exactly.
#include <gtest/gtest.h>

#include <cstdlib>
#include <fstream>
#include <random>

#include <strata/gl/objects.hpp>
#include <strata/gl/state.hpp>
#include "grid_params.hpp"

#include "gl_fixture.hpp"
#include "strata_test.hpp"

namespace strata::gl {
namespace {

using test::GlTest;

TEST_F(GlTest, ParallelReductionIsExact) {
  // 1,000,003 values (not a multiple of the group size) in [-1000, 1000]: the integer sum,
  // min and max must match the CPU's exactly.
  const uint32_t n = 1000003;
  std::mt19937 rng(42);
  std::uniform_int_distribution<int> dist(-1000, 1000);
  std::vector<int> values(n);
  long long sum = 0;
  int lo = INT32_MAX, hi = INT32_MIN;
  for (auto& v : values) {
    v = dist(rng);
    sum += v;
    lo = std::min(lo, v);
    hi = std::max(hi, v);
  }
  auto prog = Program::compute("tests/gl/shaders/reduce.comp");
  ASSERT_TRUE(prog) << prog.message();
  auto input = Buffer::from(std::span<const int>(values));
  const int init[3] = {0, INT32_MAX, INT32_MIN};
  Buffer output(sizeof init, init);
  input.bindStorage(0);
  output.bindStorage(1);
  prog->set("count", n);
  prog->dispatchCovering(int(n));
  memoryBarrier(Barrier::kBufferUpdate);
  const auto r = output.read<int>();
  EXPECT_EQ(r[0], sum);
  EXPECT_EQ(r[1], lo);
  EXPECT_EQ(r[2], hi);
}

TEST_F(GlTest, LaplacianStencilIsExact) {
  // f = x^2 + 3y^2 on integer points has a 5-point Laplacian of exactly 2 + 6 = 8 inside;
  // every value is an integer below 2^24, so float arithmetic is exact.
  const int w = 67, h = 45;
  std::vector<float> f(size_t(w * h));
  for (int y = 0; y < h; ++y) {
    for (int x = 0; x < w; ++x) f[size_t(y * w + x)] = float(x * x + 3 * y * y);
  }
  auto src = Texture::create2D(TextureFormat::kR32F, w, h);
  auto dst = Texture::create2D(TextureFormat::kR32F, w, h);
  src.upload(f.data());
  test::GridParams grid;
  grid.size = {w, h};
  Buffer params(sizeof grid, &grid);
  auto prog = Program::compute("tests/gl/shaders/laplacian.comp");
  ASSERT_TRUE(prog) << prog.message();
  src.bindImage(0, Access::kRead);
  dst.bindImage(1, Access::kWrite);
  params.bindStorage(2);
  prog->dispatchCovering(w, h);
  memoryBarrier(Barrier::kTextureUpdate);
  const auto out = dst.read<float>();
  for (int y = 0; y < h; ++y) {
    for (int x = 0; x < w; ++x) {
      // Borders clamp (a zero-gradient ghost cell): compute the expected value the same way.
      auto at = [&](int xx, int yy) {
        xx = std::clamp(xx, 0, w - 1);
        yy = std::clamp(yy, 0, h - 1);
        return double(xx * xx + 3 * yy * yy);
      };
      const double expected = at(x - 1, y) + at(x + 1, y) + at(x, y - 1) + at(x, y + 1) - 4 * at(x, y);
      ASSERT_EQ(out[size_t(y * w + x)], float(expected)) << "at " << x << "," << y;
      if (x > 0 && y > 0 && x < w - 1 && y < h - 1) {
        ASSERT_EQ(out[size_t(y * w + x)], 8.0f);
      }
    }
  }
}

TEST_F(GlTest, GridParamsLayoutAgreesBetweenCppAndGlsl) {
  test::GridParams g;
  g.size = {1001, 1002};
  g.cellSizeM = {3.5f, 4.25f};
  g.datumM = 2000.5f;
  g.noData = -9999.0f;
  g.flags = 7;
  g.pad0 = 9;
  g.sun = {0.25f, 0.5f, 0.75f, 2.0f};
  Buffer params(sizeof g, &g);
  Buffer fields(12 * sizeof(float));
  fields.fill(0xFFFFFFFFu);  // NaN: a field the shader does not write shows up
  auto prog = Program::compute("tests/gl/shaders/layout_probe.comp");
  ASSERT_TRUE(prog) << prog.message();
  params.bindStorage(0);
  fields.bindStorage(1);
  prog->dispatchCovering(1);
  memoryBarrier(Barrier::kBufferUpdate);
  EXPECT_EQ(fields.read<float>(),
            (std::vector<float>{1001, 1002, 3.5f, 4.25f, 2000.5f, -9999.0f, 7, 9, 0.25f, 0.5f, 0.75f, 2.0f}));
}

// The counts of what the host asks of GL (callCounts): a linked program knows its work-group
// size and its uniforms' locations, so dispatching and setting uniforms query nothing (an array's
// element other than the first is asked once, then remembered); a read counts with its bytes.
TEST_F(GlTest, DispatchesAndUniformsQueryNothingAfterLink) {
  const std::string source =
      "#version 450\nlayout(local_size_x = 4) in;\nlayout(std430, binding = 0) buffer Out { float v[]; };\n"
      "uniform uint count;\nuniform float scale[3];\n"
      "void main() { const uint i = gl_GlobalInvocationID.x; if (i < count) v[i] = scale[i % 3u] * float(i); }\n";
  auto prog = Program::link({{ShaderStage::kCompute, source, {"inline.comp"}}}, "inline.comp");
  ASSERT_TRUE(prog) << prog.message();
  EXPECT_EQ(prog->workGroupSize(), glm::ivec3(4, 1, 1));
  Buffer out(6 * sizeof(float));
  out.bindStorage(0);
  const CallCounts c0 = callCounts();
  prog->set("count", 6u);
  prog->set("scale", 2.0f);  // the array's first element, by its name
  prog->set("scale[2]", 5.0f);
  prog->set("scale[1]", 3.0f);
  prog->set("scale[1]", 3.0f);  // remembered
  prog->dispatchCovering(6);
  prog->dispatchCovering(6);
  memoryBarrier(Barrier::kBufferUpdate);
  const CallCounts c1 = callCounts();
  EXPECT_EQ(c1.queries - c0.queries, 2u);  // scale[2] and scale[1], once each
  EXPECT_EQ(c1.dispatches - c0.dispatches, 2u);
  EXPECT_EQ(c1.hostReads, c0.hostReads);
  EXPECT_EQ(out.read<float>(), (std::vector<float>{0, 3, 10, 6, 12, 25}));
  const CallCounts c2 = callCounts();
  EXPECT_EQ(c2.hostReads - c1.hostReads, 1u);
  EXPECT_EQ(c2.hostReadBytes - c1.hostReadBytes, 6 * sizeof(float));
  EXPECT_EQ(c2.queries, c1.queries);
}

TEST_F(GlTest, BrokenShaderErrorNamesTheRealFileAndLine) {
  // A shader folder with a typo on line 3 of an included file; loaded the way a developer
  // editing shaders would (STRATA_SHADER_DIR), and the message must say "common/bad.glsl:3".
  const auto dir = test::tempDir("shaders");
  std::filesystem::create_directories(dir / "common");
  std::ofstream(dir / "common/bad.glsl") << "// helper\nfloat good() { return 1.0; }\nfloat bad() { return 1.0 }\n";
  std::ofstream(dir / "main.comp") << "#version 450\nlayout(local_size_x = 1) in;\n#include \"common/bad.glsl\"\n"
                                      "void main() {}\n";
  std::ofstream(dir / "main2.comp")
      << "#version 450\nlayout(local_size_x = 1) in;\n\n\nvoid main() { undeclared = 1; }\n";
  setenv("STRATA_SHADER_DIR", dir.c_str(), 1);
  auto bad = Program::compute("main.comp");
  auto bad2 = Program::compute("main2.comp");
  unsetenv("STRATA_SHADER_DIR");
  ASSERT_FALSE(bad);
  EXPECT_NE(bad.message().find("common/bad.glsl:3"), std::string::npos) << bad.message();
  EXPECT_NE(bad.message().find("'main.comp' does not compile"), std::string::npos) << bad.message();
  ASSERT_FALSE(bad2);
  EXPECT_NE(bad2.message().find("main2.comp:5"), std::string::npos) << bad2.message();
}

}  // namespace
}  // namespace strata::gl
