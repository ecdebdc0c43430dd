#pragma once
// Private GDAL helpers shared by dem_io, geodesy and mosaic: registration, quiet error capture,
// owning handles, Georef from a dataset. GDAL headers stay out of the public headers.

#include <gdal_priv.h>
#include <ogr_spatialref.h>

#include <memory>
#include <optional>
#include <string>

#include <strata/core/result.hpp>
#include <strata/gis/raster.hpp>

namespace strata::gis::detail {

/// Registers GDAL's drivers once (thread-safe).
void ensureGdal();

/// Silences GDAL's stderr output for its lifetime and keeps the last error message.
class GdalErrorCapture {
 public:
  GdalErrorCapture();
  ~GdalErrorCapture();
  GdalErrorCapture(const GdalErrorCapture&) = delete;
  GdalErrorCapture& operator=(const GdalErrorCapture&) = delete;
  /// GDAL's last error (failure or warning) since construction, or `fallback`.
  std::string last(const std::string& fallback = "unknown GDAL error") const;

 private:
  static void CPL_STDCALL handler(CPLErr level, CPLErrorNum num, const char* msg);
  std::string message_;
  bool failed_ = false;
};

struct DatasetCloser {
  GDALDataset* base = nullptr;  ///< a dataset this one reads from (a VRT's source), closed after it
  void operator()(GDALDataset* ds) const {
    GDALClose(GDALDataset::ToHandle(ds));
    if (base) GDALClose(GDALDataset::ToHandle(base));
  }
};
using DatasetPtr = std::unique_ptr<GDALDataset, DatasetCloser>;

/// `message` with every mention of `path` removed (GDAL and libtiff repeat the file name).
std::string withoutPath(std::string message, const std::string& path);

/// Opens a raster read-only; errors name the file: missing, not a raster, corrupt.
Result<DatasetPtr> openRaster(const std::string& path);

/// Opens a raster read-only with a CRS and/or geotransform assigned (replacing the file's): the
/// file wrapped in an in-memory VRT that carries them, so GDAL's warper and readers see them.
/// Without either it is openRaster. Errors name the file (and the CRS that does not parse).
Result<DatasetPtr> openRaster(const std::string& path, const std::optional<std::string>& crs,
                              const std::optional<GeoTransform>& transform);

/// Parses a user CRS ("EPSG:32612", WKT, PROJ string); traditional GIS axis order (x = lon/east).
Result<OGRSpatialReference> parseCrs(const std::string& text);

/// Fills Georef's CRS fields (WKT, EPSG, name, geographic, body) from a spatial reference.
void fillCrs(const OGRSpatialReference& srs, Georef& georef);

/// The spatial reference of a Georef (traditional axis order), or an error naming the CRS.
Result<OGRSpatialReference> srsOf(const Georef& georef);

/// An in-memory float32 dataset with the Georef's size, CRS and geotransform, nodata NaN,
/// filled with NaN (or with the raster's values when given).
Result<DatasetPtr> memDataset(const Georef& georef, const Grid<float>* values);

}  // namespace strata::gis::detail
