#include <algorithm>
#include <cstring>

#include <strata/gl/state.hpp>
#include <strata/viewer/hud.hpp>
#include <strata/viewer/shader_slots.hpp>

// stb_easy_font.h defines its functions static in the including translation unit.
#if defined(__GNUC__)
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wunused-function"
#pragma GCC diagnostic ignored "-Wsign-compare"
#pragma GCC diagnostic ignored "-Wmissing-field-initializers"
#endif
#include <stb/stb_easy_font.h>
#if defined(__GNUC__)
#pragma GCC diagnostic pop
#endif

namespace strata::viewer {

namespace {
constexpr int kLineHeight = 12;  // stb_easy_font's glyphs are 7 pixels tall; 12 leaves a gap
constexpr int kPad = 4;
}  // namespace

Result<HudRenderer> HudRenderer::create() {
  HudRenderer h;
  STRATA_TRY(h.program_,
             gl::Program::graphics("viewer/shaders/hud.vert", "viewer/shaders/hud.frag", gl::definesFor(slots::kAll)));
  h.vao_ = gl::VertexArray::create();
  return h;
}

void HudRenderer::measure(const std::vector<std::string>& lines, int scale, int& width, int& height) {
  width = 0;
  for (const auto& l : lines) width = std::max(width, stb_easy_font_width(const_cast<char*>(l.c_str())));
  width = (width + 2 * kPad) * scale;
  height = (int(lines.size()) * kLineHeight + 2 * kPad) * scale;
}

void HudRenderer::draw(const std::vector<std::string>& lines, int x, int y, int viewportW, int viewportH, int scale) {
  if (lines.empty()) return;
  // Glyph quads: stb writes 4 vertices of 16 bytes (x, y, z, rgba8) per quad.
  std::vector<float> text;
  std::vector<char> scratch(size_t(64000));
  for (size_t i = 0; i < lines.size(); ++i) {
    const int quads = stb_easy_font_print(0.0f, float(i * kLineHeight), const_cast<char*>(lines[i].c_str()), nullptr,
                                          scratch.data(), int(scratch.size()));
    for (int v = 0; v < quads * 4; ++v) {
      float xyz[3];
      std::memcpy(xyz, scratch.data() + size_t(v) * 16, sizeof xyz);
      text.push_back(float(x) + float(scale) * (xyz[0] + kPad));
      text.push_back(float(y) + float(scale) * (xyz[1] + kPad));
    }
  }
  int w = 0, h = 0;
  measure(lines, scale, w, h);
  const float x0 = float(x), y0 = float(y), x1 = float(x + w), y1 = float(y + h);
  const std::vector<float> box{x0, y0, x1, y0, x1, y1, x0, y1};

  const gl::Viewport previousViewport = gl::viewport();
  gl::setViewport({0, 0, viewportW, viewportH});
  gl::setDepthTest(gl::DepthTest::kOff);
  gl::setBlend(gl::Blend::kAlpha);
  program_.use();
  program_.set("uViewport", glm::vec2(float(viewportW), float(viewportH)));
  auto drawQuads = [&](const std::vector<float>& corners, glm::vec4 colour) {
    if (corners.empty()) return;
    const auto buffer = gl::Buffer::from(std::span<const float>(corners));
    buffer.bind(slots::kHudCorners);
    program_.set("uColour", colour);
    vao_.drawArrays(gl::Primitive::kTriangles, 0, int(corners.size() / 8 * 6));
  };
  drawQuads(box, {0.0f, 0.0f, 0.0f, 0.55f});
  drawQuads(text, {1.0f, 1.0f, 1.0f, 1.0f});
  gl::setBlend(gl::Blend::kOff);
  gl::setViewport(previousViewport);
}

}  // namespace strata::viewer
