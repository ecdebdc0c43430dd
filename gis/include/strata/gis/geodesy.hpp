#pragma once
// Coordinates and geodesy on a raster's body (GeographicLib): geographic <-> UTM/UPS, ECEF,
// local ENU; geodesic distance and polygon area; other CRSs through GDAL/PROJ; per-cell areas.
// Coordinate frames are types. Angles in degrees, lengths in metres. See docs/gis.md.

#include <array>
#include <memory>
#include <span>
#include <string>

#include <strata/core/result.hpp>
#include <strata/gis/body.hpp>
#include <strata/gis/raster.hpp>

namespace strata::gis {

/// Geodetic longitude/latitude (degrees) and height above the ellipsoid (m).
struct LonLat {
  double lonDeg = 0, latDeg = 0, heightM = 0;
};
/// Earth-centred, Earth-fixed (body-fixed) Cartesian coordinates (m).
struct Ecef {
  double x = 0, y = 0, z = 0;
};
/// Local east-north-up coordinates (m) about an origin.
struct Enu {
  double e = 0, n = 0, u = 0;
};
/// A UTM (zone 1..60) or UPS (zone 0) coordinate on WGS84 (m).
struct Utm {
  int zone = 0;
  bool north = true;
  double eastingM = 0, northingM = 0;
};

/// Geographic -> UTM/UPS on WGS84, in the standard zone or a forced one (1..60, 0 = UPS).
/// Fails for latitudes outside [-90, 90] or a zone the point cannot be expressed in.
Result<Utm> toUtm(const LonLat& p, int forceZone = -1);
/// UTM/UPS on WGS84 -> geographic (height 0).
Result<LonLat> fromUtm(const Utm& u);

/// Geodetic -> body-fixed Cartesian on `body`'s ellipsoid (a sphere for the Moon and Mars).
Ecef toEcef(const LonLat& p, const Body& body);
/// Body-fixed Cartesian -> geodetic on `body`.
LonLat fromEcef(const Ecef& p, const Body& body);

/// A local tangent frame (east, north, up) at an origin on a body.
class LocalFrame {
 public:
  /// East-north-up axes at `origin` (its height included) on `body`'s ellipsoid.
  LocalFrame(const LonLat& origin, const Body& body);
  ~LocalFrame();
  LocalFrame(LocalFrame&&) noexcept;
  LocalFrame& operator=(LocalFrame&&) noexcept;
  /// Geodetic point -> local east, north, up (m).
  Enu toEnu(const LonLat& p) const;
  /// Local east, north, up (m) -> geodetic point.
  LonLat fromEnu(const Enu& p) const;
  /// Body-fixed Cartesian point -> local east, north, up (m).
  Enu toEnu(const Ecef& p) const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

/// Geodesic (shortest path on the ellipsoid) distance between two points (m).
double geodesicDistanceM(const LonLat& a, const LonLat& b, const Body& body);
/// Area (m^2, positive) of a simple polygon whose edges are geodesics; vertices in either order.
double geodesicPolygonAreaM2(std::span<const LonLat> ring, const Body& body);

/// Area (m^2) of the region between two parallels and two meridians on `body`'s ellipsoid,
/// closed form through the authalic function q(phi) (docs/gis.md, "Cell areas").
double ellipsoidalQuadAreaM2(double lat0Deg, double lat1Deg, double lonSpanDeg, const Body& body);

/// Area of each cell of a grid (m^2), for any CRS: exact closed form for north-up geographic
/// grids; for other grids the cell corners are taken to lon/lat of the CRS's own datum and the
/// area integrated on the ellipsoid's authalic sphere (docs/gis.md). NaN where a corner cannot
/// be transformed. Fails when the Georef has no usable CRS.
Result<Grid<double>> cellAreasM2(const Georef& georef);
/// The areas of the cells of `window` (inside the grid), the same bits as the whole grid's there.
Result<Grid<double>> cellAreasM2(const Georef& georef, const CellRect& window);

/// A coordinate transformation between two CRSs (GDAL/PROJ), x = easting/longitude first.
class CrsTransform {
 public:
  /// `from`/`to`: "EPSG:n", WKT or PROJ strings. Fails naming the CRS that GDAL cannot parse.
  static Result<CrsTransform> create(const std::string& from, const std::string& to);
  /// From a Georef's CRS to the geographic lon/lat CRS on the same datum (the body's).
  static Result<CrsTransform> toGeographic(const Georef& georef);
  /// The inverse: lon/lat on the Georef's own datum to its CRS.
  static Result<CrsTransform> fromGeographic(const Georef& georef);
  ~CrsTransform();
  CrsTransform(CrsTransform&&) noexcept;
  CrsTransform& operator=(CrsTransform&&) noexcept;
  /// Transforms points in place (z may be null); false where a point fails (set to NaN).
  bool transform(std::size_t n, double* x, double* y, double* z = nullptr) const;

 private:
  CrsTransform();
  static Result<CrsTransform> lonLat(const Georef& georef, bool fromLonLat);  ///< both of the above
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

/// A CRS ("EPSG:n", WKT or PROJ) as a Georef's CRS fields (WKT2, EPSG code, name, geographic,
/// body); the grid fields are left at their defaults. Fails naming the CRS when it does not
/// parse or is neither geographic nor projected.
Result<Georef> describeCrs(const std::string& crs);

/// Geographic lon/lat of a grid position (pixel coordinates, (0,0) = top-left corner).
Result<LonLat> pixelToLonLat(const Georef& georef, double col, double row);

/// Ground metres per CRS unit along the grid's x (east) and y (north) axes at grid position
/// (col, row) of a projected grid: the inverse of the projection's point scale, e.g. about
/// cos(lat) for Web Mercator (0.81 over the Grand Canyon), 1 / 0.9996 on a UTM central
/// meridian. Measured as geodesic
/// distances over one cell each way. Fails for geographic grids and CRSs without a lon/lat base.
Result<std::array<double, 2>> metresPerCrsUnit(const Georef& georef, double col, double row);

}  // namespace strata::gis
