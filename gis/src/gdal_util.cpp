#include "gdal_util.hpp"

#include <strata/core/files.hpp>

#include <cpl_conv.h>
#include <cpl_error.h>
#include <cpl_vsi.h>

#include <cmath>
#include <filesystem>
#include <mutex>

namespace strata::gis::detail {

void ensureGdal() {
  static std::once_flag once;
  std::call_once(once, [] { GDALAllRegister(); });
}

GdalErrorCapture::GdalErrorCapture() {
  CPLPushErrorHandlerEx(&GdalErrorCapture::handler, this);
  CPLErrorReset();
}

GdalErrorCapture::~GdalErrorCapture() { CPLPopErrorHandler(); }

void CPL_STDCALL GdalErrorCapture::handler(CPLErr level, CPLErrorNum, const char* msg) {
  auto* self = static_cast<GdalErrorCapture*>(CPLGetErrorHandlerUserData());
  if (!self || level == CE_Debug || !msg) return;
  // Keep the first failure (the cause; later ones are usually consequences), else the last warning.
  if (level >= CE_Failure) {
    if (!self->failed_) self->message_ = msg;
    self->failed_ = true;
  } else if (!self->failed_) {
    self->message_ = msg;
  }
}

std::string GdalErrorCapture::last(const std::string& fallback) const {
  std::string m = message_.empty() ? fallback : message_;
  for (char& c : m) {
    if (c == '\n' || c == '\r') c = ' ';
  }
  return m;
}

std::string withoutPath(std::string message, const std::string& path) {
  // libtiff prefixes its messages with the file name; ours already starts with it.
  for (const std::string& p : {path + ": ", path + ":", path}) {
    for (size_t at = message.find(p); at != std::string::npos; at = message.find(p)) message.erase(at, p.size());
  }
  return message;
}

Result<DatasetPtr> openRaster(const std::string& path) {
  ensureGdal();
  const bool virtualPath = path.rfind("/vsi", 0) == 0;
  if (!virtualPath) {
    STRATA_TRY_STATUS(requireRegularFile(path, "a raster file"));
  } else {
    VSIStatBufL st;
    if (VSIStatL(path.c_str(), &st) != 0) return fail(path + ": no such file");
  }
  GdalErrorCapture errors;
  GDALDatasetH h = GDALOpenEx(path.c_str(), GDAL_OF_RASTER | GDAL_OF_READONLY, nullptr, nullptr, nullptr);
  if (!h) {
    // GDAL says "not recognized as a supported file format" for non-rasters; TIFF parse errors
    // (corrupt or truncated headers) come through as failures with libtiff's message.
    const std::string why = errors.last("");
    if (why.empty() || why.find("not recognized as a supported file format") != std::string::npos) {
      return fail(path + ": not a raster GDAL can read");
    }
    return fail(path + ": cannot open as a raster (corrupt or truncated?): " + withoutPath(why, path));
  }
  DatasetPtr ds(GDALDataset::FromHandle(h));
  if (ds->GetRasterCount() < 1) return fail(path + ": not a raster (no bands)");
  return ds;
}

Result<DatasetPtr> openRaster(const std::string& path, const std::optional<std::string>& crs,
                              const std::optional<GeoTransform>& transform) {
  STRATA_TRY(DatasetPtr ds, openRaster(path));
  if (!crs && !transform) return ds;
  std::optional<OGRSpatialReference> srs;
  if (crs) {
    auto parsed = parseCrs(*crs);
    if (!parsed) return fail(path + ": " + parsed.message());
    srs = std::move(*parsed);
  }
  GdalErrorCapture errors;
  GDALDriver* vrt = GetGDALDriverManager()->GetDriverByName("VRT");
  STRATA_CHECK(vrt) << "GDAL has no VRT driver";
  // A VRT copy references the file's pixels (nothing is copied) and takes its own georeference.
  GDALDataset* copy = vrt->CreateCopy("", ds.get(), FALSE, nullptr, nullptr, nullptr);
  if (!copy) return fail(path + ": cannot assign a georeference: " + errors.last());
  // The VRT reads through the file's dataset: it is closed after the VRT.
  DatasetPtr wrapped(copy, DatasetCloser{ds.release()});
  if (transform) {
    double gt[6];
    std::copy(transform->c, transform->c + 6, gt);
    wrapped->SetGeoTransform(gt);
  }
  if (srs) wrapped->SetSpatialRef(&*srs);
  return wrapped;
}

Result<OGRSpatialReference> parseCrs(const std::string& text) {
  ensureGdal();
  OGRSpatialReference srs;
  GdalErrorCapture errors;
  if (text.empty() || srs.SetFromUserInput(text.c_str()) != OGRERR_NONE) {
    return fail("unknown CRS '" + text + "'" + (errors.last("").empty() ? "" : ": " + errors.last("")));
  }
  srs.SetAxisMappingStrategy(OAMS_TRADITIONAL_GIS_ORDER);
  return srs;
}

void fillCrs(const OGRSpatialReference& srsIn, Georef& georef) {
  OGRSpatialReference srs(srsIn);
  srs.SetAxisMappingStrategy(OAMS_TRADITIONAL_GIS_ORDER);
  const char* wktOptions[] = {"FORMAT=WKT2_2019", nullptr};
  char* wkt = nullptr;
  if (srs.exportToWkt(&wkt, wktOptions) == OGRERR_NONE && wkt) georef.crsWkt = wkt;
  CPLFree(wkt);
  const char* name = srs.GetName();
  georef.crsName = name ? name : "";
  georef.geographic = srs.IsGeographic();
  georef.epsg.reset();
  const char* root = srs.IsProjected() ? "PROJCS" : (srs.IsGeographic() ? "GEOGCS" : nullptr);
  OGRSpatialReference ident(srs);
  const char* auth = root ? ident.GetAuthorityName(root) : nullptr;
  if (!auth) {
    // No explicit code (e.g. a GeoTIFF with user-defined keys matching EPSG): ask GDAL to identify.
    if (ident.AutoIdentifyEPSG() == OGRERR_NONE) auth = root ? ident.GetAuthorityName(root) : nullptr;
  }
  if (auth && EQUAL(auth, "EPSG")) {
    const char* code = ident.GetAuthorityCode(root);
    if (code) georef.epsg = std::atoi(code);
  }
  OGRErr err = OGRERR_NONE;
  const double a = srs.GetSemiMajor(&err);
  const double invF = srs.GetInvFlattening(&err);
  const char* ellName = srs.GetAttrValue("SPHEROID");
  georef.body = Body::fromEllipsoid(a, invF == 0 ? 0.0 : 1.0 / invF, ellName ? ellName : "");
}

Result<OGRSpatialReference> srsOf(const Georef& georef) {
  if (georef.crsWkt.empty()) {
    if (georef.epsg) return parseCrs("EPSG:" + std::to_string(*georef.epsg));
    return fail("georeference has no CRS");
  }
  return parseCrs(georef.crsWkt);
}

Result<DatasetPtr> memDataset(const Georef& georef, const Grid<float>* values) {
  ensureGdal();
  GDALDriver* mem = GetGDALDriverManager()->GetDriverByName("MEM");
  STRATA_CHECK(mem) << "GDAL has no MEM driver";
  STRATA_CHECK(georef.width > 0 && georef.height > 0) << "memDataset " << georef.width << "x" << georef.height;
  GdalErrorCapture errors;
  DatasetPtr ds(mem->Create("", georef.width, georef.height, 1, GDT_Float32, nullptr));
  if (!ds) return fail("cannot allocate an in-memory raster: " + errors.last());
  double gt[6];
  for (int i = 0; i < 6; ++i) gt[i] = georef.transform.c[i];
  ds->SetGeoTransform(gt);
  STRATA_TRY(OGRSpatialReference srs, srsOf(georef));
  ds->SetSpatialRef(&srs);
  GDALRasterBand* band = ds->GetRasterBand(1);
  band->SetNoDataValue(std::nan(""));
  if (values) {
    STRATA_CHECK(values->width == georef.width && values->height == georef.height) << "raster and georef sizes differ";
    if (band->RasterIO(GF_Write, 0, 0, georef.width, georef.height, const_cast<float*>(values->data.data()),
                       georef.width, georef.height, GDT_Float32, 0, 0) != CE_None) {
      return fail("cannot fill an in-memory raster: " + errors.last());
    }
  } else {
    band->Fill(std::nan(""));
  }
  return ds;
}

}  // namespace strata::gis::detail
