#include <strata/gis/fill_nodata.hpp>

#include <gdal_alg.h>

#include <algorithm>
#include <cmath>
#include <string>

#include "gdal_util.hpp"

namespace strata::gis {

Result<size_t> fillVoids(Grid<float>& grid) {
  const size_t voids = size_t(std::count_if(grid.data.begin(), grid.data.end(), isNoData));
  if (voids == 0) return size_t(0);
  if (voids == grid.size()) return fail("fill voids: the grid has no valid cell");
  detail::ensureGdal();
  GDALDriver* mem = GetGDALDriverManager()->GetDriverByName("MEM");
  STRATA_CHECK(mem) << "GDAL has no MEM driver";
  detail::GdalErrorCapture errors;
  detail::DatasetPtr ds(mem->Create("", grid.width, grid.height, 1, GDT_Float32, nullptr));
  if (!ds) return fail("fill voids: cannot allocate an in-memory raster: " + errors.last());
  GDALRasterBand* band = ds->GetRasterBand(1);
  band->SetNoDataValue(std::nan(""));
  CPLErr err = band->RasterIO(GF_Write, 0, 0, grid.width, grid.height, grid.data.data(), grid.width, grid.height,
                              GDT_Float32, 0, 0);
  if (err == CE_None) {
    err = GDALFillNodata(GDALRasterBand::ToHandle(band), nullptr, double(std::max(grid.width, grid.height)), 0, 0,
                         nullptr, nullptr, nullptr);
  }
  if (err == CE_None) {
    err = band->RasterIO(GF_Read, 0, 0, grid.width, grid.height, grid.data.data(), grid.width, grid.height, GDT_Float32,
                         0, 0);
  }
  if (err != CE_None) return fail("fill voids: GDAL: " + errors.last());
  const size_t left = size_t(std::count_if(grid.data.begin(), grid.data.end(), isNoData));
  STRATA_CHECK(left == 0) << "GDALFillNodata left " << left << " of " << voids << " voids";
  return voids;
}

}  // namespace strata::gis
