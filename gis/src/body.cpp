#include <strata/gis/body.hpp>

#include <cmath>

namespace strata::gis {

Body Body::wgs84() { return {"Earth (WGS84)", 6378137.0, 1.0 / 298.257223563}; }
Body Body::moon() { return {"Moon", 1737400.0, 0.0}; }
Body Body::mars() { return {"Mars", 3396190.0, 0.0}; }

Body Body::fromEllipsoid(double semiMajorM, double flattening, const std::string& ellipsoidName) {
  for (const Body& b : {wgs84(), moon(), mars()}) {
    if (std::abs(b.semiMajorM - semiMajorM) < 1.0 && std::abs(b.flattening - flattening) < 1e-9) return b;
  }
  return {ellipsoidName.empty() ? "unknown body" : ellipsoidName, semiMajorM, flattening};
}

}  // namespace strata::gis
