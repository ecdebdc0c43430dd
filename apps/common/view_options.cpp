#include "view_options.hpp"

#include <array>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <numbers>
#include <optional>

#include <strata/core/angles.hpp>
#include <strata/render/colour_ramp.hpp>
#include <strata/render/drape.hpp>
#include <strata/render/sun.hpp>

namespace strata::apps {

namespace {
// "A,B" as two numbers, or a message naming the option and an example.
Result<std::array<double, 2>> parsePair(const std::string& text, const std::string& option, const char* example) {
  double a = 0, b = 0;
  char end = 0;
  if (std::sscanf(text.c_str(), "%lf,%lf%c", &a, &b, &end) != 2 || !std::isfinite(a) || !std::isfinite(b)) {
    return fail(option + " '" + text + "': expected two numbers, e.g. " + example);
  }
  return std::array<double, 2>{a, b};
}

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
      STRATA_TRY(auto range, parsePair(a.drapeRange, "--drape-range", "0.1,10"));
      if (!(range[0] < range[1])) {
        return fail("--drape-range '" + a.drapeRange + "': expected LOW,HIGH with LOW < HIGH, e.g. 0.1,10");
      }
      o.range = range;
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

void addLightOptions(CLI::App& cmd, LightArgs& a) {
  cmd.add_option("--sun", a.sun, "AZ,EL: the sun's azimuth (clockwise from north) and elevation (deg)");
  cmd.add_option(
      "--sun-at", a.sunAt,
      "LON,LAT: where the sun stands overhead (deg), fixing it on the body (any body: shows its night side)");
  cmd.add_option("--time", a.time, "UTC date and time (e.g. 2026-06-21T18:30:00Z): the sun's place then (the Earth)");
  cmd.add_flag("--shadows", a.shadows, "Cast shadows (each cell's horizon towards the sun)");
  cmd.add_option("--ambient", a.ambient, "Light where the sun does not reach, 0 to 1")->check(CLI::Range(0.0, 1.0));
}

Status applyLight(const LightArgs& a, render::TerrainScene& scene, render::Shading& shading) {
  if (int(!a.sun.empty()) + int(!a.sunAt.empty()) + int(!a.time.empty()) > 1) {
    return fail("--sun, --sun-at and --time each place the sun: give one");
  }
  shading.ambient = a.ambient;
  if (!a.sun.empty()) {
    STRATA_TRY(auto ae, parsePair(a.sun, "--sun", "135,30"));
    if (!(ae[1] >= -90 && ae[1] <= 90)) return fail("--sun '" + a.sun + "': the elevation is not within -90..90");
    shading.sunDir = glm::vec3(render::sunDirectionEnu(ae[0], ae[1]));
  } else if (!a.sunAt.empty()) {
    STRATA_TRY(auto ll, parsePair(a.sunAt, "--sun-at", "-75,23.4"));
    if (!(ll[1] >= -90 && ll[1] <= 90)) return fail("--sun-at '" + a.sunAt + "': the latitude is not within -90..90");
    shading.subsolarLonLat = glm::dvec2(ll[0], ll[1]);
  } else if (!a.time.empty()) {
    const auto& body = scene.georef().body;
    if (std::abs(body.semiMajorM - 6378137.0) > 10000.0) {
      return fail("--time: the sun's place by date is computed for the Earth only; on " + body.name +
                  " give --sun-at LON,LAT");
    }
    STRATA_TRY(auto t, render::parseUtc(a.time));
    shading.subsolarLonLat = render::earthSubsolarPoint(t);
  }
  if (shading.subsolarLonLat) {
    const glm::dvec2 c = scene.centreLonLat();
    const glm::dvec3 d = render::sunDirectionEnu(*shading.subsolarLonLat, c.x, c.y);
    std::printf("sun: overhead at %.3f, %.3f; at the terrain's centre azimuth %.1f, elevation %.1f deg\n",
                shading.subsolarLonLat->x, shading.subsolarLonLat->y, std::fmod(std::atan2(d.x, d.y) / kDeg + 360, 360),
                std::asin(std::clamp(d.z, -1.0, 1.0)) / kDeg);
  }
  if (a.shadows) {
    render::SunSpec sun;
    sun.subsolarLonLat = shading.subsolarLonLat;
    sun.dirEnu = glm::normalize(glm::dvec3(shading.sunDir));
    if (auto st = scene.castShadows(sun, shading.exaggeration); !st) return fail("--shadows: " + st.message());
  }
  return {};
}

Status applyPalette(const std::string& palette, const render::TerrainScene& scene, render::Shading& shading) {
  using render::Palette;
  if (palette.empty()) {
    shading.palette = render::paletteFor(scene.georef().body);
  } else if (palette == "hypsometric") {
    shading.palette = Palette::Hypsometric;
  } else if (palette == "grey") {
    shading.palette = Palette::Grey;
  } else if (palette == "rust") {
    shading.palette = Palette::Rust;
  } else if (std::filesystem::is_regular_file(palette)) {
    STRATA_TRY(shading.ramp, render::loadColourRamp(palette, scene.minElevationM(), scene.maxElevationM()));
    shading.palette = Palette::Ramp;
    std::printf("palette: %s, %zu stops from %g to %g m\n", palette.c_str(), shading.ramp.elevationsM.size(),
                double(shading.ramp.elevationsM.front()), double(shading.ramp.elevationsM.back()));
  } else {
    return fail("--palette '" + palette +
                "': expected hypsometric, grey, rust or a gdaldem color-relief file (there is no such file)");
  }
  return {};
}

}  // namespace

void addViewOptions(CLI::App& cmd, ViewArgs& a) {
  cmd.add_option("--sky", a.sky,
                 "air (a sky and aerial perspective from the body's atmosphere; the default on the Earth and Mars) or "
                 "flat (one colour, with --fog's haze)")
      ->check(CLI::IsMember({"air", "flat"}));
  cmd.add_option("--msaa", a.msaa, "Samples a pixel: 1 (none), 2, 4 or 8 (antialiased edges)")
      ->check(CLI::IsMember({1, 2, 4, 8}));
  cmd.add_option("--palette", a.palette,
                 "Elevation colours: hypsometric, grey, rust or a gdaldem color-relief file (default: the body's: grey "
                 "on the Moon, rust on Mars)");
  addMapLayerOptions(cmd, a.layers);
  addLightOptions(cmd, a.light);
}

Status applyView(const ViewArgs& a, render::TerrainScene& scene, render::Shading& shading) {
  STRATA_TRY_STATUS(applyPalette(a.palette, scene, shading));
  const auto& body = scene.georef().body;
  shading.atmosphere = a.sky == "flat" ? std::nullopt : render::atmosphereFor(body);
  if (a.sky == "air" && !shading.atmosphere)
    return fail("--sky air: " + body.name + " has no atmosphere known to Strata");
  STRATA_TRY_STATUS(applyMapLayers(a.layers, scene, shading));
  return applyLight(a.light, scene, shading);
}

}  // namespace strata::apps
