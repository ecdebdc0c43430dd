#pragma once
// Reading DEMs through GDAL (any raster format GDAL reads) and writing GeoTIFF / COG.
// Values come back as float32 metres with the band's scale/offset applied and nodata as NaN.

#include <cstddef>
#include <cstdint>
#include <optional>
#include <string>

#include <strata/core/result.hpp>
#include <strata/gis/raster.hpp>

namespace strata::gis {

/// A pixel rectangle of a raster: top-left (x, y) and size, in pixels.
struct PixelWindow {
  int x = 0, y = 0, width = 0, height = 0;
};

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
  /// True when the band's offset is the body's radius (PDS radius products such as LOLA's LDEM):
  /// readDem then returns heights above the reference sphere (offset minus the radius).
  bool offsetIsBodyRadius = false;
};

/// How to read a DEM.
struct ReadOptions {
  std::optional<PixelWindow> window;  ///< read only this window (default: the whole raster)
  /// For files without georeference: the CRS (EPSG:n, WKT or PROJ) and geotransform to use.
  /// Both or neither; without them a file with no CRS or no geotransform is refused.
  std::optional<std::string> crs;
  std::optional<GeoTransform> transform;
  int band = 1;                                 ///< 1-based band index
  std::size_t maxBytes = std::size_t(4) << 30;  ///< refuse windows whose float32 copy exceeds this
  bool allowAllNoData = false;                  ///< an all-nodata window is an error unless set
  bool keepBodyRadius = false;                  ///< keep radius values when offsetIsBodyRadius (no subtraction)
};

/// Metadata of a DEM (driver, georeference, band type, scale/offset, nodata). Errors name the file.
Result<DemInfo> probeDem(const std::string& path, const ReadOptions& options = {});

/// Reads a DEM (or a window of it) as metres; nodata -> NaN. NaN values stored in the file (other
/// than as the nodata value) are an error. The Georef describes the window read.
Result<Raster> readDem(const std::string& path, const ReadOptions& options = {});

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
};

/// Writes float32, DEFLATE-compressed, tiled GeoTIFF with CRS, geotransform and nodata; writes a
/// temporary next to `path` and renames it into place, so readers never see a partial file.
Status writeGeoTiff(const std::string& path, const Raster& raster, const WriteOptions& options = {});

}  // namespace strata::gis
