#pragma once
// Helpers for the terrain renderer tests: synthetic DEMs, a minimal GDAL DEM reader (a stand-in
// until strata::gis::readDem lands on main; delete it then), and golden-image comparison.

#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

#include <strata/core/result.hpp>
#include <strata/gis/raster.hpp>
#include <strata/render/image_io.hpp>

namespace strata::test {

/// Reads band 1 of a DEM with GDAL (scale/offset applied, nodata -> NaN), georeferenced with
/// `body`. Test-only stand-in for strata::gis::readDem. A PDS product in an equirectangular
/// projection in metres on the body's sphere (the LOLA LDEM) is turned into lon/lat degrees,
/// and `subtractM` (e.g. the reference radius the file adds as an offset) is taken off.
Result<gis::Raster> readDemForTest(const std::string& path, const gis::Body& body, double subtractM = 0);

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
