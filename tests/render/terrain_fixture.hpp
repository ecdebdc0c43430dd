#pragma once
// Helpers for the terrain renderer tests: DEMs as lon/lat grids, and golden-image comparison.

#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

#include <strata/core/result.hpp>
#include <strata/gis/raster.hpp>
#include <strata/render/image_io.hpp>

namespace strata::test {

/// Golden comparison: a pixel differs when any channel differs by more than `maxChannelDiff`;
/// passes when at most `allowedFraction` of the pixels differ. On failure (or when the golden
/// is missing) writes <name>.actual.png and <name>.diff.png to `outDir` and says so.
struct GoldenResult {
  bool ok = false;
  double differingFraction = 1;
  int maxDiff = 255;
  std::string message;
};
GoldenResult compareWithGolden(const std::string& name, const render::Image8& actual, int maxChannelDiff,
                               double allowedFraction, const std::filesystem::path& outDir);

}  // namespace strata::test
