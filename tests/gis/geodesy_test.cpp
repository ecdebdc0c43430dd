// Coordinates and geodesy: UTM/UPS and ECEF against gdaltransform, ENU properties, geodesic
// distance, and per-cell areas against closed forms and GeographicLib's PolygonArea.
#include <gtest/gtest.h>
#include <GeographicLib/Ellipsoid.hpp>
#include <GeographicLib/Geodesic.hpp>
#include <GeographicLib/PolygonArea.hpp>

#include <cmath>
#include <fstream>
#include <numbers>
#include <sstream>

#include <strata/gis/dem_io.hpp>
#include <strata/gis/geodesy.hpp>

#include "gis_test_util.hpp"
#include "strata_test.hpp"

namespace strata::gis {
namespace {

using test::runCommand;

// gdaltransform on a list of "lon lat h" points (`options`: more of its arguments, e.g. -ct);
// returns the transformed triples.
std::vector<std::array<double, 3>> gdaltransform(const std::string& from, const std::string& to,
                                                 const std::vector<LonLat>& pts,
                                                 const std::vector<std::string>& options = {}) {
  std::ostringstream in;
  in.precision(17);
  for (const auto& p : pts) in << p.lonDeg << " " << p.latDeg << " " << p.heightM << "\n";
  std::vector<std::string> argv{"gdaltransform", "-s_srs", from};
  argv.insert(argv.end(), options.begin(), options.end());
  argv.insert(argv.end(), {"-t_srs", to});
  const auto r = runCommand(argv, false, in.str());
  EXPECT_EQ(r.status, 0);
  std::vector<std::array<double, 3>> out;
  std::istringstream s(r.out);
  double x, y, z;
  while (s >> x >> y >> z) out.push_back({x, y, z});
  EXPECT_EQ(out.size(), pts.size()) << r.out;
  return out;
}

const std::vector<LonLat> kPoints = {
    {-112.5, 36.5, 0},   {-121.76, 46.85, 4392}, {-113.99, 36.02, -80}, {18.42, -33.92, 15}, {2.35, 48.86, 35},
    {-0.001, 0.0005, 0}, {174.77, -36.85, 20},   {-179.9, 51.8, 0},     {9.0, 63.9, 120},    {-66.0, -54.8, 300},
};

TEST(Geodesy, UtmAgreesWithGdaltransformTo1mm) {
  // Group points by their standard zone: one gdaltransform run per zone.
  for (const LonLat& p : kPoints) {
    auto u = toUtm(p);
    ASSERT_TRUE(u.ok()) << u.message();
    const int epsg = (u->north ? 32600 : 32700) + u->zone;
    const auto ref = gdaltransform("EPSG:4326", "EPSG:" + std::to_string(epsg), {p});
    ASSERT_EQ(ref.size(), 1u);
    // The bar: 1 mm. GeographicLib's Krueger series is good to 5 nm; PROJ's to < 0.1 mm.
    EXPECT_NEAR(u->eastingM, ref[0][0], 1e-3) << p.lonDeg << "," << p.latDeg;
    EXPECT_NEAR(u->northingM, ref[0][1], 1e-3) << p.lonDeg << "," << p.latDeg;
    auto back = fromUtm(*u);
    ASSERT_TRUE(back.ok());
    // Round trip to 1e-9 degree (0.1 mm).
    EXPECT_NEAR(back->lonDeg, p.lonDeg, 1e-9);
    EXPECT_NEAR(back->latDeg, p.latDeg, 1e-9);
  }
  // UPS north and south (zone 0), against EPSG:32661 / 32761.
  for (const LonLat& p : {LonLat{30, 85.5, 0}, LonLat{-150, -87.2, 0}}) {
    auto u = toUtm(p);
    ASSERT_TRUE(u.ok()) << u.message();
    EXPECT_EQ(u->zone, 0);
    const auto ref = gdaltransform("EPSG:4326", u->north ? "EPSG:32661" : "EPSG:32761", {p});
    ASSERT_EQ(ref.size(), 1u);
    EXPECT_NEAR(u->eastingM, ref[0][0], 1e-3);
    EXPECT_NEAR(u->northingM, ref[0][1], 1e-3);
  }
  // A forced neighbouring zone still matches PROJ (same tolerance).
  auto forced = toUtm(kPoints[0], 11);
  ASSERT_TRUE(forced.ok());
  const auto ref = gdaltransform("EPSG:4326", "EPSG:32611", {kPoints[0]});
  EXPECT_NEAR(forced->eastingM, ref[0][0], 1e-3);
  EXPECT_NEAR(forced->northingM, ref[0][1], 1e-3);
  auto bad = toUtm(LonLat{0, 95, 0});
  ASSERT_FALSE(bad.ok());
  EXPECT_NE(bad.message().find("cannot convert lon 0.000000, lat 95.000000 to UTM/UPS"), std::string::npos)
      << bad.message();
}

TEST(Geodesy, EcefAgreesWithGdaltransformTo1mm) {
  const auto ref = gdaltransform("EPSG:4979", "EPSG:4978", kPoints);
  ASSERT_EQ(ref.size(), kPoints.size());
  for (size_t i = 0; i < kPoints.size(); ++i) {
    const Ecef e = toEcef(kPoints[i], Body::wgs84());
    // 1 mm, the bar; both are closed-form, so they agree to ~1e-8 m.
    EXPECT_NEAR(e.x, ref[i][0], 1e-3);
    EXPECT_NEAR(e.y, ref[i][1], 1e-3);
    EXPECT_NEAR(e.z, ref[i][2], 1e-3);
    const LonLat back = fromEcef(e, Body::wgs84());
    EXPECT_NEAR(back.latDeg, kPoints[i].latDeg, 1e-11);
    EXPECT_NEAR(back.heightM, kPoints[i].heightM, 1e-6);
  }
}

TEST(Geodesy, MoonAndMarsAreSpheres) {
  // On a sphere ECEF is (R + h) * unit vector: exact up to rounding (1e-6 m on 1.7e6 m).
  for (const Body& b : {Body::moon(), Body::mars()}) {
    const LonLat p{123.0, -41.0, 2500.0};
    const Ecef e = toEcef(p, b);
    const double r = b.semiMajorM + p.heightM, la = p.latDeg * std::numbers::pi / 180,
                 lo = p.lonDeg * std::numbers::pi / 180;
    EXPECT_NEAR(e.x, r * std::cos(la) * std::cos(lo), 1e-6);
    EXPECT_NEAR(e.y, r * std::cos(la) * std::sin(lo), 1e-6);
    EXPECT_NEAR(e.z, r * std::sin(la), 1e-6);
    // A quarter of the equator.
    EXPECT_NEAR(geodesicDistanceM({0, 0, 0}, {90, 0, 0}, b), std::numbers::pi / 2 * b.semiMajorM, 1e-6);
  }
  // Longitudes 0..360 (Mars, Moon) are the same points as -180..180.
  const Ecef a = toEcef({300, 10, 0}, Body::mars()), c = toEcef({-60, 10, 0}, Body::mars());
  EXPECT_NEAR(a.x, c.x, 1e-6);
  EXPECT_NEAR(a.y, c.y, 1e-6);
}

TEST(Geodesy, LocalEnuFrame) {
  const LonLat origin{-112.1, 36.1, 2100};
  const LocalFrame frame(origin, Body::wgs84());
  const Enu o = frame.toEnu(origin);
  EXPECT_NEAR(std::hypot(o.e, o.n, o.u), 0, 1e-9);
  // Straight up is +u only.
  const Enu up = frame.toEnu(LonLat{origin.lonDeg, origin.latDeg, origin.heightM + 500});
  EXPECT_NEAR(up.u, 500, 1e-8);
  EXPECT_NEAR(std::hypot(up.e, up.n), 0, 1e-8);
  // A point to the north-east has e > 0, n > 0; distances equal the ECEF chord (the frame is a
  // rotation + translation: 1e-8 m is rounding on 6.4e6 m coordinates).
  const LonLat p{-112.05, 36.13, 1800};
  const Enu q = frame.toEnu(p);
  EXPECT_GT(q.e, 0);
  EXPECT_GT(q.n, 0);
  const Ecef a = toEcef(origin, Body::wgs84()), b = toEcef(p, Body::wgs84());
  EXPECT_NEAR(std::hypot(q.e, q.n, q.u), std::hypot(a.x - b.x, a.y - b.y, a.z - b.z), 1e-8);
  const Enu viaEcef = frame.toEnu(b);
  EXPECT_NEAR(viaEcef.e, q.e, 1e-8);
  // Against PROJ's topocentric conversion (ECEF in, ENU out) through gdaltransform -ct: 1 mm.
  std::vector<LonLat> ecefPts;
  std::vector<Enu> ours;
  for (const LonLat& k : kPoints) {
    const Ecef x = toEcef(k, Body::wgs84());
    ecefPts.push_back({x.x, x.y, x.z});
    ours.push_back(frame.toEnu(k));
  }
  const auto proj = gdaltransform("EPSG:4978", "EPSG:4978", ecefPts,
                                  {"-ct", "+proj=topocentric +ellps=WGS84 +lat_0=36.1 +lon_0=-112.1 +h_0=2100"});
  ASSERT_EQ(proj.size(), kPoints.size());
  for (size_t i = 0; i < proj.size(); ++i) {
    EXPECT_NEAR(ours[i].e, proj[i][0], 1e-3) << i;
    EXPECT_NEAR(ours[i].n, proj[i][1], 1e-3) << i;
    EXPECT_NEAR(ours[i].u, proj[i][2], 1e-3) << i;
  }
  const LonLat back = frame.fromEnu(q);
  EXPECT_NEAR(back.lonDeg, p.lonDeg, 1e-12);
  EXPECT_NEAR(back.heightM, p.heightM, 1e-8);
}

TEST(Geodesy, GeodesicDistanceMatchesKarneyExample) {
  // GeographicLib's documented example: JFK (40.6, -73.8) to LHR (51.6, -0.5) is 5551.759400319 km.
  EXPECT_NEAR(geodesicDistanceM({-73.8, 40.6, 0}, {-0.5, 51.6, 0}, Body::wgs84()), 5551759.400319, 1e-6);
}

// Independent closed form: the authalic sphere, R_q^2 = (ellipsoid area) / 4 pi, and the
// authalic latitude xi: A = R_q^2 * dlon * (sin xi1 - sin xi0).
double authalicArea(double lat0, double lat1, double dlonDeg) {
  const GeographicLib::Ellipsoid& e = GeographicLib::Ellipsoid::WGS84();
  const double rq2 = e.Area() / (4 * std::numbers::pi);
  const double d = std::numbers::pi / 180;
  return rq2 * dlonDeg * d * (std::sin(e.AuthalicLatitude(lat1) * d) - std::sin(e.AuthalicLatitude(lat0) * d));
}

TEST(CellAreas, OneDegreeCellAtGrandCanyon) {
  Georef g;
  g.crsWkt = "EPSG:4326";
  g.geographic = true;
  g.width = g.height = 1;
  g.transform = GeoTransform{{-113, 1, 0, 37, 0, -1}};
  auto areas = cellAreasM2(g);
  ASSERT_TRUE(areas.ok()) << areas.message();
  const double a = areas->at(0, 0);
  const double closed = authalicArea(36, 37, 1);
  // Both closed forms in double: agree to rounding, far inside the 1e-9.
  EXPECT_NEAR(a / closed - 1, 0, 1e-9) << a << " vs " << closed;
  // PolygonArea over the outline with the parallels densified (geodesics between points 1/2000
  // degree apart sag from the parallel by < 1 mm): within the 1e-6.
  std::vector<LonLat> ring;
  const int n = 2000;
  for (int i = 0; i <= n; ++i) ring.push_back({-113 + double(i) / n, 36, 0});
  for (int i = 0; i <= n; ++i) ring.push_back({-112 - double(i) / n, 37, 0});
  const double poly = geodesicPolygonAreaM2(ring, Body::wgs84());
  EXPECT_NEAR(a / poly - 1, 0, 1e-6) << a << " vs " << poly;
  std::printf("cell 36..37N x 113..112W: %.6f m^2; closed form rel. diff %.3e; PolygonArea rel. diff %.3e\n", a,
              a / closed - 1, a / poly - 1);
}

TEST(CellAreas, GrandCanyonGridSumsToItsExtent) {
  auto info = probeDem(test::dataFile("grand_canyon/grand_canyon_512.tif"));
  ASSERT_TRUE(info.ok()) << info.message();
  const Georef& g = info->georef;
  auto areas = cellAreasM2(g);
  ASSERT_TRUE(areas.ok()) << areas.message();
  double sum = 0;
  for (double v : areas->data) sum += v;
  const double top = g.transform.y(0, 0), bottom = g.transform.y(0, g.height);
  const double closed = authalicArea(bottom, top, g.transform.c[1] * g.width);
  // Telescoping sum of 512 rows in double: rounding ~1e-13; bar 1e-9 (the issue's).
  EXPECT_NEAR(sum / closed - 1, 0, 1e-9) << sum << " vs " << closed;
  // Cells shrink poleward: the top (north) row is smaller than the bottom row.
  EXPECT_LT(areas->at(0, 0), areas->at(0, g.height - 1));
  std::printf("grand_canyon_512: sum %.3f m^2, rel. diff %.3e\n", sum, sum / closed - 1);
}

TEST(CellAreas, WebMercatorGridSumsToItsLonLatExtent) {
  // A Web Mercator grid is bounded by parallels and meridians: its area is the same closed form.
  auto info = probeDem(test::dataFile("grand_canyon/grandcanyon_srtm_3857.tif"));
  ASSERT_TRUE(info.ok()) << info.message();
  const Georef& g = info->georef;
  auto areas = cellAreasM2(g);
  ASSERT_TRUE(areas.ok()) << areas.message();
  double sum = 0;
  for (double v : areas->data) sum += v;
  auto tl = pixelToLonLat(g, 0, 0), br = pixelToLonLat(g, g.width, g.height);
  ASSERT_TRUE(tl.ok() && br.ok());
  const double closed = authalicArea(br->latDeg, tl->latDeg, br->lonDeg - tl->lonDeg);
  // Corners through PROJ (1e-12 relative) and a telescoping sum: 1e-9 holds with room.
  EXPECT_NEAR(sum / closed - 1, 0, 1e-9) << sum << " vs " << closed;
  // Each 76.4 m Mercator cell is ~76.4 * cos(36.2 deg) m on a side.
  const double side = 76.437028 * std::cos(36.17 * std::numbers::pi / 180);
  EXPECT_NEAR(areas->at(256, 256) / (side * side) - 1, 0, 0.01);
}

// A window's areas are the whole grid's bits there (what a rank that builds only some rows of a
// region computes), on a projected grid (corners through PROJ) and a geographic one.
TEST(CellAreas, AWindowHasTheWholeGridsBits) {
  for (const char* dem : {"grand_canyon/grandcanyon_srtm_3857.tif", "grand_canyon/grand_canyon_512.tif"}) {
    auto info = probeDem(test::dataFile(dem));
    ASSERT_TRUE(info.ok()) << info.message();
    const Georef& g = info->georef;
    auto whole = cellAreasM2(g);
    ASSERT_TRUE(whole.ok()) << whole.message();
    for (const CellRect w : {CellRect{256, 0, 1, 512}, CellRect{3, 101, 77, 45}, CellRect{0, 511, 512, 1}}) {
      auto part = cellAreasM2(g, w);
      ASSERT_TRUE(part.ok()) << part.message();
      for (int y = 0; y < w.height; ++y) {
        for (int x = 0; x < w.width; ++x)
          ASSERT_EQ(part->at(x, y), whole->at(w.x + x, w.y + y)) << dem << " " << x << "," << y;
      }
    }
    EXPECT_FALSE(cellAreasM2(g, CellRect{500, 0, 13, 1}).ok());  // past the east edge
  }
}

TEST(CellAreas, UtmCellsMatchGeodesicPolygons) {
  Georef g;
  g.crsWkt = "EPSG:32612";
  g.width = 6;
  g.height = 5;
  g.transform = GeoTransform{{350000, 1000, 0, 4050000, 0, -1000}};
  auto areas = cellAreasM2(g);
  ASSERT_TRUE(areas.ok()) << areas.message();
  auto ct = CrsTransform::create("EPSG:32612", "EPSG:4326");
  ASSERT_TRUE(ct.ok()) << ct.message();
  for (int r = 0; r < g.height; ++r) {
    for (int c = 0; c < g.width; ++c) {
      double x[4] = {g.transform.x(c, r), g.transform.x(c + 1, r), g.transform.x(c + 1, r + 1),
                     g.transform.x(c, r + 1)};
      double y[4] = {g.transform.y(c, r), g.transform.y(c + 1, r), g.transform.y(c + 1, r + 1),
                     g.transform.y(c, r + 1)};
      ASSERT_TRUE(ct->transform(4, x, y));
      std::vector<LonLat> ring;
      for (int k = 0; k < 4; ++k) ring.push_back({x[k], y[k], 0});
      const double poly = geodesicPolygonAreaM2(ring, Body::wgs84());
      // 1 km cells: straight UTM edges vs geodesics and the trapezoid rule differ by ~(1 km / R)^2
      // ~ 2.5e-8 relative; 1e-6 is the bar.
      EXPECT_NEAR(areas->at(c, r) / poly - 1, 0, 1e-6);
      // And a UTM cell is ~1 km^2 (scale factor 0.9996..1.0004 squared).
      EXPECT_NEAR(areas->at(c, r), 1e6, 2e3);
    }
  }
}

TEST(CellAreas, WholeMoonAndMarsSumToTheSphere) {
  // The Moon's grid is projected (equirectangular about 180 E), Mars' geographic 0..360.
  for (const char* f : {"moon/LDEM_4.LBL", "mars/mola_megdr_4ppd.vrt"}) {
    auto info = probeDem(test::dataFile(f));
    ASSERT_TRUE(info.ok()) << info.message();
    const Georef& g = info->georef;
    auto areas = cellAreasM2(g);
    ASSERT_TRUE(areas.ok()) << areas.message();
    double sum = 0;
    for (double v : areas->data) sum += v;
    // LOLA's label rounds the pixel size: its 1440 columns span 360.0001 degrees (PROJ says so),
    // and its edge rows reach 0.1" past the poles (taken as the poles). The expected area is the
    // sphere's times the longitude span over 360.
    auto a = pixelToLonLat(g, 0, g.height / 2.0), b = pixelToLonLat(g, 1, g.height / 2.0);
    ASSERT_TRUE(a.ok() && b.ok());
    const double spanDeg = (b->lonDeg - a->lonDeg) * g.width;
    const double r = g.body.semiMajorM;
    // 1M cells summed in double: ~1e-12; 1e-9 leaves room.
    EXPECT_NEAR(sum / (4 * std::numbers::pi * r * r * spanDeg / 360) - 1, 0, 1e-9) << f;
    std::printf("%s: span %.7f deg, sum / sphere - 1 = %.3e\n", f, spanDeg, sum / (4 * std::numbers::pi * r * r) - 1);
  }
}

TEST(CellAreas, AWebMercatorGridFarOffTheEarthFailsAtOnce) {
  // A fuzzed GeoTIFF put a 3857 grid's corners at 1e20 m: GDAL 3.6's Web Mercator shortcut
  // wraps such a longitude 360 degrees per iteration and did not return within 29 s (CI's fuzzer
  // timed out). Such points now fail before reaching GDAL: NaN areas, at once.
  auto info = probeDem(test::dataFile("grand_canyon/grandcanyon_srtm_3857.tif"));
  ASSERT_TRUE(info.ok()) << info.message();
  Georef g = info->georef;
  g.width = g.height = 4;
  g.transform = GeoTransform{{-1e20, 5e19, 0, 1e20, 0, -5e19}};
  auto areas = cellAreasM2(g);
  ASSERT_TRUE(areas.ok()) << areas.message();
  for (double a : areas->data) EXPECT_TRUE(std::isnan(a)) << a;
  auto ct = CrsTransform::toGeographic(g);
  ASSERT_TRUE(ct.ok()) << ct.message();
  double x[3] = {-1e20, 1e11, 1000}, y[3] = {0, 0, 1000};
  EXPECT_FALSE(ct->transform(3, x, y));
  EXPECT_TRUE(std::isnan(x[0]) && std::isnan(y[0]) && std::isnan(x[1]) && std::isnan(y[1]));
  EXPECT_NEAR(x[2], 1000 / 6378137.0 * 180 / std::numbers::pi, 1e-9);  // the sane point still goes through
}

TEST(Geodesy, MetresPerCrsUnitIsTheProjectionsPointScale) {
  // Web Mercator puts geodetic latitude on a sphere of radius a: along a parallel one unit is
  // N cos(phi) / a metres of ground, along a meridian M cos(phi) / a (N, M: the ellipsoid's
  // radii of curvature), 0.81 over the Grand Canyon. The renderer once took it as 1.
  auto info = probeDem(test::dataFile("grand_canyon/grandcanyon_srtm_3857.tif"));
  ASSERT_TRUE(info.ok()) << info.message();
  Georef g = info->georef;
  const double a = g.body.semiMajorM, e2 = g.body.flattening * (2 - g.body.flattening);
  for (double latDeg : {0.0, 36.1, 60.0, -75.0}) {
    const double phi = latDeg * std::numbers::pi / 180.0, s2 = std::sin(phi) * std::sin(phi);
    const double n = a / std::sqrt(1 - e2 * s2), m = a * (1 - e2) / std::pow(1 - e2 * s2, 1.5);
    g.transform = GeoTransform{{-12.5e6, 30, 0, a * std::log(std::tan(std::numbers::pi / 4 + phi / 2)), 0, -30}};
    auto k = metresPerCrsUnit(g, 0.0, 0.0);
    ASSERT_TRUE(k.ok()) << k.message();
    EXPECT_NEAR((*k)[0], n * std::cos(phi) / a, 1e-7) << latDeg;
    EXPECT_NEAR((*k)[1], m * std::cos(phi) / a, 1e-7) << latDeg;
  }
  // UTM zone 12 on its central meridian (111 W): the point scale is k0 = 0.9996 both ways, so a
  // unit is 1 / 0.9996 m of ground.
  auto utm = describeCrs("EPSG:32612");
  ASSERT_TRUE(utm.ok()) << utm.message();
  utm->transform = GeoTransform{{500000, 30, 0, 4000000, 0, -30}};
  auto k = metresPerCrsUnit(*utm, 0.0, 0.0);
  ASSERT_TRUE(k.ok()) << k.message();
  EXPECT_NEAR((*k)[0], 1 / 0.9996, 1e-6);
  EXPECT_NEAR((*k)[1], 1 / 0.9996, 1e-6);
  Georef geographic = g;
  geographic.geographic = true;
  EXPECT_FALSE(metresPerCrsUnit(geographic, 0, 0).ok());
}

TEST(Geodesy, CrsTransformErrorsNameTheCrs) {
  auto t = CrsTransform::create("EPSG:4326", "EPSG:999999");
  ASSERT_FALSE(t.ok());
  EXPECT_NE(t.message().find("unknown CRS 'EPSG:999999'"), std::string::npos) << t.message();
}

}  // namespace
}  // namespace strata::gis
