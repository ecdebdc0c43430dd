#pragma once
// The out-of-core layered terrain: a pyramid of equal-footprint tiles on disk, each stored at the
// coarsest resolution whose reconstruction stays within a vertical error bound (or, as an option,
// at the resolution the seed's relief metric picks), each with a mip chain, read and written
// through a RAM cache with a byte budget. One writer at a time (a lock); a store being built is
// marked incomplete until its ingest finishes. See docs/architecture.md, "Terrain store".
//
// Grids and levels: the store's base grid (level 0) is georef.width x georef.height cells. A tile
// covers footprint() = 2^maxExp base cells a side; level L has cells 2^L base cells wide, so a tile
// spans footprint() >> L level-L cells. A tile of exponent e stores 2^e x 2^e samples per field
// (box means of the base cells; e = maxExp is the base grid itself) plus its mip chain down to 1x1
// (box means of the level before; rounded to whole numbers where the samples are whole numbers,
// as GDAL's overviews of an integer raster are).
// A base-grid read of a tile repeats each sample over its block (piecewise constant): that is the
// reconstruction the error bound is measured on.

#include <cstdint>
#include <filesystem>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <strata/core/result.hpp>
#include <strata/gis/raster.hpp>
#include <strata/terrain/layered_terrain.hpp>
#include <strata/terrain/material.hpp>

