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

struct LightArgs {
  std::string sun;    ///< "AZ,EL" (deg)
  std::string sunAt;  ///< "LON,LAT": the subsolar point (deg)
  std::string time;   ///< UTC, the Earth's subsolar point
  bool shadows = false;
  float ambient = 0.25f;
};

struct ViewArgs {
  std::string palette;  ///< hypsometric, grey, rust or a gdaldem color-relief file; empty: the body's
  std::string sky;      ///< air or flat; empty: air where the body has an atmosphere
  int msaa = 1;         ///< samples a pixel (the caller creates its target with them)
  MapLayerArgs layers;
  LightArgs light;
};

/// --palette, --sky, --msaa; --drape, --drape-opacity, --drape-range, --drape-hide-below, --graticule,
/// --scale-bar; --sun, --sun-at, --time, --shadows, --ambient.
void addViewOptions(CLI::App& cmd, ViewArgs& a);

/// Sets the palette (by default the body's: grey for the Moon, rust for Mars, hypsometric
/// otherwise) and the sky (by default the body's air, if it has one), loads the drape and the graticule's lon/lat onto
/// `scene`, places the sun and casts shadows (at shading.exaggeration, so set that first). The scale bar is drawn by
/// the caller after each frame. Fails naming the option and the file; prints what it loaded.
Status applyView(const ViewArgs& a, render::TerrainScene& scene, render::Shading& shading);

}  // namespace strata::apps
