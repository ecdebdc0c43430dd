#pragma once
// The map layers both front ends (strata render, strata-view) draw on the terrain: a draped
// raster, a graticule and a scale bar, with one set of options (docs/render-rings.md).

#include <string>

#include <CLI/CLI.hpp>

#include <strata/core/result.hpp>
#include <strata/render/terrain_renderer.hpp>

namespace strata::apps {

struct MapLayerArgs {
  std::string drape, drapeRange;
  float drapeOpacity = 1;
  bool drapeHideBelow = false;
  double graticuleDeg = 0;
  bool scaleBar = false;
};

/// --drape, --drape-opacity, --drape-range, --drape-hide-below, --graticule, --scale-bar.
void addMapLayerOptions(CLI::App& cmd, MapLayerArgs& a);

/// Loads the drape and the graticule's lon/lat onto `scene` and sets `shading` for them (the
/// scale bar is drawn by the caller after each frame); fails naming the option and the file.
/// Prints what it loaded.
Status applyMapLayers(const MapLayerArgs& a, render::TerrainScene& scene, render::Shading& shading);

}  // namespace strata::apps
