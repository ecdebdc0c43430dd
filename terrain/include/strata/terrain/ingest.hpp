#pragma once
// Streaming ingest of rasters into a new tile store. Sources are window readers, so the input
// can be a DEM read through GDAL, a mosaic, or a synthetic field generated on the fly; memory
// stays at a few tiles whatever the input size.

#include <cstdint>
#include <filesystem>
#include <functional>
#include <vector>

#include <strata/core/result.hpp>
#include <strata/gis/raster.hpp>
#include <strata/terrain/tile_store.hpp>

namespace strata::terrain {

/// Reads base-grid cells [x, x+w) x [y, y+h) of a source as a w x h grid (NaN = no data).
using WindowReader = std::function<Result<gis::Grid<float>>(int x, int y, int w, int h)>;

/// One field of the new store and where its values come from.
struct IngestSource {
  StoreField field;
  WindowReader read;
};

/// How to build the store.
struct IngestOptions {
  TileLayout layout = TileLayout::Planar;
  TileMetricParams metric;
  std::vector<Material> materials = defaultMaterials();
  CacheOptions cache;
  int commitEveryTiles = 64;  ///< manifest checkpoints during the load (a killed ingest keeps them)
};

/// What an ingest did.
struct IngestReport {
  int tilesPresent = 0, tilesAbsent = 0;
  uint64_t cellsRead = 0;  ///< source cells read, both passes
  double seconds = 0;
  StorageFootprint footprint;
};

/// Builds a store in `dir` (new) over the base grid `georef` (width x height cells) from
/// `sources`, tile by tile in two passes: the first finds each field's range (the metric needs the
/// global range), the second writes every tile at the resolution the metric picks. Fails naming
/// the source field on a read error or a wrongly sized window.
Result<IngestReport> ingest(const std::filesystem::path& dir, const gis::Georef& georef,
                            const std::vector<IngestSource>& sources, const IngestOptions& options = {});

}  // namespace strata::terrain
