#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <cstring>

#include <strata/gl/state.hpp>
#include <strata/render/overlay.hpp>
#include <strata/render/shader_slots.hpp>
#include <strata/render/terrain_renderer.hpp>

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

namespace strata::render {

namespace {
constexpr int kLineHeight = 12;  // stb_easy_font's glyphs are 7 pixels tall; 12 leaves a gap
constexpr int kPad = 4;

// Glyph quads of `lines` with their top-left at (x, y), each font pixel `scale` pixels.
std::vector<float> textQuads(const std::vector<std::string>& lines, float x, float y, int scale) {
  std::vector<float> text;
  std::vector<char> scratch(size_t(64000));  // stb writes 4 vertices of 16 bytes (x, y, z, rgba8) per quad
  for (size_t i = 0; i < lines.size(); ++i) {
    const int quads = stb_easy_font_print(0.0f, float(i * kLineHeight), const_cast<char*>(lines[i].c_str()), nullptr,
                                          scratch.data(), int(scratch.size()));
    for (int v = 0; v < quads * 4; ++v) {
      float xyz[3];
      std::memcpy(xyz, scratch.data() + size_t(v) * 16, sizeof xyz);
      text.push_back(x + float(scale) * xyz[0]);
      text.push_back(y + float(scale) * xyz[1]);
    }
  }
  return text;
}

void addRect(std::vector<float>& q, float x0, float y0, float x1, float y1) {
  q.insert(q.end(), {x0, y0, x1, y0, x1, y1, x0, y1});
}
}  // namespace

double roundScaleLength(double maxM) {
  if (!(maxM > 0) || !std::isfinite(maxM)) return 0;
  const double decade = std::pow(10.0, std::floor(std::log10(maxM)));
  for (double m : {5.0, 2.0, 1.0}) {
    if (m * decade <= maxM * (1 + 1e-12)) return m * decade;
  }
  return decade;
}

std::string formatDistance(double metres) {
  char buf[64];
  if (metres >= 1000) {
    std::snprintf(buf, sizeof buf, "%g km", metres / 1000);
  } else {
    std::snprintf(buf, sizeof buf, "%g m", metres);
  }
  return buf;
}

std::optional<ScaleBar> measureScaleBar(const TerrainScene& scene, const CameraPose& camera, const Shading& shading,
                                        const OffscreenTarget& target, double maxPixels) {
  const int w = target.width(), h = target.height();
  const FrameGeometry f = frameGeometry(scene, camera, shading, w, h);
  const int x0 = w / 2 - w / 10, x1 = w / 2 + w / 10;
  if (x1 <= x0) return std::nullopt;
  for (double fromBottom : {0.1, 0.25, 0.4, 0.5}) {
    const int y = std::clamp(int(h * (1 - fromBottom)), 0, h - 1);
    const auto a = groundEnuAt(f, target, x0, y), b = groundEnuAt(f, target, x1, y);
    if (!a || !b) continue;
    const double metresPerPixel = std::hypot(b->x - a->x, b->y - a->y) / double(x1 - x0);
    if (!(metresPerPixel > 0)) continue;
    ScaleBar bar;
    bar.lengthM = roundScaleLength(maxPixels * metresPerPixel);
    bar.pixels = bar.lengthM / metresPerPixel;
    bar.label = formatDistance(bar.lengthM);
    return bar;
  }
  return std::nullopt;
}

Result<Overlay> Overlay::create() {
  Overlay o;
  STRATA_TRY(o.program_, gl::Program::graphics("render/shaders/overlay.vert", "render/shaders/overlay.frag",
                                               gl::definesFor(slots::kAll)));
  o.vao_ = gl::VertexArray::create();
  return o;
}

void Overlay::measureText(const std::vector<std::string>& lines, int scale, int& width, int& height) {
  width = 0;
  for (const auto& l : lines) width = std::max(width, stb_easy_font_width(const_cast<char*>(l.c_str())));
  width = (width + 2 * kPad) * scale;
  height = (int(lines.size()) * kLineHeight + 2 * kPad) * scale;
}

void Overlay::drawText(const std::vector<std::string>& lines, int x, int y, int viewportW, int viewportH, int scale) {
  if (lines.empty()) return;
  int w = 0, h = 0;
  measureText(lines, scale, w, h);
  Batch box{{}, {0.0f, 0.0f, 0.0f, 0.55f}};
  addRect(box.corners, float(x), float(y), float(x + w), float(y + h));
  draw({box, {textQuads(lines, float(x + kPad * scale), float(y + kPad * scale), scale), {1.0f, 1.0f, 1.0f, 1.0f}}},
       viewportW, viewportH);
}

void Overlay::drawScaleBar(const ScaleBar& bar, int viewportW, int viewportH, int scale) {
  if (!(bar.pixels > 0)) return;
  const float s = float(scale), margin = 12 * s, pad = kPad * s;
  const float labelW = float(stb_easy_font_width(const_cast<char*>(bar.label.c_str()))) * s;
  const float barH = 4 * s, tickH = 10 * s, edge = s;
  // From the bottom up: the bar with its end ticks, then the label.
  const float x0 = margin + pad + edge, x1 = x0 + float(bar.pixels);
  const float barBottom = float(viewportH) - margin - pad - edge, barTop = barBottom - barH;
  const float tickTop = barBottom - tickH, labelTop = tickTop - 2 * s - 7 * s;
  Batch box{{}, {0.0f, 0.0f, 0.0f, 0.55f}}, black{{}, {0.0f, 0.0f, 0.0f, 1.0f}}, white{{}, {1.0f, 1.0f, 1.0f, 1.0f}};
  addRect(box.corners, margin, labelTop - pad, std::max(x1, x0 + labelW) + edge + pad, float(viewportH) - margin);
  for (auto [a, b, c, d] : {std::array<float, 4>{x0, barTop, x1, barBottom},
                            {x0, tickTop, x0 + 2 * s, barBottom},
                            {x1 - 2 * s, tickTop, x1, barBottom}}) {
    addRect(black.corners, a - edge, b - edge, c + edge, d + edge);
    addRect(white.corners, a, b, c, d);
  }
  draw({box, black, white, {textQuads({bar.label}, x0, labelTop, scale), {1.0f, 1.0f, 1.0f, 1.0f}}}, viewportW,
       viewportH);
}

std::optional<ScaleBar> Overlay::drawScaleBarOver(const OffscreenTarget& target, const TerrainScene& scene,
                                                  const CameraPose& camera, const Shading& shading) {
  const int w = target.width(), h = target.height();
  auto bar = measureScaleBar(scene, camera, shading, target, w / 5.0);
  if (!bar) return std::nullopt;
  target.bindColourOnly();
  drawScaleBar(*bar, w, h, h >= 700 ? 2 : 1);
  return bar;
}

void Overlay::draw(const std::vector<Batch>& batches, int viewportW, int viewportH) {
  const gl::Viewport previousViewport = gl::viewport();
  gl::setViewport({0, 0, viewportW, viewportH});
  gl::setDepthTest(gl::DepthTest::kOff);
  gl::setBlend(gl::Blend::kAlpha);
  program_.use();
  program_.set("uViewport", glm::vec2(float(viewportW), float(viewportH)));
  for (const auto& b : batches) {
    if (b.corners.empty()) continue;
    const auto buffer = gl::Buffer::from(std::span<const float>(b.corners));
    buffer.bind(slots::kOverlayCorners);
    program_.set("uColour", b.colour);
    vao_.drawArrays(gl::Primitive::kTriangles, 0, int(b.corners.size() / 8 * 6));
  }
  gl::setBlend(gl::Blend::kOff);
  gl::setViewport(previousViewport);
}

}  // namespace strata::render
