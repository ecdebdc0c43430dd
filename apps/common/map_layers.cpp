#include "map_layers.hpp"

#include <array>
#include <cstdio>

#include <strata/render/drape.hpp>

namespace strata::apps {

void addMapLayerOptions(CLI::App& cmd, MapLayerArgs& a) {
  cmd.add_option("--drape", a.drape,
                 "A georeferenced raster drawn on the terrain (orthophoto: 3-4 Byte bands; hillshade: 1 Byte band; any "
                 "other single band through a colour ramp), reprojected by GDAL");
  cmd.add_option("--drape-opacity", a.drapeOpacity, "How much the drape hides the elevation tint")
      ->check(CLI::Range(0.0, 1.0));
  cmd.add_option("--drape-range", a.drapeRange,
                 "LOW,HIGH: a single-band drape's values at the ramp's ends (default: its 2nd-98th percentile)");
  cmd.add_flag("--drape-hide-below", a.drapeHideBelow,
               "Do not draw a single-band drape's values below its range (e.g. dry cells of a depth map)");
  cmd.add_option("--graticule", a.graticuleDeg, "Lines of longitude and latitude this many degrees apart (e.g. 0.5)")
      ->check(CLI::Range(0.0, 90.0));
  cmd.add_flag("--scale-bar", a.scaleBar,
               "Draw a scale bar (the ground's scale a tenth of the height above the image's bottom)");
}

Status applyMapLayers(const MapLayerArgs& a, render::TerrainScene& scene, render::Shading& shading) {
  if (!a.drape.empty()) {
    render::DrapeOptions o;
    o.transparentBelow = a.drapeHideBelow;
    if (!a.drapeRange.empty()) {
      double lo = 0, hi = 0;
      char end = 0;
      if (std::sscanf(a.drapeRange.c_str(), "%lf,%lf%c", &lo, &hi, &end) != 2 || !(lo < hi)) {
        return fail("--drape-range '" + a.drapeRange + "': expected LOW,HIGH with LOW < HIGH, e.g. 0.1,10");
      }
      o.range = std::array<double, 2>{lo, hi};
    }
    auto image = render::loadDrape(a.drape, scene.georef(), o);
    if (!image) return fail("--drape " + image.message());
    if (auto st = scene.setDrape(*image); !st) return fail("--drape " + a.drape + ": " + st.message());
    shading.drapeOpacity = a.drapeOpacity;
    std::printf("drape: %s, %dx%d texels\n", image->description.c_str(), image->width, image->height);
  }
  if (a.graticuleDeg > 0) {
    if (auto st = scene.enableGraticule(); !st) return fail("--graticule: " + st.message());
    shading.graticuleDeg = a.graticuleDeg;
  }
  return {};
}

}  // namespace strata::apps
