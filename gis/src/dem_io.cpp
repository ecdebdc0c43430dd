// DEM reading and GeoTIFF writing through GDAL. See docs/gis.md ("Reading", "Writing").
#include <strata/gis/dem_io.hpp>

#include <cpl_string.h>
#include <cpl_vsi.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <numbers>
#include <optional>
#include <sstream>
#include <utility>

#include "gdal_util.hpp"

namespace strata::gis {
namespace {

using detail::DatasetPtr;
using detail::GdalErrorCapture;

std::string lower(std::string s) {
  std::transform(s.begin(), s.end(), s.begin(), [](unsigned char c) { return char(std::tolower(c)); });
  return s;
}

// Metres per unit of the band's vertical unit; nullopt when the unit is not a length we know.
std::optional<double> metresPerUnit(const std::string& unit) {
  const std::string u = lower(unit);
  if (u.empty() || u == "m" || u == "metre" || u == "metres" || u == "meter" || u == "meters") return 1.0;
  if (u == "ft" || u == "foot" || u == "feet" || u == "international foot") return 0.3048;
  if (u == "us-ft" || u == "us survey foot" || u == "ftus") return 1200.0 / 3937.0;
  if (u == "km" || u == "kilometre" || u == "kilometer") return 1000.0;
  return std::nullopt;
}

struct Probed {
  DemInfo info;
  DatasetPtr ds;
};

Result<Probed> probe(const std::string& path, const ReadOptions& options) {
  STRATA_TRY(DatasetPtr ds, detail::openRaster(path, options.crs, options.transform));
  Probed p;
  DemInfo& info = p.info;
  info.path = path;
  info.driver = ds->GetDriver() ? ds->GetDriver()->GetDescription() : "unknown";
  if (info.driver == "VRT" && (options.crs || options.transform)) {
    // The wrapper that carries an assigned georeference; name the file's own driver.
    if (auto raw = detail::openRaster(path); raw && (*raw)->GetDriver())
      info.driver = (*raw)->GetDriver()->GetDescription();
  }
  info.bandCount = ds->GetRasterCount();
  if (options.band < 1 || options.band > info.bandCount) {
    return fail(path + ": band " + std::to_string(options.band) + " requested, the file has " +
                std::to_string(info.bandCount));
  }
  Georef& g = info.georef;
  g.width = ds->GetRasterXSize();
  g.height = ds->GetRasterYSize();
  if (g.width <= 0 || g.height <= 0)
    return fail(path + ": empty raster (" + std::to_string(g.width) + "x" + std::to_string(g.height) + ")");

  double gt[6];
  const bool hasTransform = ds->GetGeoTransform(gt) == CE_None;
  const OGRSpatialReference* srs = ds->GetSpatialRef();
  if (!hasTransform || !srs) {
    return fail(path + ": no georeference (" +
                std::string(!srs && !hasTransform ? "no CRS and no geotransform"
                            : !srs                ? "no CRS"
                                                  : "no geotransform") +
                "); assign one (strata: --assign-crs EPSG:n / --assign-geotransform c0,c1,c2,c3,c4,c5)");
  }
  if (!srs->IsGeographic() && !srs->IsProjected()) {
    return fail(path + ": unknown CRS '" + std::string(srs->GetName() ? srs->GetName() : "") +
                "' (neither geographic nor projected)");
  }
  detail::fillCrs(*srs, g);
  std::copy(gt, gt + 6, g.transform.c);
  const GeoTransform& t = g.transform;
  if (!(std::isfinite(t.c[0]) && std::isfinite(t.c[1]) && std::isfinite(t.c[2]) && std::isfinite(t.c[3]) &&
        std::isfinite(t.c[4]) && std::isfinite(t.c[5])) ||
      t.c[1] * t.c[5] - t.c[2] * t.c[4] == 0) {
    return fail(path + ": degenerate geotransform (zero or non-finite pixel size)");
  }
  for (const auto& [col, row] : {std::pair{0, 0}, {g.width, 0}, {0, g.height}, {g.width, g.height}}) {
    const double x = t.x(col, row), y = t.y(col, row);
    if (!(std::abs(x) <= 1e10 && std::abs(y) <= 1e10)) {  // as CrsTransform::transform's bound
      std::ostringstream m;
      m << path << ": geotransform puts corner (" << col << ", " << row << ") at (" << x << ", " << y
        << "), beyond any body (more than 1e10 CRS units from the origin)";
      return fail(m.str());
    }
  }
  if (!(g.body.semiMajorM > 0) || !(g.body.flattening >= 0 && g.body.flattening < 1)) {
    return fail(path + ": unknown CRS '" + g.crsName + "' (no usable ellipsoid)");
  }

  GDALRasterBand* band = ds->GetRasterBand(options.band);
  info.bandType = GDALGetDataTypeName(band->GetRasterDataType());
  if (GDALDataTypeIsComplex(band->GetRasterDataType())) {
    return fail(path + ": band type " + info.bandType + " is complex, not an elevation");
  }
  band->GetBlockSize(&info.blockWidth, &info.blockHeight);
  int ok = 0;
  info.scale = band->GetScale(&ok);
  if (!ok) info.scale = 1;
  info.offset = band->GetOffset(&ok);
  if (!ok) info.offset = 0;
  if (!std::isfinite(info.scale) || !std::isfinite(info.offset) || info.scale == 0) {
    return fail(path + ": invalid scale/offset " + std::to_string(info.scale) + "/" + std::to_string(info.offset));
  }
  int hasNoData = 0;
  const double nd = band->GetNoDataValue(&hasNoData);
  if (hasNoData) info.nodata = nd;
  const std::string unit = band->GetUnitType() ? band->GetUnitType() : "";
  const auto perUnit = metresPerUnit(unit);
  if (!perUnit) return fail(path + ": unsupported vertical unit '" + unit + "' (expected metres or feet)");
  info.unitToMetres = *perUnit;
  g.verticalUnit = "m";
  info.offsetIsBodyRadius = g.body.isSphere() && info.offset != 0 && std::abs(info.offset - g.body.semiMajorM) < 1.0;
  p.ds = std::move(ds);
  return p;
}

// A band of whole rows larger than this is not cached (a striped file that wide is read window
// by window instead): 256 MiB of float32.
constexpr double kMaxBandBytes = double(256 << 20);

}  // namespace

struct DemFile::Impl {
  Probed p;
  ReadOptions options;
  // Striped files: rows [bandY0, bandY0 + bandRows) of raw values, whole width.
  std::vector<float> band;
  int bandY0 = 0, bandRows = 0;
  int lastY = -1;  // row of the previous window (another: a new row of tiles, flush GDAL's cache)

