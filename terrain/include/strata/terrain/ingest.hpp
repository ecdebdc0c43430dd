#pragma once
// Streaming ingest of rasters into a new tile store. Sources are window readers, so the input
// can be a DEM read through GDAL, a mosaic, or a synthetic field generated on the fly; memory
// stays at a few tiles whatever the input size. An ingest marks its store incomplete until it
// finishes, records its progress at checkpoints, stops cleanly at a tile boundary on Ctrl-C, and
// can be resumed (to the same bytes as an uninterrupted run).

#include <cstdint>
#include <filesystem>
#include <functional>
#include <string>
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
  /// What the field is read from (files with their size and time, options); recorded in the
  /// manifest, and a resume refuses sources whose identity differs. Empty: not checked.
  std::string identity = {};
};

/// How to build the store.
struct IngestOptions {
  TileLayout layout = TileLayout::Planar;
  TileMetricParams metric;
  std::vector<Material> materials = defaultMaterials();
  CacheOptions cache;
  int commitEveryTiles = 64;       ///< manifest checkpoints during the load (a killed ingest keeps them)
  double commitEverySeconds = 30;  ///< ... and at least this often
  bool resume = false;             ///< continue the interrupted ingest of the same sources into `dir`
};

/// What an ingest did.
struct IngestReport {
  int tilesPresent = 0, tilesAbsent = 0;
  uint64_t cellsRead = 0;  ///< source cells read (both passes under the Range metric)
  double seconds = 0;
  int64_t resumedAt = -1;        ///< resume: the tile it continued from (-1: a fresh ingest)
  bool alreadyComplete = false;  ///< resume of a store that was already complete (nothing done)
  StorageFootprint footprint;
  std::vector<ErrorSummary> errors;  ///< per field, over the whole store
};

/// Builds a store in `dir` over the base grid `georef` (width x height cells) from `sources`,
/// tile by tile in row-major order: under the MaxError metric in one pass; under the Range
/// metric in two (the field ranges first, then the tiles). The store is marked incomplete until
/// the end; checkpoints (every `commitEveryTiles` tiles or `commitEverySeconds`) record how far
/// it got. strata::interrupted() is polled after every tile: on Ctrl-C the progress is committed
/// and an error says how to resume. A read error commits the progress too and leaves the store
/// incomplete. Input with no data at all is an error (and the empty store it started is removed).
/// Fails naming the source field on a read error or a wrongly sized window.
Result<IngestReport> ingest(const std::filesystem::path& dir, const gis::Georef& georef,
                            const std::vector<IngestSource>& sources, const IngestOptions& options = {});

}  // namespace strata::terrain
