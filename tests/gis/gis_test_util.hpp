#pragma once
// Helpers for the gis tests: run GDAL's command-line tools and read their output, write small
// synthetic rasters with GDAL's C++ API.
#include <gdal_priv.h>
#include <ogr_spatialref.h>

#include <array>
#include <cstdio>
#include <optional>
#include <string>
#include <vector>

#include "strata_test.hpp"

namespace strata::gis::test {

/// Runs a program (GDAL's tools, strata) with `argv`, no shell between, and returns its stdout
/// (stderr discarded unless merged) and exit status; `input` goes to its stdin.
struct CommandOutput {
  std::string out;
  int status = -1;
};
inline CommandOutput runCommand(const std::vector<std::string>& argv, bool mergeStderr = false,
                                const std::string& input = {}) {
  auto r = strata::test::runProgram(argv, input, mergeStderr);
  return {std::move(r.output), r.status};
}

/// A shared real DEM by path. Uses this binary's STRATA_DATA_DIR (an absolute path): the shared
/// test main is compiled without it, so strata::test::dataPath() is relative to the working folder.
inline std::string dataFile(const std::string& relative) { return std::string(STRATA_DATA_DIR) + "/" + relative; }

/// What a synthetic raster looks like.
struct SyntheticRaster {
  int width = 8, height = 8;
  GDALDataType type = GDT_Float32;
  std::vector<double> values;  ///< row-major; empty: v = x + 10 y
  std::optional<double> nodata;
  std::optional<std::string> crs;           ///< "EPSG:4326", WKT; none: no CRS written
  std::optional<std::array<double, 6>> gt;  ///< none: no geotransform written
  std::vector<std::string> creationOptions;
};

/// Writes a synthetic raster with GDAL (driver "GTiff" unless told), returns false on failure.
inline bool writeSynthetic(const std::string& path, const SyntheticRaster& s, const char* driverName = "GTiff") {
  GDALAllRegister();
  GDALDriver* driver = GetGDALDriverManager()->GetDriverByName(driverName);
  if (!driver) return false;
  std::vector<const char*> opts;
  for (const auto& o : s.creationOptions) opts.push_back(o.c_str());
  opts.push_back(nullptr);
  GDALDataset* ds = driver->Create(path.c_str(), s.width, s.height, 1, s.type, const_cast<char**>(opts.data()));
  if (!ds) return false;
  if (s.gt) ds->SetGeoTransform(const_cast<double*>(s.gt->data()));
  if (s.crs) {
    OGRSpatialReference srs;
    srs.SetFromUserInput(s.crs->c_str());
    ds->SetSpatialRef(&srs);
  }
  GDALRasterBand* band = ds->GetRasterBand(1);
  if (s.nodata) band->SetNoDataValue(*s.nodata);
  std::vector<double> v = s.values;
  if (v.empty()) {
    v.resize(size_t(s.width) * s.height);
    for (int y = 0; y < s.height; ++y)
      for (int x = 0; x < s.width; ++x) v[size_t(y) * s.width + x] = x + 10.0 * y;
  }
  const bool ok =
      band->RasterIO(GF_Write, 0, 0, s.width, s.height, v.data(), s.width, s.height, GDT_Float64, 0, 0) == CE_None;
  GDALClose(ds);
  return ok;
}

}  // namespace strata::gis::test
