#pragma once
// The celestial body a dataset lives on: its reference ellipsoid (a sphere for the Moon and
// Mars in the PDS products Strata reads). Identified from the CRS's ellipsoid parameters, never
// from a file name.

#include <optional>
#include <string>

namespace strata::gis {

struct Body {
  std::string name;       ///< "Earth (WGS84)", "Moon", "Mars", or the CRS's ellipsoid name
  double semiMajorM = 0;  ///< equatorial radius a (m)
  double flattening = 0;  ///< f = (a - b) / a; 0 for a sphere

  double semiMinorM() const { return semiMajorM * (1 - flattening); }
  bool isSphere() const { return flattening == 0; }

  static Body wgs84();
  static Body moon();  ///< IAU sphere, 1737.4 km (LOLA LDEM reference)
  static Body mars();  ///< sphere, 3396.19 km (MOLA MEGDR reference)

  /// The known body whose ellipsoid matches (a within 1 m, f within 1e-9), else a body named
  /// `ellipsoidName` with the given ellipsoid.
  static Body fromEllipsoid(double semiMajorM, double flattening, const std::string& ellipsoidName = {});
};

}  // namespace strata::gis
