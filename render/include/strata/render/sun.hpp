#pragma once
// Where the sun is and what it lights: the subsolar point at a UTC time (the Earth), the
// direction to the sun in a place's east-north-up frame, and cast shadows by the horizon method
// (each cell's horizon towards the sun against the sun's elevation). docs/render-rings.md, "Sun
// and shadows".

#include <chrono>
#include <optional>
#include <string>

#include <glm/vec2.hpp>
#include <glm/vec3.hpp>

#include <strata/core/result.hpp>
#include <strata/gis/raster.hpp>

namespace strata::render {

/// The point on the Earth where the sun stands overhead at `utc` (lon, lat in degrees): the
/// Astronomical Almanac's low-precision solar coordinates (declination and equation of time to
/// about 0.01 degree and 3 s over 1950-2050) with the Greenwich mean sidereal time.
glm::dvec2 earthSubsolarPoint(std::chrono::sys_seconds utc);

/// "2026-06-21T18:30:00Z" (seconds optional, 'Z' or "+00:00" required: UTC only). Errors quote
/// the text and say what was expected.
Result<std::chrono::sys_seconds> parseUtc(const std::string& text);

/// Unit vector towards a sun standing over `subsolar` (lon, lat in degrees; the sun taken as
/// infinitely far), in the east-north-up frame at (lonDeg, latDeg) (geodetic; its up the
/// ellipsoid normal on the Earth, the radius on a sphere).
glm::dvec3 sunDirectionEnu(glm::dvec2 subsolar, double lonDeg, double latDeg);

/// Unit vector towards the sun at azimuth `azimuthDeg` (clockwise from north) and `elevationDeg`
/// above the horizon, in east-north-up.
glm::dvec3 sunDirectionEnu(double azimuthDeg, double elevationDeg);

/// How the sun is given to castShadows: a subsolar point (the sun fixed on the body, its
/// direction computed at each cell of a geographic grid, at the grid's centre for a projected
/// one) or, without one, a fixed east-north-up direction.
struct SunSpec {
  std::optional<glm::dvec2> subsolarLonLat;
  glm::dvec3 dirEnu{0, 0, 1};
};

/// The fraction of the sun's disc (0.53 degree across) each cell sees over its horizon towards
/// the sun, 0 (in shadow) to 1 (lit): the highest elevation angle of the terrain along the
/// sun's azimuth (bilinear heights times `exaggeration`, the body's curvature subtracted), out
/// to where no terrain could rise above the sun's line. Cells facing away from the sun are
/// still 1 (self-shading is the lighting's). NaN heights (voids) cast no shadow and get 1.
/// Geographic grids use spherical cell sizes on the body's semi-major axis; projected grids
/// `metresPerUnit` (TerrainScene::metresPerCrsUnit) and grid north as north.
gis::Grid<float> castShadows(const gis::Grid<float>& heights, const gis::Georef& georef, const SunSpec& sun,
                             float exaggeration, glm::dvec2 metresPerUnit = {1, 1});

}  // namespace strata::render
