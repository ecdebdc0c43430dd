#pragma once
// Window readers over GDAL DEMs and mosaics (strata::gis), for ingest(): a tile's window is read
// (or warped) on demand, so an ingest never holds a whole DEM.

#include <string>
#include <vector>

#include <strata/core/result.hpp>
#include <strata/gis/mosaic.hpp>
#include <strata/terrain/ingest.hpp>

namespace strata::terrain {

/// Windows of band 1 of `path`, on the DEM's own grid (metres; nodata -> NaN). The file is opened
/// once (gis::DemFile), so a row of tiles decodes each of its blocks about once.
WindowReader demReader(const std::string& path);

/// Windows of `inputs` on `grid`, blended in order (gis::MosaicReader); NaN where no input has
/// data. Inputs on the grid's own cells are read directly, the others warped per window.
Result<WindowReader> mosaicReader(std::vector<gis::MosaicInput> inputs, const gis::Georef& grid);

}  // namespace strata::terrain
