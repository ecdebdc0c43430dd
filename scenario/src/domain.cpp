#include <strata/scenario/domain.hpp>
#include <strata/scenario/run.hpp>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <map>
#include <memory>
#include <set>
#include <tuple>

#include <strata/core/memory.hpp>
#include <strata/core/progress.hpp>
#include <strata/gis/dem_io.hpp>
#include <strata/gis/fill_depressions.hpp>
#include <strata/gis/fill_nodata.hpp>
#include <strata/gis/geodesy.hpp>
#include <strata/gis/mosaic.hpp>
#include <strata/sim/exact_sum.hpp>
#include <strata/terrain/material.hpp>
#include <strata/terrain/tile_store.hpp>

#include "domain_rows.hpp"

namespace strata::scenario {
namespace {

using terrain::findMaterial;
using terrain::LayerKind;
using terrain::Material;
using terrain::TileStore;

// "file:line: key 'k': message" for a place read from the scenario.
Error placeError(const Scenario& s, const Place& p, const std::string& message) {
  return fail(s.file.string() + ":" + std::to_string(p.line) + ": key '" + oneLine(p.key) + "': " + oneLine(message));
}

// Converts places of the scenario to pixel coordinates of a georef (fractional, (0,0) = top-left
// corner of the top-left cell).
class PixelMapper {
 public:
  static Result<PixelMapper> create(const gis::Georef& g) {
    if (!g.transform.isNorthUp()) return fail("the DEM is not north-up (rotated geotransforms are not supported)");
    PixelMapper m;
    m.g_ = g;
    if (!g.geographic) {
      if (g.body.name != gis::Body::wgs84().name) {
        m.lonLatError_ = "lon/lat places on a projected CRS of " + g.body.name + " are not supported; use *_xy";
      } else {
        auto t = gis::CrsTransform::create("EPSG:4326", g.crsWkt);
        if (!t) return t.error();
        m.toCrs_ = std::make_shared<gis::CrsTransform>(std::move(t).value());
      }
    }
    return m;
  }

  // Pixel coordinates of a place's points.
  Result<std::vector<std::array<double, 2>>> pixels(const Scenario& s, const Place& p) const {
    std::vector<std::array<double, 2>> out;
    for (auto pt : p.points) {
      double x = pt[0], y = pt[1];
      if (p.frame == CoordFrame::LonLat) {
        if (!lonLatError_.empty()) return placeError(s, p, lonLatError_);
        if (g_.geographic) {
          // Longitudes 0..360 and -180..180 both: move x into the DEM's longitude range.
          const double west = g_.transform.c[0], east = west + g_.width * g_.transform.c[1];
          while (x < west && x + 360 <= east + 1e-9) x += 360;
          while (x > east && x - 360 >= west - 1e-9) x -= 360;
        } else if (!toCrs_->transform(1, &x, &y)) {
          return placeError(
              s, p, "cannot transform [" + std::to_string(pt[0]) + ", " + std::to_string(pt[1]) + "] to the DEM's CRS");
        }
      }
      out.push_back({(x - g_.transform.c[0]) / g_.transform.c[1], (y - g_.transform.c[3]) / g_.transform.c[5]});
    }
    return out;
  }

 private:
  gis::Georef g_;
  std::shared_ptr<gis::CrsTransform> toCrs_;
  std::string lonLatError_;
};

std::string describeExtent(const gis::Georef& g) {
  char buf[160];
  const double x0 = g.transform.c[0], y0 = g.transform.c[3];
  const double x1 = x0 + g.width * g.transform.c[1], y1 = y0 + g.height * g.transform.c[5];
  std::snprintf(buf, sizeof buf, "[%.8g, %.8g, %.8g, %.8g]", std::min(x0, x1), std::min(y0, y1), std::max(x0, x1),
                std::max(y0, y1));
  return buf;
}

// A material layer read from a tile store: its thickness (m) on the region and its material.
struct StoredLayer {
  gis::Raster thickness;
  int material = 0;  ///< index into TerrainSource::materials()
};

// Where the bed (and stored layers) come from: DEM files read through GDAL, or a tile store read
// at its base level (level 0, full resolution). The region's window, the resampling and
// everything after are the same for both.
class TerrainSource {
 public:
  static Result<TerrainSource> open(const Scenario& s) {
    TerrainSource t;
    if (s.terrain.store.empty()) {
      t.path_ = s.terrain.dems.front();
      STRATA_TRY(t.assigned_, assignments(s));
      STRATA_TRY(auto info, gis::probeDem(t.path_, t.readOptions(t.path_)));
      t.georef_ = info.georef;
      return t;
    }
    t.path_ = s.terrain.store;
    const std::string key = s.file.string() + ": key 'terrain.store': ";
    auto store = TileStore::open(t.path_);
    if (!store) return fail(key + store.message());
    for (size_t f = 0; f < store->desc().fields.size(); ++f) {
      const auto& field = store->desc().fields[f];
      if (field.kind == LayerKind::Bedrock && t.bedField_ < 0) t.bedField_ = int(f);
      if (field.kind == LayerKind::Material) {
        if (findMaterial(store->desc().materials, field.material) < 0) {
          return fail(key + t.path_ + ": field '" + field.name + "' has material \"" + field.material +
                      "\", which the store's material table lacks");
        }
        t.layerFields_.push_back(int(f));
      }
    }
    if (t.bedField_ < 0) return fail(key + t.path_ + ": the store has no bedrock field");
    t.georef_ = store->windowGeoref({0, 0, store->width(), store->height()}, 0);
    t.store_ = std::make_shared<TileStore>(std::move(store).value());
    return t;
  }

  /// How many material layers the store holds (none for DEMs).
  int layerCount() const { return int(layerFields_.size()); }
  /// The full base grid (the first DEM's, or the store's level 0).
  const gis::Georef& georef() const { return georef_; }
  const std::string& path() const { return path_; }
  std::string kind() const { return store_ ? "store" : "DEM"; }
  /// "DEM <path>" or "store <path>", for messages.
  std::string name() const { return kind() + " " + path_; }
  std::vector<Material> materials() const { return store_ ? store_->desc().materials : terrain::defaultMaterials(); }
  /// The materials of the store's layers, bottom first (none for DEMs).
  std::vector<Material> layerMaterials() const {
    std::vector<Material> out;
    for (int f : layerFields_) {
      out.push_back(
          store_->desc()
              .materials[size_t(findMaterial(store_->desc().materials, store_->desc().fields[size_t(f)].material))]);
    }
    return out;
  }

  /// The bed elevation of `w` (base-grid cells), at the source's own resolution.
  Result<gis::Raster> readBed(const gis::CellRect& w) const {
    if (!store_) {
      gis::ReadOptions ro = readOptions(path_);
      ro.window = w;
      return gis::readDem(path_, ro);
    }
    return readField(bedField_, w);
  }

  /// What gis::MosaicReader resamples from: the DEM file `path` itself (GDAL reads what it needs;
  /// by default the first DEM).
  gis::MosaicInput resampleInput(const std::string& path = {}) const {
    gis::MosaicInput in{path.empty() ? path_ : path, std::nullopt};
    const gis::ReadOptions ro = readOptions(in.path);
    in.assignCrs = ro.crs;
    in.assignTransform = ro.transform;
    return in;
  }

  /// A store's window `w` as a warp of a store window of it sees it (MosaicInput::within): its
  /// georeference, the one readBed gives it.
  gis::MosaicInput storeWindowInput(gis::Raster cells, const gis::CellRect& w, int x, int y) const {
    gis::MosaicInput in{"", std::move(cells)};
    in.within = store_->windowGeoref(w, 0);
    in.withinX = x;
    in.withinY = y;
    return in;
  }

  /// The store's material layers over `w`, bottom first (none for DEMs).
  Result<std::vector<StoredLayer>> readLayers(const gis::CellRect& w) const {
    std::vector<StoredLayer> out;
    for (int f : layerFields_) {
      STRATA_TRY(auto r, readField(f, w));
      out.push_back({std::move(r), findMaterial(store_->desc().materials, store_->desc().fields[size_t(f)].material)});
    }
    return out;
  }

 private:
  Result<gis::Raster> readField(int field, const gis::CellRect& w) const {
    const gis::CellRect sw{w.x, w.y, w.width, w.height};
    auto values = store_->readWindow(field, sw, 0);
    if (!values) {
      return fail(path_ + ": field '" + store_->desc().fields[size_t(field)].name + "': " + values.message());
    }
    return gis::Raster{store_->windowGeoref(sw, 0), std::move(values).value()};
  }

  // What [terrain] assign_crs / assign_geotransform fill in for one DEM: only what it lacks.
  struct Assigned {
    std::optional<std::string> crs;
    std::optional<gis::GeoTransform> transform;
  };

