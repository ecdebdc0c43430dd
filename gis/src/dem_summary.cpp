#include <strata/gis/dem_summary.hpp>

#include <algorithm>
#include <cmath>
#include <limits>
#include <vector>

#include <strata/gis/geodesy.hpp>

namespace strata::gis {

Result<DemSummary> summarizeDem(const std::string& path, const ReadOptions& options) {
  ReadOptions o = options;
  o.allowAllNoData = true;  // an empty DEM is still described (nodata share 100 %)
  STRATA_TRY(DemInfo info, probeDem(path, o));
  STRATA_TRY(Raster r, readDem(path, o));
  DemSummary s;
  s.info = std::move(info);
  const Georef& g = r.georef;

  // Extent in the CRS: the four corners (the geotransform may be rotated).
  const double cx[4] = {0, double(g.width), double(g.width), 0}, cy[4] = {0, 0, double(g.height), double(g.height)};
  s.minX = s.minY = std::numeric_limits<double>::infinity();
  s.maxX = s.maxY = -std::numeric_limits<double>::infinity();
  for (int k = 0; k < 4; ++k) {
    s.minX = std::min(s.minX, g.transform.x(cx[k], cy[k]));
    s.maxX = std::max(s.maxX, g.transform.x(cx[k], cy[k]));
    s.minY = std::min(s.minY, g.transform.y(cx[k], cy[k]));
    s.maxY = std::max(s.maxY, g.transform.y(cx[k], cy[k]));
  }

  // Extent in lon/lat: the boundary, 64 points per edge, walked in order so that longitudes can
  // be unwrapped (a grid across 180 E reads 0..360, not -180..180).
  constexpr int kPerEdge = 64;
  std::vector<double> bx, by;
  for (int e = 0; e < 4; ++e) {
    for (int i = 0; i < kPerEdge; ++i) {
      const double t = double(i) / kPerEdge;
      const int n = (e + 1) % 4;
      const double col = cx[e] + (cx[n] - cx[e]) * t, row = cy[e] + (cy[n] - cy[e]) * t;
      bx.push_back(g.transform.x(col, row));
      by.push_back(g.transform.y(col, row));
    }
  }
  if (!g.geographic) {
    auto ct = CrsTransform::toGeographic(g);
    if (!ct) return fail(path + ": " + ct.message());
    ct->transform(bx.size(), bx.data(), by.data());
  }
  s.minLon = s.minLat = std::numeric_limits<double>::infinity();
  s.maxLon = s.maxLat = -std::numeric_limits<double>::infinity();
  double prev = std::nan("");
  for (size_t i = 0; i < bx.size(); ++i) {
    if (std::isnan(bx[i])) continue;  // outside the projection's domain
    double lon = bx[i];
    if (!std::isnan(prev)) lon = prev + std::remainder(lon - prev, 360.0);
    prev = lon;
    s.minLon = std::min(s.minLon, lon);
    s.maxLon = std::max(s.maxLon, lon);
    s.minLat = std::min(s.minLat, by[i]);
    s.maxLat = std::max(s.maxLat, by[i]);
  }

  // A pole inside the grid is the extreme latitude and every longitude meets there; the boundary
  // never passes through it (a polar stereographic grid's edge stays at -52 degrees while its
  // middle reaches -90).
  if (!g.geographic) {
    auto inv = CrsTransform::fromGeographic(g);
    if (!inv) return fail(path + ": " + inv.message());
    const auto& t = g.transform.c;
    const double det = t[1] * t[5] - t[2] * t[4];
    for (double lat : {90.0, -90.0}) {
      // The pole seen from two meridians: one point (polar projections) or a line (cylindrical
      // ones, whose edge the boundary walk already follows).
      double x[2] = {0, 120}, y[2] = {lat, lat};
      if (!inv->transform(2, x, y)) continue;
      double col[2], row[2];
      for (int k = 0; k < 2; ++k) {
        col[k] = ((x[k] - t[0]) * t[5] - (y[k] - t[3]) * t[2]) / det;
        row[k] = ((y[k] - t[3]) * t[1] - (x[k] - t[0]) * t[4]) / det;
      }
      const bool point = std::abs(col[0] - col[1]) < 1e-6 && std::abs(row[0] - row[1]) < 1e-6;
      if (point && col[0] > 0.5 && col[0] < g.width - 0.5 && row[0] > 0.5 && row[0] < g.height - 0.5) {
        (lat > 0 ? s.maxLat : s.minLat) = lat;
        s.minLon = -180;
        s.maxLon = 180;
      }
    }
  }

  // Centre pixel size along its edges, as geodesics on the body.
  const double mc = g.width / 2.0, mr = g.height / 2.0;
  auto p0 = pixelToLonLat(g, mc, mr), px = pixelToLonLat(g, mc + 1, mr), py = pixelToLonLat(g, mc, mr + 1);
  if (!p0 || !px || !py) return fail(path + ": the centre pixel has no lon/lat");
  s.pixelWidthM = geodesicDistanceM(*p0, *px, g.body);
  s.pixelHeightM = geodesicDistanceM(*p0, *py, g.body);

  s.cells = r.values.size();
  size_t valid = 0;
  double sum = 0;
  s.minM = std::numeric_limits<double>::infinity();
  s.maxM = -std::numeric_limits<double>::infinity();
  for (float v : r.values.data) {
    if (isNoData(v)) continue;
    ++valid;
    sum += v;
    s.minM = std::min(s.minM, double(v));
    s.maxM = std::max(s.maxM, double(v));
  }
  if (valid == 0) s.minM = s.maxM = std::nan("");
  s.meanM = valid ? sum / double(valid) : std::nan("");
  s.noDataFraction = s.cells ? double(s.cells - valid) / double(s.cells) : 0;
  return s;
}

}  // namespace strata::gis