  bool striped() const { return p.info.blockWidth == p.info.georef.width && p.info.georef.height > p.info.blockHeight; }

  // Raw float32 values of a window inside the raster.
  Status fetchRaw(const CellRect& w, Grid<float>& out) {
    const auto& full = p.info.georef;
    GdalErrorCapture errors;
    GDALRasterBand* b = p.ds->GetRasterBand(options.band);
    const bool useBand = striped() && w.width < full.width && double(full.width) * w.height * 4 <= kMaxBandBytes;
    if (useBand) {
      if (w.y < bandY0 || w.y + w.height > bandY0 + bandRows) {
        // A band as tall as the window from its first row: windows of one row of tiles share it.
        bandY0 = w.y;
        bandRows = std::min(w.height, full.height - w.y);
        band.assign(size_t(full.width) * size_t(bandRows), 0.0f);
        if (b->RasterIO(GF_Read, 0, bandY0, full.width, bandRows, band.data(), full.width, bandRows, GDT_Float32, 0,
                        0) != CE_None) {
          bandRows = 0;
          return fail(p.info.path + ": read failed (truncated or corrupt file?): " + errors.last());
        }
        b->FlushCache(false);  // the band is the only copy kept
      }
      for (int y = 0; y < w.height; ++y) {
        std::copy_n(&band[size_t(w.y + y - bandY0) * size_t(full.width) + size_t(w.x)], w.width,
                    &out.data[out.index(0, y)]);
      }
      return {};
    }
    if (w.y != lastY) b->FlushCache(false);
    lastY = w.y;
    // RasterIO on the window reads only the blocks that intersect it.
    if (b->RasterIO(GF_Read, w.x, w.y, w.width, w.height, out.data.data(), w.width, w.height, GDT_Float32, 0, 0) !=
        CE_None) {
      return fail(p.info.path + ": read failed (truncated or corrupt file?): " + errors.last());
    }
    return {};
  }