  // The assignments of every DEM of the scenario; a DEM without georeference and nothing to fill it
  // in, or an assignment no DEM needs, is an error naming the key.
  static Result<std::map<std::string, Assigned>> assignments(const Scenario& s) {
    std::map<std::string, Assigned> out;
    bool crsUsed = false, gtUsed = false;
    for (const auto& path : s.terrain.dems) {
      STRATA_TRY(auto has, gis::georefPresence(path));
      Assigned a;
      if (!has.crs && s.terrain.assignCrs) a.crs = *s.terrain.assignCrs, crsUsed = true;
      if (!has.transform && s.terrain.assignGeotransform) {
        gis::GeoTransform gt;
        std::copy(s.terrain.assignGeotransform->begin(), s.terrain.assignGeotransform->end(), gt.c);
        a.transform = gt;
        gtUsed = true;
      }
      if (!has.crs && !a.crs) {
        return fail(s.at("terrain.dem") + path +
                    ": has no CRS; give it one with [terrain] assign_crs = \"EPSG:n\" (or WKT or PROJ text)");
      }
      if (!has.transform && !a.transform) {
        return fail(s.at("terrain.dem") + path +
                    ": has no geotransform; give it one with [terrain] assign_geotransform = "
                    "[x0, dx, rx, y0, ry, dy]");
      }
      out[path] = std::move(a);
    }
    if (s.terrain.assignCrs && !crsUsed) {
      return fail(s.at("terrain.assign_crs") + "every DEM has a CRS of its own (it fills in a missing one)");
    }
    if (s.terrain.assignGeotransform && !gtUsed) {
      return fail(s.at("terrain.assign_geotransform") +
                  "every DEM has a geotransform of its own (it fills in a missing one)");
    }
    return out;
  }

  gis::ReadOptions readOptions(const std::string& path) const {
    gis::ReadOptions ro;
    if (auto it = assigned_.find(path); it != assigned_.end()) {
      ro.crs = it->second.crs;
      ro.transform = it->second.transform;
    }
    return ro;
  }

  std::string path_;
  std::map<std::string, Assigned> assigned_;  // DEMs only, by path
  gis::Georef georef_;
  std::shared_ptr<TileStore> store_;  // shared: readWindow caches tiles (non-const)
  int bedField_ = -1;
  std::vector<int> layerFields_;
};

}  // namespace

std::vector<std::pair<int, int>> cellsAlong(const std::vector<std::array<double, 2>>& pts, int width, int height) {
  std::vector<std::pair<int, int>> cells;
  std::set<std::pair<int, int>> seen;
  auto add = [&](double x, double y) {
    // Compared as doubles first: a point far outside (or NaN) must not reach an int conversion.
    if (!(x >= 0 && y >= 0 && x < width && y < height)) return;
    const int cx = int(std::floor(x)), cy = int(std::floor(y));
    if (cx >= width || cy >= height) return;
    if (seen.insert({cx, cy}).second) cells.push_back({cx, cy});
  };
  if (pts.size() == 1) add(pts[0][0], pts[0][1]);
  for (size_t i = 1; i < pts.size(); ++i) {
    const double dx = pts[i][0] - pts[i - 1][0], dy = pts[i][1] - pts[i - 1][1];
    // A quarter cell per sample, over at most the grid's diagonal (the part inside).
    const double len = std::min(std::hypot(dx, dy), 2.0 * std::hypot(double(width), double(height)) + 2);
    if (!std::isfinite(len)) continue;
    const int n = std::max(1, int(std::ceil(4 * len)));
    for (int k = 0; k <= n; ++k) add(pts[i - 1][0] + dx * k / n, pts[i - 1][1] + dy * k / n);
  }
  return cells;
}

std::vector<ScenarioDomain::SectionFace> facesCrossed(const std::vector<std::array<double, 2>>& pts, int width,
                                                      int height) {
  // Each face's centre-to-centre segment lies on a line x = const (a y face) or y = const (an x
  // face); a polyline segment crosses it where it crosses that line within the face's span. The
  // half-open test (a <= c) != (b <= c) counts a vertex on the line once. A face crossed twice sums.
  std::map<std::tuple<bool, int, int>, float> sum;
  for (size_t i = 1; i < pts.size(); ++i) {
    const auto a = pts[i - 1], b = pts[i];
    const double dx = b[0] - a[0], dy = b[1] - a[1];
    if (!std::isfinite(dx) || !std::isfinite(dy)) continue;
    // x faces (x, y): the line y + 0.5, between centres x - 0.5 and x + 0.5; positive east, which
    // is from the left to the right of a line heading north (dy < 0 in pixels, rows go south).
    const int ya = std::max(0, int(std::floor(std::min(a[1], b[1]) - 0.5)));
    const int yb = std::min(height - 1, int(std::ceil(std::max(a[1], b[1]))));
    for (int y = ya; y <= yb; ++y) {
      const double c = y + 0.5;
      if ((a[1] <= c) == (b[1] <= c)) continue;
      const int x = int(std::floor(a[0] + (c - a[1]) * dx / dy + 0.5));
      if (x >= 1 && x <= width - 1) sum[{true, x, y}] += dy > 0 ? -1.0f : 1.0f;
    }
    // y faces (x, y): the line x + 0.5, between centres y - 0.5 and y + 0.5; positive south,
    // from the left to the right of a line heading east.
    const int xa = std::max(0, int(std::floor(std::min(a[0], b[0]) - 0.5)));
    const int xb = std::min(width - 1, int(std::ceil(std::max(a[0], b[0]))));
    for (int x = xa; x <= xb; ++x) {
      const double c = x + 0.5;
      if ((a[0] <= c) == (b[0] <= c)) continue;
      const int y = int(std::floor(a[1] + (c - a[0]) * dy / dx + 0.5));
      if (y >= 1 && y <= height - 1) sum[{false, x, y}] += dx > 0 ? 1.0f : -1.0f;
    }
  }
  std::vector<ScenarioDomain::SectionFace> faces;
  for (const auto& [k, sign] : sum) {
    if (sign != 0.0f) faces.push_back({std::get<0>(k), std::get<1>(k), std::get<2>(k), sign});
  }
  return faces;
}

bool insidePolygon(const std::vector<std::array<double, 2>>& poly, double x, double y) {
  bool in = false;
  for (size_t i = 0, j = poly.size() - 1; i < poly.size(); j = i++) {
    const auto &a = poly[i], &b = poly[j];
    if ((a[1] > y) != (b[1] > y) && x < (b[0] - a[0]) * (y - a[1]) / (b[1] - a[1]) + a[0]) in = !in;
  }
  return in;
}

namespace {

// Where the region lies on the source's grid: the window of source cells it covers, how many
// region cells a source cell becomes along each axis (region.cell_size), and the polygon in
// source pixels (empty for a bbox or the whole grid).
struct RegionFrame {
  gis::CellRect window;
  int width = 0, height = 0;  ///< the grid's cells (planGrid)
  double scaleX = 1.0, scaleY = 1.0;
  std::vector<std::array<double, 2>> polygonPx;

