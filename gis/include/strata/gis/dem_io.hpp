#pragma once
// Reading DEMs through GDAL (any raster format GDAL reads) and writing GeoTIFF / COG.
// Values come back as float32 metres with the band's scale/offset applied and nodata as NaN.

#include <cstddef>
#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include <strata/core/result.hpp>
#include <strata/gis/raster.hpp>

namespace strata::gis {

/// A DEM's metadata, read without reading its pixels.
struct DemInfo {
  std::string path;
  std::string driver;    ///< GDAL short name: "GTiff", "PDS", "VRT", ...
  Georef georef;         ///< full-raster georeference
  std::string bandType;  ///< GDAL data type of band 1: "Int16", "Float32", ...
  int bandCount = 0;
  double scale = 1;  ///< value = raw * scale + offset
  double offset = 0;
  std::optional<double> nodata;  ///< raw nodata value, when the band has one
  double unitToMetres = 1;       ///< metres per unit of the band's vertical unit (0.3048 for feet)
  /// Block (GDAL's natural read unit) of band 1: a striped file has blockWidth = the raster width.
  int blockWidth = 0, blockHeight = 0;
  /// True when the band's offset is the body's radius (PDS radius products such as LOLA's LDEM):
  /// readDem then returns heights above the reference sphere (offset minus the radius).
  bool offsetIsBodyRadius = false;
};

/// How to read a DEM.
struct ReadOptions {
  std::optional<CellRect> window = std::nullopt;  ///< read only this window (default: the whole raster)
  /// A CRS (EPSG:n, WKT or PROJ) and/or a geotransform to assign, replacing the file's (for
  /// files without georeference; GDAL's -a_srs / -a_gt). A file left with no CRS or no
  /// geotransform is refused.
  std::optional<std::string> crs = std::nullopt;
  std::optional<GeoTransform> transform = std::nullopt;
  int band = 1;                                 ///< 1-based band index
  std::size_t maxBytes = std::size_t(4) << 30;  ///< refuse windows whose float32 copy exceeds this
  bool allowAllNoData = false;                  ///< an all-nodata window is an error unless set
  bool keepBodyRadius = false;                  ///< keep radius values when offsetIsBodyRadius (no subtraction)
};

/// Metadata of a DEM (driver, georeference, band type, scale/offset, nodata). Errors name the file.
Result<DemInfo> probeDem(const std::string& path, const ReadOptions& options = {});

/// Which parts of a georeference a file has of its own.
struct GeorefPresence {
  bool crs = false;
  bool transform = false;
};
/// Opens `path` and says whether it carries a CRS and a geotransform (before any assignment).
Result<GeorefPresence> georefPresence(const std::string& path);
/// The read options that give `path` the CRS `crs` (EPSG:n, WKT or PROJ; empty: none) and the
/// geotransform `transform` where the file has none of its own; what the file has is kept (the
/// commands' --assign-crs and --assign-geotransform).
Result<ReadOptions> assignMissingGeoref(const std::string& path, const std::string& crs,
                                        const std::optional<GeoTransform>& transform);

/// Reads a DEM (or a window of it) as metres; nodata -> NaN. NaN values stored in the file (other
/// than as the nodata value) are an error. The Georef describes the window read.
Result<Raster> readDem(const std::string& path, const ReadOptions& options = {});

/// An open DEM read window after window without reopening it, for streaming (ingest, mosaics).
/// Windows requested row of tiles by row of tiles decode each input block about once: a striped
/// file (blocks as wide as the raster) is read a band of whole rows at a time and the band is
/// kept until a window leaves it; other layouts go through GDAL's block cache, which is flushed
/// when a window starts a new row (so memory stays at about one row of tiles). Not thread-safe.
class DemFile {
 public:
  /// Probes `path` (as probeDem) and keeps it open. options.window is ignored.
  static Result<DemFile> open(const std::string& path, const ReadOptions& options = {});
  DemFile(DemFile&&) noexcept;
  DemFile& operator=(DemFile&&) noexcept;
  ~DemFile();

