#include <strata/render/sun.hpp>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <numbers>

#include <glm/geometric.hpp>

#include <strata/core/angles.hpp>
#include <strata/gis/geodesy.hpp>

namespace strata::render {

namespace {
constexpr double kSunRadiusDeg = 0.2666;  // the sun's apparent radius from the Earth

double wrap180(double deg) { return deg - 360.0 * std::floor((deg + 180.0) / 360.0); }
}  // namespace

glm::dvec2 earthSubsolarPoint(std::chrono::sys_seconds utc) {
  // Days from J2000.0 (2000-01-01 12:00 TT; the 69 s TT - UTC difference moves the sun by 0.0008 degree).
  const double n = double(utc.time_since_epoch().count()) / 86400.0 - 10957.5;
  const double meanLon = 280.460 + 0.9856474 * n, anomaly = (357.528 + 0.9856003 * n) * kDeg;
  const double eclipticLon = (meanLon + 1.915 * std::sin(anomaly) + 0.020 * std::sin(2 * anomaly)) * kDeg;
  const double obliquity = (23.439 - 0.0000004 * n) * kDeg;
  const double rightAscension = std::atan2(std::cos(obliquity) * std::sin(eclipticLon), std::cos(eclipticLon));
  const double declination = std::asin(std::sin(obliquity) * std::sin(eclipticLon));
  const double gmstDeg = 280.46061837 + 360.98564736629 * n;
  return {wrap180(rightAscension / kDeg - gmstDeg), declination / kDeg};
}

Result<std::chrono::sys_seconds> parseUtc(const std::string& text) {
  int y = 0, mo = 0, d = 0, h = 0, mi = 0, s = 0, used = 0;
  const char* t = text.c_str();
  bool ok = std::sscanf(t, "%4d-%2d-%2dT%2d:%2d:%2d%n", &y, &mo, &d, &h, &mi, &s, &used) == 6;
  if (!ok) {
    s = 0;
    ok = std::sscanf(t, "%4d-%2d-%2dT%2d:%2d%n", &y, &mo, &d, &h, &mi, &used) == 5;
  }
  const std::string zone = ok ? text.substr(size_t(used)) : "";
  const std::chrono::year_month_day date{std::chrono::year(y), std::chrono::month(unsigned(mo)),
                                         std::chrono::day(unsigned(d))};
  if (!ok || (zone != "Z" && zone != "+00:00") || !date.ok() || h > 23 || mi > 59 || s > 60 || h < 0 || mi < 0 ||
      s < 0) {
    return fail("time '" + text + "': expected a UTC date and time such as 2026-06-21T18:30:00Z");
  }
  return std::chrono::sys_days(date) + std::chrono::hours(h) + std::chrono::minutes(mi) + std::chrono::seconds(s);
}

glm::dvec3 sunDirectionEnu(glm::dvec2 subsolar, double lonDeg, double latDeg) {
  const double ls = subsolar.x * kDeg, ps = subsolar.y * kDeg, l = lonDeg * kDeg, p = latDeg * kDeg;
  const glm::dvec3 sun(std::cos(ps) * std::cos(ls), std::cos(ps) * std::sin(ls), std::sin(ps));  // body-fixed
  const glm::dvec3 east(-std::sin(l), std::cos(l), 0.0);
  const glm::dvec3 north(-std::sin(p) * std::cos(l), -std::sin(p) * std::sin(l), std::cos(p));
  const glm::dvec3 up(std::cos(p) * std::cos(l), std::cos(p) * std::sin(l), std::sin(p));
  return glm::normalize(glm::dvec3(glm::dot(sun, east), glm::dot(sun, north), glm::dot(sun, up)));
}

glm::dvec3 sunDirectionEnu(double azimuthDeg, double elevationDeg) {
  const double a = azimuthDeg * kDeg, e = elevationDeg * kDeg;
  return {std::sin(a) * std::cos(e), std::cos(a) * std::cos(e), std::sin(e)};
}

gis::Grid<float> castShadows(const gis::Grid<float>& heights, const gis::Georef& georef, const SunSpec& sun,
                             float exaggeration, glm::dvec2 metresPerUnit) {
  const int w = heights.width, h = heights.height;
  gis::Grid<float> lit(w, h, 1.0f);
  const auto& c = georef.transform.c;
  const double radius = georef.body.semiMajorM;
  float hMax = -std::numeric_limits<float>::infinity();
  for (float v : heights.data) {
    if (!gis::isNoData(v)) hMax = std::max(hMax, v * exaggeration);
  }
  if (!std::isfinite(hMax) || w < 2 || h < 2) return lit;
  auto heightAt = [&](double x, double y) {  // bilinear between cell centres, x y in cells
    x = std::clamp(x - 0.5, 0.0, double(w - 1));
    y = std::clamp(y - 0.5, 0.0, double(h - 1));
    const int x0 = std::min(int(x), w - 2), y0 = std::min(int(y), h - 2), x1 = x0 + 1, y1 = y0 + 1;
    const double fx = x - x0, fy = y - y0;
    const double a = heights.at(x0, y0), b = heights.at(x1, y0), cc = heights.at(x0, y1), d = heights.at(x1, y1);
    return ((a * (1 - fx) + b * fx) * (1 - fy) + (cc * (1 - fx) + d * fx) * fy) * exaggeration;
  };
  glm::dvec3 centreSun = sun.dirEnu;
  if (sun.subsolarLonLat && !georef.geographic) {
    const auto ll = gis::pixelToLonLat(georef, 0.5 * w, 0.5 * h);
    if (ll) centreSun = sunDirectionEnu(*sun.subsolarLonLat, ll->lonDeg, ll->latDeg);
  }
#pragma omp parallel for schedule(dynamic, 4)
  for (int r = 0; r < h; ++r) {
    const double lat = c[3] + c[5] * (r + 0.5);
    // Metres a cell spans east and north on this row.
    const double cellX =
        georef.geographic ? radius * std::max(std::cos(lat * kDeg), 1e-6) * c[1] * kDeg : c[1] * metresPerUnit.x;
    const double cellY = georef.geographic ? radius * -c[5] * kDeg : -c[5] * metresPerUnit.y;
    for (int col = 0; col < w; ++col) {
      const float h0f = heights.at(col, r);
      if (gis::isNoData(h0f)) continue;
      glm::dvec3 s = centreSun;
      if (sun.subsolarLonLat && georef.geographic)
        s = sunDirectionEnu(*sun.subsolarLonLat, c[0] + c[1] * (col + 0.5), lat);
      const double horizontal = std::hypot(s.x, s.y);
      const double sunElev = std::atan2(s.z, horizontal);
      if (sunElev < -kSunRadiusDeg * kDeg) {
        lit.at(col, r) = 0;  // below the horizon of a flat body
        continue;
      }
      if (horizontal < 1e-9) continue;  // overhead: nothing casts a shadow
      const double h0 = double(h0f) * exaggeration;
      // One metre along the sun's azimuth in cells (rows grow southwards).
      const double ux = s.x / horizontal / cellX, uy = -s.y / horizontal / cellY;
      const double cellM = std::min(cellX, cellY);
      // The horizon as its steepest slope (a tangent: no atan2 per step), out to where terrain
      // at the grid's highest could no longer rise above the sun's line (its disc's top edge),
      // in steps of at least a cell growing with the distance.
      const double tanTop = std::tan(std::min(sunElev + kSunRadiusDeg * kDeg, 1.5));
      double maxSlope = -std::numeric_limits<double>::infinity();
      const double reach = (hMax - h0) / std::max(tanTop, 1e-4) + cellM;
      for (double dist = cellM; dist <= reach; dist += std::max(cellM, 0.02 * dist)) {
        const double x = col + 0.5 + ux * dist, y = r + 0.5 + uy * dist;
        if (x < 0 || y < 0 || x > w || y > h) break;
        const double z = heightAt(x, y);
        if (std::isnan(z)) continue;
        const double drop = dist * dist / (2 * radius);  // the body's curvature
        maxSlope = std::max(maxSlope, (z - h0 - drop) / dist);
        if (maxSlope > tanTop) break;
      }
      const double maxAngle = std::isfinite(maxSlope) ? std::atan(maxSlope) : -std::numbers::pi / 2;
      // The part of the disc above the horizon, linear across its diameter.
      const double t = (sunElev - maxAngle) / (2 * kSunRadiusDeg * kDeg) + 0.5;
      lit.at(col, r) = float(std::clamp(t, 0.0, 1.0));
    }
  }
  return lit;
}

}  // namespace strata::render
