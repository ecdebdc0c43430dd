// Geodesy on a raster's body with GeographicLib; CRS transformations through GDAL/PROJ.
// The cell-area formulas are derived in docs/gis.md ("Cell areas").
#include <strata/gis/geodesy.hpp>

#include <GeographicLib/Geocentric.hpp>
#include <GeographicLib/Geodesic.hpp>
#include <GeographicLib/LocalCartesian.hpp>
#include <GeographicLib/PolygonArea.hpp>
#include <GeographicLib/UTMUPS.hpp>

#include <algorithm>
#include <cmath>
#include <numbers>
#include <vector>

#include "gdal_util.hpp"

namespace strata::gis {
namespace {

constexpr double kDegToRad = std::numbers::pi / 180.0;

// f(phi) = sin(phi) / (2 (1 - e^2 sin^2 phi)) + atanh(e sin phi) / (2 e): the area from the
// equator to latitude phi over one radian of longitude is b^2 f(phi) (docs/gis.md, eq. A).
// For a sphere (e = 0) it is sin(phi).
double authalicF(double latDeg, double e) {
  const double s = std::sin(latDeg * kDegToRad);
  if (e < 1e-12) return s;
  const double es = e * s;
  return s / (2 * (1 - es * es)) + std::atanh(es) / (2 * e);
}

double eccentricity(const Body& body) { return std::sqrt(body.flattening * (2 - body.flattening)); }

double wrap180(double dLonDeg) {
  double d = std::remainder(dLonDeg, 360.0);
  if (d == -180.0) d = 180.0;
  return d;
}

// Latitudes beyond a pole by at most 1e-4 degree (0.36", 11 m on Earth) are the pole: labels
// that round the pixel size put the grid edge slightly past it (LOLA's LDEM_4: 0.1" past).
// Anything further out is not on the body (NaN).
constexpr double kPoleSnapDeg = 1e-4;
double poleSnap(double latDeg) {
  if (std::abs(latDeg) > 90.0 && std::abs(latDeg) <= 90.0 + kPoleSnapDeg) return std::copysign(90.0, latDeg);
  return latDeg;
}

}  // namespace

Result<Utm> toUtm(const LonLat& p, int forceZone) {
  try {
    Utm u;
    double gamma = 0, k = 0;
    GeographicLib::UTMUPS::Forward(p.latDeg, p.lonDeg, u.zone, u.north, u.eastingM, u.northingM, gamma, k, forceZone);
    return u;
  } catch (const std::exception& e) {
    return fail("cannot convert lon " + std::to_string(p.lonDeg) + ", lat " + std::to_string(p.latDeg) +
                " to UTM/UPS: " + e.what());
  }
}

Result<LonLat> fromUtm(const Utm& u) {
  try {
    LonLat p;
    GeographicLib::UTMUPS::Reverse(u.zone, u.north, u.eastingM, u.northingM, p.latDeg, p.lonDeg);
    return p;
  } catch (const std::exception& e) {
    return fail("cannot convert UTM zone " + std::to_string(u.zone) + " to geographic: " + e.what());
  }
}

Ecef toEcef(const LonLat& p, const Body& body) {
  const GeographicLib::Geocentric g(body.semiMajorM, body.flattening);
  Ecef r;
  g.Forward(p.latDeg, p.lonDeg, p.heightM, r.x, r.y, r.z);
  return r;
}

LonLat fromEcef(const Ecef& p, const Body& body) {
  const GeographicLib::Geocentric g(body.semiMajorM, body.flattening);
  LonLat r;
  g.Reverse(p.x, p.y, p.z, r.latDeg, r.lonDeg, r.heightM);
  return r;
}

struct LocalFrame::Impl {
  GeographicLib::LocalCartesian lc;
};

LocalFrame::LocalFrame(const LonLat& origin, const Body& body)
    : impl_(new Impl{GeographicLib::LocalCartesian(origin.latDeg, origin.lonDeg, origin.heightM,
                                                   GeographicLib::Geocentric(body.semiMajorM, body.flattening))}) {}
LocalFrame::~LocalFrame() = default;
LocalFrame::LocalFrame(LocalFrame&&) noexcept = default;
LocalFrame& LocalFrame::operator=(LocalFrame&&) noexcept = default;

Enu LocalFrame::toEnu(const LonLat& p) const {
  Enu r;
  impl_->lc.Forward(p.latDeg, p.lonDeg, p.heightM, r.e, r.n, r.u);
  return r;
}

LonLat LocalFrame::fromEnu(const Enu& p) const {
  LonLat r;
  impl_->lc.Reverse(p.e, p.n, p.u, r.latDeg, r.lonDeg, r.heightM);
  return r;
}

Enu LocalFrame::toEnu(const Ecef& p) const {
  // LocalCartesian has no ECEF input: go through geodetic on the same ellipsoid (exact round trip).
  const GeographicLib::Geocentric g(impl_->lc.EquatorialRadius(), impl_->lc.Flattening());
  LonLat q;
  g.Reverse(p.x, p.y, p.z, q.latDeg, q.lonDeg, q.heightM);
  return toEnu(q);
}

double geodesicDistanceM(const LonLat& a, const LonLat& b, const Body& body) {
  const GeographicLib::Geodesic g(body.semiMajorM, body.flattening);
  double s12 = 0;
  g.Inverse(a.latDeg, a.lonDeg, b.latDeg, b.lonDeg, s12);
  return s12;
}

double geodesicPolygonAreaM2(std::span<const LonLat> ring, const Body& body) {
  const GeographicLib::Geodesic g(body.semiMajorM, body.flattening);
  GeographicLib::PolygonArea poly(g);
  for (const LonLat& p : ring) poly.AddPoint(p.latDeg, p.lonDeg);
  double perimeter = 0, area = 0;
  poly.Compute(false, true, perimeter, area);
  return std::abs(area);
}

double ellipsoidalQuadAreaM2(double lat0Deg, double lat1Deg, double lonSpanDeg, const Body& body) {
  // Eq. A of docs/gis.md: A = b^2 * dlon * |f(phi1) - f(phi0)|.
  const double e = eccentricity(body);
  const double b = body.semiMinorM();
  return b * b * std::abs(lonSpanDeg * kDegToRad) * std::abs(authalicF(lat1Deg, e) - authalicF(lat0Deg, e));
}

struct CrsTransform::Impl {
  struct Destroy {
    void operator()(OGRCoordinateTransformation* t) const { OGRCoordinateTransformation::DestroyCT(t); }
  };
  std::unique_ptr<OGRCoordinateTransformation, Destroy> ct;
};

CrsTransform::CrsTransform() : impl_(new Impl) {}
CrsTransform::~CrsTransform() = default;
CrsTransform::CrsTransform(CrsTransform&&) noexcept = default;
CrsTransform& CrsTransform::operator=(CrsTransform&&) noexcept = default;

Result<CrsTransform> CrsTransform::create(const std::string& from, const std::string& to) {
  STRATA_TRY(OGRSpatialReference a, detail::parseCrs(from));
  STRATA_TRY(OGRSpatialReference b, detail::parseCrs(to));
  detail::GdalErrorCapture errors;
  CrsTransform t;
  t.impl_->ct.reset(OGRCreateCoordinateTransformation(&a, &b));
  if (!t.impl_->ct) return fail("no transformation from '" + from + "' to '" + to + "': " + errors.last());
  return t;
}

Result<CrsTransform> CrsTransform::lonLat(const Georef& georef, bool fromLonLat) {
  STRATA_TRY(OGRSpatialReference srs, detail::srsOf(georef));
  std::unique_ptr<OGRSpatialReference> geog(srs.CloneGeogCS());
  if (!geog) return fail("CRS '" + georef.crsName + "' has no geographic base");
  geog->SetAxisMappingStrategy(OAMS_TRADITIONAL_GIS_ORDER);
  detail::GdalErrorCapture errors;
  CrsTransform t;
  t.impl_->ct.reset(fromLonLat ? OGRCreateCoordinateTransformation(geog.get(), &srs)
                               : OGRCreateCoordinateTransformation(&srs, geog.get()));
  if (!t.impl_->ct) {
    return fail(fromLonLat ? "no transformation from lon/lat to '" + georef.crsName + "': " + errors.last()
                           : "no transformation from '" + georef.crsName + "' to lon/lat: " + errors.last());
  }
  return t;
}

Result<CrsTransform> CrsTransform::toGeographic(const Georef& georef) { return lonLat(georef, false); }

Result<CrsTransform> CrsTransform::fromGeographic(const Georef& georef) { return lonLat(georef, true); }

Result<Georef> describeCrs(const std::string& crs) {
  STRATA_TRY(OGRSpatialReference srs, detail::parseCrs(crs));
  if (!srs.IsGeographic() && !srs.IsProjected()) {
    return fail("CRS '" + crs.substr(0, 80) + "' is neither geographic nor projected");
  }
  Georef g;
  detail::fillCrs(srs, g);
  return g;
}

bool CrsTransform::transform(std::size_t n, double* x, double* y, double* z) const {
  // No coordinate of any CRS on any body is this far from its origin (1e10 units is 1,500 Earth
  // radii in metres); such points fail without reaching GDAL, whose Web Mercator shortcut (GDAL
  // 3.6) wraps a longitude by 360 degrees per iteration: a 1e20 m easting spins for hours.
  constexpr double kFarthest = 1e10;
  std::vector<char> tooFar(n, 0);
  for (std::size_t i = 0; i < n; ++i) {
    if (!(std::abs(x[i]) <= kFarthest && std::abs(y[i]) <= kFarthest)) {
      tooFar[i] = 1;
      x[i] = y[i] = 0;  // a harmless stand-in for GDAL; the point fails below
    }
  }
  std::vector<int> ok(n, 0);
  detail::GdalErrorCapture quiet;
  bool allOk = impl_->ct->Transform(n, x, y, z, nullptr, ok.data()) != 0;
  for (std::size_t i = 0; i < n; ++i) {
    if (tooFar[i] || !ok[i] || !std::isfinite(x[i]) || !std::isfinite(y[i])) {
      x[i] = y[i] = std::nan("");
      allOk = false;
    }
  }
  return allOk;
}

Result<LonLat> pixelToLonLat(const Georef& georef, double col, double row) {
  double x = georef.transform.x(col, row), y = georef.transform.y(col, row);
  if (!georef.geographic) {
    STRATA_TRY(CrsTransform t, CrsTransform::toGeographic(georef));
    if (!t.transform(1, &x, &y))
      return fail("pixel (" + std::to_string(col) + ", " + std::to_string(row) + ") has no lon/lat in '" +
                  georef.crsName + "'");
  }
  return LonLat{x, y, 0};
}

Result<std::array<double, 2>> metresPerCrsUnit(const Georef& georef, double col, double row) {
  if (georef.geographic) return fail("metres per CRS unit: '" + georef.crsName + "' is geographic (degrees)");
  const auto& t = georef.transform;
  // The two ends of a one-cell segment along each grid axis, about (col, row).
  double x[4] = {t.x(col - 0.5, row), t.x(col + 0.5, row), t.x(col, row - 0.5), t.x(col, row + 0.5)};
  double y[4] = {t.y(col - 0.5, row), t.y(col + 0.5, row), t.y(col, row - 0.5), t.y(col, row + 0.5)};
  const double unitsX = std::hypot(x[1] - x[0], y[1] - y[0]), unitsY = std::hypot(x[3] - x[2], y[3] - y[2]);
  STRATA_TRY(CrsTransform ct, CrsTransform::toGeographic(georef));
  if (!ct.transform(4, x, y) || !(unitsX > 0) || !(unitsY > 0)) {
    return fail("metres per CRS unit: grid position (" + std::to_string(col) + ", " + std::to_string(row) +
                ") has no lon/lat in '" + georef.crsName + "'");
  }
  return std::array<double, 2>{geodesicDistanceM({x[0], y[0], 0}, {x[1], y[1], 0}, georef.body) / unitsX,
                               geodesicDistanceM({x[2], y[2], 0}, {x[3], y[3], 0}, georef.body) / unitsY};
}

Result<Grid<double>> cellAreasM2(const Georef& georef) {
  return cellAreasM2(georef, {0, 0, georef.width, georef.height});
}

Result<Grid<double>> cellAreasM2(const Georef& georef, const CellRect& w) {
  if (georef.width <= 0 || georef.height <= 0) return fail("cell areas: empty grid");
  if (w.empty() || w.x < 0 || w.y < 0 || w.x + w.width > georef.width || w.y + w.height > georef.height) {
    return fail("cell areas: the window is not inside the grid");
  }
  Grid<double> areas(w.width, w.height, std::nan(""));
  const GeoTransform& t = georef.transform;
  if (georef.geographic && t.isNorthUp()) {
    // Closed form (eq. A), one value per row.
    for (int row = 0; row < w.height; ++row) {
      const double lat0 = poleSnap(t.y(0, w.y + row)), lat1 = poleSnap(t.y(0, w.y + row + 1));
      if (std::abs(lat0) > 90 || std::abs(lat1) > 90) continue;
      const double a = ellipsoidalQuadAreaM2(lat0, lat1, t.c[1], georef.body);
      for (int col = 0; col < w.width; ++col) areas.at(col, row) = a;
    }
    return areas;
  }
  // Any other grid: corners to lon/lat on the CRS's own datum, then the ring integral
  // A = b^2 |sum over edges (f_i + f_j) / 2 * dlon_ij| (eq. B), exact along parallels and meridians.
  // (Corners of the window, from the whole grid's transform: a window's areas are the whole's.)
  const int cw = w.width + 1, ch = w.height + 1;
  std::vector<double> lon(size_t(cw) * ch), lat(size_t(cw) * ch);
  for (int r = 0; r < ch; ++r) {
    for (int c = 0; c < cw; ++c) {
      lon[size_t(r) * cw + c] = t.x(w.x + c, w.y + r);
      lat[size_t(r) * cw + c] = t.y(w.x + c, w.y + r);
    }
  }
  if (!georef.geographic) {
    STRATA_TRY(CrsTransform ct, CrsTransform::toGeographic(georef));
    if (!ct.transform(lon.size(), lon.data(), lat.data())) {
      // Corners on the edge of the projection's domain (the poles of the Moon's equirectangular
      // grid, stored with 1e-16 rounding beyond 90 degrees) fail in PROJ: retry them moved 1e-9
      // pixel towards the grid centre, which changes a cell's area by ~1e-9 of one edge strip.
      const double cx = georef.width / 2.0, cy = georef.height / 2.0;
      for (int r = 0; r < ch; ++r) {
        for (int c = 0; c < cw; ++c) {
          const size_t i = size_t(r) * cw + c;
          if (!std::isnan(lon[i])) continue;
          const double gc = w.x + c, gr = w.y + r;
          const double pc = gc + (cx - gc) * 1e-9 / std::max(1.0, std::abs(cx - gc)),
                       pr = gr + (cy - gr) * 1e-9 / std::max(1.0, std::abs(cy - gr));
          double x = t.x(pc, pr), y = t.y(pc, pr);
          if (ct.transform(1, &x, &y)) {
            lon[i] = x;
            lat[i] = y;
          }
        }
      }
    }
  }
  const double e = eccentricity(georef.body);
  const double b = georef.body.semiMinorM();
  std::vector<double> f(lat.size());
  for (size_t i = 0; i < lat.size(); ++i) {
    const double la = poleSnap(lat[i]);
    f[i] = std::abs(la) <= 90 ? authalicF(la, e) : std::nan("");
  }
  constexpr double kRad = kDegToRad;
  for (int row = 0; row < w.height; ++row) {
    for (int col = 0; col < w.width; ++col) {
      const size_t idx[4] = {size_t(row) * cw + col, size_t(row) * cw + col + 1, size_t(row + 1) * cw + col + 1,
                             size_t(row + 1) * cw + col};
      double sum = 0;
      for (int k = 0; k < 4; ++k) {
        const size_t i = idx[k], j = idx[(k + 1) % 4];
        sum += 0.5 * (f[i] + f[j]) * wrap180(lon[j] - lon[i]) * kRad;
      }
      areas.at(col, row) = b * b * std::abs(sum);  // NaN propagates from untransformable corners
    }
  }
  return areas;
}

}  // namespace strata::gis
