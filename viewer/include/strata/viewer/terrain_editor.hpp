#pragma once
// Height brushes applied on the GPU to the elevations a TerrainScene draws, with undo/redo that
// restore the exact earlier values. The CPU copy of the scene's heights is the mirror: a stroke
// remembers the pre-edit values of the cells it touched (their bounding box only), and undo and
// redo upload those patches. Tools and their equations: docs/viewer.md, "Tools".

#include <optional>
#include <string>
#include <vector>

#include <glm/glm.hpp>

#include <strata/core/result.hpp>
#include <strata/gl/objects.hpp>
#include <strata/render/terrain_renderer.hpp>

namespace strata::viewer {

/// The editing and simulation tools. Raise .. paste edit the terrain (TerrainEditor); water,
/// spring and region act on the viewer's simulation region (Viewer).
enum class Tool {
  kRaise,
  kLower,
  kSmooth,
  kFlatten,
  kCopy,
  kPaste,
  kWater,
  kSpring,
  kRegion,
  kStamp,
  kRain,
  kAddMaterial,
  kRemoveMaterial
};
/// "raise", "lower", ... ; nullopt for an unknown name.
std::optional<Tool> toolFromName(const std::string& name);
const char* toolName(Tool tool);

/// How a stamp combines with the elevation h, with f = strength * t (t: the image's value).
enum class Blend { kAdd, kSubtract, kMultiply, kReplace };
/// "add", "subtract", "multiply", "replace"; nullopt otherwise.
std::optional<Blend> blendFromName(const std::string& name);

/// The active brush.
struct Brush {
  Tool tool = Tool::kRaise;
  double radiusM = 300;  ///< radius (m) on the ground
  double strength = 5;   ///< raise/lower: m at the centre per dab; smooth/flatten: blend fraction per dab
  int layer = 0;         ///< add/remove material: the layer (0 = bottom, < 4)
};

using gis::CellRect;  ///< a rectangle of grid cells

class TerrainEditor {
 public:
  /// Compiles the brush kernel. `scene` must outlive the editor.
  static Result<TerrainEditor> create(render::TerrainScene& scene);

  /// Grid position (cells, continuous) of a map position (lon/lat or easting/northing).
  glm::dvec2 cellOf(double lon, double lat) const;
  /// The brush's radius in cells along x and y at grid row `y`.
  glm::dvec2 radiusCells(double radiusM, double y) const;

  /// Starts a stroke: the dabs until endStroke() are one undo step.
  void beginStroke();
  /// Applies one dab of a height tool (raise, lower, smooth, flatten) or of copy/paste centred
  /// at `cell`. Cells outside the grid are ignored. Needs an open stroke.
  Status dab(const Brush& brush, glm::dvec2 cell);
  /// Sets the stamp image (t per pixel, top row first; drawn over the brush's square, bilinear)
  /// and its blend mode, for Tool::kStamp.
  void setStamp(const gis::Grid<float>& image, Blend blend);
  bool hasStamp() const { return bool(stamp_); }
  /// Material layers (up to 4, bottom first, thickness in m) the add/remove material tools edit:
  /// shown by the scene (setMaterialLayers) and mirrored here for undo. The elevations must
  /// already include them. Without a call, the first material dab starts from four empty layers.
  Status setLayers(const std::vector<gis::Grid<float>>& thicknessM);
  /// The current thicknesses, 4 per cell (empty before any layers exist).
  const std::vector<float>& layers() const { return layers_; }
  /// The simulation changed the terrain in `rect`: elevations (rect cells) and, if layers exist,
  /// thicknesses (4 per rect cell). Written to the scene and the mirror, outside the undo
  /// history (an undo of an earlier edit there restores that edit's values).
  void applyExternal(const CellRect& rect, const std::vector<float>& heights, const std::vector<float>& layers4);
  /// Closes the stroke and records it for undo (nothing if it changed nothing).
  void endStroke();
  bool inStroke() const { return inStroke_; }

  /// Restores the cells of the last stroke to their pre-stroke values; false if none.
  bool undo();
  /// Re-applies the last undone stroke; false if none.
  bool redo();
  size_t undoDepth() const { return undo_.size(); }
  size_t redoDepth() const { return redo_.size(); }
  /// Bytes the history holds (two floats per cell of each recorded stroke).
  size_t historyBytes() const;
  /// The union of every cell changed since the start or the last clearDirty() (for saving).
  const CellRect& dirty() const { return dirty_; }
  void clearDirty() { dirty_ = {}; }
  /// The cells the last dab wrote.
  const CellRect& lastDab() const { return lastDab_; }

 private:
  struct Edit {
    CellRect rect;
    std::vector<float> before, after;              ///< elevations
    std::vector<float> layersBefore, layersAfter;  ///< 4 per cell; empty when no layers exist
  };
  CellRect clip(CellRect r) const;
  void apply(const Edit& edit, bool forward);

  render::TerrainScene* scene_ = nullptr;
  gl::Program brush_;
  gl::Texture clipboard_, stamp_;
  Blend blend_ = Blend::kAdd;
  std::vector<float> strokeBefore_, strokeLayersBefore_, layers_;
  CellRect strokeRect_, dirty_, lastDab_;
  bool inStroke_ = false;
  std::optional<float> flattenTarget_;
  std::vector<Edit> undo_, redo_;
};

}  // namespace strata::viewer
