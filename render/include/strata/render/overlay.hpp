#pragma once
// The heads-up display: lines of text in a translucent box, drawn with stb_easy_font (a vector
// font built from quads: no font file, no texture) into the bound framebuffer.

#include <string>
#include <vector>

#include <strata/core/result.hpp>
#include <strata/gl/objects.hpp>

namespace strata::viewer {

class HudRenderer {
 public:
  static Result<HudRenderer> create();
  /// Draws `lines` at window pixel (x, y) (top-left, y down) into the bound framebuffer of
  /// `viewportW` x `viewportH` pixels, each glyph pixel `scale` pixels wide.
  void draw(const std::vector<std::string>& lines, int x, int y, int viewportW, int viewportH, int scale = 1);
  /// The size (pixels) `lines` take at `scale`.
  static void measure(const std::vector<std::string>& lines, int scale, int& width, int& height);

 private:
  gl::Program program_;
  gl::VertexArray vao_;
};

}  // namespace strata::viewer
