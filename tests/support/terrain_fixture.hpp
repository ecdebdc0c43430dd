#pragma once
// Helpers for the terrain renderer tests: DEMs as lon/lat grids, and golden-image comparison.

#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

#include <strata/core/result.hpp>
#include <strata/gis/raster.hpp>
#include <strata/render/image_io.hpp>
#include <strata/render/terrain_renderer.hpp>

namespace strata::test {

/// The fixed oblique view of the Grand Canyon of the golden images and the error report: from
/// above the South Rim east of Grand Canyon Village, looking west-north-west along the canyon.
inline const render::CameraPose kCanyonCamera{
    .lon = -112.08, .lat = 36.06, .heightM = 3800, .headingDeg = 295, .pitchDeg = -14};

/// Tolerances of a golden comparison (Magnum's CompareImage habit: a per-pixel cap plus a mean).
/// A pixel's difference is the largest channel difference. The cap applies to every pixel, but
/// after allowing one pixel of displacement: a pixel passes when some pixel of the other image's
/// 3 x 3 neighbourhood is within `maxPixelDiff` of it, both ways (an edge or a silhouette moved
/// by one pixel, as another driver's rasterisation moves it, passes; a crack or a hole, which
/// has no match nearby, does not). The mean of the plain differences over the whole image is
/// capped by `maxMeanDiff`: a change of every pixel below the cap, such as a brightness shift,
/// does not pass, while rounding noise of +-2 on every channel (mean 1.8) does. A few lone
/// pixels over the cap (none of their 8 neighbours over it) pass: an NVIDIA H100 drew 1 or 2
/// such pixels in 5 of the llvmpipe goldens (a sub-pixel triangle at a silhouette rasterised
/// differently), while a crack, a seam or a hole is pixels that touch.
struct GoldenTolerance {
  int maxPixelDiff = 24;   ///< per pixel, after one pixel of displacement (0..255)
  double maxMeanDiff = 3;  ///< mean over all pixels of the plain difference (0..255)
  int maxLonePixels = 4;   ///< pixels over the cap with no neighbour over it
};

/// The outcome of a golden comparison, with the figures for the message and for tests.
struct GoldenResult {
  bool ok = false;
  int maxDiff = 255;             ///< largest plain pixel difference
  int maxDisplacedDiff = 255;    ///< largest difference after one pixel of displacement (the cap's)
  size_t pixelsOverCap = 0;      ///< pixels whose displaced difference exceeds the cap
  size_t lonePixels = 0;         ///< of those, pixels with none of their 8 neighbours over the cap
  double meanDiff = 255;         ///< mean plain pixel difference
  double plainFractionOver = 1;  ///< fraction of pixels whose plain difference exceeds the cap
  std::vector<uint8_t> diff;     ///< RGBA: grey = 4 x the plain difference, red where over the cap
  std::string message;
};

/// tests/render/golden/<name>.png in the source tree.
std::filesystem::path goldenPath(const std::string& name);

/// Compares two images of the same size and channels with the tolerances above.
GoldenResult compareImages(const render::Image8& expected, const render::Image8& actual, const GoldenTolerance& tol);

/// Compares `actual` with tests/render/golden/<name>.png. Always writes <name>.actual.png to
/// `outDir`; on failure also <name>.diff.png, and says so (a missing golden is a failure:
/// check the actual image and run scripts/promote-golden.sh).
GoldenResult compareWithGolden(const std::string& name, const render::Image8& actual, const GoldenTolerance& tol,
                               const std::filesystem::path& outDir);

}  // namespace strata::test