  const DemInfo& info() const;
  /// Reads a window inside the raster, as readDem with that window (options.allowAllNoData and
  /// options.maxBytes apply).
  Result<Raster> read(const CellRect& window);
  /// Reads a window that may reach past the raster's edges (NaN there), all-nodata allowed.
  Result<Grid<float>> readPadded(const CellRect& window);

 private:
  friend Result<Raster> readDem(const std::string& path, const ReadOptions& options);
  struct Impl;
  explicit DemFile(std::unique_ptr<Impl> impl);
  std::unique_ptr<Impl> impl_;
};

/// Parses a geotransform "c0,c1,c2,c3,c4,c5" (GDAL's order; commas or spaces between the six
/// numbers): every term finite, the pixel size not degenerate. `key` names the option in errors.
Result<GeoTransform> parseGeoTransform(std::string_view text, const std::string& key);

/// Reads a DEM on a lon/lat grid of its body, as planetary rendering needs: a geographic DEM as
/// it is; an equirectangular (equidistant cylindrical) DEM on a sphere with its standard parallel
/// at the equator, such as LOLA's LDEM, by relabelling its grid in degrees (x and y are linear in
/// lon and lat there, so no cell is resampled). Other projections are refused, naming the CRS.
Result<Raster> readDemLonLat(const std::string& path, const ReadOptions& options = {});
/// The same for a DEM already in memory (`label` names it in errors).
Result<Raster> toLonLat(Raster dem, const std::string& label);

/// How to write a GeoTIFF.
struct WriteOptions {
  bool cog = false;          ///< Cloud Optimized GeoTIFF (GDAL's COG driver, with overviews)
  float nodata = -32768.0f;  ///< value written for NaN cells (must not occur as a real value)
  int blockSize = 256;       ///< tile size in pixels (power of two, 16..4096)
  bool overwrite = true;     ///< false: an existing `path` is an error (checked atomically at the rename)
  /// GDAL metadata items (name, value) written into the file (gdalinfo lists them).
  std::vector<std::pair<std::string, std::string>> metadata;
  /// The band's description and unit (GDAL's band description and unit type: gdalinfo shows
  /// them, QGIS lists the description as the band's name); empty: none.
  std::string description, units;
};

/// Writes float32, DEFLATE-compressed, tiled GeoTIFF with CRS, geotransform and nodata; writes a
/// temporary next to `path` and renames it into place, so readers never see a partial file.
/// With `overwrite` false the temporary is linked into place (fails if `path` exists) instead.
Status writeGeoTiff(const std::string& path, const Raster& raster, const WriteOptions& options = {});

/// Rewrites the GeoTIFF at `path` as a Cloud Optimized GeoTIFF (GDAL's COG driver: tiles of
/// `blockSize`, DEFLATE with a predictor, overviews by averaging), keeping its values, nodata,
/// CRS, geotransform, band description, unit and metadata; through a temporary renamed into place.
Status rewriteAsCog(const std::string& path, int blockSize = 256);

/// A float32 GeoTIFF written window by window, by one process or by several in turn (each rank of
/// a run over MPI writes its own blocks; docs/distributed.md): createGeoTiff makes `path` (a
/// temporary, committed by the caller) with `georef`'s size, CRS and geotransform and no cells
/// written (sparse tiles: every cell reads as nodata until written); writeGeoTiffWindows then
/// writes each window's values at its cell (x, y), opening the file once and closing it after
/// (one writer at a time; a tile is written once per call, again by a later call that touches it).
/// Same encoding as writeGeoTiff (DEFLATE, float predictor, tiles of `options.blockSize`; `cog`
/// is not available: a COG's overviews need the whole raster).
struct GridWindow {
  int x = 0, y = 0;  ///< the top-left cell of `values` in the raster
  Grid<float> values;
};
Status createGeoTiff(const std::string& path, const Georef& georef, const WriteOptions& options = {});
Status writeGeoTiffWindows(const std::string& path, const std::vector<GridWindow>& windows, float nodata = -32768.0f);

}  // namespace strata::gis
