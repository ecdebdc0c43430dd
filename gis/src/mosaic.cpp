// Mosaics through GDAL's warper: each input is resampled onto the target grid with an exact
// (not approximated) source<->target transformer, then blended in order.
#include <strata/gis/mosaic.hpp>

#include <gdalwarper.h>

#include <algorithm>
#include <cmath>

#include <strata/gis/dem_io.hpp>

#include "gdal_util.hpp"

namespace strata::gis {

std::string_view toString(BlendMode mode) {
  switch (mode) {
    case BlendMode::Replace: return "replace";
    case BlendMode::Add: return "add";
    case BlendMode::Subtract: return "subtract";
    case BlendMode::Multiply: return "multiply";
    case BlendMode::Max: return "max";
    case BlendMode::Min: return "min";
  }
  return "?";
}

Result<BlendMode> parseBlendMode(std::string_view name) {
  for (BlendMode m :
       {BlendMode::Replace, BlendMode::Add, BlendMode::Subtract, BlendMode::Multiply, BlendMode::Max, BlendMode::Min}) {
    if (toString(m) == name) return m;
  }
  return fail("blend mode '" + std::string(name) + "' is not one of replace, add, subtract, multiply, max, min");
}

void blendInto(Grid<float>& layer, const Grid<float>& src, BlendMode mode) {
  STRATA_CHECK(layer.width == src.width && layer.height == src.height)
      << "blendInto: " << layer.width << "x" << layer.height << " vs " << src.width << "x" << src.height;
  for (size_t i = 0; i < layer.data.size(); ++i) {
    const float s = src.data[i];
    float& a = layer.data[i];
    if (std::isnan(s)) continue;
    if (std::isnan(a)) {
      a = s;
      continue;
    }
    switch (mode) {
      case BlendMode::Replace: a = s; break;
      case BlendMode::Add: a = a + s; break;
      case BlendMode::Subtract: a = a - s; break;
      case BlendMode::Multiply: a = a * s; break;
      case BlendMode::Max: a = std::max(a, s); break;
      case BlendMode::Min: a = std::min(a, s); break;
    }
  }
}

Result<Raster> warpToGrid(const MosaicInput& input, const Georef& target) {
  using detail::DatasetPtr;
  const std::string name = input.raster ? std::string("in-memory raster") : input.path;
  if (target.width <= 0 || target.height <= 0) return fail("mosaic target grid is empty");

  DatasetPtr src;
  int band = 1;
  double scale = 1, offset = 0;
  std::optional<double> srcNoData;
  Body srcBody;
  if (input.raster) {
    auto ds = detail::memDataset(input.raster->georef, &input.raster->values);
    if (!ds) return fail(name + ": " + ds.message());
    src = std::move(*ds);
    srcNoData = std::nan("");
    srcBody = input.raster->georef.body;
  } else {
    ReadOptions ro;
    ro.band = input.band;
    STRATA_TRY(DemInfo info, probeDem(input.path, ro));
    STRATA_TRY(src, detail::openRaster(input.path));
    band = input.band;
    scale = info.scale;
    offset = info.offsetIsBodyRadius ? info.offset - info.georef.body.semiMajorM : info.offset;
    srcNoData = info.nodata;
    if (!srcNoData && GDALDataTypeIsFloating(src->GetRasterBand(band)->GetRasterDataType())) {
      srcNoData = std::nan("");
    }
    srcBody = info.georef.body;
  }
  if (std::abs(srcBody.semiMajorM - target.body.semiMajorM) > 1.0) {
    return fail(name + ": lives on " + srcBody.name + ", the mosaic target on " + target.body.name);
  }
  STRATA_TRY(DatasetPtr dst, detail::memDataset(target, nullptr));

  detail::GdalErrorCapture errors;
  // Exact transformer: no approximation error at cell centres (GDAL's default allows 0.125 px).
  void* transformer =
      GDALCreateGenImgProjTransformer2(GDALDataset::ToHandle(src.get()), GDALDataset::ToHandle(dst.get()), nullptr);
  if (!transformer) return fail(name + ": no transformation to the mosaic grid: " + errors.last());
  GDALWarpOptions* wo = GDALCreateWarpOptions();
  wo->hSrcDS = GDALDataset::ToHandle(src.get());
  wo->hDstDS = GDALDataset::ToHandle(dst.get());
  wo->nBandCount = 1;
  wo->panSrcBands = static_cast<int*>(CPLMalloc(sizeof(int)));
  wo->panSrcBands[0] = band;
  wo->panDstBands = static_cast<int*>(CPLMalloc(sizeof(int)));
  wo->panDstBands[0] = 1;
  wo->eWorkingDataType = GDT_Float32;
  switch (input.resampling) {
    case Resampling::Nearest: wo->eResampleAlg = GRA_NearestNeighbour; break;
    case Resampling::Bilinear: wo->eResampleAlg = GRA_Bilinear; break;
    case Resampling::Cubic: wo->eResampleAlg = GRA_Cubic; break;
    case Resampling::Minimum: wo->eResampleAlg = GRA_Min; break;
  }
  if (srcNoData) {
    wo->padfSrcNoDataReal = static_cast<double*>(CPLMalloc(sizeof(double)));
    wo->padfSrcNoDataReal[0] = *srcNoData;
  }
  wo->padfDstNoDataReal = static_cast<double*>(CPLMalloc(sizeof(double)));
  wo->padfDstNoDataReal[0] = std::nan("");
  wo->papszWarpOptions = CSLSetNameValue(wo->papszWarpOptions, "INIT_DEST", "NO_DATA");
  wo->pfnTransformer = GDALGenImgProjTransform;
  wo->pTransformerArg = transformer;
  CPLErr err = CE_Failure;
  {
    GDALWarpOperation op;
    if (op.Initialize(wo) == CE_None) err = op.ChunkAndWarpImage(0, 0, target.width, target.height);
  }
  GDALDestroyGenImgProjTransformer(transformer);
  GDALDestroyWarpOptions(wo);
  if (err != CE_None) return fail(name + ": warp onto the mosaic grid failed: " + errors.last());

  Raster out;
  out.georef = target;
  out.values = Grid<float>(target.width, target.height);
  if (dst->GetRasterBand(1)->RasterIO(GF_Read, 0, 0, target.width, target.height, out.values.data.data(), target.width,
                                      target.height, GDT_Float32, 0, 0) != CE_None) {
    return fail(name + ": reading the warped grid failed: " + errors.last());
  }
  if (scale != 1 || offset != 0) {
    for (float& v : out.values.data) {
      if (!std::isnan(v)) v = float(double(v) * scale + offset);
    }
  }
  return out;
}

Result<Layer> buildMosaic(const std::string& name, const Georef& target, std::span<const MosaicInput> inputs) {
  Layer layer;
  layer.name = name;
  layer.raster.georef = target;
  layer.raster.values = Grid<float>(target.width, target.height, kNoData);
  for (const MosaicInput& in : inputs) {
    auto warped = warpToGrid(in, target);
    if (!warped) return fail("mosaic '" + name + "': " + warped.message());
    blendInto(layer.raster.values, warped->values, in.mode);
  }
  return layer;
}

}  // namespace strata::gis
