#include <algorithm>
#include <cmath>
#include <cstring>
#include <numbers>

#include <strata/core/angles.hpp>
#include <strata/gl/state.hpp>
#include <strata/viewer/shader_slots.hpp>
#include <strata/viewer/terrain_editor.hpp>

namespace strata::viewer {

namespace {
constexpr const char* kToolNames[] = {"raise",  "lower",  "smooth", "flatten", "copy",      "paste",    "water",
                                      "spring", "region", "stamp",  "rain",    "material+", "material-"};
constexpr const char* kBlendNames[] = {"add", "subtract", "multiply", "replace"};
}  // namespace

std::optional<Tool> toolFromName(const std::string& name) {
  for (int i = 0; i < int(std::size(kToolNames)); ++i) {
    if (name == kToolNames[i]) return Tool(i);
  }
  return std::nullopt;
}

const char* toolName(Tool tool) { return kToolNames[int(tool)]; }

std::optional<Blend> blendFromName(const std::string& name) {
  for (int i = 0; i < int(std::size(kBlendNames)); ++i) {
    if (name == kBlendNames[i]) return Blend(i);
  }
  return std::nullopt;
}

void TerrainEditor::setStamp(const gis::Grid<float>& image, Blend blend) {
  STRATA_CHECK(image.width > 0 && image.height > 0) << "setStamp: empty image";
  stamp_ = gl::Texture::create2D(gl::TextureFormat::kR32F, image.width, image.height, 1);
  stamp_.upload(image.data.data());
  stamp_.setFilter(gl::Filter::kLinear);
  stamp_.setWrap(gl::Wrap::kClampToEdge);
  blend_ = blend;
}

Result<TerrainEditor> TerrainEditor::create(render::TerrainScene& scene) {
  TerrainEditor e;
  e.scene_ = &scene;
  STRATA_TRY(e.brush_, gl::Program::compute("viewer/shaders/brush.comp", gl::definesFor(slots::kAll)));
  return e;
}

glm::dvec2 TerrainEditor::cellOf(double lon, double lat) const {
  const auto& c = scene_->georef().transform.c;
  return {(lon - c[0]) / c[1], (lat - c[3]) / c[5]};
}

glm::dvec2 TerrainEditor::radiusCells(double radiusM, double y) const {
  const auto& g = scene_->georef();
  const auto& c = g.transform.c;
  if (!g.geographic) {
    const glm::dvec2 k = scene_->metresPerCrsUnit();
    return {radiusM / (c[1] * k.x), radiusM / (-c[5] * k.y)};
  }
  const double lat = c[3] + c[5] * y, r = scene_->radiusM();
  const double dx = r * std::max(std::cos(lat * kDeg), 1e-3) * c[1] * kDeg, dy = r * -c[5] * kDeg;
  return {radiusM / dx, radiusM / dy};
}

CellRect TerrainEditor::clip(CellRect r) const {
  const int x0 = std::max(r.x, 0), y0 = std::max(r.y, 0);
  const int x1 = std::min(r.x + r.width, scene_->width()), y1 = std::min(r.y + r.height, scene_->height());
  return {x0, y0, std::max(x1 - x0, 0), std::max(y1 - y0, 0)};
}

Status TerrainEditor::setLayers(const std::vector<gis::Grid<float>>& thicknessM) {
  STRATA_CHECK(!inStroke_) << "setLayers during a stroke";
  STRATA_TRY_STATUS(scene_->setMaterialLayers(thicknessM));
  layers_.assign(size_t(scene_->width()) * size_t(scene_->height()) * 4, 0.0f);
  for (size_t k = 0; k < thicknessM.size(); ++k) {
    for (size_t i = 0; i < thicknessM[k].data.size(); ++i) layers_[i * 4 + k] = thicknessM[k].data[i];
  }
  // History entries without layers cannot be mixed with ones that have them.
  undo_.clear();
  redo_.clear();
  return {};
}

void TerrainEditor::beginStroke() {
  STRATA_CHECK(!inStroke_) << "beginStroke: a stroke is already open";
  inStroke_ = true;
  strokeBefore_ = scene_->heights().data;
  strokeLayersBefore_ = layers_;
  strokeRect_ = {};
  flattenTarget_.reset();
}

Status TerrainEditor::dab(const Brush& brush, glm::dvec2 cell) {
  STRATA_CHECK(inStroke_) << "dab outside a stroke";
  const glm::dvec2 rc = radiusCells(brush.radiusM, cell.y);
  const CellRect box = clip({int(std::floor(cell.x - rc.x)), int(std::floor(cell.y - rc.y)),
                             int(std::ceil(2 * rc.x)) + 1, int(std::ceil(2 * rc.y)) + 1});
  lastDab_ = {};
  if (box.empty()) return {};
  const gl::Texture& heights = scene_->heightTexture();
  switch (brush.tool) {
    case Tool::kCopy:
      clipboard_ = gl::Texture::create2D(gl::TextureFormat::kR32F, box.width, box.height, 1);
      gl::copyTexels(heights, {.x = box.x, .y = box.y}, clipboard_, {}, box.width, box.height);
      return {};
    case Tool::kPaste: {
      if (!clipboard_) return fail("paste: nothing copied yet (use the copy tool first)");
      const CellRect want{int(std::floor(cell.x)) - clipboard_.width() / 2,
                          int(std::floor(cell.y)) - clipboard_.height() / 2, clipboard_.width(), clipboard_.height()};
      const CellRect dst = clip(want);
      if (dst.empty()) return {};
      gl::copyTexels(clipboard_, {.x = dst.x - want.x, .y = dst.y - want.y}, heights, {.x = dst.x, .y = dst.y},
                     dst.width, dst.height);
      lastDab_ = dst;
      break;
    }
    case Tool::kWater:
    case Tool::kSpring:
    case Tool::kRegion:
    case Tool::kRain:
      return fail(std::string(toolName(brush.tool)) + ": not a terrain brush (it acts on the simulation region)");
    default: {
      // The kernel reads a copy of the box plus a one-cell margin (smooth's neighbours).
      const CellRect src = clip({box.x - 1, box.y - 1, box.width + 2, box.height + 2});
      auto scratch = gl::Texture::create2D(gl::TextureFormat::kR32F, src.width, src.height, 1);
      gl::copyTexels(heights, {.x = src.x, .y = src.y}, scratch, {}, src.width, src.height);
      if (brush.tool == Tool::kFlatten && !flattenTarget_) {
        const int cx = std::clamp(int(std::floor(cell.x)), 0, scene_->width() - 1);
        const int cy = std::clamp(int(std::floor(cell.y)), 0, scene_->height() - 1);
        flattenTarget_ = scene_->heights().at(cx, cy);
      }
      if (brush.tool == Tool::kStamp && !stamp_) return fail("stamp: no stamp image set");
      const bool material = brush.tool == Tool::kAddMaterial || brush.tool == Tool::kRemoveMaterial;
      if (material) {
        if (brush.layer < 0 || brush.layer > 3)
          return fail("material: layer " + std::to_string(brush.layer) + " is not 0..3");
        if (layers_.empty()) {  // four empty layers; the open stroke started from them
          const auto& h = scene_->heights();
          STRATA_TRY_STATUS(
              scene_->setMaterialLayers(std::vector<gis::Grid<float>>(4, gis::Grid<float>(h.width, h.height, 0.0f))));
          layers_.assign(h.data.size() * 4, 0.0f);
          strokeLayersBefore_ = layers_;
        }
        scene_->layerTexture()->bindImage(slots::kBrushLayers, gl::Access::kReadWrite);
      }
      int mode = 0;
      if (brush.tool == Tool::kAddMaterial) mode = 8;
      if (brush.tool == Tool::kRemoveMaterial) mode = 9;
      if (brush.tool == Tool::kStamp) mode = 4 + int(blend_);
      if (brush.tool == Tool::kLower) mode = 1;
      if (brush.tool == Tool::kSmooth) mode = 2;
      if (brush.tool == Tool::kFlatten) mode = 3;
      brush_.use();
      brush_.set("uOrigin", glm::ivec2(box.x, box.y));
      brush_.set("uSize", glm::ivec2(box.width, box.height));
      brush_.set("uSrcOrigin", glm::ivec2(src.x, src.y));
      brush_.set("uCentre", glm::vec2(cell));
      brush_.set("uRadius", glm::vec2(rc));
      brush_.set("uMode", mode);
      brush_.set("uStrength", float(brush.strength));
      brush_.set("uTarget", flattenTarget_.value_or(0.0f));
      brush_.set("uLayer", brush.layer);
      if (stamp_) stamp_.bind(slots::kBrushStamp);
      scratch.bindImage(slots::kBrushSrc, gl::Access::kRead);
      heights.bindImage(slots::kBrushDst, gl::Access::kWrite);
      brush_.dispatchCovering(box.width, box.height);
      gl::memoryBarrier(gl::Barrier::kTextureUpdate | gl::Barrier::kTextureFetch | gl::Barrier::kImageAccess);
      lastDab_ = box;
      if (material) {
        const auto window = scene_->layersEditedOnGpu(box.x, box.y, box.width, box.height);
        for (int y = 0; y < box.height; ++y) {
          std::copy_n(&window[size_t(y) * size_t(box.width) * 4], size_t(box.width) * 4,
                      &layers_[(size_t(box.y + y) * size_t(scene_->width()) + size_t(box.x)) * 4]);
        }
      }
    }
  }
  scene_->heightsEditedOnGpu(lastDab_.x, lastDab_.y, lastDab_.width, lastDab_.height);
  strokeRect_ = strokeRect_.united(lastDab_);
  dirty_ = dirty_.united(lastDab_);
  return {};
}

void TerrainEditor::endStroke() {
  STRATA_CHECK(inStroke_) << "endStroke without beginStroke";
  inStroke_ = false;
  if (strokeRect_.empty()) return;
  Edit e;
  e.rect = strokeRect_;
  const auto& now = scene_->heights();
  const size_t cells = size_t(e.rect.width) * size_t(e.rect.height);
  e.before.reserve(cells);
  e.after.reserve(cells);
  bool changed = false;
  const bool withLayers = !layers_.empty() && strokeLayersBefore_.size() == layers_.size();
  for (int y = e.rect.y; y < e.rect.y + e.rect.height; ++y) {
    for (int x = e.rect.x; x < e.rect.x + e.rect.width; ++x) {
      const size_t i = size_t(y) * size_t(now.width) + size_t(x);
      e.before.push_back(strokeBefore_[i]);
      e.after.push_back(now.data[i]);
      changed |= std::memcmp(&e.before.back(), &e.after.back(), sizeof(float)) != 0;
      if (withLayers) {
        e.layersBefore.insert(e.layersBefore.end(), &strokeLayersBefore_[i * 4], &strokeLayersBefore_[i * 4] + 4);
        e.layersAfter.insert(e.layersAfter.end(), &layers_[i * 4], &layers_[i * 4] + 4);
        changed |= std::memcmp(&strokeLayersBefore_[i * 4], &layers_[i * 4], 4 * sizeof(float)) != 0;
      }
    }
  }
  strokeBefore_.clear();
  strokeBefore_.shrink_to_fit();
  strokeLayersBefore_.clear();
  strokeLayersBefore_.shrink_to_fit();
  if (!changed) return;
  undo_.push_back(std::move(e));
  redo_.clear();
}

void TerrainEditor::apply(const Edit& edit, bool forward) {
  gis::Grid<float> patch(edit.rect.width, edit.rect.height);
  patch.data = forward ? edit.after : edit.before;
  scene_->writeHeights(edit.rect.x, edit.rect.y, patch);
  if (!edit.layersBefore.empty() && !layers_.empty()) {
    const auto& l = forward ? edit.layersAfter : edit.layersBefore;
    scene_->writeLayers(edit.rect.x, edit.rect.y, edit.rect.width, edit.rect.height, l);
    for (int y = 0; y < edit.rect.height; ++y) {
      std::copy_n(&l[size_t(y) * size_t(edit.rect.width) * 4], size_t(edit.rect.width) * 4,
                  &layers_[(size_t(edit.rect.y + y) * size_t(scene_->width()) + size_t(edit.rect.x)) * 4]);
    }
  }
  dirty_ = dirty_.united(edit.rect);
}

void TerrainEditor::applyExternal(const CellRect& rect, const std::vector<float>& heights,
                                  const std::vector<float>& layers4) {
  STRATA_CHECK(!inStroke_) << "applyExternal during a stroke";
  STRATA_CHECK(heights.size() == size_t(rect.width) * size_t(rect.height)) << "applyExternal: wrong patch size";
  Edit e;
  e.rect = rect;
  e.after = heights;
  if (!layers_.empty()) {
    STRATA_CHECK(layers4.size() == heights.size() * 4) << "applyExternal: wrong layer patch size";
    e.layersBefore = layers4;  // apply() only checks that layers are present
    e.layersAfter = layers4;
  }
  apply(e, true);
}

bool TerrainEditor::undo() {
  if (inStroke_ || undo_.empty()) return false;
  apply(undo_.back(), false);
  redo_.push_back(std::move(undo_.back()));
  undo_.pop_back();
  return true;
}

bool TerrainEditor::redo() {
  if (inStroke_ || redo_.empty()) return false;
  apply(redo_.back(), true);
  undo_.push_back(std::move(redo_.back()));
  redo_.pop_back();
  return true;
}

size_t TerrainEditor::historyBytes() const {
  size_t n = 0;
  for (const auto* stack : {&undo_, &redo_}) {
    for (const auto& e : *stack) {
      n += (e.before.size() + e.after.size() + e.layersBefore.size() + e.layersAfter.size()) * sizeof(float);
    }
  }
  return n;
}

}  // namespace strata::viewer
