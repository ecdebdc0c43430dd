// Mosaics through GDAL's warper: each input is resampled onto the target grid with an exact
// (not approximated) source<->target transformer, then blended in order. Inputs already on the
// target's cells are read directly; the output grid defaults to the union of the inputs.
#include <strata/gis/mosaic.hpp>

#include <gdal_vrt.h>
#include <gdalwarper.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <vector>

#include "gdal_util.hpp"

namespace strata::gis {

namespace {

using detail::DatasetPtr;

// An input's extent and natural cell size in another CRS (GDALSuggestedWarpOutput2).
struct Footprint {
  double minX = 0, minY = 0, maxX = 0, maxY = 0;
  double cellX = 0, cellY = 0;  // positive
};

// The georeference of cells [x, x+w) x [y, y+h) of `g`.
Georef windowOf(const Georef& g, int x, int y, int w, int h) {
  Georef out = g;
  out.transform.c[0] = g.transform.x(x, y);
  out.transform.c[3] = g.transform.y(x, y);
  out.width = w;
  out.height = h;
  return out;
}

bool nearlyEqual(double a, double b, double rel) { return std::abs(a - b) <= rel * std::max(std::abs(a), std::abs(b)); }

// One opened input: its dataset (for the warper), or its cells read directly when it lies on
// the target's grid.
struct Source {
  MosaicInput in;
  std::string name;
  DatasetPtr held;  // an in-memory raster that is a window of `ds` (MosaicInput::within)
  DatasetPtr ds;    // the file (with any assigned georeference) or the in-memory raster
  std::optional<DemFile> file;
  Georef georef;  // the input's own
  int band = 1;
  double scale = 1, offset = 0;  // metres = raw * scale + offset (after the warp)
  std::optional<double> noData;
  // On the target's grid: target cell (x, y) is input cell (x - dx, y - dy).
  bool aligned = false;
  int dx = 0, dy = 0;
  // Footprint in target pixel coordinates (cull windows it does not reach); unknown: no cull.
  bool culls = false;
  double px0 = 0, py0 = 0, px1 = 0, py1 = 0;
  GDALResampleAlg alg = GRA_Bilinear;
  // Target cells per source cell along x and y, fixed for the whole grid: GDAL otherwise derives
  // the kernel's scale from each chunk's source window, so results would depend on the window.
  double xScale = 0, yScale = 0;
};

Result<Source> openSource(const MosaicInput& input) {
  Source s;
  s.in = input;
  s.name = inputName(input);
  if (input.raster && input.within) {
    // A virtual raster of the larger one's size and georeference, holding the window's cells
    // where they lie in it (GDAL's VRT: nothing of the rest is allocated).
    const Georef& g = *input.within;
    const auto& v = input.raster->values;
    if (!(input.withinX >= 0 && input.withinY >= 0 && input.withinX + v.width <= g.width &&
          input.withinY + v.height <= g.height)) {
      return fail(s.name + ": the window does not lie inside the raster it is a window of");
    }
    STRATA_TRY(s.held, detail::memDataset(windowOf(g, input.withinX, input.withinY, v.width, v.height), &v));
    detail::GdalErrorCapture errors;
    GDALDriver* vrt = GetGDALDriverManager()->GetDriverByName("VRT");
    STRATA_CHECK(vrt) << "GDAL has no VRT driver";
    s.ds.reset(vrt->Create("", g.width, g.height, 0, GDT_Float32, nullptr));
    if (!s.ds) return fail(s.name + ": cannot make a virtual raster: " + errors.last());
    double gt[6];
    for (int i = 0; i < 6; ++i) gt[i] = g.transform.c[i];
    s.ds->SetGeoTransform(gt);
    STRATA_TRY(OGRSpatialReference srs, detail::srsOf(g));
    s.ds->SetSpatialRef(&srs);
    if (VRTAddBand(GDALDataset::ToHandle(s.ds.get()), GDT_Float32, nullptr) != CE_None) {
      return fail(s.name + ": cannot make a virtual raster: " + errors.last());
    }
    GDALRasterBandH band = GDALGetRasterBand(GDALDataset::ToHandle(s.ds.get()), 1);
    GDALSetRasterNoDataValue(band, std::nan(""));
    if (VRTAddSimpleSource(static_cast<VRTSourcedRasterBandH>(band), GDALRasterBand::ToHandle(s.held->GetRasterBand(1)),
                           0, 0, v.width, v.height, input.withinX, input.withinY, v.width, v.height, nullptr,
                           VRT_NODATA_UNSET) != CE_None) {
      return fail(s.name + ": cannot make a virtual raster: " + errors.last());
    }
    s.georef = g;
    s.noData = std::nan("");
    return s;
  }
  if (input.raster) {
    STRATA_TRY(s.ds, detail::memDataset(input.raster->georef, &input.raster->values));
    s.georef = input.raster->georef;
    s.noData = std::nan("");
    return s;
  }
  ReadOptions ro;
  ro.band = input.band;
  ro.crs = input.assignCrs;
  ro.transform = input.assignTransform;
  ro.allowAllNoData = true;
  STRATA_TRY(DemFile f, DemFile::open(input.path, ro));
  const DemInfo& info = f.info();
  STRATA_TRY(s.ds, detail::openRaster(input.path, input.assignCrs, input.assignTransform));
  s.band = input.band;
  s.georef = info.georef;
  s.scale = info.scale * info.unitToMetres;
  s.offset = (info.offsetIsBodyRadius ? info.offset - info.georef.body.semiMajorM : info.offset) * info.unitToMetres;
  s.noData = info.nodata;
  if (!s.noData && GDALDataTypeIsFloating(s.ds->GetRasterBand(s.band)->GetRasterDataType())) s.noData = std::nan("");
  s.file = std::move(f);
  return s;
}

// The input's extent and cell size in the CRS `srs`.
Result<Footprint> footprintIn(const Source& s, const OGRSpatialReference& srs) {
  char* wkt = nullptr;
  const char* opts[] = {"FORMAT=WKT2_2019", nullptr};
  srs.exportToWkt(&wkt, opts);
  const std::string dst = std::string("DST_SRS=") + (wkt ? wkt : "");
  CPLFree(wkt);
  const char* topts[] = {dst.c_str(), nullptr};
  detail::GdalErrorCapture errors;
  void* tr = GDALCreateGenImgProjTransformer2(GDALDataset::ToHandle(s.ds.get()), nullptr, const_cast<char**>(topts));
  if (!tr) return fail(s.name + ": no transformation to the mosaic's CRS: " + errors.last());
  double gt[6];
  int w = 0, h = 0;
  double ext[4];
  const CPLErr err =
      GDALSuggestedWarpOutput2(GDALDataset::ToHandle(s.ds.get()), GDALGenImgProjTransform, tr, gt, &w, &h, ext, 0);
  GDALDestroyGenImgProjTransformer(tr);
  if (err != CE_None || w <= 0 || h <= 0) {
    return fail(s.name + ": cannot compute its extent in the mosaic's CRS: " + errors.last());
  }
  Footprint f;
  f.minX = ext[0];
  f.minY = ext[1];
  f.maxX = ext[2];
  f.maxY = ext[3];
  f.cellX = std::abs(gt[1]);
  f.cellY = std::abs(gt[5]);
  if (!(std::isfinite(f.minX) && std::isfinite(f.maxX) && std::isfinite(f.minY) && std::isfinite(f.maxY) &&
        f.cellX > 0 && f.cellY > 0)) {
    return fail(s.name + ": its extent in the mosaic's CRS is not finite");
  }
  return f;
}

bool sameCrs(const OGRSpatialReference& a, const OGRSpatialReference& b) {
  const char* opts[] = {"IGNORE_DATA_AXIS_TO_SRS_AXIS_MAPPING=YES", "CRITERION=EQUIVALENT", nullptr};
  return a.IsSame(&b, opts);
}

// Decides how `s` reaches `target`: directly (aligned), or warped with which kernel, and its
// footprint for culling.
Status placeSource(Source& s, const Georef& target) {
  const auto& t = target.transform;
  STRATA_TRY(OGRSpatialReference dst, detail::srsOf(target));
  STRATA_TRY(OGRSpatialReference src, detail::srsOf(s.georef));
  const auto& g = s.georef.transform;
  if (std::abs(s.georef.body.semiMajorM - target.body.semiMajorM) > 1.0) {
    return fail(s.name + ": lives on " + s.georef.body.name + ", the mosaic target on " + target.body.name);
  }
  const bool same = sameCrs(src, dst);
  if (same && t.isNorthUp() && g.isNorthUp() && nearlyEqual(g.c[1], t.c[1], 1e-9) &&
      nearlyEqual(g.c[5], t.c[5], 1e-9)) {
    const double ox = (g.c[0] - t.c[0]) / t.c[1], oy = (g.c[3] - t.c[3]) / t.c[5];
    if (std::abs(ox - std::round(ox)) < 1e-6 && std::abs(oy - std::round(oy)) < 1e-6 && std::abs(ox) < 1e12 &&
        std::abs(oy) < 1e12) {
      s.aligned = true;
      s.dx = int(std::round(ox));
      s.dy = int(std::round(oy));
      return {};
    }
  }
  auto fp = footprintIn(s, dst);
  if (fp) {
    s.xScale = fp->cellX / std::abs(t.c[1]);
    s.yScale = fp->cellY / std::abs(t.c[5]);
  }
  Resampling r = s.in.resampling;
  if (r == Resampling::MinimumIfCoarser) {
    if (!fp) return fp.error();
    const bool coarser = std::abs(t.c[1]) > fp->cellX * (1 + 1e-6) || std::abs(t.c[5]) > fp->cellY * (1 + 1e-6);
    r = coarser ? Resampling::Minimum : Resampling::Bilinear;
  }
  switch (r) {
    case Resampling::Nearest: s.alg = GRA_NearestNeighbour; break;
    case Resampling::Bilinear: s.alg = GRA_Bilinear; break;
    case Resampling::Cubic: s.alg = GRA_Cubic; break;
    case Resampling::Minimum:
    case Resampling::MinimumIfCoarser: s.alg = GRA_Min; break;
  }
  // Culling needs a north-up target and a footprint that cannot wrap around the globe.
  const bool wraps = target.geographic && (fp && (fp->maxX - fp->minX >= 359.0 || fp->minX < -180 || fp->maxX > 180 ||
                                                  t.c[0] < -180 || t.x(target.width, 0) > 180));
  if (fp && t.isNorthUp() && !wraps) {
    s.culls = true;
    s.px0 = (fp->minX - t.c[0]) / t.c[1];
    s.px1 = (fp->maxX - t.c[0]) / t.c[1];
    s.py0 = (fp->maxY - t.c[3]) / t.c[5];
    s.py1 = (fp->minY - t.c[3]) / t.c[5];
    if (s.px0 > s.px1) std::swap(s.px0, s.px1);
    if (s.py0 > s.py1) std::swap(s.py0, s.py1);
  }
  return {};
}

// The input's cells on window `w` of `target` (NaN where it has none).
Result<Grid<float>> sample(Source& s, const Georef& target, const CellRect& w) {
  if (s.aligned) {
    const CellRect src{w.x - s.dx, w.y - s.dy, w.width, w.height};
    if (s.file) return s.file->readPadded(src);
    const auto& v = s.in.raster->values;
    const int ox = s.in.within ? s.in.withinX : 0, oy = s.in.within ? s.in.withinY : 0;  // the window's place
    Grid<float> out(w.width, w.height, kNoData);
    for (int y = 0; y < w.height; ++y) {
      for (int x = 0; x < w.width; ++x) {
        if (v.contains(src.x + x - ox, src.y + y - oy)) out.at(x, y) = v.at(src.x + x - ox, src.y + y - oy);
      }
    }
    return out;
  }
  // A margin of 4 cells: kernels (cubic reaches 2 cells) at the footprint's edge still count.
  constexpr double kMargin = 4;
  if (s.culls && (w.x + w.width < s.px0 - kMargin || w.x > s.px1 + kMargin || w.y + w.height < s.py0 - kMargin ||
                  w.y > s.py1 + kMargin)) {
    return Grid<float>(w.width, w.height, kNoData);
  }
  // The transformer maps the whole target grid's cells (a one-cell dataset of the target's CRS,
  // then the target's own geotransform): a window's cells are found where the whole grid's are,
  // to the bit, whatever the window (a window's own corner would round differently).
  STRATA_TRY(DatasetPtr dst, detail::memDataset(windowOf(target, 0, 0, 1, 1), nullptr));

  detail::GdalErrorCapture errors;
  // Exact transformer: no approximation error at cell centres (GDAL's default allows 0.125 px).
  void* transformer =
      GDALCreateGenImgProjTransformer2(GDALDataset::ToHandle(s.ds.get()), GDALDataset::ToHandle(dst.get()), nullptr);
  if (!transformer) return fail(s.name + ": no transformation to the mosaic grid: " + errors.last());
  GDALSetGenImgProjTransformerDstGeoTransform(transformer, target.transform.c);
  GDALWarpOptions* wo = GDALCreateWarpOptions();
  wo->hSrcDS = GDALDataset::ToHandle(s.ds.get());
  wo->hDstDS = nullptr;  // warped into `out` (WarpRegionToBuffer)
  wo->nBandCount = 1;
  wo->panSrcBands = static_cast<int*>(CPLMalloc(sizeof(int)));
  wo->panSrcBands[0] = s.band;
  wo->panDstBands = static_cast<int*>(CPLMalloc(sizeof(int)));
  wo->panDstBands[0] = 1;
  wo->eWorkingDataType = GDT_Float32;
  wo->eResampleAlg = s.alg;
  if (s.noData) {
    wo->padfSrcNoDataReal = static_cast<double*>(CPLMalloc(sizeof(double)));
    wo->padfSrcNoDataReal[0] = *s.noData;
  }
  wo->padfDstNoDataReal = static_cast<double*>(CPLMalloc(sizeof(double)));
  wo->padfDstNoDataReal[0] = std::nan("");
  wo->papszWarpOptions = CSLSetNameValue(wo->papszWarpOptions, "INIT_DEST", "NO_DATA");
  if (s.xScale > 0 && s.yScale > 0) {
    char scale[32];
    std::snprintf(scale, sizeof scale, "%.17g", s.xScale);
    wo->papszWarpOptions = CSLSetNameValue(wo->papszWarpOptions, "XSCALE", scale);
    std::snprintf(scale, sizeof scale, "%.17g", s.yScale);
    wo->papszWarpOptions = CSLSetNameValue(wo->papszWarpOptions, "YSCALE", scale);
  }
  wo->pfnTransformer = GDALGenImgProjTransform;
  wo->pTransformerArg = transformer;
  Grid<float> out(w.width, w.height, kNoData);
  CPLErr err = CE_Failure;
  {
    // In strips of rows, each with the source window it needs (as ChunkAndWarpImage would): at
    // most ~4 M cells of the window and ~16 M cells of the source under them (many source cells
    // to a cell where the target is much coarser; a single row may exceed that).
    GDALWarpOperation op;
    if (op.Initialize(wo) == CE_None) {
      const double perCell = s.xScale > 0 && s.yScale > 0 ? std::max(1.0, 1.0 / (s.xScale * s.yScale)) : 1.0;
      const double stripCells = std::min(double(1 << 22), double(1 << 24) / perCell);
      const int strip = int(std::clamp(stripCells / std::max(1, w.width), 1.0, double(w.height)));
      err = CE_None;
      for (int y = 0; y < w.height && err == CE_None; y += strip) {
        err = op.WarpRegionToBuffer(w.x, w.y + y, w.width, std::min(strip, w.height - y), &out.at(0, y), GDT_Float32);
      }
    }
  }
  GDALDestroyGenImgProjTransformer(transformer);
  GDALDestroyWarpOptions(wo);
  if (err != CE_None) return fail(s.name + ": warp onto the mosaic grid failed: " + errors.last());
  // Scale and offset after the warp: the kernels are affine combinations with weights summing to
  // 1 (and min picks a value), so this equals warping metres.
  if (s.scale != 1 || s.offset != 0) {
    for (float& v : out.data) {
      if (!std::isnan(v)) v = float(double(v) * s.scale + s.offset);
    }
  }
  return out;
}

}  // namespace

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

Result<BlendSpec> parseBlendSpec(std::string_view text) {
  BlendSpec spec;
  constexpr std::string_view kFill = "+fill";
  if (text.size() > kFill.size() && text.substr(text.size() - kFill.size()) == kFill) {
    spec.fillNoData = true;
    text.remove_suffix(kFill.size());
  }
  STRATA_TRY(spec.mode, parseBlendMode(text));
  return spec;
}

std::string inputName(const MosaicInput& input) { return input.raster ? std::string("in-memory raster") : input.path; }

void blendInto(Grid<float>& layer, const Grid<float>& src, BlendMode mode, bool fillNoData) {
  STRATA_CHECK(layer.width == src.width && layer.height == src.height)
      << "blendInto: " << layer.width << "x" << layer.height << " vs " << src.width << "x" << src.height;
  const bool corrects = mode == BlendMode::Add || mode == BlendMode::Subtract || mode == BlendMode::Multiply;
  for (size_t i = 0; i < layer.data.size(); ++i) {
    const float s = src.data[i];
    float& a = layer.data[i];
    if (std::isnan(s)) continue;
    if (std::isnan(a)) {
      if (!corrects || fillNoData) a = s;
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

struct MosaicReader::Impl {
  Georef grid;
  std::vector<Source> sources;
};

MosaicReader::MosaicReader(std::unique_ptr<Impl> impl) : impl_(std::move(impl)) {}
MosaicReader::MosaicReader(MosaicReader&&) noexcept = default;
MosaicReader& MosaicReader::operator=(MosaicReader&&) noexcept = default;
MosaicReader::~MosaicReader() = default;

Result<MosaicReader> MosaicReader::open(std::vector<MosaicInput> inputs, const Georef& grid) {
  if (inputs.empty()) return fail("mosaic: no inputs");
  if (grid.width <= 0 || grid.height <= 0) return fail("mosaic target grid is empty");
  auto impl = std::make_unique<Impl>();
  impl->grid = grid;
  for (const auto& in : inputs) {
    STRATA_TRY(Source s, openSource(in));
    STRATA_TRY_STATUS(placeSource(s, grid));
    impl->sources.push_back(std::move(s));
  }
  return MosaicReader(std::move(impl));
}

const Georef& MosaicReader::grid() const { return impl_->grid; }

bool MosaicReader::readsDirectly(size_t i) const { return i < impl_->sources.size() && impl_->sources[i].aligned; }

Result<Grid<float>> MosaicReader::read(const CellRect& w) {
  if (w.width <= 0 || w.height <= 0) return fail("mosaic: empty window");
  Grid<float> layer(w.width, w.height, kNoData);
  for (auto& s : impl_->sources) {
    STRATA_TRY(auto values, sample(s, impl_->grid, w));
    blendInto(layer, values, s.in.mode, s.in.fillNoData);
  }
  return layer;
}

Result<Raster> warpToGrid(const MosaicInput& input, const Georef& target) {
  MosaicInput in = input;
  in.mode = BlendMode::Replace;
  STRATA_TRY(MosaicReader r, MosaicReader::open({std::move(in)}, target));
  Raster out;
  out.georef = target;
  STRATA_TRY(out.values, r.read({0, 0, target.width, target.height}));
  return out;
}

Result<Layer> buildMosaic(const std::string& name, const Georef& target, std::span<const MosaicInput> inputs) {
  auto reader = MosaicReader::open(std::vector<MosaicInput>(inputs.begin(), inputs.end()), target);
  if (!reader) return fail("mosaic '" + name + "': " + reader.message());
  auto values = reader->read({0, 0, target.width, target.height});
  if (!values) return fail("mosaic '" + name + "': " + values.message());
  Layer layer;
  layer.name = name;
  layer.raster.georef = target;
  layer.raster.values = std::move(*values);
  return layer;
}

Result<Georef> mosaicGrid(std::span<const MosaicInput> inputs, const MosaicGridOptions& options) {
  if (inputs.empty()) return fail("mosaic: no inputs");
  std::vector<Source> sources;
  for (const auto& in : inputs) {
    STRATA_TRY(Source s, openSource(in));
    sources.push_back(std::move(s));
  }
  Georef grid;
  if (options.crs) {
    STRATA_TRY(OGRSpatialReference srs, detail::parseCrs(*options.crs));
    if (!srs.IsGeographic() && !srs.IsProjected())
      return fail("--crs '" + *options.crs + "' is neither geographic nor projected");
    detail::fillCrs(srs, grid);
  } else {
    grid = sources[0].georef;
  }
  STRATA_TRY(OGRSpatialReference dst, detail::srsOf(grid));
  if (options.resolution) {
    const auto& r = *options.resolution;
    if (!(std::isfinite(r[0]) && std::isfinite(r[1]) && r[0] > 0 && r[1] > 0)) {
      return fail("--resolution: cell sizes must be finite and positive");
    }
  }
  if (options.extent) {
    const auto& e = *options.extent;
    for (double v : e) {
      if (!std::isfinite(v)) return fail("--extent: coordinates must be finite");
    }
    if (!(e[0] < e[2] && e[1] < e[3])) return fail("--extent: needs xmin < xmax and ymin < ymax");
  }

  double minX = std::numeric_limits<double>::infinity(), minY = minX, maxX = -minX, maxY = -minX;
  double cellX = minX, cellY = minX;
  // Per input: its cell size in the grid's CRS, and whether it is on that CRS, north-up.
  std::vector<std::array<double, 2>> cells;
  std::vector<bool> native;
  for (auto& s : sources) {
    auto src = detail::srsOf(s.georef);
    const bool onGrid = src && s.georef.transform.isNorthUp() && sameCrs(*src, dst);
    Footprint f;
    if (onGrid) {
      // Its own extent, exactly (GDAL's suggestion may normalise longitudes or pad the edges).
      const auto& t = s.georef.transform;
      const double xa = t.c[0], xb = t.x(s.georef.width, 0), ya = t.c[3], yb = t.y(0, s.georef.height);
      f = {std::min(xa, xb), std::min(ya, yb), std::max(xa, xb), std::max(ya, yb), std::abs(t.c[1]), std::abs(t.c[5])};
    } else {
      STRATA_TRY(f, footprintIn(s, dst));
    }
    if (options.extent) {
      const auto& e = *options.extent;
      if (f.maxX <= e[0] || f.minX >= e[2] || f.maxY <= e[1] || f.minY >= e[3]) {
        return fail(s.name + ": lies outside --extent (its extent " + std::to_string(f.minX) + " " +
                    std::to_string(f.minY) + " " + std::to_string(f.maxX) + " " + std::to_string(f.maxY) + ")");
      }
    }
    minX = std::min(minX, f.minX);
    minY = std::min(minY, f.minY);
    maxX = std::max(maxX, f.maxX);
    maxY = std::max(maxY, f.maxY);
    native.push_back(onGrid);
    cells.push_back(onGrid ? std::array<double, 2>{std::abs(s.georef.transform.c[1]), std::abs(s.georef.transform.c[5])}
                           : std::array<double, 2>{f.cellX, f.cellY});
    cellX = std::min(cellX, cells.back()[0]);
    cellY = std::min(cellY, cells.back()[1]);
  }
  if (options.resolution) {
    cellX = (*options.resolution)[0];
    cellY = (*options.resolution)[1];
  }
  int anchor = -1;  // the first input on the grid's CRS and cell size: the output is aligned with it
  for (size_t i = 0; i < sources.size() && anchor < 0; ++i) {
    if (native[i] && nearlyEqual(cells[i][0], cellX, 1e-9) && nearlyEqual(cells[i][1], cellY, 1e-9)) anchor = int(i);
  }
  double x0, y0;
  int64_t w, h;
  auto cellsAlong = [](double span, double cell) { return std::ceil(span / cell - 1e-6); };
  if (options.extent) {
    const auto& e = *options.extent;
    x0 = e[0];
    y0 = e[3];
    const double cw = cellsAlong(e[2] - e[0], cellX), ch = cellsAlong(e[3] - e[1], cellY);
    if (!(cw < 1e15 && ch < 1e15)) return fail("--extent / --resolution: the grid would be too large");
    w = int64_t(cw);
    h = int64_t(ch);
  } else if (anchor >= 0) {
    // Aligned with the anchor: its cell edges are the output's, so its cells are kept unresampled.
    const auto& a = sources[size_t(anchor)].georef.transform;
    const double c0 = std::floor((minX - a.c[0]) / cellX + 1e-6), c1 = std::ceil((maxX - a.c[0]) / cellX - 1e-6);
    const double r0 = std::floor((a.c[3] - maxY) / cellY + 1e-6), r1 = std::ceil((a.c[3] - minY) / cellY - 1e-6);
    if (!(c1 - c0 < 1e15 && r1 - r0 < 1e15)) return fail("mosaic: the union of the inputs is too large a grid");
    x0 = a.c[0] + c0 * cellX;
    y0 = a.c[3] - r0 * cellY;
    w = int64_t(c1 - c0);
    h = int64_t(r1 - r0);
  } else {
    x0 = minX;
    y0 = maxY;
    const double cw = cellsAlong(maxX - minX, cellX), ch = cellsAlong(maxY - minY, cellY);
    if (!(cw < 1e15 && ch < 1e15)) return fail("mosaic: the union of the inputs is too large a grid");
    w = int64_t(cw);
    h = int64_t(ch);
  }
  const std::string what = options.extent || options.resolution ? "--extent / --resolution" : "the union of the inputs";
  if (w < 1 || h < 1) return fail("mosaic: " + what + " gives an empty grid");
  if (w > (int64_t(1) << 30) || h > (int64_t(1) << 30) || w * h > options.maxCells) {
    return fail("mosaic: " + what + " gives a grid of " + std::to_string(w) + " x " + std::to_string(h) +
                " cells, more than allowed (2^30 a side, " + std::to_string(options.maxCells) +
                " in all); choose --extent or a coarser --resolution");
  }
  grid.transform = {{x0, cellX, 0.0, y0, 0.0, -cellY}};
  grid.width = int(w);
  grid.height = int(h);
  grid.verticalUnit = "m";
  return grid;
}

}  // namespace strata::gis