namespace strata::terrain {

/// Planar: a projected CRS, the domain is a rectangle (cells outside are no data). Global: a
/// geographic grid covering the whole body (360 x 180 degrees); reads wrap across the 0/360 seam
/// and fold over the poles.
enum class TileLayout { Planar, Global };

/// How a tile's resolution is chosen.
/// MaxError: the coarsest 2^e (minExp <= e <= maxExp) whose reconstruction (each sample repeated
/// over its block) differs from every source cell by at most maxErrorM, and whose blocks are each
/// all data or all no data (a coarse tile never fills a void). Range: the seed's relief metric
/// (chooseTileExp), with the same no-void rule.
enum class TileMetric { MaxError, Range };

/// Default vertical tolerance of MaxError (m): half a metre, below the 1 m step of the integer
/// DEMs (SRTM, ETOPO, MOLA) and far below their stated accuracy (SRTM: 16 m absolute, 6 m
/// relative at 90 %). See docs/architecture.md, "Terrain store".
inline constexpr double kDefaultMaxErrorM = 0.5;

/// The metric's parameters: tile resolutions are 2^minExp .. 2^maxExp cells a side.
struct TileMetricParams {
  int minExp = 5;
  int maxExp = 10;
  TileMetric kind = TileMetric::MaxError;
  double maxErrorM = kDefaultMaxErrorM;  ///< MaxError: largest |stored - source| allowed (m), finite, >= 0
};

/// The seed metric. For each field f, m_f = tileRange[f] / globalRange[f] (0 where either is 0 or
/// NaN); m = max_f m_f decides. [0,1] is cut into (maxExp - minExp + 1) equal bins, bin k giving
/// exponent minExp + k (m = 1 gives maxExp).
int chooseTileExp(const std::vector<float>& tileRange, const std::vector<float>& globalRange, int minExp, int maxExp);

/// Box mean of `factor` x `factor` blocks, ignoring NaN cells (all-NaN blocks give NaN).
/// Precondition: the grid's sides are multiples of `factor`.
gis::Grid<float> boxDownsample(const gis::Grid<float>& src, int factor);
/// Each cell repeated `factor` x `factor` times (piecewise-constant upsampling; keeps block means).
gis::Grid<float> replicateUpsample(const gis::Grid<float>& src, int factor);

/// One stored field: its name (letters, digits, '_' or '-'), kind and material name (material layers).
struct StoreField {
  std::string name;
  LayerKind kind = LayerKind::Bedrock;
  std::string material;
};

/// What a new store is: its base grid and georeference, layout, metric, fields and materials.
struct StoreDesc {
  gis::Georef georef;  ///< width x height = the base grid
  TileLayout layout = TileLayout::Planar;
  TileMetricParams metric;
  std::vector<StoreField> fields;
  std::vector<Material> materials = defaultMaterials();
};

/// The manifest's record of one tile.
struct TileRecord {
  bool present = false;           ///< false: the tile has no data (outside a non-rectangular domain)
  int exp = 0;                    ///< stored resolution 2^exp
  uint64_t generation = 0;        ///< bumped on every rewrite; part of the file name
  std::string file;               ///< relative to the store folder
  uint32_t crc32 = 0;             ///< zlib crc32 of the whole file
  uint64_t bytes = 0;             ///< file size
  std::vector<float> minV, maxV;  ///< per field, over the tile's valid base cells (NaN: none)
  /// Per field: base cells with data, and the largest and RMS |reconstruction - source| over them
  /// (m). After edits (writeWindow) the errors are bounds: the error against what was written
  /// plus the tile's earlier error.
  std::vector<uint64_t> validCells;
  std::vector<float> maxErrorM, rmsErrorM;
};

/// Achieved vertical error over some tiles of one field.
struct ErrorSummary {
  double maxM = 0;     ///< largest |reconstruction - source| (m)
  double rmsM = 0;     ///< root mean square over the cells with data (m)
  uint64_t cells = 0;  ///< cells with data
};

/// How far a store's build got. An ingest marks its store incomplete while it runs and records
/// its progress at each checkpoint, so `ingest --resume` continues where it stopped; readers
/// refuse an incomplete store unless told otherwise.
struct BuildState {
  bool complete = true;
  int pass = 0;           ///< ingest pass in progress (1: field ranges, 2: tiles)
  int64_t tilesDone = 0;  ///< tiles of that pass done, in row-major order
  /// Per field, what it is read from (files with size and time, options): resume checks it.
  std::vector<std::string> sources;
};

/// How to open a store.
struct OpenOptions {
  bool allowIncomplete = false;  ///< open a store whose build did not finish (check, resume)
};

/// RAM cache settings.
struct CacheOptions {
  size_t budgetBytes = size_t(256) << 20;  ///< decoded tiles kept in RAM (bytes)
  bool prefetch = true;                    ///< load the 8 neighbours of a missed tile in the background
  double loadDelayMs = 0;                  ///< added to every tile decode (a slow disk, for tests and benchmarks)
};

/// Demand lookups of the decoded-tile cache since open (or resetCacheStats()).
struct CacheStats {
  uint64_t hits = 0, misses = 0;
  uint64_t prefetchLoads = 0;  ///< tiles decoded by the prefetcher
  uint64_t prefetchHits = 0;   ///< demand hits on a tile the prefetcher loaded
  uint64_t syncLoads = 0;      ///< tiles decoded by readWindow on the calling thread (a wait for the disk)
  uint64_t requestLoads = 0;   ///< tiles decoded by the background loader for tryReadWindow
  uint64_t evictions = 0;
  size_t bytes = 0;  ///< decoded bytes held now
  double hitRate() const { return hits + misses ? double(hits) / double(hits + misses) : 0.0; }
};

/// A tile that failed verification: its file (relative to the store) and why.
struct TileProblem {
  std::string file;
  std::string message;
};

/// Sizes for "memory saved against a dense grid". Samples are counted where they cover the grid:
/// an edge tile's samples beyond the grid's edge hold nothing (NaN, compressed away) and are not
/// counted, so a store never "saves" a negative amount.
struct StorageFootprint {
  uint64_t denseSamples = 0;    ///< width x height x fields of the base grid
  uint64_t storedSamples = 0;   ///< over present tiles: samples (finest level) covering the grid, x fields
  uint64_t storedWithMips = 0;  ///< the same with each tile's mip chain
  uint64_t fileBytes = 0;       ///< tile files on disk (compressed)
  double savedFraction() const { return denseSamples ? 1.0 - double(storedSamples) / double(denseSamples) : 0.0; }
};

class TileStore {
 public:
  /// Creates an empty, incomplete store (every tile absent) in `dir` (created; must not hold a
  /// manifest or tile files yet) and holds its writer lock. Call setBuildState({.complete = true})
  /// and commit() when it holds its data.
  static Result<TileStore> create(const std::filesystem::path& dir, StoreDesc desc, CacheOptions cache = {});
  /// Opens a store from its manifest. Fails, naming the file and field, on a bad manifest, and on
  /// an incomplete store unless `options.allowIncomplete`. Reading takes no lock; the first write
  /// takes the store's writer lock (and fails if another process or object holds it).
  static Result<TileStore> open(const std::filesystem::path& dir, CacheOptions cache = {}, OpenOptions options = {});

  TileStore(TileStore&&) noexcept;
  TileStore& operator=(TileStore&&) noexcept;
  ~TileStore();

  const StoreDesc& desc() const;
  const std::filesystem::path& dir() const;
  int width() const;  ///< base grid cells
  int height() const;
  int footprint() const;  ///< base cells per tile side (2^maxExp)
  int tilesX() const;
  int tilesY() const;
  int maxLod() const;             ///< coarsest level (maxExp): one cell per tile
  int levelWidth(int lod) const;  ///< ceil(width / 2^lod)
  int levelHeight(int lod) const;
  /// Index of the field called `name`, or -1.
  int fieldIndex(const std::string& name) const;
  const TileRecord& tile(int tx, int ty) const;
  /// The range each tile's metric is evaluated against (the union of the tiles' ranges).
  std::pair<float, float> globalRange(int field) const;
  /// Achieved error of field `field` over the whole store, or over the tiles a base-grid window
  /// touches.
  ErrorSummary errorSummary(int field, std::optional<gis::CellRect> baseWindow = std::nullopt) const;
  const BuildState& buildState() const;
  /// Records the build state (written by the next commit).
  void setBuildState(BuildState state);

