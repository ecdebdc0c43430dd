#include <strata/render/screen_error.hpp>

#include <algorithm>
#include <cmath>
#include <numbers>
#include <numeric>
#include <vector>

namespace strata::render {

glm::dvec3 pixelRay(const FrameGeometry& frame, const CameraPose& camera, int x, int y, int width, int height) {
  const double t = std::tan(0.5 * camera.fovYDeg * std::numbers::pi / 180), aspect = double(width) / height;
  const glm::dvec3 eye((2 * (x + 0.5) / width - 1) * t * aspect, (1 - 2 * (y + 0.5) / height) * t, -1);
  return glm::normalize(glm::dvec3(glm::transpose(glm::dmat3(frame.view)) * eye));
}

glm::dvec3 unprojectPixel(const FrameGeometry& frame, const CameraPose& camera, int x, int y, int width, int height,
                          float depth) {
  const glm::dvec3 ray = pixelRay(frame, camera, x, y, width, height);
  const glm::dvec3 axis = glm::transpose(glm::dmat3(frame.view)) * glm::dvec3(0, 0, -1);
  const double along = frame.nearM / double(depth);  // reversed infinite depth: near / distance along the axis
  return ray * (along / glm::dot(ray, axis));
}

ScreenError screenSpaceError(const TerrainScene& scene, const CameraPose& camera, const Shading& shading,
                             const OffscreenTarget& target) {
  STRATA_CHECK(!scene.planetary()) << "screenSpaceError: planar scenes only";
  const int w = target.width(), h = target.height();
  const auto f = frameGeometry(scene, camera, shading, w, h);
  const auto depth = target.depth();
  const glm::dmat4 vp = f.viewProj();
  auto toPixel = [&](const glm::dvec3& p) {
    const glm::dvec4 c = vp * glm::dvec4(p, 1.0);
    return glm::dvec2((c.x / c.w * 0.5 + 0.5) * w, (0.5 - c.y / c.w * 0.5) * h);
  };
  std::vector<double> err;
  for (int y = 0; y < h; ++y) {
    for (int x = 0; x < w; ++x) {
      const float d = depth[size_t(y) * size_t(w) + size_t(x)];
      if (d <= 0) continue;
      const glm::dvec3 p = unprojectPixel(f, camera, x, y, w, h, d);
      const glm::dvec2 uv = f.uvCam + glm::dvec2(p) * f.uvPerMetre;
      if (uv.x < 0 || uv.y < 0 || uv.x > 1 || uv.y > 1) continue;
      const glm::dvec3 q(p.x, p.y, shading.exaggeration * scene.gridSurfaceAt(uv.x, uv.y) - f.camZ);
      err.push_back(glm::length(toPixel(p) - toPixel(q)));
    }
  }
  ScreenError s;
  s.pixels = err.size();
  if (err.empty()) return s;
  s.meanPx = std::accumulate(err.begin(), err.end(), 0.0) / double(err.size());
  std::sort(err.begin(), err.end());
  s.p99Px = err[std::min(err.size() - 1, size_t(0.99 * double(err.size())))];
  s.maxPx = err.back();
  return s;
}

std::vector<ElevationError> elevationErrorByDistance(const TerrainScene& scene, const CameraPose& camera,
                                                     const Shading& shading, const OffscreenTarget& target,
                                                     const std::vector<std::pair<double, double>>& bands) {
  STRATA_CHECK(!scene.planetary()) << "elevationErrorByDistance: planar scenes only";
  const int w = target.width(), h = target.height();
  const auto f = frameGeometry(scene, camera, shading, w, h);
  const auto depth = target.depth();
  const auto elevation = target.elevation();
  std::vector<std::vector<double>> err(bands.size());
  for (int y = 0; y < h; ++y) {
    for (int x = 0; x < w; ++x) {
      const size_t i = size_t(y) * size_t(w) + size_t(x);
      if (depth[i] <= 0 || !std::isfinite(elevation[i])) continue;
      const glm::dvec3 p = unprojectPixel(f, camera, x, y, w, h, depth[i]);
      const glm::dvec2 uv = f.uvCam + glm::dvec2(p) * f.uvPerMetre;
      if (uv.x < 0 || uv.y < 0 || uv.x > 1 || uv.y > 1) continue;
      const double d = glm::length(glm::dvec2(p));
      for (size_t b = 0; b < bands.size(); ++b) {
        if (d >= bands[b].first && d < bands[b].second) {
          err[b].push_back(std::abs(double(elevation[i]) - scene.gridSurfaceAt(uv.x, uv.y)));
        }
      }
    }
  }
  std::vector<ElevationError> out(bands.size());
  for (size_t b = 0; b < bands.size(); ++b) {
    auto& e = err[b];
    auto& o = out[b];
    o.fromM = bands[b].first;
    o.toM = bands[b].second;
    o.pixels = e.size();
    if (e.empty()) continue;
    o.meanM = std::accumulate(e.begin(), e.end(), 0.0) / double(e.size());
    std::sort(e.begin(), e.end());
    o.p95M = e[std::min(e.size() - 1, size_t(0.95 * double(e.size())))];
    o.maxM = e.back();
  }
  return out;
}

}  // namespace strata::render
