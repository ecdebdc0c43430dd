#include <strata/gis/fill_nodata.hpp>

#include <gdal_alg.h>

#include <algorithm>
#include <cmath>
#include <string>

#include "gdal_util.hpp"

namespace strata::gis {

Result<size_t> fillVoids(Grid<float>& grid) { return fillVoids(grid, std::max(grid.width, grid.height)); }

Result<size_t> fillVoids(Grid<float>& grid, int maxSearchCells) {
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
    err = GDALFillNodata(GDALRasterBand::ToHandle(band), nullptr, double(maxSearchCells), 0, 0, nullptr, nullptr,
                         nullptr);
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

std::optional<std::array<int, 2>> voidFillRows(const Grid<float>& rows, int top, int height, int y0, int y1) {
  const int w = rows.width, bottom = top + rows.height;
  STRATA_CHECK(top <= y0 && y0 <= y1 && y1 <= bottom && bottom <= height)
      << "voidFillRows: rows [" << y0 << ", " << y1 << ") are not held";
  std::array<int, 2> span{y0, y1};
  // The first valid row above (step -1) or below (step +1) cell (x, y) in its column: the grid's
  // edge where the column has none, nothing where `rows` ends before either.
  auto firstValid = [&](int x, int y, int step) -> std::optional<int> {
    for (int r = y + step; r >= top && r < bottom; r += step) {
      if (!isNoData(rows.at(x, r - top))) return r;
    }
    if (step < 0 ? top == 0 : bottom == height) return step < 0 ? 0 : height - 1;
    return std::nullopt;
  };
  for (int y = y0; y < y1; ++y) {
    for (int x = 0; x < w; ++x) {
      if (!isNoData(rows.at(x, y - top))) continue;
      for (const int column : {x, std::min(x + 1, w - 1)}) {
        const auto above = firstValid(column, y, -1), below = firstValid(column, y, 1);
        if (!above || !below) return std::nullopt;
        span[0] = std::min(span[0], *above);
        span[1] = std::max(span[1], *below + 1);
      }
    }
  }
  return span;
}

}  // namespace strata::gis
