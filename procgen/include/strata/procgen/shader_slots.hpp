#pragma once
// The binding slots of procgen/shaders, declared once: the wavelet and generator programs are
// compiled with this table as #defines (GLSL writes `layout(binding = SLOT_DWT_SRC)`) and bound
// through it; a GPU test checks every program against it (docs/architecture.md, "The GL layer").

#include <strata/gl/bindings.hpp>

namespace strata::procgen::slots {

using gl::ResourceKind;

/// dwt53.comp, dwt97.comp: the pass's input.
inline constexpr gl::Binding kDwtSrc{"SLOT_DWT_SRC", ResourceKind::kImage, 0, "src"};
/// dwt53.comp, dwt97.comp: the pass's output.
inline constexpr gl::Binding kDwtDst{"SLOT_DWT_DST", ResourceKind::kImage, 1, "dst"};
/// generate.comp: the field a script fills.
inline constexpr gl::Binding kField{"SLOT_FIELD", ResourceKind::kImage, 1, "uOut"};
/// builtins.glsl: the transforms of input DEMs 0 and 1.
inline constexpr gl::Binding kDem0{"SLOT_DEM0", ResourceKind::kImage, 2, "uDem0"};
inline constexpr gl::Binding kDem1{"SLOT_DEM1", ResourceKind::kImage, 3, "uDem1"};

inline constexpr gl::Binding kAll[] = {kDwtSrc, kDwtDst, kField, kDem0, kDem1};

}  // namespace strata::procgen::slots
