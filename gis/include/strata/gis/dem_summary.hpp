#pragma once
// What `strata info` reports about a DEM: georeference, extent in the CRS and in lon/lat,
// resolution in metres at the centre, value statistics, nodata share.

#include <cstddef>
#include <string>

#include <strata/core/result.hpp>
#include <strata/gis/dem_io.hpp>

namespace strata::gis {

/// A DEM described for people (all of it read once for the statistics).
struct DemSummary {
  DemInfo info;
  double minX = 0, maxX = 0, minY = 0, maxY = 0;  ///< extent in CRS units (degrees or metres)
  /// Extent in lon/lat on the CRS's own datum (degrees); longitudes as the grid runs (0..360 stays).
  double minLon = 0, maxLon = 0, minLat = 0, maxLat = 0;
  double pixelWidthM = 0, pixelHeightM = 0;  ///< geodesic size of the centre pixel (m)
  double minM = 0, maxM = 0, meanM = 0;      ///< over cells with data (NaN when there are none)
  std::size_t cells = 0;                     ///< width * height
  double noDataFraction = 0;                 ///< share of nodata cells, 0..1
};

/// Reads `path` (within options.maxBytes) and summarises it. Errors name the file.
Result<DemSummary> summarizeDem(const std::string& path, const ReadOptions& options = {});

}  // namespace strata::gis
