#include <numbers>

#include <strata/render/terrain/lon_lat_dem.hpp>

namespace strata::render::terrain {

Result<gis::Raster> toLonLat(gis::Raster dem, const std::string& label) {
  auto& g = dem.georef;
  if (g.geographic) return dem;
  const bool equirectangular = g.crsWkt.find("Equirectangular") != std::string::npos ||
                               g.crsWkt.find("Equidistant Cylindrical") != std::string::npos;
  if (!equirectangular || !g.body.isSphere()) {
    return fail(label + ": not geographic and not equirectangular on a sphere (" + g.crsName + ")");
  }
  const std::string key = "\"Longitude of natural origin\",";
  const auto at = g.crsWkt.find(key);
  if (at == std::string::npos) return fail(label + ": equirectangular CRS without a longitude of natural origin");
  const double centralDeg = std::stod(g.crsWkt.substr(at + key.size()));
  const double mPerDeg = g.body.semiMajorM * std::numbers::pi / 180;
  for (int k : {0, 1, 3, 5}) g.transform.c[k] /= mPerDeg;
  g.transform.c[0] += centralDeg;
  g.geographic = true;
  return dem;
}

}  // namespace strata::render::terrain
