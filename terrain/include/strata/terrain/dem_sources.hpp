#pragma once
// Window readers over GDAL DEMs and mosaics (strata::gis), for ingest(): a tile's window is read
// (or warped) on demand, so an ingest never holds a whole DEM.

#include <string>
#include <vector>

#include <strata/core/result.hpp>
#include <strata/gis/mosaic.hpp>
#include <strata/terrain/ingest.hpp>

namespace strata::terrain {

/// Windows of band 1 of `path`, on the DEM's own grid (metres; nodata -> NaN).
WindowReader demReader(const std::string& path);

/// Windows of `inputs` warped onto `grid` and blended in order (gis::warpToGrid / blendInto);
/// NaN where no input has data. When the only input is a file on exactly `grid` with mode
/// Replace, windows are read directly instead of warped.
Result<WindowReader> mosaicReader(std::vector<gis::MosaicInput> inputs, const gis::Georef& grid);

}  // namespace strata::terrain
