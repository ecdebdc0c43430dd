#pragma once
// Georeferenced rasters in memory. Elevations are float32 metres; no data is NaN in memory
// (never a number that could be mistaken for an elevation), and is written back as the file's
// nodata value.

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <limits>
#include <optional>
#include <string>
#include <vector>

#include <strata/core/check.hpp>
#include <strata/gis/body.hpp>

namespace strata::gis {

/// GDAL's affine geotransform: x = c[0] + col*c[1] + row*c[2]; y = c[3] + col*c[4] + row*c[5],
/// (col, row) at a pixel's top-left corner. North-up grids have c[2] = c[4] = 0, c[5] < 0.
struct GeoTransform {
  double c[6] = {0, 1, 0, 0, 0, -1};

  double x(double col, double row) const { return c[0] + col * c[1] + row * c[2]; }
  double y(double col, double row) const { return c[3] + col * c[4] + row * c[5]; }
  bool isNorthUp() const { return c[2] == 0 && c[4] == 0; }
};

/// Where a raster lies: CRS, geotransform, size, and the body it lives on.
struct Georef {
  std::string crsWkt;       ///< WKT2 of the horizontal CRS (empty: none)
  std::optional<int> epsg;  ///< EPSG code when the CRS has one
  std::string crsName;      ///< e.g. "WGS 84", "WGS 84 / Pseudo-Mercator"
  bool geographic = false;  ///< lon/lat degrees (true) or projected metres (false)
  GeoTransform transform;
  int width = 0, height = 0;
  Body body = Body::wgs84();
  std::string verticalUnit = "m";
};

/// A rectangle of cells of a grid (pixels of a raster, cells of a tile level or of a simulation
/// region): [x, x + width) x [y, y + height), (x, y) its top-left cell. The one cell rectangle of
/// Strata: readers' windows, tile store windows, simulation regions and blocks, editor dabs.
struct CellRect {
  int x = 0, y = 0, width = 0, height = 0;

  bool empty() const { return width <= 0 || height <= 0; }
  /// The smallest rectangle holding both (an empty one adds nothing).
  CellRect united(const CellRect& o) const {
    if (empty()) return o;
    if (o.empty()) return *this;
    const int x0 = std::min(x, o.x), y0 = std::min(y, o.y);
    const int x1 = std::max(x + width, o.x + o.width), y1 = std::max(y + height, o.y + o.height);
    return {x0, y0, x1 - x0, y1 - y0};
  }
  /// The cells in both (empty when they do not overlap).
  CellRect intersected(const CellRect& o) const {
    const int x0 = std::max(x, o.x), y0 = std::max(y, o.y);
    const int x1 = std::min(x + width, o.x + o.width), y1 = std::min(y + height, o.y + o.height);
    return x1 > x0 && y1 > y0 ? CellRect{x0, y0, x1 - x0, y1 - y0} : CellRect{};
  }
  bool operator==(const CellRect&) const = default;
};

/// A dense row-major grid, row 0 at the top (north for north-up rasters).
template <class T>
struct Grid {
  int width = 0, height = 0;
  std::vector<T> data;

  Grid() = default;
  Grid(int w, int h, T fill = T{}) : width(w), height(h), data(size_t(w) * size_t(h), fill) {
    STRATA_CHECK(w >= 0 && h >= 0) << "grid " << w << "x" << h;
  }
  size_t size() const { return data.size(); }
  size_t index(int x, int y) const { return size_t(y) * size_t(width) + size_t(x); }
  T& at(int x, int y) { return data[index(x, y)]; }
  const T& at(int x, int y) const { return data[index(x, y)]; }
  bool contains(int x, int y) const { return x >= 0 && y >= 0 && x < width && y < height; }
};

inline constexpr float kNoData = std::numeric_limits<float>::quiet_NaN();
inline bool isNoData(float v) { return std::isnan(v); }

/// An elevation raster: values in metres (scale/offset applied), NaN where there is no data.
struct Raster {
  Georef georef;
  Grid<float> values;
};

}  // namespace strata::gis