  /// Reads `window` (cells of level `lod`) of field `field`. Touches only the tiles the window
  /// covers. Planar: cells outside the grid are NaN. Global: x wraps at the seam and rows beyond
  /// a pole continue on the other side of it. Fails naming the tile file when a tile is corrupt.
  Result<gis::Grid<float>> readWindow(int field, gis::CellRect window, int lod = 0);
  /// readWindow without waiting for the disk: the window if every tile level it needs is decoded
  /// in RAM, else nullopt, after asking the background loader for each missing one. Requests are
  /// served in order, before neighbour prefetches, one at a time, and decode into the RAM cache
  /// (a later call reads them, unless the cache evicted them meanwhile). Fails like readWindow on
  /// bad arguments, and naming the tile once the loader found it corrupt.
  Result<std::optional<gis::Grid<float>>> tryReadWindow(int field, gis::CellRect window, int lod = 0);
  /// Drops the loader's requests that it has not started (the reader moved on; it asks again).
  void clearRequests();
  /// Tile levels requested and not yet decoded (queued or being decoded).
  int requestsPending() const;
  /// Writes base-grid cells at (x, y) of field `field` (inside the grid). The affected tiles are
  /// re-evaluated and rewritten (as new files); if the global range moves, every tile whose
  /// metric changes is resampled. Nothing is visible to other openers before commit().
  Status writeWindow(int field, int x, int y, const gis::Grid<float>& values);
  /// Replaces tile (tx, ty): `fields` are footprint() x footprint() base grids, one per field
  /// (NaN outside the domain). Its resolution comes from the current global range; call
  /// reevaluate() afterwards (writeWindow does) to let range changes reach other tiles.
  Status putTile(int tx, int ty, const std::vector<gis::Grid<float>>& fields);
  /// Sets the range the metric is evaluated against before a bulk load (ingest knows it up front).
  void setEvaluationRange(int field, float lo, float hi);
  /// Recomputes the global ranges from the tiles; where they moved, resamples every tile whose
  /// exponent changes.
  Status reevaluate();
  /// Takes the store's writer lock now (writes take it anyway): fails, naming the holder's pid,
  /// while another process or TileStore object writes the store. Held until destruction.
  Status lockForWriting();
  /// Makes all writes durable: the manifest is written to a temporary file and renamed into
  /// place (after the tile files it names), then superseded tile files are removed (only files
  /// named like this store's tiles, x<X>_y<Y>_g<G>.exr, and their temporaries; nothing else in
  /// the folder is touched).
  Status commit();

  /// Checks the whole store: the manifest's CRS parses and agrees with its EPSG code, name and
  /// body; every present tile's file exists with its size and checksum, decodes at the recorded
  /// resolution, carries the manifest's georeference for its place, and holds samples within the
  /// recorded range and error; field ranges and error summaries agree with the tiles; no tile
  /// file in tiles/ is left that the manifest does not name. Empty: the store is sound.
  std::vector<TileProblem> verify() const;
  /// Tile exponents, tilesX() x tilesY() (NaN where absent).
  gis::Grid<float> resolutionMap() const;
  StorageFootprint footprintStats() const;
  /// The georeference of a window read at `lod` (same CRS, scaled and shifted geotransform).
  gis::Georef windowGeoref(gis::CellRect window, int lod) const;
  /// All fields of a base-grid window as a LayeredTerrain (materials from the store).
  Result<LayeredTerrain> readTerrain(gis::CellRect window);

  CacheStats cacheStats() const;
  void resetCacheStats();
  /// Drops every decoded tile from RAM (for cold-read measurements).
  void clearCache();

 private:
  struct Impl;
  explicit TileStore(std::unique_ptr<Impl> impl);
  // readWindow (missing null) or tryReadWindow (missing set when a tile level was requested).
  Result<gis::Grid<float>> read(int field, gis::CellRect window, int lod, bool* missing);
  std::unique_ptr<Impl> impl_;
};

/// A store described for people (what `strata info STORE` and `strata check STORE` print): grid,
/// CRS, tiles, metric and tolerance, build state, per field its range and achieved error, the
/// resolution histogram and the storage saved. One line per item, each ending in '\n'.
std::string describeStore(const TileStore& store);

}  // namespace strata::terrain
