#pragma once
// Options both front ends (strata render, strata-view) share, registered and applied once: the
// map layers drawn on the terrain (a draped raster, a graticule, a scale bar) and the sun
// (direction, date and time, cast shadows). docs/render-rings.md.

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

struct LightArgs {
  std::string sun;    ///< "AZ,EL" (deg)
  std::string sunAt;  ///< "LON,LAT": the subsolar point (deg)
  std::string time;   ///< UTC, the Earth's subsolar point
  bool shadows = false;
  float ambient = 0.25f;
};

/// --sun, --sun-at, --time, --shadows, --ambient.
void addLightOptions(CLI::App& cmd, LightArgs& a);

/// Sets the sun on `shading` and casts shadows on `scene` (at shading.exaggeration, so set that
/// first); fails naming the option. Prints where the sun is.
Status applyLight(const LightArgs& a, render::TerrainScene& scene, render::Shading& shading);

}  // namespace strata::apps
