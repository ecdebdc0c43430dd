#include <strata/gis/polygons.hpp>

#include <gdal_alg.h>
#include <ogrsf_frmts.h>

#include <algorithm>
#include <deque>

#include <strata/core/files.hpp>

#include "gdal_util.hpp"

namespace strata::gis {

Grid<int32_t> labelComponents(const Grid<uint8_t>& mask, int32_t* count) {
  Grid<int32_t> labels(mask.width, mask.height, 0);
  int32_t next = 0;
  std::deque<std::pair<int, int>> queue;
  for (int y = 0; y < mask.height; ++y) {
    for (int x = 0; x < mask.width; ++x) {
      if (!mask.at(x, y) || labels.at(x, y) != 0) continue;
      labels.at(x, y) = ++next;
      queue.push_back({x, y});
      while (!queue.empty()) {
        const auto [cx, cy] = queue.front();
        queue.pop_front();
        const int nx[4] = {cx - 1, cx + 1, cx, cx}, ny[4] = {cy, cy, cy - 1, cy + 1};
        for (int k = 0; k < 4; ++k) {
          if (mask.contains(nx[k], ny[k]) && mask.at(nx[k], ny[k]) && labels.at(nx[k], ny[k]) == 0) {
            labels.at(nx[k], ny[k]) = next;
            queue.push_back({nx[k], ny[k]});
          }
        }
      }
    }
  }
  if (count) *count = next;
  return labels;
}

Status writeLabelPolygons(const std::string& path, const Georef& georef, const Grid<int32_t>& labels,
                          const PolygonLayer& layer) {
  detail::ensureGdal();
  detail::GdalErrorCapture errors;
  if (labels.width != georef.width || labels.height != georef.height) {
    return fail(path + ": the labels (" + std::to_string(labels.width) + " x " + std::to_string(labels.height) +
                ") are not the raster's size");
  }
  // The labels as an in-memory raster: its own band is its mask (0: no polygon).
  GDALDriver* mem = GetGDALDriverManager()->GetDriverByName("MEM");
  GDALDriver* gpkg = GetGDALDriverManager()->GetDriverByName("GPKG");
  if (!mem || !gpkg) return fail(path + ": GDAL has no MEM or GPKG driver");
  detail::DatasetPtr raster(mem->Create("", labels.width, labels.height, 1, GDT_Int32, nullptr));
  if (!raster) return fail(path + ": " + errors.last("cannot make the label raster"));
  double gt[6];
  std::copy(georef.transform.c, georef.transform.c + 6, gt);
  raster->SetGeoTransform(gt);
  GDALRasterBand* band = raster->GetRasterBand(1);
  if (band->RasterIO(GF_Write, 0, 0, labels.width, labels.height, const_cast<int32_t*>(labels.data.data()),
                     labels.width, labels.height, GDT_Int32, 0, 0, nullptr) != CE_None) {
    return fail(path + ": " + errors.last("cannot fill the label raster"));
  }
  const std::filesystem::path target(path);
  const std::filesystem::path tmp = temporaryPathFor(target);
  Status status;
  {
    char** options = CSLSetNameValue(nullptr, "FID", "fid");
    detail::DatasetPtr out(gpkg->Create(tmp.c_str(), 0, 0, 0, GDT_Unknown, nullptr));
    if (!out) {
      CSLDestroy(options);
      return fail(path + ": " + errors.last("cannot create the GeoPackage"));
    }
    OGRSpatialReference srs;
    srs.SetAxisMappingStrategy(OAMS_TRADITIONAL_GIS_ORDER);
    const bool hasCrs = !georef.crsWkt.empty() && srs.importFromWkt(georef.crsWkt.c_str()) == OGRERR_NONE;
    OGRLayer* l = out->CreateLayer(layer.name.c_str(), hasCrs ? &srs : nullptr, wkbMultiPolygon, options);
    CSLDestroy(options);
    if (!l) {
      out.reset();
      std::filesystem::remove(tmp);
      return fail(path + ": " + errors.last("cannot create the layer " + layer.name));
    }
    OGRFieldDefn id("id", OFTInteger64);
    l->CreateField(&id);
    for (const auto& f : layer.fields) {
      OGRFieldDefn d(f.c_str(), OFTReal);
      l->CreateField(&d);
    }
    // Polygonize into a memory layer (its polygons carry the label), then one multipolygon per
    // label with its values: GDAL traces holes, and cells of one label touching only at a
    // corner come out as separate polygons of the same feature.
    GDALDriver* memVector = GetGDALDriverManager()->GetDriverByName("Memory");
    detail::DatasetPtr scratch(memVector ? memVector->Create("", 0, 0, 0, GDT_Unknown, nullptr) : nullptr);
    OGRLayer* traced = scratch ? scratch->CreateLayer("traced", hasCrs ? &srs : nullptr, wkbPolygon, nullptr) : nullptr;
    OGRFieldDefn label("id", OFTInteger);
    if (!traced || traced->CreateField(&label) != OGRERR_NONE) {
      status = fail(path + ": " + errors.last("cannot make a memory layer"));
    } else if (GDALPolygonize(band, band, OGRLayer::ToHandle(traced), 0, nullptr, nullptr, nullptr) != CE_None) {
      status = fail(path + ": " + errors.last("cannot trace the polygons"));
    }
    std::map<int32_t, OGRMultiPolygon> byLabel;
    if (status.ok()) {
      traced->ResetReading();
      for (auto& f : *traced) {
        const int32_t k = f->GetFieldAsInteger(0);
        if (const OGRGeometry* g = f->GetGeometryRef(); g && k > 0) byLabel[k].addGeometry(g);
      }
    }
    if (status.ok() && l->StartTransaction() != OGRERR_NONE)
      status = fail(path + ": " + errors.last("cannot start a transaction"));
    for (auto& [k, geometry] : byLabel) {
      if (!status.ok()) break;
      OGRFeature feature(l->GetLayerDefn());
      feature.SetField(0, GIntBig(k));
      if (auto v = layer.values.find(k); v != layer.values.end()) {
        for (size_t i = 0; i < layer.fields.size() && i < v->second.size(); ++i)
          feature.SetField(int(i) + 1, v->second[i]);
      }
      feature.SetGeometry(&geometry);
      if (l->CreateFeature(&feature) != OGRERR_NONE) status = fail(path + ": " + errors.last("cannot write a polygon"));
    }
    if (status.ok() && l->CommitTransaction() != OGRERR_NONE)
      status = fail(path + ": " + errors.last("cannot commit the polygons"));
  }
  if (!status.ok()) {
    std::error_code ec;
    std::filesystem::remove(tmp, ec);
    return status;
  }
  return commitTemporary(tmp, target);
}

}  // namespace strata::gis