  Result<Raster> read(const CellRect& w, bool allowAllNoData, bool isWindow) {
    const DemInfo& info = p.info;
    const std::string& path = info.path;
    const Georef& full = info.georef;
    if (w.width <= 0 || w.height <= 0 || w.x < 0 || w.y < 0 || w.x > full.width - w.width ||
        w.y > full.height - w.height) {
      std::ostringstream m;
      m << path << ": window " << w.width << "x" << w.height << "+" << w.x << "+" << w.y << " is outside the "
        << full.width << "x" << full.height << " raster";
      return fail(m.str());
    }
    // The byte budget is checked before anything is allocated: a header may claim any size.
    const double bytes = double(w.width) * double(w.height) * sizeof(float);
    if (bytes > double(options.maxBytes)) {
      std::ostringstream m;
      m << path << ": " << w.width << "x" << w.height << " pixels (" << bytes / double(1 << 20)
        << " MiB as float32) exceed the read budget of " << double(options.maxBytes) / double(1 << 20)
        << " MiB; read a window";
      return fail(m.str());
    }

    Raster r;
    r.georef = full;
    r.georef.width = w.width;
    r.georef.height = w.height;
    GeoTransform& t = r.georef.transform;
    t.c[0] = full.transform.x(w.x, w.y);
    t.c[3] = full.transform.y(w.x, w.y);
    r.values = Grid<float>(w.width, w.height);
    STRATA_TRY_STATUS(fetchRaw(w, r.values));

    const bool nodataIsNaN = info.nodata && std::isnan(*info.nodata);
    const float nodataRaw = info.nodata && !nodataIsNaN ? float(*info.nodata) : 0.0f;
    const bool hasNumericNoData = info.nodata && !nodataIsNaN;
    const double offset =
        info.offsetIsBodyRadius && !options.keepBodyRadius ? info.offset - full.body.semiMajorM : info.offset;
    const double scale = info.scale * info.unitToMetres;
    const double offsetM = offset * info.unitToMetres;
    size_t valid = 0;
    for (int y = 0; y < w.height; ++y) {
      for (int x = 0; x < w.width; ++x) {
        float& v = r.values.at(x, y);
        if (std::isnan(v)) {
          if (nodataIsNaN) continue;
          std::ostringstream m;
          m << path << ": NaN value at pixel (" << w.x + x << ", " << w.y + y
            << ") and no NaN nodata value; NaN is not an elevation (set a nodata value)";
          return fail(m.str());
        }
        if (hasNumericNoData && v == nodataRaw) {
          v = kNoData;
          continue;
        }
        if (!std::isfinite(v)) {
          std::ostringstream m;
          m << path << ": infinite value at pixel (" << w.x + x << ", " << w.y + y << ")";
          return fail(m.str());
        }
        v = float(double(v) * scale + offsetM);
        ++valid;
      }
    }
    if (valid == 0 && !allowAllNoData) {
      std::ostringstream m;
      m << path << ": no data: all " << w.width << "x" << w.height << " cells" << (isWindow ? " of the window" : "")
        << " are nodata";
      return fail(m.str());
    }
    return r;
  }
};

DemFile::DemFile(std::unique_ptr<Impl> impl) : impl_(std::move(impl)) {}
DemFile::DemFile(DemFile&&) noexcept = default;
DemFile& DemFile::operator=(DemFile&&) noexcept = default;
DemFile::~DemFile() = default;

Result<DemFile> DemFile::open(const std::string& path, const ReadOptions& options) {
  STRATA_TRY(Probed p, probe(path, options));
  auto impl = std::make_unique<Impl>();
  impl->p = std::move(p);
  impl->options = options;
  return DemFile(std::move(impl));
}

const DemInfo& DemFile::info() const { return impl_->p.info; }

Result<Raster> DemFile::read(const CellRect& window) {
  return impl_->read(window, impl_->options.allowAllNoData, true);
}

Result<Grid<float>> DemFile::readPadded(const CellRect& w) {
  if (w.width < 0 || w.height < 0) return fail(impl_->p.info.path + ": window with a negative size");
  Grid<float> out(w.width, w.height, kNoData);
  const auto& g = impl_->p.info.georef;
  const int x0 = std::max(0, w.x), y0 = std::max(0, w.y);
  const int x1 = int(std::min<int64_t>(g.width, int64_t(w.x) + w.width));
  const int y1 = int(std::min<int64_t>(g.height, int64_t(w.y) + w.height));
  if (x0 >= x1 || y0 >= y1) return out;
  STRATA_TRY(Raster r, impl_->read({x0, y0, x1 - x0, y1 - y0}, true, true));
  for (int y = y0; y < y1; ++y) {
    std::copy_n(&r.values.data[r.values.index(0, y - y0)], x1 - x0, &out.data[out.index(x0 - w.x, y - w.y)]);
  }
  return out;
}

Result<DemInfo> probeDem(const std::string& path, const ReadOptions& options) {
  STRATA_TRY(Probed p, probe(path, options));
  return std::move(p.info);
}

Result<Raster> readDem(const std::string& path, const ReadOptions& options) {
  STRATA_TRY(DemFile f, DemFile::open(path, options));
  const Georef& full = f.info().georef;
  const CellRect w = options.window.value_or(CellRect{0, 0, full.width, full.height});
  return f.impl_->read(w, options.allowAllNoData, options.window.has_value());
}

Result<GeorefPresence> georefPresence(const std::string& path) {
  STRATA_TRY(DatasetPtr ds, detail::openRaster(path));
  GeorefPresence p;
  double gt[6];
  p.transform = ds->GetGeoTransform(gt) == CE_None;
  p.crs = ds->GetSpatialRef() != nullptr;
  return p;
}

Result<ReadOptions> assignMissingGeoref(const std::string& path, const std::string& crs,
                                        const std::optional<GeoTransform>& transform) {
  ReadOptions ro;
  if (crs.empty() && !transform) return ro;
  STRATA_TRY(const GeorefPresence has, georefPresence(path));
  if (!has.crs && !crs.empty()) ro.crs = crs;
  if (!has.transform && transform) ro.transform = transform;
  return ro;
}

Result<GeoTransform> parseGeoTransform(std::string_view text, const std::string& key) {
  GeoTransform t;
  std::string s(text);
  for (char& c : s) {
    if (c == ',') c = ' ';
  }
  std::istringstream in(s);
  std::string word;
  int n = 0;
  while (in >> word) {
    if (n == 6) return fail(key + ": '" + std::string(text) + "' has more than 6 numbers (c0,c1,c2,c3,c4,c5)");
    char* end = nullptr;
    const double v = std::strtod(word.c_str(), &end);
    if (end != word.c_str() + word.size() || !std::isfinite(v)) {
      return fail(key + ": '" + word + "' is not a finite number");
    }
    t.c[n++] = v;
  }
  if (n != 6)
    return fail(key + ": '" + std::string(text) + "' needs 6 numbers (c0,c1,c2,c3,c4,c5 as GDAL orders them)");
  if (t.c[1] * t.c[5] - t.c[2] * t.c[4] == 0) return fail(key + ": the pixel size is degenerate (c1 c5 - c2 c4 = 0)");
  return t;
}

namespace {

// `values` with the nodata value for NaN; a real value equal to it would turn into nodata.
Result<Grid<float>> withNoData(const std::string& path, const Grid<float>& values, float nodata) {
  Grid<float> out = values;
  for (float& v : out.data) {
    if (std::isnan(v)) {
      v = nodata;
    } else if (v == nodata) {
      return fail(path + ": cannot write: the value " + std::to_string(nodata) +
                  " occurs in the data and is the nodata value");
    }
  }
  return out;
}

// Creation options of the GeoTIFFs Strata writes (tiled, DEFLATE with the float predictor).
CPLStringList geoTiffOptions(const WriteOptions& options) {
  const std::string block = std::to_string(options.blockSize);
  CPLStringList co;
  co.SetNameValue("COMPRESS", "DEFLATE");
  co.SetNameValue("BIGTIFF", "IF_SAFER");
  if (options.cog) {
    co.SetNameValue("BLOCKSIZE", block.c_str());
    co.SetNameValue("PREDICTOR", "YES");
    co.SetNameValue("RESAMPLING", "AVERAGE");
  } else {
    co.SetNameValue("TILED", "YES");
    co.SetNameValue("BLOCKXSIZE", block.c_str());
    co.SetNameValue("BLOCKYSIZE", block.c_str());
    co.SetNameValue("PREDICTOR", "3");
  }
  return co;
}

Status checkBlockSize(const std::string& path, const WriteOptions& options) {
  if (options.blockSize < 16 || options.blockSize > 4096 || (options.blockSize & (options.blockSize - 1))) {
    return fail(path + ": block size " + std::to_string(options.blockSize) + " is not a power of two in 16..4096");
  }
  if (std::isnan(options.nodata)) return fail(path + ": the nodata value written must be a number");
  return {};
}

}  // namespace

Status createGeoTiff(const std::string& path, const Georef& g, const WriteOptions& options) {
  detail::ensureGdal();
  if (g.width <= 0 || g.height <= 0) {
    return fail(path + ": cannot write an empty raster (" + std::to_string(g.width) + "x" + std::to_string(g.height) +
                ")");
  }
  STRATA_TRY_STATUS(checkBlockSize(path, options));
  if (options.cog) return fail(path + ": a COG cannot be written window by window");
  GdalErrorCapture errors;
  GDALDriver* driver = GetGDALDriverManager()->GetDriverByName("GTiff");
  if (!driver) return fail(path + ": GDAL has no GTiff driver");
  CPLStringList co = geoTiffOptions(options);
  co.SetNameValue("SPARSE_OK", "TRUE");  // tiles never written take no space and read as nodata
  DatasetPtr ds(driver->Create(path.c_str(), g.width, g.height, 1, GDT_Float32, co.List()));
  if (!ds) return fail(path + ": cannot create GeoTIFF: " + errors.last());
  double gt[6];
  for (int i = 0; i < 6; ++i) gt[i] = g.transform.c[i];
  ds->SetGeoTransform(gt);
  auto srs = detail::srsOf(g);
  if (!srs) {
    ds.reset();
    VSIUnlink(path.c_str());
    return fail(path + ": " + srs.message());
  }
  ds->SetSpatialRef(&*srs);
  ds->GetRasterBand(1)->SetNoDataValue(options.nodata);
  for (const auto& [name, value] : options.metadata) ds->SetMetadataItem(name.c_str(), value.c_str());
  if (!options.description.empty()) ds->GetRasterBand(1)->SetDescription(options.description.c_str());
  if (!options.units.empty()) ds->GetRasterBand(1)->SetUnitType(options.units.c_str());
  ds.reset();  // flush and close
  if (CPLGetLastErrorType() >= CE_Failure) {
    VSIUnlink(path.c_str());
    return fail(path + ": cannot create GeoTIFF: " + errors.last());
  }
  return {};
}

Status writeGeoTiffWindows(const std::string& path, const std::vector<GridWindow>& windows, float nodata) {
  detail::ensureGdal();
  GdalErrorCapture errors;
  DatasetPtr ds(GDALDataset::Open(path.c_str(), GDAL_OF_RASTER | GDAL_OF_UPDATE, nullptr, nullptr, nullptr));
  if (!ds) return fail(path + ": cannot open for writing: " + errors.last());
  for (const auto& w : windows) {
    const int width = w.values.width, height = w.values.height;
    if (w.x < 0 || w.y < 0 || width <= 0 || height <= 0 || w.x + width > ds->GetRasterXSize() ||
        w.y + height > ds->GetRasterYSize()) {
      return fail(path + ": the window (" + std::to_string(w.x) + ", " + std::to_string(w.y) + ") " +
                  std::to_string(width) + "x" + std::to_string(height) + " is not inside its " +
                  std::to_string(ds->GetRasterXSize()) + "x" + std::to_string(ds->GetRasterYSize()) + " cells");
    }
    STRATA_TRY(Grid<float> out, withNoData(path, w.values, nodata));
    if (ds->GetRasterBand(1)->RasterIO(GF_Write, w.x, w.y, width, height, out.data.data(), width, height, GDT_Float32,
                                       0, 0) != CE_None) {
      return fail(path + ": cannot write a window: " + errors.last());
    }
  }
  ds.reset();  // flush and close: the next writer opens it after
  if (CPLGetLastErrorType() >= CE_Failure) return fail(path + ": cannot write a window: " + errors.last());
  return {};
}

Status writeGeoTiff(const std::string& path, const Raster& raster, const WriteOptions& options) {
  detail::ensureGdal();
  const Georef& g = raster.georef;
  if (g.width <= 0 || g.height <= 0 || raster.values.width != g.width || raster.values.height != g.height) {
    return fail(path + ": cannot write: raster is " + std::to_string(raster.values.width) + "x" +
                std::to_string(raster.values.height) + ", georeference says " + std::to_string(g.width) + "x" +
                std::to_string(g.height));
  }
  STRATA_TRY_STATUS(checkBlockSize(path, options));
  STRATA_TRY(Grid<float> out, withNoData(path, raster.values, options.nodata));
  const bool virtualPath = path.rfind("/vsi", 0) == 0;
  if (!options.overwrite) {
    VSIStatBufL st;
    if (VSIStatL(path.c_str(), &st) == 0) return fail(path + ": already exists (not overwritten)");
  }
  auto mem = detail::memDataset(g, &out);
  if (!mem) return fail(path + ": cannot write: " + mem.message());
  (*mem)->GetRasterBand(1)->SetNoDataValue(options.nodata);
  for (const auto& [name, value] : options.metadata) (*mem)->SetMetadataItem(name.c_str(), value.c_str());
  if (!options.description.empty()) (*mem)->GetRasterBand(1)->SetDescription(options.description.c_str());
  if (!options.units.empty()) (*mem)->GetRasterBand(1)->SetUnitType(options.units.c_str());

  GdalErrorCapture errors;
  GDALDriver* driver = GetGDALDriverManager()->GetDriverByName(options.cog ? "COG" : "GTiff");
  if (!driver) return fail(path + ": GDAL has no " + std::string(options.cog ? "COG" : "GTiff") + " driver");
  const CPLStringList co = geoTiffOptions(options);
  const std::string tmp = path + ".tmp" + std::to_string(::getpid());
  DatasetPtr written(driver->CreateCopy(tmp.c_str(), mem->get(), FALSE, co.List(), nullptr, nullptr));
  if (!written) {
    VSIUnlink(tmp.c_str());
    return fail(path + ": cannot write GeoTIFF: " + errors.last());
  }
  written.reset();  // flush and close before the rename
  if (CPLGetLastErrorType() >= CE_Failure) {
    VSIUnlink(tmp.c_str());
    return fail(path + ": cannot write GeoTIFF: " + errors.last());
  }
  if (!options.overwrite && !virtualPath) {
    // link() fails if the target exists: no window between a check and the rename.
    const int rc = ::link(tmp.c_str(), path.c_str());
    const int err = errno;
    VSIUnlink(tmp.c_str());
    if (rc != 0) {
      return fail(path + (err == EEXIST
                              ? ": already exists (not overwritten)"
                              : ": cannot move the written temporary into place: " + std::string(std::strerror(err))));
    }
    return {};
  }
  if (VSIRename(tmp.c_str(), path.c_str()) != 0) {
    VSIUnlink(tmp.c_str());
    return fail(path + ": cannot rename the written temporary into place");
  }
  return {};
}

Status rewriteAsCog(const std::string& path, int blockSize) {
  detail::ensureGdal();
  GdalErrorCapture errors;
  DatasetPtr src(GDALDataset::FromHandle(GDALOpen(path.c_str(), GA_ReadOnly)));
  if (!src) return fail(path + ": cannot open: " + errors.last());
  GDALDriver* driver = GetGDALDriverManager()->GetDriverByName("COG");
  if (!driver) return fail(path + ": GDAL has no COG driver");
  WriteOptions options;
  options.cog = true;
  options.blockSize = blockSize;
  STRATA_TRY_STATUS(checkBlockSize(path, options));
  const CPLStringList co = geoTiffOptions(options);
  const std::string tmp = path + ".tmp" + std::to_string(::getpid());
  DatasetPtr written(driver->CreateCopy(tmp.c_str(), src.get(), FALSE, co.List(), nullptr, nullptr));
  src.reset();
  if (!written) {
    VSIUnlink(tmp.c_str());
    return fail(path + ": cannot write a COG: " + errors.last());
  }
  written.reset();
  if (CPLGetLastErrorType() >= CE_Failure || VSIRename(tmp.c_str(), path.c_str()) != 0) {
    VSIUnlink(tmp.c_str());
    return fail(path + ": cannot write a COG: " + errors.last("cannot rename the temporary into place"));
  }
  return {};
}

namespace {
// The numeric value of PARAMETER["name", value, ...] in a WKT2 string.
std::optional<double> wktParameter(const std::string& wkt, const std::string& name) {
  const std::string key = "\"" + name + "\",";
  const auto at = wkt.find(key);
  if (at == std::string::npos) return std::nullopt;
  return std::strtod(wkt.c_str() + at + key.size(), nullptr);
}
}  // namespace

Result<Raster> readDemLonLat(const std::string& path, const ReadOptions& options) {
  STRATA_TRY(auto dem, readDem(path, options));
  return toLonLat(std::move(dem), path);
}

Result<Raster> toLonLat(Raster dem, const std::string& label) {
  auto& g = dem.georef;
  if (g.geographic) return dem;
  const bool equirectangular = g.crsWkt.find("Equirectangular") != std::string::npos ||
                               g.crsWkt.find("Equidistant Cylindrical") != std::string::npos;
  if (!equirectangular || !g.body.isSphere()) {
    return fail(label + ": not geographic and not equirectangular on a sphere (" + g.crsName +
                "); reproject it to lon/lat first (gdalwarp -t_srs with the body's geographic CRS)");
  }
  const auto central = wktParameter(g.crsWkt, "Longitude of natural origin");
  if (!central) return fail(label + ": equirectangular CRS without a longitude of natural origin");
  const double parallel = wktParameter(g.crsWkt, "Latitude of 1st standard parallel").value_or(0.0);
  if (parallel != 0.0) {
    return fail(label + ": equirectangular with its standard parallel at " + std::to_string(parallel) +
                " degrees; only 0 (x linear in longitude at the body's radius) is supported");
  }
  if (std::abs(g.transform.c[2]) > 0 || std::abs(g.transform.c[4]) > 0) {
    return fail(label + ": rotated geotransform");
  }
  const double mPerDeg = g.body.semiMajorM * std::numbers::pi / 180;
  for (int k : {0, 1, 3, 5}) g.transform.c[k] /= mPerDeg;
  g.transform.c[0] += *central;
  g.geographic = true;
  return dem;
}

}  // namespace strata::gis