  // Source pixel coordinates to region cell coordinates.
  std::vector<std::array<double, 2>> toRegion(std::vector<std::array<double, 2>> px) const {
    for (auto& p : px) p = {(p[0] - window.x) * scaleX, (p[1] - window.y) * scaleY};
    return px;
  }
};

// Step 1: the region's pixel bounding box, which must lie inside the source.
Result<RegionFrame> regionWindow(const Scenario& s, const TerrainSource& source, const PixelMapper& mapper) {
  const gis::Georef& full = source.georef();
  RegionFrame f;
  f.window = {0, 0, full.width, full.height};
  if (s.region.kind == decltype(s.region)::Whole) return f;
  STRATA_TRY(auto px, mapper.pixels(s, s.region.place));
  double x0 = 1e300, y0 = 1e300, x1 = -1e300, y1 = -1e300;
  for (const auto& p : px) {
    x0 = std::min(x0, p[0]);
    x1 = std::max(x1, p[0]);
    y0 = std::min(y0, p[1]);
    y1 = std::max(y1, p[1]);
  }
  if (!(x0 >= -1e-3 && y0 >= -1e-3 && x1 <= full.width + 1e-3 && y1 <= full.height + 1e-3)) {  // 1e-3 px: rounding
    return placeError(
        s, s.region.place,
        "the region is not inside the " + source.name() + " (extent " + describeExtent(full) + " in its CRS)");
  }
  auto& w = f.window;
  w.x = std::clamp(int(std::floor(x0 + 1e-6)), 0, full.width - 1);
  w.y = std::clamp(int(std::floor(y0 + 1e-6)), 0, full.height - 1);
  w.width = std::clamp(int(std::ceil(x1 - 1e-6)), w.x + 1, full.width) - w.x;
  w.height = std::clamp(int(std::ceil(y1 - 1e-6)), w.y + 1, full.height) - w.y;
  if (w.width < 4 || w.height < 4) {
    return placeError(s, s.region.place, "the region covers fewer than 4x4 cells of the DEM");
  }
  if (s.region.kind == decltype(s.region)::Polygon) f.polygonPx = px;
  return f;
}

// Bytes a run holds per cell at its peak with `layers` material layers: the CPU backend's buffers
// (nine 4-vectors: state, next state, Heun stage, pipe fluxes and diagonals, x and y face fluxes,
// thermal flows, flood statistics; 8 accumulators; base, bed, tilt, outflow limit, rain; a float
// per layer), the checkpoint (the saved state, and its encoding beside it), what the outputs read
// back at each interval (detail::readPieces: the state block, depth, flood statistics, mask, the
// model input's window, in erosion runs suspended sediment and the layers now and at the start),
// and the domain (bed, mask, area in double, base, layers, water, rain). Over `ranks` MPI ranks
// every rank builds a 1/ranks share of the domain (RowBuilder, and lets it go before the run),
// then holds a 1/ranks share (its blocks' halos add ~10% at the default block sizes) of the
// solver, checkpoint and read-back: no rank holds a whole grid. Pictures add a bounded amount on
// the lead (pictureBytes).
double bytesPerCell(int layers, int ranks) {
  const double solver = 4.0 * (9 * 4 + 8 + 5 + layers);
  const double checkpoint = 2 * 4.0 * (4 + 4 + 4 + 8 + 4 + layers);
  const double readBack = 16 + 4 + 16 + 1 + 4.0 * (3 + layers) + 4 + 8.0 * layers;
  const double domain = 4 + 1 + 8 + 4 + 4.0 * layers + 4 + 4;
  if (ranks <= 1) return solver + checkpoint + readBack + domain;
  const double run = (solver + checkpoint + readBack) * 1.1 / ranks;
  return std::max(domain * 1.1 / ranks, run);
}

// What pictures hold on the lead: the bed drawn and the state gathered for it (depth; in erosion
// runs the surface and the top four layers), at most RunOptions::pictureCells (by default 4096)
// a side (detail::pictureStride).
double pictureBytes(double width, double height) {
  const double stride = std::max(1.0, std::ceil(std::max(width, height) / RunOptions{}.pictureCells));
  return (4 + 4 + 4 + 16) * std::ceil(width / stride) * std::ceil(height / stride);
}

// The key a message about the region's size names: cell_size when given, else the region, else
// the terrain.
std::string sizeKey(const Scenario& s) {
  if (s.region.cellSizeM > 0) return "region.cell_size";
  if (s.region.kind != decltype(s.region)::Whole) return s.region.place.key;
  return s.terrain.store.empty() ? "terrain.dem" : "terrain.store";
}

// The window's georeference (the source's, shifted to the window's corner).
gis::Georef windowGeoref(const gis::Georef& full, const gis::CellRect& w) {
  gis::Georef g = full;
  g.transform.c[0] = full.transform.c[0] + w.x * full.transform.c[1];
  g.transform.c[3] = full.transform.c[3] + w.y * full.transform.c[5];
  g.width = w.width;
  g.height = w.height;
  return g;
}

// Step 2: the grid, planned before anything is read: the window at region.cell_size (sizes in
// double, so no count overflows), at least 4 x 4 cells, and a run on it must fit in the memory
// this process can have, its share of a run over `ranks` MPI ranks: `budget` bytes (0: what the
// machine has available) shared by the `ranksOnNode` ranks that run on this machine.
Status planGrid(const Scenario& s, const TerrainSource& source, RegionFrame& frame, uint64_t budget, int ranks,
                bool pictures, int ranksOnNode) {
  const gis::Georef g0 = windowGeoref(source.georef(), frame.window);
  double width = g0.width, height = g0.height;
  if (s.region.cellSizeM > 0) {
    // Square cells: each axis gets as many cells as its geodesic length at the window's centre
    // holds (a geographic DEM's native cell is ~20% narrower than tall at 36 deg N). Away from the
    // centre row a cell's width follows the cosine of its latitude; the report states the range.
    STRATA_TRY(auto c, gis::pixelToLonLat(g0, g0.width * 0.5, g0.height * 0.5));
    STRATA_TRY(auto east, gis::pixelToLonLat(g0, g0.width * 0.5 + 1, g0.height * 0.5));
    STRATA_TRY(auto south, gis::pixelToLonLat(g0, g0.width * 0.5, g0.height * 0.5 + 1));
    const double nativeXM = gis::geodesicDistanceM(c, east, g0.body);
    const double nativeYM = gis::geodesicDistanceM(c, south, g0.body);
    width = std::round(g0.width * nativeXM / s.region.cellSizeM);
    height = std::round(g0.height * nativeYM / s.region.cellSizeM);
    if (!(width >= 4 && height >= 4)) {
      STRATA_TRY(auto westEdge, gis::pixelToLonLat(g0, 0, g0.height * 0.5));
      STRATA_TRY(auto eastEdge, gis::pixelToLonLat(g0, g0.width, g0.height * 0.5));
      char msg[200];
      std::snprintf(msg, sizeof msg,
                    "%.6g m cells give %.0f x %.0f cells over the region (%.4g x %.4g km); at least 4 x 4 are needed",
                    s.region.cellSizeM, std::max(0.0, width), std::max(0.0, height),
                    gis::geodesicDistanceM(westEdge, eastEdge, g0.body) / 1e3, g0.height * nativeYM / 1e3);
      return fail(s.at("region.cell_size") + msg);
    }
    frame.scaleX = width / g0.width;
    frame.scaleY = height / g0.height;
  }
  const int layers = std::max<int>(1, source.layerCount() + int(s.terrain.layers.size()));
  const double cells = width * height, nativeCells = double(g0.width) * g0.height;
  // The window as read (and GDAL's copy while it resamples) comes on top.
  const double native = s.region.cellSizeM > 0 ? 8 * nativeCells / ranks : 0;
  const double bytes = cells * bytesPerCell(layers, ranks) + native + (pictures ? pictureBytes(width, height) : 0);
  const double node = budget > 0 ? double(budget) : double(availableMemoryBytes());
  const double available = node / std::max(1, ranksOnNode);  // this rank's share of the machine
  const bool tooWide = width > std::numeric_limits<int>::max() / 2 || height > std::numeric_limits<int>::max() / 2;
  if (tooWide || (available > 0 && bytes > available)) {
    char msg[320];
    std::snprintf(msg, sizeof msg, "%.0f x %.0f = %.4g million cells need about %s of memory, ", width, height,
                  cells / 1e6, formatBytes(bytes).c_str());
    char cellSize[64] = "";
    if (s.region.cellSizeM > 0) std::snprintf(cellSize, sizeof cellSize, "%.6g m cells: ", s.region.cellSizeM);
    const std::string have = tooWide ? "more than one grid can index"
                             : available > 0 && ranksOnNode > 1
                                 ? "and " + formatBytes(available) + " are available to each of the " +
                                       std::to_string(ranksOnNode) + " MPI ranks on this machine (" +
                                       formatBytes(node) + " in all)"
                             : available > 0 ? "and " + formatBytes(available) + " are available"
                                             : "more than there is";
    return fail(s.at(sizeKey(s)) + cellSize + msg + have + " (use larger cells or a smaller region)");
  }
  if (ranks > height) {
    char msg[200];
    std::snprintf(msg, sizeof msg,
                  "the region is %.0f cells high, fewer than the %d MPI ranks (each builds and runs its own rows): "
                  "run it on at most %.0f ranks, or use smaller cells",
                  height, ranks, height);
    return fail(s.at(sizeKey(s)) + msg);
  }
  frame.width = int(width);
  frame.height = int(height);
  return {};
}

// What every build of the region starts from, read from no cell: the source, where the region
// lies on it, the region's grid (the bed's georeference), its per-row cell sizes and the layers'
// materials.
struct Plan {
  TerrainSource source;
  PixelMapper mapper;
  RegionFrame frame;
  gis::Georef grid;
  std::vector<double> rowDxM;  ///< per row: dx such that dx * dy is the row's cell area at the middle column
  double dyM = 0;
  std::vector<Material> materials;  ///< the store's layers, or bare rock, then the scenario's
};

// The layers' materials, bottom first: the store's, else bare rock when the scenario adds none,
// then the scenario's [[terrain.layer]]s.
Result<std::vector<Material>> layerMaterials(const Scenario& s, const TerrainSource& source) {
  const auto table = source.materials();
  std::vector<Material> out = source.layerMaterials();
  if (out.empty() && s.terrain.layers.empty()) out.push_back(table[size_t(findMaterial(table, "rock"))]);
  for (size_t l = 0; l < s.terrain.layers.size(); ++l) {
    const auto& spec = s.terrain.layers[l];
    const int m = findMaterial(table, spec.material);
    if (m < 0) {
      std::string names;
      for (const auto& mat : table) names += (names.empty() ? "" : ", ") + mat.name;
      return fail(s.at("terrain.layer[" + std::to_string(l) + "].material") + "unknown material \"" + spec.material +
                  "\" (" + names + ")");
    }
    out.push_back(table[size_t(m)]);
  }
  // [materials.NAME]: the run's changes to a material's constants.
  for (const auto& c : s.materials) {
    if (findMaterial(table, c.name) < 0) {
      std::string names;
      for (const auto& mat : table) names += (names.empty() ? "" : ", ") + mat.name;
      return fail(s.at("materials." + c.name) + "unknown material \"" + oneLine(c.name) + "\" (" + names + ")");
    }
    for (auto& m : out) {
      if (m.name != c.name) continue;
      auto set = [](float& field, const std::optional<double>& v) {
        if (v) field = float(*v);
      };
      set(m.criticalShearPa, c.criticalShearPa);
      set(m.shearErodibility, c.shearErodibility);
      set(m.settlingVelocityMS, c.settlingVelocityMS);
      set(m.frictionAngleDeg, c.frictionAngleDeg);
      set(m.cohesionPa, c.cohesionPa);
      set(m.talusAngleDeg, c.talusAngleDeg);
      set(m.weatheringRatePerS, c.weatheringRatePerS);
      set(m.dissolutionRate, c.dissolutionRate);
      set(m.erodibility, c.erodibility);
    }
  }
  return out;
}

// Steps 1 and 2, and the grid: the region's window of the source, the grid planned against
// memory, its georeference (the window's, resampled to region.cell_size) and cell sizes.
Result<Plan> planRegion(const Scenario& s, uint64_t budget, int ranks, bool pictures, int ranksOnNode) {
  STRATA_TRY(auto source, TerrainSource::open(s));
  STRATA_TRY(auto mapper, PixelMapper::create(source.georef()));
  STRATA_TRY(auto frame, regionWindow(s, source, mapper));
  STRATA_TRY_STATUS(planGrid(s, source, frame, budget, ranks, pictures, ranksOnNode));
  const gis::Georef g0 = windowGeoref(source.georef(), frame.window);
  gis::Georef grid = g0;
  if (s.region.cellSizeM > 0) {
    grid.width = frame.width;
    grid.height = frame.height;
    grid.transform.c[1] = g0.transform.c[1] * g0.width / grid.width;
    grid.transform.c[5] = g0.transform.c[5] * g0.height / grid.height;
  }
  STRATA_TRY(auto materials, layerMaterials(s, source));
  // The cell sizes of the middle column (gis::cellAreasM2 of a window has the whole grid's bits).
  STRATA_TRY(auto top, gis::pixelToLonLat(grid, grid.width * 0.5, 0));
  STRATA_TRY(auto bottom, gis::pixelToLonLat(grid, grid.width * 0.5, grid.height));
  const double dy = gis::geodesicDistanceM(top, bottom, grid.body) / grid.height;
  STRATA_TRY(auto middle, gis::cellAreasM2(grid, {grid.width / 2, 0, 1, grid.height}));
  std::vector<double> rowDx(size_t(grid.height));
  for (int y = 0; y < grid.height; ++y) rowDx[size_t(y)] = middle.at(0, y) / dy;
  return Plan{std::move(source),   std::move(mapper), std::move(frame), std::move(grid), std::move(rowDx), dy,
              std::move(materials)};
}

// The georeference of rows [y0, y1) of a grid.
gis::Georef rowsGeoref(const gis::Georef& grid, int y0, int y1) {
  return windowGeoref(grid, {0, y0, grid.width, y1 - y0});
}

// Step 3b: the bed's cells without data ([terrain] voids). Every mode but "refuse" fills their bed
// from the cells around them (GDAL's fill-nodata): "walls" then masks them out (maskRegion) and
// "holes" drains them (placeVoidHoles).
Error refuseVoids(const TerrainSource& source, long long count) {
  return fail(source.path() + ": the region has " + std::to_string(count) +
              " cells without data (nodata); choose a region the " + source.kind() +
              " covers, or set [terrain] voids = \"fill\", \"walls\" or \"holes\"");
}

// The voids of the bed read (d.voids, d.voidCells).
void findVoids(ScenarioDomain& d) {
  d.voids = gis::Grid<uint8_t>(d.bed.values.width, d.bed.values.height, 0);
  d.voidCells = 0;
  for (size_t i = 0; i < d.bed.values.size(); ++i) {
    if (gis::isNoData(d.bed.values.data[i])) d.voids.data[i] = 1, d.voidCells += 1;
  }
}

// Step 3: the bed of rows [y0, y1) of the region's grid (all of them for the whole region),
// resampled to region.cell_size (coarser cells take the lowest of the cells they cover: averaging
// raises a canyon's narrow floor towards its rim and dams the river, docs/scenario.md),
// mosaicked when the scenario lists several DEMs; and the store's layers on the same grid. Any
// rows have the bits the whole grid has there: gis::MosaicReader reads windows of its grid as the
// grid has them, a native window is the DEM's own cells, and a store resampled to cell_size is
// warped from the store's cells under the rows (with a margin for the kernel) as from the whole
// region's.
Status readBed(const Scenario& s, const Plan& plan, int y0, int y1, ScenarioDomain& d,
               std::vector<StoredLayer>& storeLayers) {
  const auto& source = plan.source;
  const auto& frame = plan.frame;
  const gis::Georef& grid = plan.grid;
  const bool resample = s.region.cellSizeM > 0, mosaic = s.terrain.dems.size() > 1;
  d.firstRow = y0;
  // The lowest-elevation rule where the grid is coarser than the source, else bilinear.
  const auto kernel = std::min(frame.scaleX, frame.scaleY) < 1 ? gis::Resampling::Minimum : gis::Resampling::Bilinear;
  // Rows [y0, y1) of the region's grid warped from `inputs`.
  auto warpRows = [&](std::vector<gis::MosaicInput> inputs) -> Result<gis::Raster> {
    STRATA_TRY(auto reader, gis::MosaicReader::open(std::move(inputs), grid));
    gis::Raster out;
    out.georef = rowsGeoref(grid, y0, y1);
    STRATA_TRY(out.values, reader.read({0, y0, grid.width, y1 - y0}));
    return out;
  };
  if (!resample) {
    const gis::CellRect native{frame.window.x, frame.window.y + y0, frame.window.width, y1 - y0};
    STRATA_TRY(d.bed, source.readBed(native));
    STRATA_TRY(storeLayers, source.readLayers(native));
  }
  if (resample && source.kind() == "store") {
    constexpr int kMargin = 4;  // store cells: a kernel reaches 2
    const int top = frame.window.y, bottom = frame.window.y + frame.window.height;
    const int n0 = std::max(top, top + int(std::floor(y0 / frame.scaleY)) - kMargin);
    const int n1 = std::min(bottom, top + int(std::ceil(y1 / frame.scaleY)) + kMargin);
    const gis::CellRect native{frame.window.x, n0, frame.window.width, n1 - n0};
    STRATA_TRY(auto bed, source.readBed(native));
    STRATA_TRY(storeLayers, source.readLayers(native));
    // Each warped as the region's whole window of the store is (MosaicInput::within).
    auto windowOfRegion = [&](gis::Raster cells) {
      return source.storeWindowInput(std::move(cells), frame.window, 0, n0 - top);
    };
    gis::MosaicInput in = windowOfRegion(std::move(bed));
    in.resampling = kernel;
    STRATA_TRY(d.bed, warpRows({std::move(in)}));
    // Stored layer thicknesses are averaged (bilinear): their volume is what matters, not a channel.
    for (auto& layer : storeLayers) {
      STRATA_TRY(layer.thickness, warpRows({windowOfRegion(std::move(layer.thickness))}));
    }
    return {};
  }
  if (!resample && !mosaic) return {};
  std::vector<gis::MosaicInput> inputs;
  if (mosaic) {
    for (const auto& p : s.terrain.dems) {
      gis::MosaicInput in = source.resampleInput(p);
      in.mode = gis::BlendMode::Replace;
      in.resampling = gis::Resampling::MinimumIfCoarser;  // the lowest-elevation rule, as above
      inputs.push_back(std::move(in));
    }
  } else {
    gis::MosaicInput in = source.resampleInput();
    in.resampling = kernel;
    inputs.push_back(std::move(in));
  }
  STRATA_TRY(d.bed, warpRows(std::move(inputs)));
  return {};
}
Status fillVoidsOfRows(const Scenario& s, const Plan& plan, int y0, int y1, ScenarioDomain& d) {
  if (s.terrain.voids == decltype(s.terrain)::Voids::kRefuse || d.voidCells == 0) return {};
  const int w = plan.grid.width, h = plan.grid.height;
  for (int margin = 16;; margin *= 2) {
    const int top = std::max(0, y0 - margin), bottom = std::min(h, y1 + margin);
    ScenarioDomain around;
    std::vector<StoredLayer> layers;
    STRATA_TRY_STATUS(readBed(s, plan, top, bottom, around, layers));
    const auto span = gis::voidFillRows(around.bed.values, top, h, y0, y1);
    if (!span) continue;
    gis::Grid<float> rows(w, (*span)[1] - (*span)[0]);
    const auto& all = around.bed.values.data;
    std::copy(all.begin() + ptrdiff_t((*span)[0] - top) * w, all.begin() + ptrdiff_t((*span)[1] - top) * w,
              rows.data.begin());
    auto filled = gis::fillVoids(rows, std::max(w, h));
    if (!filled) return fail(plan.source.path() + ": " + filled.message());
    std::copy(rows.data.begin() + ptrdiff_t(y0 - (*span)[0]) * w, rows.data.begin() + ptrdiff_t(y1 - (*span)[0]) * w,
              d.bed.values.data.begin());
    return {};
  }
}

// The rows [y0, y0 + height) of a raster warped onto the region's grid (a rain or layer raster):
// the whole warp's bits there.
Result<gis::Grid<float>> readRows(const std::string& path, const gis::Georef& grid, int y0, int height,
                                  gis::Resampling resampling = gis::Resampling::Bilinear) {
  gis::MosaicInput input{path};
  input.resampling = resampling;
  STRATA_TRY(auto reader, gis::MosaicReader::open({input}, grid));
  return reader.read({0, y0, grid.width, height});
}

// Step 4: the region mask: a polygon's outside becomes a wall (the mask of rows from firstRow).
void maskRegion(const Scenario& s, const RegionFrame& frame, ScenarioDomain& d) {
  const int w = d.bed.values.width, h = d.bed.values.height;
  d.inside = gis::Grid<uint8_t>(w, h, 1);
  if (s.terrain.voids == decltype(s.terrain)::Voids::kWalls) {
    for (size_t i = 0; i < d.inside.size(); ++i) d.inside.data[i] = d.voids.data[i] ? 0 : 1;
  }
  if (frame.polygonPx.empty()) return;
  const auto poly = frame.toRegion(frame.polygonPx);
  for (int y = 0; y < h; ++y) {
    for (int x = 0; x < w; ++x) {
      if (!insidePolygon(poly, x + 0.5, d.firstRow + y + 0.5)) d.inside.at(x, y) = 0;
    }
  }
}

// Step 5: geodesic cell sizes (the plan's per-row sizes; each cell's area, with the whole grid's
// bits) and the area of the region's cells (an exact sum: the same over any rows).
Status measureRegion(const Plan& plan, ScenarioDomain& d) {
  const int h = d.bed.values.height;
  STRATA_TRY(d.cellAreaM2, gis::cellAreasM2(plan.grid, {0, d.firstRow, plan.grid.width, h}));
  d.input.dyM = plan.dyM;
  d.input.rowDxM.assign(plan.rowDxM.begin() + d.firstRow, plan.rowDxM.begin() + d.firstRow + h);
  sim::ExactSum area;
  for (size_t i = 0; i < d.inside.size(); ++i) {
    if (d.inside.data[i]) area.add(d.cellAreaM2.data[i]);
  }
  d.totalAreaM2 = area.value();
  return {};
}

// Step 6: base and layers (of the rows read). Cells outside a polygon become walls. Returns the
// lowest bed of the region's cells: the datum is the region's lowest point (floored), so float32
// keeps millimetres.
Result<float> stackLayers(const Scenario& s, const Plan& plan, std::vector<StoredLayer>& storeLayers,
                          ScenarioDomain& d) {
  const int w = d.bed.values.width, h = d.bed.values.height;
  float lo = 1e30f;
  for (size_t i = 0; i < d.bed.values.size(); ++i) {
    if (d.inside.data[i]) lo = std::min(lo, d.bed.values.data[i]);
  }
  d.input.baseM = d.bed.values;
  for (size_t i = 0; i < d.input.baseM.size(); ++i) {
    if (!d.inside.data[i]) d.input.baseM.data[i] = kWallElevationM;
  }
  d.input.materials = plan.materials;
  for (auto& layer : storeLayers) {
    gis::Grid<float> thickness = std::move(layer.thickness.values);
    for (auto& v : thickness.data) v = gis::isNoData(v) ? 0.0f : std::max(0.0f, v);
    d.input.layersM.push_back(std::move(thickness));
  }
  // Bare rock: one layer of zero thickness so erosion has a material to read.
  if (d.input.layersM.empty() && s.terrain.layers.empty()) d.input.layersM.push_back(gis::Grid<float>(w, h, 0.0f));
  for (const auto& spec : s.terrain.layers) {
    gis::Grid<float> thickness(w, h, float(spec.thicknessM));
    if (!spec.raster.empty()) {
      STRATA_TRY(auto r, readRows(spec.raster, plan.grid, d.firstRow, h));
      for (size_t i = 0; i < thickness.size(); ++i) {
        const float v = r.data[i];
        thickness.data[i] = gis::isNoData(v) ? 0.0f : std::max(0.0f, v);
      }
    }
    d.input.layersM.push_back(std::move(thickness));
  }
  return lo;
}

// Which cells of the region's grid are the region's: a mask, or the polygon alone (the places: a
// void wall under one is refused, firstPlaceOnWalls).
struct RegionCells {
  int width = 0, height = 0;
  const gis::Grid<uint8_t>* mask = nullptr;
  std::vector<std::array<double, 2>> polygon;  ///< region cells; empty: every cell
  bool inside(int x, int y) const {
    return mask ? mask->at(x, y) != 0 : polygon.empty() || insidePolygon(polygon, x + 0.5, y + 0.5);
  }
};

// The region cells of a line's points, which must lie inside the region (`what` names it).
Result<std::vector<std::pair<int, int>>> lineCells(const Scenario& s, const Place& place,
                                                   const std::vector<std::array<double, 2>>& px,
                                                   const RegionCells& region, const std::string& what) {
  const int w = region.width, h = region.height;
  for (const auto& pt : px) {
    if (!(pt[0] >= 0 && pt[1] >= 0 && pt[0] < w && pt[1] < h) ||
        !region.inside(int(std::floor(pt[0])), int(std::floor(pt[1])))) {
      return placeError(s, place, what + " is outside the region");
    }
  }
  auto cells = cellsAlong(px, w, h);
  std::erase_if(cells, [&](auto c) { return !region.inside(c.first, c.second); });
  return cells;
}

// The region cells whose centres lie inside a polygon (only its bounding box is scanned).
std::vector<std::pair<int, int>> polygonCells(const std::vector<std::array<double, 2>>& px, const RegionCells& region) {
  double x0 = 1e300, y0 = 1e300, x1 = -1e300, y1 = -1e300;
  for (const auto& p : px) {
    x0 = std::min(x0, p[0]), x1 = std::max(x1, p[0]);
    y0 = std::min(y0, p[1]), y1 = std::max(y1, p[1]);
  }
  std::vector<std::pair<int, int>> cells;
  if (!(x1 >= 0 && y1 >= 0 && x0 <= region.width && y0 <= region.height)) return cells;  // outside (or NaN)
  const int cx0 = std::max(0, int(std::floor(x0))), cy0 = std::max(0, int(std::floor(y0)));
  const int cx1 = std::min(region.width, int(std::ceil(x1)) + 1), cy1 = std::min(region.height, int(std::ceil(y1)) + 1);
  for (int y = cy0; y < cy1; ++y) {
    for (int x = cx0; x < cx1; ++x) {
      if (region.inside(x, y) && insidePolygon(px, x + 0.5, y + 0.5)) cells.push_back({x, y});
    }
  }
  return cells;
}

// Step 8: inflows on the cells of their point or line.
Status placeInflows(const Scenario& s, const Plan& plan, const RegionCells& region, ScenarioDomain& d) {
  for (const auto& in : s.water.inflows) {
    STRATA_TRY(auto demPx, plan.mapper.pixels(s, in.place));
    STRATA_TRY(auto cells,
               lineCells(s, in.place, plan.frame.toRegion(demPx), region, "the source \"" + in.name + "\""));
    d.sources.push_back(sim::Source{std::move(cells), in.hydrograph});
    d.sourceNames.push_back(in.name);
  }
  return {};
}

// Step 9: fixed levels on the cells of a line or a polygon.
Status placeLevels(const Scenario& s, const Plan& plan, const RegionCells& region, ScenarioDomain& d) {
  for (const auto& lv : s.water.levels) {
    STRATA_TRY(auto demPx, plan.mapper.pixels(s, lv.place));
    const auto px = plan.frame.toRegion(demPx);
    sim::LevelBoundary level{{}, lv.stage};
    if (lv.polygon) {
      level.cells = polygonCells(px, region);
      if (level.cells.empty()) {
        return placeError(s, lv.place, "the level \"" + lv.name + "\" covers no cell of the region");
      }
    } else {
      STRATA_TRY(level.cells, lineCells(s, lv.place, px, region, "the level \"" + lv.name + "\""));
    }
    d.levels.push_back(std::move(level));
    d.levelNames.push_back(lv.name);
  }
  return {};
}

// Step 10: gauges on their cells, sections on the faces their lines cross (inside the region).
Status placeProbes(const Scenario& s, const Plan& plan, const RegionCells& region, ScenarioDomain& d) {
  for (const auto& g : s.outputs.gauges) {
    STRATA_TRY(auto demPx, plan.mapper.pixels(s, g.place));
    STRATA_TRY(auto cells, lineCells(s, g.place, plan.frame.toRegion(demPx), region, "the gauge \"" + g.name + "\""));
    d.gauges.push_back({g.name, cells.front().first, cells.front().second});
  }
  for (const auto& sec : s.outputs.sections) {
    STRATA_TRY(auto demPx, plan.mapper.pixels(s, sec.place));
    const auto px = plan.frame.toRegion(demPx);
    STRATA_TRY(auto cells, lineCells(s, sec.place, px, region, "the section \"" + sec.name + "\""));
    auto faces = facesCrossed(px, region.width, region.height);
    std::erase_if(faces, [&](const auto& f) {
      return !region.inside(f.x, f.y) || !region.inside(f.xFace ? f.x - 1 : f.x, f.xFace ? f.y : f.y - 1);
    });
    if (faces.empty()) {
      return placeError(
          s, sec.place,
          "the section \"" + sec.name + "\" crosses no face between two cells (make it longer than a cell)");
    }
    d.sections.push_back({sec.name, std::move(faces), std::move(cells)});
  }
  return {};
}

// The lowest bed (base and layers) of each of the scenario's levels over the cells of `d`'s rows
// (1e300 for a level with none there).
std::vector<double> lowestLevelBeds(const Scenario& s, const ScenarioDomain& shape, const ScenarioDomain& d) {
  std::vector<double> lowest(s.water.levels.size(), 1e300);
  const int h = d.input.baseM.height;
  for (size_t i = 0; i < lowest.size(); ++i) {
    for (auto [x, y] : shape.levels[i].cells) {
      if (y < d.firstRow || y >= d.firstRow + h) continue;
      double b = d.input.baseM.at(x, y - d.firstRow);
      for (const auto& l : d.input.layersM) b += l.at(x, y - d.firstRow);
      lowest[i] = std::min(lowest[i], b);
    }
  }
  return lowest;
}

// Each level's stage must rise above the bed of at least one of its cells.
Status checkLevelStages(const Scenario& s, const std::vector<double>& lowestBed) {
  for (size_t i = 0; i < s.water.levels.size(); ++i) {
    double highestStage = -1e300;
    for (const auto& st : s.water.levels[i].stage.samples()) highestStage = std::max(highestStage, st[1]);
    if (highestStage <= lowestBed[i]) {
      char msg[200];
      std::snprintf(msg, sizeof msg,
                    "the stage (at most %.2f m) never rises above the bed of the level's cells (lowest %.2f m): "
                    "it would hold no water",
                    highestStage, lowestBed[i]);
      return fail(s.at("water.level[" + std::to_string(i) + "].stage") + msg);
    }
  }
  return {};
}

// Step 9b: [terrain] voids = "holes": the region's void cells are held at depth 0 (a fixed level
// below every bed), so whatever water reaches them leaves the region there and is counted as the
// level's outflow in the balance.
// The region's void cells that are holes (voids = "holes"), of the first `rows` rows of `d`, on
// the region's rows.
std::vector<std::pair<int, int>> voidHoleCells(const Scenario& s, const ScenarioDomain& d, int rows) {
  std::vector<std::pair<int, int>> cells;
  if (s.terrain.voids != decltype(s.terrain)::Voids::kHoles) return cells;
  for (int y = 0; y < rows; ++y) {
    for (int x = 0; x < d.voids.width; ++x) {
      if (d.voids.at(x, y) && d.inside.at(x, y)) cells.push_back({x, d.firstRow + y});
    }
  }
  return cells;
}

// The holes as a level far below the region (the domain `d`'s datum) that drains them.
void addVoidHoles(std::vector<std::pair<int, int>> cells, ScenarioDomain& d) {
  if (cells.empty()) return;
  sim::LevelBoundary holes;
  holes.cells = std::move(cells);
  holes.stageM = TimeSeries::constant(d.input.datumM - 1e4);
  d.levels.push_back(std::move(holes));
  d.levelNames.push_back("voids (holes)");
}

// Step 10, a rain series: each frame's raster read for these rows (bilinear; no data is no rain);
// a negative or non-finite value is refused naming the frame, its file and a cell.
Status placeRainFrames(const Scenario& s, const Plan& plan, ScenarioDomain& d) {
  const auto& rain = *s.water.rain;
  d.rainFramesEndS = rain.endS < 0 ? s.durationS : rain.endS;
  const int h = d.bed.values.height;
  if (h == 0) return {};  // a shape: no rows
  for (size_t k = 0; k < rain.frames.size(); ++k) {
    const auto& f = rain.frames[k];
    const std::string key = "water.rain.frames[" + std::to_string(k) + "]";
    auto read = readRows(f.raster, plan.grid, d.firstRow, h);
    if (!read) return fail(s.at("water.rain.frames") + oneLine(read.message()));
    ScenarioDomain::RainFrame frame{f.timeS, gis::Grid<float>(plan.grid.width, h, 0.0f)};
    for (int y = 0; y < h; ++y) {
      for (int x = 0; x < plan.grid.width; ++x) {
        const float v = read->at(x, y);
        if (gis::isNoData(v)) continue;
        if (!(v >= 0.0f && v <= 10000.0f)) {
          char where[96];
          std::snprintf(where, sizeof where, " at column %d, row %d of the region", x, d.firstRow + y);
          return fail(s.at("water.rain.frames") + key + " " + oneLine(f.raster) + ": rain " + std::to_string(v) +
                      " mm/h" + where + " (0 to 10000 mm/h)");
        }
        frame.mmPerHour.at(x, y) = v;
      }
    }
    d.rainFrames.push_back(std::move(frame));
  }
  return {};
}

// Step 10: rain, uniform for a span of time or as a raster of multipliers for the whole run (the
// raster's rows of `d`).
Status placeRain(const Scenario& s, const Plan& plan, ScenarioDomain& d) {
  if (!s.water.rain) return {};
  if (!s.water.rain->frames.empty()) return placeRainFrames(s, plan, d);
  const double rate = s.water.rain->rateMPerS * 3.6e6;
  d.rainMmPerHour = rate;
  d.rainStartS = s.water.rain->startS;
  d.rainEndS = s.water.rain->endS < 0 ? s.durationS : s.water.rain->endS;
  if (s.water.rain->raster.empty()) return {};
  if (s.water.rain->startS > 0 || s.water.rain->endS >= 0) {
    return fail(s.at("water.rain.raster") +
                "a rain raster falls for the whole run; start and end apply to a uniform rate only");
  }
  d.rainMmPerHour = 0;  // the raster carries the rate
  const int h = d.bed.values.height;
  if (h == 0) return {};  // a shape: no rows
  STRATA_TRY(auto r, readRows(s.water.rain->raster, plan.grid, d.firstRow, h));
  d.input.rainMmPerHour = gis::Grid<float>(plan.grid.width, h, 0.0f);
  for (size_t i = 0; i < r.size(); ++i) {
    const float v = r.data[i];
    d.input.rainMmPerHour.data[i] = gis::isNoData(v) ? 0.0f : float(std::max(0.0f, v) * rate);
  }
  return {};
}

// Step 10b: a roughness map ([model] manning_raster, or land_cover with its table): Manning's n
// per cell of these rows; no data takes [model] manning_n; a value outside 0..1, or a class the
// table lacks, is refused naming the key, the value and a cell.
Status placeManning(const Scenario& s, const Plan& plan, ScenarioDomain& d) {
  const bool classes = !s.model.landCoverRaster.empty();
  if (s.model.manningRaster.empty() && !classes) return {};
  const int h = d.bed.values.height;
  if (h == 0) return {};  // a shape: no rows
  const std::string key = classes ? "model.land_cover.raster" : "model.manning_raster";
  const std::string& path = classes ? s.model.landCoverRaster : s.model.manningRaster;
  auto read = readRows(path, plan.grid, d.firstRow, h, classes ? gis::Resampling::Nearest : gis::Resampling::Bilinear);
  if (!read) return fail(s.at(key) + oneLine(read.message()));
  const auto& r = *read;
  d.input.manningN = gis::Grid<float>(plan.grid.width, h, float(s.model.manningN));
  for (int y = 0; y < h; ++y) {
    for (int x = 0; x < plan.grid.width; ++x) {
      const float v = r.at(x, y);
      if (gis::isNoData(v)) continue;
      char where[96];
      std::snprintf(where, sizeof where, " at column %d, row %d of the region", x, d.firstRow + y);
      if (classes) {
        const long long code = std::llround(v);
        const auto n = s.model.landCoverManning.find(code);
        if (n == s.model.landCoverManning.end()) {
          return fail(s.at("model.land_cover.manning") + "no n for class " + std::to_string(code) + " of " +
                      oneLine(path) + where + ": add it to the table");
        }
        d.input.manningN.at(x, y) = float(n->second);
      } else {
        if (!(v >= 0.0f && v <= 1.0f)) {
          return fail(s.at(key) + oneLine(path) + ": Manning's n " + std::to_string(v) + where +
                      " (s/m^(1/3), 0 to 1)");
        }
        d.input.manningN.at(x, y) = v;
      }
    }
  }
  return {};
}

// Step 10c: infiltration ([water.infiltration]): the rate (or Green-Ampt's Ks) per cell of these
// rows in mm/h, from its raster where it has one (no data takes the uniform value; a negative or
// non-finite value is refused naming the key, the value and a cell), and Green-Ampt's suction head
// x moisture deficit.
Status placeInfiltration(const Scenario& s, const Plan& plan, ScenarioDomain& d) {
  if (!s.water.infiltration) return {};
  const auto& f = *s.water.infiltration;
  const int h = d.bed.values.height;
  if (h == 0) return {};  // a shape: no rows
  const float uniform = float(f.rateMPerS * 3.6e6);
  d.input.infiltrationMmPerHour = gis::Grid<float>(plan.grid.width, h, uniform);
  if (f.greenAmpt)
    d.input.infiltrationSuctionM = gis::Grid<float>(plan.grid.width, h, float(f.suctionM * f.moistureDeficit));
  if (f.raster.empty()) return {};
  const std::string key = "water.infiltration.raster";
  auto read = readRows(f.raster, plan.grid, d.firstRow, h, gis::Resampling::Bilinear);
  if (!read) return fail(s.at(key) + oneLine(read.message()));
  for (int y = 0; y < h; ++y) {
    for (int x = 0; x < plan.grid.width; ++x) {
      const float v = read->at(x, y);
      if (gis::isNoData(v)) continue;
      if (!(v >= 0.0f && v <= 1000.0f)) {
        char where[96];
        std::snprintf(where, sizeof where, " at column %d, row %d of the region", x, d.firstRow + y);
        return fail(s.at(key) + oneLine(f.raster) + ": " + (f.greenAmpt ? "Ks " : "loss rate ") + std::to_string(v) +
                    " mm/h" + where + " (0 to 1000 mm/h)");
      }
      d.input.infiltrationMmPerHour.at(x, y) = v;
    }
  }
  return {};
}

// Step 11: dam breaks: water standing up to the given surface inside each polygon. The cells of
// each polygon (some, or it is refused)...
using CellList = std::vector<std::pair<int, int>>;
Result<std::vector<CellList>> damBreakCells(const Scenario& s, const Plan& plan, const RegionCells& region) {
  std::vector<CellList> out;
  for (const auto& db : s.water.damBreaks) {
    STRATA_TRY(auto demPx, plan.mapper.pixels(s, db.polygon));
    out.push_back(polygonCells(plan.frame.toRegion(demPx), region));
    if (out.back().empty()) return placeError(s, db.polygon, "the dam-break polygon covers no cell of the region");
  }
  return out;
}

// ... the initial depth on the rows of `d` (and the volume there), returning each dam's lowest bed
// over those rows (1e300 where it has no cell) ...
std::vector<double> placeDamBreaks(const Scenario& s, const std::vector<CellList>& cells, ScenarioDomain& d) {
  const int w = d.bed.values.width, h = d.bed.values.height;
  std::vector<double> lowest(cells.size(), 1e300);
  if (cells.empty()) return lowest;
  d.input.waterDepthM = gis::Grid<float>(w, h, 0.0f);
  for (size_t i = 0; i < cells.size(); ++i) {
    const float surface = float(s.water.damBreaks[i].surfaceElevationM);
    for (auto [x, gy] : cells[i]) {
      const int y = gy - d.firstRow;
      if (y < 0 || y >= h) continue;
      lowest[i] = std::min(lowest[i], double(d.bed.values.at(x, y)));
      const float depth = std::max(0.0f, surface - d.bed.values.at(x, y));
      d.input.waterDepthM.at(x, y) = std::max(d.input.waterDepthM.at(x, y), depth);
    }
  }
  sim::ExactSum volume;
  for (int y = 0; y < h; ++y) {
    for (int x = 0; x < w; ++x) volume.add(double(d.input.waterDepthM.at(x, y)) * d.cellAreaM2.at(x, y));
  }
  d.damBreakVolumeM3 = volume.value();
  return lowest;
}

// ... and each surface must stand above the lowest bed of its polygon.
Status checkDamBreaks(const Scenario& s, const std::vector<double>& lowestBed) {
  for (size_t i = 0; i < s.water.damBreaks.size(); ++i) {
    const auto& db = s.water.damBreaks[i];
    if (!(db.surfaceElevationM > lowestBed[i])) {
      char msg[200];
      std::snprintf(msg, sizeof msg,
                    "the surface (%.2f m) is below the bed of every cell of the polygon (lowest %.2f m): "
                    "the dam would hold no water",
                    db.surfaceElevationM, lowestBed[i]);
      return fail(s.at("water.dam_break[" + std::to_string(i) + "].surface") + msg);
    }
  }
  return {};
}

// Erosion moves loose material: on bare bedrock (no layer, or layers of no thickness over the
// region) it would run and change nothing, so it is refused.
bool hasLooseMaterial(const ScenarioDomain& d) {
  for (const auto& layer : d.input.layersM) {
    for (size_t i = 0; i < layer.size(); ++i) {
      if (d.inside.data[i] && layer.data[i] > 0) return true;
    }
  }
  return false;
}
Error refuseNoLooseMaterial(const Scenario& s) {
  return fail(s.at("terrain") +
              "erosion needs loose material, and the terrain has none over the region (add a [[terrain.layer]] with "
              "a material and a thickness, docs/scenario.md)");
}

// The solver's own check of its parameters. The scenario's ranges are narrower, so it cannot fail
// on what a file holds; should it, the message names the scenario key, not the solver's field.
Status checkModelParams(const Scenario& s, const sim::SimParams& p) {
  const auto status = sim::validateParams(p);
  if (status.ok()) return {};
  static const std::pair<const char*, const char*> kKeys[] = {
      {"cflAlpha", "model.cfl"},
      {"maxDtS", "model.max_step"},
      {"manningN", "model.manning_n"},
      {"evaporationMmPerHour", "water.evaporation"},
      {"rainMmPerHour", "water.rain.rate"},
      {"capacityK", "erosion.capacity"},
      {"erosionRate", "erosion.erosion_rate"},
      {"depositionRate", "erosion.deposition_rate"},
  };
  const Error& e = status.error();
  for (const auto& [field, key] : kKeys) {
    if (e.field == field) return fail(s.at(key) + "the model refuses it" + (e.reason.empty() ? "" : ": " + e.reason));
  }
  return fail(s.file.string() + ": the model refuses these parameters (" + e.message + ")");
}

// Where fill_depressions' floods start: the region's cells on an open edge, and voids that are
// holes (the rows of `d`, of a region `height` rows high).
gis::Grid<uint8_t> drainCells(const Scenario& s, const ScenarioDomain& d, int height) {
  const int w = d.inside.width, h = d.inside.height;
  const auto& open = s.model.boundaries;  // W E S N
  gis::Grid<uint8_t> drains(w, h, 0);
  for (int y = 0; y < h; ++y) {
    const int gy = d.firstRow + y;
    for (int x = 0; x < w; ++x) {
      const size_t c = size_t(y) * size_t(w) + size_t(x);
      const bool edge = (x == 0 && open[0] == Boundary::Open) || (x == w - 1 && open[1] == Boundary::Open) ||
                        (gy == height - 1 && open[2] == Boundary::Open) || (gy == 0 && open[3] == Boundary::Open);
      const bool hole = s.terrain.voids == decltype(s.terrain)::Voids::kHoles && d.voids.data[c];
      drains.data[c] = (edge || hole) && d.inside.data[c] ? 1 : 0;
    }
  }
  return drains;
}
Error refuseNothingDrains(const Scenario& s) {
  return fail(s.at("terrain.fill_depressions") +
              "no edge is open (model.boundary) and no void is a hole: nothing drains");
}

// Raises the cells of `d` (its first `rows` rows) to `filled` where that is higher, counting what
// was raised.
sim::ExactSum raiseTo(const gis::Grid<float>& filled, int rows, ScenarioDomain& d) {
  sim::ExactSum volume;
  const size_t n = size_t(rows) * size_t(d.input.baseM.width);
  for (size_t c = 0; c < n; ++c) {
    if (!(filled.data[c] > d.input.baseM.data[c])) continue;
    const double raised = double(filled.data[c]) - double(d.input.baseM.data[c]);
    d.filled.cells += 1;
    d.filled.maxM = std::max(d.filled.maxM, raised);
    volume.add(raised * d.cellAreaM2.data[c]);
    d.input.baseM.data[c] = filled.data[c];
    d.bed.values.data[c] = filled.data[c];
  }
  d.filled.volumeM3 = volume.value();
  return volume;
}

// The lowest and highest bed of the region's cells of `d`'s first `rows` rows.
std::array<float, 2> bedRange(const ScenarioDomain& d, int rows) {
  std::array<float, 2> r{std::numeric_limits<float>::max(), std::numeric_limits<float>::lowest()};
  const size_t n = size_t(rows) * size_t(d.bed.values.width);
  for (size_t i = 0; i < n; ++i) {
    if (!d.inside.data[i]) continue;
    r[0] = std::min(r[0], d.bed.values.data[i]);
    r[1] = std::max(r[1], d.bed.values.data[i]);
  }
  return r;
}

}  // namespace

Result<CellSizes> measureCells(const gis::Georef& g) {
  CellSizes c;
  const int w = g.width, h = g.height;
  STRATA_TRY(c.cellAreaM2, gis::cellAreasM2(g));
  STRATA_TRY(auto top, gis::pixelToLonLat(g, w * 0.5, 0));
  STRATA_TRY(auto bottom, gis::pixelToLonLat(g, w * 0.5, h));
  c.dyM = gis::geodesicDistanceM(top, bottom, g.body) / h;
  c.rowDxM.resize(size_t(h));
  for (int y = 0; y < h; ++y) c.rowDxM[size_t(y)] = c.cellAreaM2.at(w / 2, y) / c.dyM;
  return c;
}

sim::SimParams modelParams(const Scenario& s) {
  sim::SimParams p;
  p.waterModel = s.model.kind;
  p.floodScheme = s.model.inertial ? sim::FloodScheme::kLocalInertial : sim::FloodScheme::kFiniteVolume;
  p.localStepLevels = s.model.localSteps ? sim::kMaxLocalStepLevels : 0;
  p.cflAlpha = float(s.model.cfl);
  // The CFL step (W10) is capped (docs/scenario.md, max_step).
  p.maxDtS = float(s.model.maxStepS);
  p.manningN = float(s.model.manningN);
  p.slopeLimiter = s.model.sharpSlopes ? sim::SlopeLimiter::kMonotonizedCentral : sim::SlopeLimiter::kMinmod;
  const uint32_t bits[4] = {sim::kEdgeWest, sim::kEdgeEast, sim::kEdgeSouth, sim::kEdgeNorth};
  p.openEdges = 0;
  for (int e = 0; e < 4; ++e) {
    if (s.model.boundaries[size_t(e)] == Boundary::Open) p.openEdges |= bits[e];
  }
  p.evaporationMmPerHour = float(s.water.evaporationMPerS * 3.6e6);
  if (s.erosion.enabled) {
    p.erosionEnabled = true;
    p.thermalEnabled = s.erosion.thermal;
    p.erosionLaw = s.erosion.law;
    p.capacityK = float(s.erosion.capacity);
    p.erosionRate = float(s.erosion.erosionRate);
    p.depositionRate = float(s.erosion.depositionRate);
  }
  return p;
}

// voids = "walls": a void is a wall no water enters, so an inflow, a level or a dam break on one
// would pour into (or hold water in) a wall. Refused, naming the first such place: inflows, then
// levels, then dam breaks (their order as an index; -1 when none is on a void of `d`'s first
// `rows` rows).
int firstPlaceOnWalls(const Scenario& s, const std::vector<sim::Source>& sources,
                      const std::vector<sim::LevelBoundary>& levels, const std::vector<CellList>& dams,
                      const ScenarioDomain& d, int rows) {
  if (s.terrain.voids != decltype(s.terrain)::Voids::kWalls) return -1;
  auto onWall = [&](const CellList& cells) {
    for (auto [x, y] : cells) {
      const int local = y - d.firstRow;
      if (local >= 0 && local < rows && d.voids.at(x, local)) return true;
    }
    return false;
  };
  int index = 0;
  for (const auto& src : sources) {
    if (onWall(src.cells)) return index;
    ++index;
  }
  for (size_t l = 0; l < s.water.levels.size() && l < levels.size(); ++l, ++index) {
    if (onWall(levels[l].cells)) return index;
  }
  for (const auto& cells : dams) {
    if (onWall(cells)) return index;
    ++index;
  }
  return -1;
}

Error refusePlaceOnWalls(const Scenario& s, int index) {
  const size_t i = size_t(index), inflows = s.water.inflows.size(), levels = s.water.levels.size();
  const Place& place = i < inflows            ? s.water.inflows[i].place
                       : i < inflows + levels ? s.water.levels[i - inflows].place
                                              : s.water.damBreaks[i - inflows - levels].polygon;
  return placeError(s, place,
                    "it lies on cells without data, which voids = \"walls\" makes walls no water enters; move it, "
                    "or set [terrain] voids = \"fill\" or \"holes\"");
}

// ---- Built rows by rows -------------------------------------------------------------------------

namespace detail {

struct RowBuilder::Impl {
  const Scenario& s;
  Plan plan;
  ScenarioDomain shape;
  std::vector<CellList> damCells;
};

RowBuilder::RowBuilder(std::unique_ptr<Impl> impl) : impl_(std::move(impl)) {}
RowBuilder::RowBuilder(RowBuilder&&) noexcept = default;
RowBuilder::~RowBuilder() = default;

Result<RowBuilder> RowBuilder::plan(const Scenario& s, uint64_t memoryBudgetBytes, int ranks, bool pictures,
                                    int ranksOnNode) {
  STRATA_TRY(auto plan, planRegion(s, memoryBudgetBytes, ranks, pictures, ranksOnNode));
  ScenarioDomain shape;
  shape.bed.georef = plan.grid;
  shape.input.rowDxM = plan.rowDxM;
  shape.input.dyM = plan.dyM;
  shape.input.materials = plan.materials;
  shape.params = modelParams(s);
  STRATA_TRY_STATUS(checkModelParams(s, shape.params));
  const RegionCells region{
      plan.grid.width, plan.grid.height, nullptr,
      plan.frame.polygonPx.empty() ? std::vector<std::array<double, 2>>{} : plan.frame.toRegion(plan.frame.polygonPx)};
  STRATA_TRY_STATUS(placeInflows(s, plan, region, shape));
  STRATA_TRY_STATUS(placeLevels(s, plan, region, shape));
  STRATA_TRY_STATUS(placeProbes(s, plan, region, shape));
  STRATA_TRY_STATUS(placeRain(s, plan, shape));
  STRATA_TRY(auto dams, damBreakCells(s, plan, region));
  // One-cell markers (modelInputSource reads them): the rows have a rain raster, a roughness map,
  // infiltration, initial water.
  if (s.water.rain && !s.water.rain->raster.empty()) shape.input.rainMmPerHour = gis::Grid<float>(1, 1, 0.0f);
  if (!s.model.manningRaster.empty() || !s.model.landCoverRaster.empty()) {
    shape.input.manningN = gis::Grid<float>(1, 1, 0.0f);
  }
  if (s.water.infiltration) {
    shape.input.infiltrationMmPerHour = gis::Grid<float>(1, 1, 0.0f);
    if (s.water.infiltration->greenAmpt) shape.input.infiltrationSuctionM = gis::Grid<float>(1, 1, 0.0f);
  }
  if (!dams.empty()) shape.input.waterDepthM = gis::Grid<float>(1, 1, 0.0f);
  return RowBuilder(std::make_unique<Impl>(Impl{s, std::move(plan), std::move(shape), std::move(dams)}));
}

const ScenarioDomain& RowBuilder::shape() const { return impl_->shape; }

Result<ScenarioDomain> RowBuilder::rows(int y0, int y1) const {
  const Scenario& s = impl_->s;
  const Plan& plan = impl_->plan;
  ScenarioDomain d;
  std::vector<StoredLayer> storeLayers;
  STRATA_TRY_STATUS(readBed(s, plan, y0, y1, d, storeLayers));
  findVoids(d);
  STRATA_TRY_STATUS(fillVoidsOfRows(s, plan, y0, y1, d));
  maskRegion(s, plan.frame, d);
  STRATA_TRY_STATUS(measureRegion(plan, d));
  STRATA_TRY_STATUS(statusOf(stackLayers(s, plan, storeLayers, d)));  // (the caller finds the lowest bed of its rows)
  STRATA_TRY_STATUS(placeRain(s, plan, d));
  STRATA_TRY_STATUS(placeManning(s, plan, d));
  STRATA_TRY_STATUS(placeInfiltration(s, plan, d));
  return d;
}

Error RowBuilder::refuseVoids(long long count) const { return scenario::refuseVoids(impl_->plan.source, count); }
int RowBuilder::firstPlaceOnWalls(const ScenarioDomain& d, int rows) const {
  return scenario::firstPlaceOnWalls(impl_->s, impl_->shape.sources, impl_->shape.levels, impl_->damCells, d, rows);
}
Error RowBuilder::refusePlaceOnWalls(int index) const { return scenario::refusePlaceOnWalls(impl_->s, index); }
std::vector<std::pair<int, int>> RowBuilder::voidHoleCells(const ScenarioDomain& d, int rows) const {
  return scenario::voidHoleCells(impl_->s, d, rows);
}
void RowBuilder::addVoidHoles(std::vector<std::pair<int, int>> cells, ScenarioDomain& shape) const {
  scenario::addVoidHoles(std::move(cells), shape);
}
bool RowBuilder::hasLooseMaterial(const ScenarioDomain& d) const { return scenario::hasLooseMaterial(d); }
Error RowBuilder::refuseNoLooseMaterial() const { return scenario::refuseNoLooseMaterial(impl_->s); }
gis::Grid<uint8_t> RowBuilder::drains(const ScenarioDomain& d) const {
  return drainCells(impl_->s, d, impl_->plan.grid.height);
}
Error RowBuilder::refuseNothingDrains() const { return scenario::refuseNothingDrains(impl_->s); }
sim::ExactSum RowBuilder::raiseTo(const gis::Grid<float>& filled, int rows, ScenarioDomain& d) const {
  return scenario::raiseTo(filled, rows, d);
}
std::vector<double> RowBuilder::lowestLevelBeds(const ScenarioDomain& d) const {
  return scenario::lowestLevelBeds(impl_->s, impl_->shape, d);
}
Status RowBuilder::checkLevelStages(const std::vector<double>& lowestBed) const {
  return scenario::checkLevelStages(impl_->s, lowestBed);
}
std::vector<double> RowBuilder::placeDamBreaks(ScenarioDomain& d) const {
  return scenario::placeDamBreaks(impl_->s, impl_->damCells, d);
}
Status RowBuilder::checkDamBreaks(const std::vector<double>& lowestBed) const {
  return scenario::checkDamBreaks(impl_->s, lowestBed);
}
std::array<float, 2> RowBuilder::bedRange(const ScenarioDomain& d, int rows) const {
  return scenario::bedRange(d, rows);
}

}  // namespace detail

}  // namespace strata::scenario
