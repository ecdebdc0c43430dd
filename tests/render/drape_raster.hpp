#pragma once
// Rasters to drape in the tests: written with GDAL, any band count, Byte or Float32.
#include <gdal_priv.h>
#include <ogr_spatialref.h>

#include <array>
#include <functional>
#include <optional>
#include <string>

namespace strata::test {

/// Writes a `bands`-band GeoTIFF whose value at (x, y, band) is value(x, y, band).
inline bool writeDrapeRaster(const std::string& path, int width, int height, int bands, GDALDataType type,
                             const char* crs, const std::array<double, 6>& gt,
                             const std::function<double(int, int, int)>& value,
                             std::optional<double> nodata = std::nullopt) {
  GDALAllRegister();
  GDALDriver* driver = GetGDALDriverManager()->GetDriverByName("GTiff");
  GDALDataset* ds = driver ? driver->Create(path.c_str(), width, height, bands, type, nullptr) : nullptr;
  if (!ds) return false;
  ds->SetGeoTransform(const_cast<double*>(gt.data()));
  OGRSpatialReference srs;
  srs.SetFromUserInput(crs);
  ds->SetSpatialRef(&srs);
  bool ok = true;
  std::vector<double> row(static_cast<size_t>(width));
  for (int b = 1; b <= bands && ok; ++b) {
    GDALRasterBand* band = ds->GetRasterBand(b);
    if (nodata) band->SetNoDataValue(*nodata);
    for (int y = 0; y < height && ok; ++y) {
      for (int x = 0; x < width; ++x) row[size_t(x)] = value(x, y, b);
      ok = band->RasterIO(GF_Write, 0, y, width, 1, row.data(), width, 1, GDT_Float64, 0, 0) == CE_None;
    }
  }
  GDALClose(ds);
  return ok;
}

// A 3-band Byte raster in UTM zone 12N (500 m pixels, 300 x 140 km, covering the Grand Canyon
// 512 DEM's degree square): blue, with a red 3 x 3 pixel marker centred on kMarkerUtm.
inline constexpr std::array<double, 6> kUtmGt{250000, 500, 0, 4110000, 0, -500};
inline constexpr std::array<double, 2> kMarkerUtm{250000 + 301.5 * 500, 4110000 - 141.5 * 500};
inline bool writeUtmMarker(const std::string& path) {
  return writeDrapeRaster(path, 600, 280, 3, GDT_Byte, "EPSG:32612", kUtmGt, [](int x, int y, int b) {
    const bool marker = x >= 300 && x <= 302 && y >= 140 && y <= 142;
    return b == 1 ? (marker ? 255 : 0) : b == 2 ? 0 : (marker ? 0 : 255);
  });
}

}  // namespace strata::test
