#pragma once
// The binding slots of render/shaders, declared once: the renderers compile their programs with
// this table as #defines (GLSL writes `layout(binding = SLOT_HEIGHT)`) and bind through it; a GPU
// test checks every program's samplers against it (docs/architecture.md, "The GL layer").

#include <strata/gl/bindings.hpp>

namespace strata::render::slots {

using gl::ResourceKind;

/// Elevation (r32f, full mip chain); streamed: the coarse level of the stack.
inline constexpr gl::Binding kHeight{"SLOT_HEIGHT", ResourceKind::kSampler, 0, "uHeight"};
/// Water depth (m), optional.
inline constexpr gl::Binding kWater{"SLOT_WATER", ResourceKind::kSampler, 1, "uWater"};
/// Thickness of up to four material layers (m), optional.
inline constexpr gl::Binding kLayers{"SLOT_LAYERS", ResourceKind::kSampler, 2, "uLayers"};
/// Streamed: the toroidal clip stack, one layer per level.
inline constexpr gl::Binding kClip{"SLOT_CLIP", ResourceKind::kSampler, 3, "uClip"};
/// Streamed: 1 where a page slot of the stack holds its window's page.
inline constexpr gl::Binding kClipPages{"SLOT_CLIP_PAGES", ResourceKind::kSampler, 4, "uClipPages"};
/// Suspended sediment (m of material), optional.
inline constexpr gl::Binding kSediment{"SLOT_SEDIMENT", ResourceKind::kSampler, 5, "uSediment"};
/// A simulation's state (h, s, hu, hv), optional.
inline constexpr gl::Binding kWaterState{"SLOT_WATER_STATE", ResourceKind::kSampler, 6, "uWaterState"};

/// 1 where the DEM has data, 0 over voids drawn as holes, optional.
inline constexpr gl::Binding kVoidMask{"SLOT_VOID_MASK", ResourceKind::kSampler, 7, "uVoidMask"};

/// A raster draped over the terrain (RGBA8, full mip chain), optional.
inline constexpr gl::Binding kDrape{"SLOT_DRAPE", ResourceKind::kSampler, 8, "uDrape"};

/// Lon/lat (deg) of the cell centres (RG32F), for the graticule, optional.
inline constexpr gl::Binding kLonLat{"SLOT_LONLAT", ResourceKind::kSampler, 9, "uLonLat"};

/// The fraction of the sun each cell sees (r32f, cast shadows), optional.
inline constexpr gl::Binding kShadow{"SLOT_SHADOW", ResourceKind::kSampler, 10, "uShadow"};

/// overlay.vert: the quads' corners (window pixels).
inline constexpr gl::Binding kOverlayCorners{"SLOT_OVERLAY_CORNERS", ResourceKind::kStorageBuffer, 0, "Corners"};

inline constexpr gl::Binding kAll[] = {kHeight,     kWater,    kLayers, kClip,   kClipPages, kSediment,
                                       kWaterState, kVoidMask, kDrape,  kLonLat, kShadow,    kOverlayCorners};

}  // namespace strata::render::slots
