#pragma once
// A georeferenced raster draped over a terrain scene (an orthophoto, a hillshade, a flood map):
// warped by GDAL onto the scene's own grid (its CRS and extent, `texelsPerCell` texels a DEM
// cell a side; at most 8192 texels a side over the whole extent of a larger or streamed scene),
// so the texture lines up with the height texture's coordinates whatever the raster's CRS. What the bands become:
// - 3 or 4 Byte bands: red, green, blue (and alpha);
// - 1 Byte band: grey (a hillshade); 2 Byte bands: grey and alpha;
// - 1 band of any other type (depths, speeds, times): a colour ramp over `range` (default: the
//   2nd to 98th percentile of the values on the scene), values below it transparent when
//   `transparentBelow` is set (dry cells of a depth map).
// Cells the raster does not cover or has no data for are transparent.

#include <array>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include <strata/core/result.hpp>
#include <strata/gis/mosaic.hpp>
#include <strata/gis/raster.hpp>

namespace strata::render {

struct DrapeOptions {
  int texelsPerCell = 4;  ///< drape texels per DEM cell, a side (the texture stays within 8192 a side)
  gis::Resampling resampling = gis::Resampling::Bilinear;
  std::optional<std::array<double, 2>> range;  ///< one-band rasters: the values at the ramp's ends
  bool transparentBelow = false;               ///< one-band rasters: values below range[0] not drawn
};

/// RGBA8 texels on the scene's grid, row 0 along the DEM's row 0.
struct DrapeImage {
  int width = 0, height = 0;
  std::vector<uint8_t> rgba;
  gis::Georef georef;                 ///< the grid the texels lie on (the scene's, finer)
  std::array<double, 2> range{0, 0};  ///< one-band rasters: the ramp's ends as used
  std::string description;            ///< e.g. "RGB (3 Byte bands)", "ramp 0.1 .. 12.5 (Float32)"
};

/// Warps `path` onto `sceneGeoref` (same CRS and extent, finer cells). Errors name the file.
Result<DrapeImage> loadDrape(const std::string& path, const gis::Georef& sceneGeoref, const DrapeOptions& options = {});

/// One band already on a grid (a flood run's maximum depth on the scene's own cells) through the
/// ramp, as loadDrape does for a one-band raster; NaN cells transparent. `georef` is the grid's.
Result<DrapeImage> drapeFromGrid(const gis::Grid<float>& values, const gis::Georef& georef, const DrapeOptions& options,
                                 const std::string& name);

/// The ramp used for one-band rasters at t in [0, 1] (dark blue through teal and green to yellow,
/// perceptually ordered as viridis), as RGB bytes.
std::array<uint8_t, 3> drapeRamp(double t);

}  // namespace strata::render
