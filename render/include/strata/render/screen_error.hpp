#pragma once
// Screen-space error of a terrain render against the full-resolution reference surface (the
// DEM's grid, two triangles per cell as GridRenderer draws it), for tests and benchmarks.

#include <cstddef>
#include <utility>
#include <vector>

#include <glm/glm.hpp>

#include <strata/render/terrain_renderer.hpp>

namespace strata::render {

/// Error statistics over the terrain pixels of one render (pixels).
struct ScreenError {
  double meanPx = 0, p99Px = 0, maxPx = 0;
  size_t pixels = 0;  ///< terrain pixels measured
};

/// For each terrain pixel of `target` (just drawn from `camera`, planar scenes), the surface
/// point drawn there (from the depth buffer) and the reference surface's point at the same
/// horizontal position are both projected; their distance is the pixel's error.
ScreenError screenSpaceError(const TerrainScene& scene, const CameraPose& camera, const Shading& shading,
                             const OffscreenTarget& target);

/// The rendered elevation against the full-resolution grid over a band of horizontal distances
/// from the viewer (metres, unexaggerated).
struct ElevationError {
  double fromM = 0, toM = 0;  ///< the band of horizontal distances from the viewer (m)
  size_t pixels = 0;          ///< terrain pixels whose ground point lies in the band
  double meanM = 0, p95M = 0, maxM = 0;
};

/// For each terrain pixel of `target` (just drawn from `camera`; planar scenes), the ground point
/// drawn there (from the depth buffer) and the elevation the renderer wrote there (the elevation
/// attachment) against the reference surface's elevation at that point; pixels are binned by the
/// point's horizontal distance from the viewer into `bands` ([from, to) pairs, metres).
std::vector<ElevationError> elevationErrorByDistance(const TerrainScene& scene, const CameraPose& camera,
                                                     const Shading& shading, const OffscreenTarget& target,
                                                     const std::vector<std::pair<double, double>>& bands);

/// Viewer-relative ENU direction of the ray through the centre of pixel (x, y), row 0 on top.
glm::dvec3 pixelRay(const FrameGeometry& frame, const CameraPose& camera, int x, int y, int width, int height);

/// Viewer-relative position (m) of the surface seen at pixel (x, y) with reversed depth `depth` > 0.
glm::dvec3 unprojectPixel(const FrameGeometry& frame, const CameraPose& camera, int x, int y, int width, int height,
                          float depth);

}  // namespace strata::render
