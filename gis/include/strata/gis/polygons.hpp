#pragma once
// Regions of a raster as vector polygons: the connected components of a mask labelled, and the
// labels' cells traced into polygons (GDAL's polygonize) in a GeoPackage layer with the raster's
// CRS, one feature per component with numbers given per label. What a flood outline is.

#include <cstdint>
#include <map>
#include <string>
#include <vector>

#include <strata/core/result.hpp>
#include <strata/gis/raster.hpp>

namespace strata::gis {

/// The 4-connected components of the cells where `mask` is not 0, labelled 1, 2, ... in scan
/// order (row by row from the top-left); 0 elsewhere. `count` receives the number of components.
Grid<int32_t> labelComponents(const Grid<uint8_t>& mask, int32_t* count = nullptr);

/// One layer of polygons: a feature per label > 0 of a label grid, with a 64-bit integer field
/// "id" (the label) and real fields named in `fields`, valued per label in `values` (one value per
/// field; a label without values gets nulls).
struct PolygonLayer {
  std::string name;
  std::vector<std::string> fields;
  std::map<int32_t, std::vector<double>> values;
};

/// Traces each label's cells (4-connected, as labelComponents makes them) into a polygon with its
/// holes and writes them into a new GeoPackage at `path` (a temporary renamed into place; an
/// existing file is replaced) in `georef`'s CRS and geotransform. Errors name the file.
Status writeLabelPolygons(const std::string& path, const Georef& georef, const Grid<int32_t>& labels,
                          const PolygonLayer& layer);

}  // namespace strata::gis
