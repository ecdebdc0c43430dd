#pragma once
// The binding slots of viewer/shaders, declared once: the brush program is compiled
// with this table as #defines (GLSL writes `layout(binding = SLOT_BRUSH_SRC)`) and bound through
// it; a GPU test checks every program against it (docs/architecture.md, "The GL layer").

#include <strata/gl/bindings.hpp>

namespace strata::viewer::slots {

using gl::ResourceKind;

/// brush.comp: copy of the cells around the dab (read).
inline constexpr gl::Binding kBrushSrc{"SLOT_BRUSH_SRC", ResourceKind::kImage, 0, "uSrc"};
/// brush.comp: the scene's elevations (written).
inline constexpr gl::Binding kBrushDst{"SLOT_BRUSH_DST", ResourceKind::kImage, 1, "uDst"};
/// brush.comp: the stamp image (sampled).
inline constexpr gl::Binding kBrushStamp{"SLOT_BRUSH_STAMP", ResourceKind::kSampler, 2, "uStamp"};
/// brush.comp: the scene's layer thicknesses (read and written).
inline constexpr gl::Binding kBrushLayers{"SLOT_BRUSH_LAYERS", ResourceKind::kImage, 3, "uLayers"};

inline constexpr gl::Binding kAll[] = {kBrushSrc, kBrushDst, kBrushStamp, kBrushLayers};

}  // namespace strata::viewer::slots
