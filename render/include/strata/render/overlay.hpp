#pragma once
// What is drawn over a rendered view in window pixels: lines of text in a translucent box (the
// viewer's HUD and help) and a scale bar. Text is stb_easy_font's vector font (quads: no font
// file, no texture). docs/render-rings.md, "Scale bar".

#include <optional>
#include <string>
#include <vector>

#include <glm/vec4.hpp>

#include <strata/core/result.hpp>
#include <strata/gl/objects.hpp>

namespace strata::render {

class TerrainScene;
class OffscreenTarget;
struct CameraPose;
struct Shading;

/// A scale bar: `lengthM` of ground is `pixels` long on screen, labelled e.g. "2 km".
struct ScaleBar {
  double lengthM = 0;
  double pixels = 0;
  std::string label;
};

/// The largest of 1, 2 and 5 times a power of ten that is at most `maxM` (m); 0 if maxM <= 0.
double roundScaleLength(double maxM);
/// "500 m", "2 km", "0.5 m", "20000 km".
std::string formatDistance(double metres);

/// The scale of the drawn view: the horizontal ground distance (in the viewer's east-north-up
/// frame) between the ground points drawn at two pixels a fifth of the width apart, centred on
/// the row a tenth of the height above the bottom (or, where that is sky, on rows nearer the
/// centre); rounded to a length at most `maxPixels` long. Nullopt where no such row hits ground.
/// `target` holds the frame just drawn with the same scene, camera and shading.
std::optional<ScaleBar> measureScaleBar(const TerrainScene& scene, const CameraPose& camera, const Shading& shading,
                                        const OffscreenTarget& target, double maxPixels);

class Overlay {
 public:
  static Result<Overlay> create();
  /// Draws `lines` at window pixel (x, y) (top-left, y down) into the bound framebuffer of
  /// `viewportW` x `viewportH` pixels, each glyph pixel `scale` pixels wide.
  void drawText(const std::vector<std::string>& lines, int x, int y, int viewportW, int viewportH, int scale = 1);
  /// The size (pixels) `lines` take at `scale`.
  static void measureText(const std::vector<std::string>& lines, int scale, int& width, int& height);
  /// Draws `bar` in the bottom-left corner of the bound framebuffer: a white bar with black
  /// edges and end ticks, its label above, on a translucent box.
  void drawScaleBar(const ScaleBar& bar, int viewportW, int viewportH, int scale = 1);
  /// Measures the scale of the frame `target` holds (measureScaleBar, at most a fifth of its
  /// width) and draws the bar over its colour alone (glyphs doubled from 700 rows up); nullopt,
  /// and nothing drawn, where no ground is in view.
  std::optional<ScaleBar> drawScaleBarOver(const OffscreenTarget& target, const TerrainScene& scene,
                                           const CameraPose& camera, const Shading& shading);

 private:
  /// Quads (four window-pixel corners each, x y pairs) in one flat colour.
  struct Batch {
    std::vector<float> corners;
    glm::vec4 colour;
  };
  void draw(const std::vector<Batch>& batches, int viewportW, int viewportH);
  gl::Program program_;
  gl::VertexArray vao_;
};

}  // namespace strata::render
