#include <gtest/gtest.h>

#include <epoxy/gl.h>

#include <strata/gl/objects.hpp>
#include <strata/gl/state.hpp>

#include "gl_fixture.hpp"

namespace strata::gl {
namespace {

using test::GlTest;

TEST_F(GlTest, ContextIsOpenGl45Core) {
  const auto& info = context().info();
  EXPECT_FALSE(info.renderer.empty());
  EXPECT_GE(epoxy_gl_version(), 45) << info.version;
  GLint mask = 0;
  glGetIntegerv(GL_CONTEXT_PROFILE_MASK, &mask);
  EXPECT_TRUE(mask & GL_CONTEXT_CORE_PROFILE_BIT);
  const auto limits = queryContextLimits();
  // What Strata's kernels rely on: 1024^2 tiles in arrays, 16x16 compute groups, big SSBOs.
  EXPECT_GE(limits.maxTextureSize, 8192);
  EXPECT_GE(limits.maxArrayTextureLayers, 256);
  EXPECT_GE(limits.maxComputeWorkGroupInvocations, 256);
  EXPECT_GE(limits.maxShaderStorageBlockSize, 128ll << 20);
  EXPECT_TRUE(limits.timerQuery);
}

TEST_F(GlTest, DrawsWithTheDefaultFramebufferBound) {
  // The surfaceless context has no framebuffer 0; the context's stand-in FBO makes draws valid.
  GLint bound = 0;
  glGetIntegerv(GL_DRAW_FRAMEBUFFER_BINDING, &bound);
  EXPECT_NE(bound, 0);
  EXPECT_EQ(glCheckFramebufferStatus(GL_DRAW_FRAMEBUFFER), GLenum(GL_FRAMEBUFFER_COMPLETE));
  auto vao = VertexArray::create();
  auto prog =
      Program::link({{ShaderStage::kVertex, "#version 450\nvoid main() { gl_Position = vec4(0, 0, 0, 1); }\n", {"v"}},
                     {ShaderStage::kFragment, "#version 450\nout vec4 c;\nvoid main() { c = vec4(1); }\n", {"f"}}},
                    "point");
  ASSERT_TRUE(prog) << prog.message();
  prog->use();
  vao.drawArrays(Primitive::kPoints, 0, 1);
  finish();
  EXPECT_EQ(glGetError(), GLenum(GL_NO_ERROR));
}

TEST_F(GlTest, RendersIntoAnOffscreenTarget) {
  constexpr int kW = 8, kH = 4;
  auto colour = Texture::create2D(TextureFormat::kRGBA8, kW, kH);
  auto fbo = Framebuffer::create();
  fbo.attachColour(0, colour);
  ASSERT_TRUE(fbo.check());
  fbo.bind();
  setViewport({0, 0, kW, kH});
  fbo.clearColour(0, {0, 0, 1, 1});
  // A triangle covering the left half of the target (x < 0 in NDC).
  auto vao = VertexArray::create();
  auto prog = Program::link(
      {{ShaderStage::kVertex,
        "#version 450\nconst vec2 p[3] = vec2[](vec2(-1,-1), vec2(0,-1), vec2(-1,3));\n"
        "void main() { gl_Position = vec4(p[gl_VertexID].x < 0.0 ? -1.0 : 0.0, p[gl_VertexID].y, 0, 1);"
        " if (gl_VertexID == 1) gl_Position.x = 0.0; }\n",
        {"v"}},
       {ShaderStage::kFragment, "#version 450\nout vec4 c;\nvoid main() { c = vec4(1, 0, 0, 1); }\n", {"f"}}},
      "half");
  ASSERT_TRUE(prog) << prog.message();
  prog->use();
  vao.drawArrays(Primitive::kTriangles, 0, 3);
  // Covers x in [-1, 0] for y in [-1, 1] after clipping the tall triangle: pixels with centre x < 0.
  context().bindDefaultFramebuffer();
  const auto px = colour.read<uint8_t>();
  int red = 0, blue = 0;
  for (int i = 0; i < kW * kH; ++i) {
    if (px[size_t(4 * i)] == 255 && px[size_t(4 * i + 2)] == 0) ++red;
    if (px[size_t(4 * i)] == 0 && px[size_t(4 * i + 2)] == 255) ++blue;
  }
  // The triangle (-1,-1),(0,-1),(-1,3) covers the lower-left half of the left half: its edge
  // x + y/4 ... is counted exactly by the rasteriser's centre rule; at least the pixel column 0
  // is red and the right half is all blue.
  EXPECT_EQ(blue + red, kW * kH);
  for (int y = 0; y < kH; ++y) {
    EXPECT_EQ(px[size_t(4 * (y * kW + 0))], 255) << "left column, row " << y;
    for (int x = kW / 2; x < kW; ++x) EXPECT_EQ(px[size_t(4 * (y * kW + x) + 2)], 255) << x << "," << y;
  }
}

TEST_F(GlTest, TimerQueryMeasuresWork) {
  Buffer buf(64 << 20);
  GpuTimer timer;
  timer.begin();
  buf.fill(0x3f800000u);
  timer.end();
  const double ms = timer.milliseconds();
  EXPECT_GE(ms, 0.0);
  EXPECT_LT(ms, 10000.0);
  EXPECT_TRUE(timer.ready());
  EXPECT_EQ(buf.read<float>(12345 * 4, 1)[0], 1.0f);
}

}  // namespace
}  // namespace strata::gl
