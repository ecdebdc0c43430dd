#include <strata/terrain/scenario_domain.hpp>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <memory>
#include <set>

#include <strata/gis/dem_io.hpp>
#include <strata/gis/geodesy.hpp>
#include <strata/gis/mosaic.hpp>
#include <strata/terrain/material.hpp>
#include <strata/terrain/tile_store.hpp>

namespace strata::terrain {
namespace {

// "file:line: key 'k': message" for a place read from the scenario.
Error placeError(const Scenario& s, const Place& p, const std::string& message) {
  return fail(s.file.string() + ":" + std::to_string(p.line) + ": key '" + p.key + "': " + message);
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
      STRATA_TRY(auto info, gis::probeDem(t.path_));
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

  /// The full base grid (the first DEM's, or the store's level 0).
  const gis::Georef& georef() const { return georef_; }
  const std::string& path() const { return path_; }
  std::string kind() const { return store_ ? "store" : "DEM"; }
  /// "DEM <path>" or "store <path>", for messages.
  std::string name() const { return kind() + " " + path_; }
  std::vector<Material> materials() const { return store_ ? store_->desc().materials : defaultMaterials(); }

  /// The bed elevation of `w` (base-grid cells), at the source's own resolution.
  Result<gis::Raster> readBed(const gis::PixelWindow& w) const {
    if (!store_) {
      gis::ReadOptions ro;
      ro.window = w;
      return gis::readDem(path_, ro);
    }
    return readField(bedField_, w);
  }

  /// What gis::warpToGrid resamples the bed from: the DEM file itself (GDAL reads what it needs),
  /// or, for a store, the window already read (`nativeBed`), held in memory.
  gis::MosaicInput resampleInput(const gis::Raster& nativeBed) const {
    if (!store_) return {path_, std::nullopt};
    return {"", nativeBed};
  }

  /// The store's material layers over `w`, bottom first (none for DEMs).
  Result<std::vector<StoredLayer>> readLayers(const gis::PixelWindow& w) const {
    std::vector<StoredLayer> out;
    for (int f : layerFields_) {
      STRATA_TRY(auto r, readField(f, w));
      out.push_back({std::move(r), findMaterial(store_->desc().materials, store_->desc().fields[size_t(f)].material)});
    }
    return out;
  }

 private:
  Result<gis::Raster> readField(int field, const gis::PixelWindow& w) const {
    const Window sw{w.x, w.y, w.width, w.height};
    auto values = store_->readWindow(field, sw, 0);
    if (!values) {
      return fail(path_ + ": field '" + store_->desc().fields[size_t(field)].name + "': " + values.message());
    }
    return gis::Raster{store_->windowGeoref(sw, 0), std::move(values).value()};
  }

  std::string path_;
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
    const int cx = int(std::floor(x)), cy = int(std::floor(y));
    if (cx < 0 || cy < 0 || cx >= width || cy >= height) return;
    if (seen.insert({cx, cy}).second) cells.push_back({cx, cy});
  };
  if (pts.size() == 1) add(pts[0][0], pts[0][1]);
  for (size_t i = 1; i < pts.size(); ++i) {
    const double dx = pts[i][0] - pts[i - 1][0], dy = pts[i][1] - pts[i - 1][1];
    const int n = std::max(1, int(std::ceil(4 * std::hypot(dx, dy))));
    for (int k = 0; k <= n; ++k) add(pts[i - 1][0] + dx * k / n, pts[i - 1][1] + dy * k / n);
  }
  return cells;
}

bool insidePolygon(const std::vector<std::array<double, 2>>& poly, double x, double y) {
  bool in = false;
  for (size_t i = 0, j = poly.size() - 1; i < poly.size(); j = i++) {
    const auto &a = poly[i], &b = poly[j];
    if ((a[1] > y) != (b[1] > y) && x < (b[0] - a[0]) * (y - a[1]) / (b[1] - a[1]) + a[0]) in = !in;
  }
  return in;
}

Result<ScenarioDomain> buildDomain(const Scenario& s) {
  STRATA_TRY(auto source, TerrainSource::open(s));
  const gis::Georef& full = source.georef();
  STRATA_TRY(auto mapper, PixelMapper::create(full));

  // The window: the region's pixel bounding box, which must lie inside the DEM.
  gis::PixelWindow window{0, 0, full.width, full.height};
  std::vector<std::array<double, 2>> polygonPx;
  if (s.region.kind != decltype(s.region)::Whole) {
    STRATA_TRY(auto px, mapper.pixels(s, s.region.place));
    double x0 = 1e300, y0 = 1e300, x1 = -1e300, y1 = -1e300;
    for (const auto& p : px) {
      x0 = std::min(x0, p[0]);
      x1 = std::max(x1, p[0]);
      y0 = std::min(y0, p[1]);
      y1 = std::max(y1, p[1]);
    }
    if (x0 < -1e-3 || y0 < -1e-3 || x1 > full.width + 1e-3 ||
        y1 > full.height + 1e-3) {  // 1e-3 pixel: rounding of the corners
      return placeError(
          s, s.region.place,
          "the region is not inside the " + source.name() + " (extent " + describeExtent(full) + " in its CRS)");
    }
    window.x = std::clamp(int(std::floor(x0 + 1e-6)), 0, full.width - 1);
    window.y = std::clamp(int(std::floor(y0 + 1e-6)), 0, full.height - 1);
    window.width = std::clamp(int(std::ceil(x1 - 1e-6)), window.x + 1, full.width) - window.x;
    window.height = std::clamp(int(std::ceil(y1 - 1e-6)), window.y + 1, full.height) - window.y;
    if (window.width < 4 || window.height < 4) {
      return placeError(s, s.region.place, "the region covers fewer than 4x4 cells of the DEM");
    }
    if (s.region.kind == decltype(s.region)::Polygon) polygonPx = px;
  }

  ScenarioDomain d;
  STRATA_TRY(d.bed, source.readBed(window));
  STRATA_TRY(auto storeLayers, source.readLayers(window));
  // Optional resampling to a coarser (or finer) grid of about region.cell_size metres.
  double scale = 1.0;  // region cells per DEM cell, along each axis
  if (s.region.cellSizeM > 0) {
    const auto& g0 = d.bed.georef;
    STRATA_TRY(auto a, gis::pixelToLonLat(g0, g0.width * 0.5, g0.height * 0.5));
    STRATA_TRY(auto b, gis::pixelToLonLat(g0, g0.width * 0.5, g0.height * 0.5 + 1));
    const double nativeM = gis::geodesicDistanceM(a, b, g0.body);
    scale = nativeM / s.region.cellSizeM;
    gis::Georef target = g0;
    target.width = std::max(4, int(std::floor(g0.width * scale)));
    target.height = std::max(4, int(std::floor(g0.height * scale)));
    target.transform.c[1] = g0.transform.c[1] * g0.width / target.width;
    target.transform.c[5] = g0.transform.c[5] * g0.height / target.height;
    scale = double(target.width) / g0.width;
    // Coarser cells take the lowest of the cells they cover: averaging (bilinear) raises a
    // canyon's narrow floor towards its rim and dams the river (docs/scenario.md).
    gis::MosaicInput in = source.resampleInput(d.bed);
    in.resampling = scale < 1 ? gis::Resampling::Minimum : gis::Resampling::Bilinear;
    STRATA_TRY(d.bed, gis::warpToGrid(in, target));
    // Stored layer thicknesses are averaged (bilinear): their volume is what matters, not a channel.
    for (auto& layer : storeLayers) {
      STRATA_TRY(layer.thickness, gis::warpToGrid({"", std::move(layer.thickness)}, target));
    }
  }
  auto toRegion = [&](std::vector<std::array<double, 2>> px) {
    for (auto& p : px) p = {(p[0] - window.x) * scale, (p[1] - window.y) * scale};
    return px;
  };
  if (!polygonPx.empty()) polygonPx = toRegion(polygonPx);
  if (s.terrain.dems.size() > 1) {
    std::vector<gis::MosaicInput> inputs;
    for (const auto& p : s.terrain.dems) inputs.push_back({p, std::nullopt, gis::BlendMode::Replace});
    STRATA_TRY(auto layer, gis::buildMosaic("bedrock", d.bed.georef, inputs));
    d.bed = std::move(layer.raster);
  }
  const gis::Georef& g = d.bed.georef;
  const int w = g.width, h = g.height;
  for (size_t i = 0; i < d.bed.values.size(); ++i) {
    if (gis::isNoData(d.bed.values.data[i])) {
      return fail(source.path() + ": the region has cells without data (nodata); choose a region the " + source.kind() +
                  " covers");
    }
  }

  // Region mask: a polygon's outside becomes a wall.
  d.inside = gis::Grid<uint8_t>(w, h, 1);
  if (!polygonPx.empty()) {
    for (int y = 0; y < h; ++y) {
      for (int x = 0; x < w; ++x) d.inside.at(x, y) = insidePolygon(polygonPx, x + 0.5, y + 0.5) ? 1 : 0;
    }
  }

  // Cell sizes: geodesic areas per cell; dy the geodesic length of a column cell; per-row dx so
  // that dx * dy is the row's true cell area.
  STRATA_TRY(d.cellAreaM2, gis::cellAreasM2(g));
  STRATA_TRY(auto top, gis::pixelToLonLat(g, w * 0.5, 0));
  STRATA_TRY(auto bottom, gis::pixelToLonLat(g, w * 0.5, h));
  const double dy = gis::geodesicDistanceM(top, bottom, g.body) / h;
  d.input.dyM = dy;
  d.input.rowDxM.resize(size_t(h));
  for (int y = 0; y < h; ++y) d.input.rowDxM[size_t(y)] = d.cellAreaM2.at(w / 2, y) / dy;
  for (int y = 0; y < h; ++y) {
    for (int x = 0; x < w; ++x) {
      if (d.inside.at(x, y)) d.totalAreaM2 += d.cellAreaM2.at(x, y);
    }
  }

  // Bed and layers. The datum is the region's lowest point, so float32 keeps millimetres.
  float lo = 1e30f;
  for (size_t i = 0; i < d.bed.values.size(); ++i) {
    if (d.inside.data[i]) lo = std::min(lo, d.bed.values.data[i]);
  }
  d.input.datumM = std::floor(double(lo));
  d.input.baseM = d.bed.values;
  for (size_t i = 0; i < d.input.baseM.size(); ++i) {
    if (!d.inside.data[i]) d.input.baseM.data[i] = kWallElevationM;
  }
  const auto table = source.materials();
  for (auto& layer : storeLayers) {
    gis::Grid<float> thickness = std::move(layer.thickness.values);
    for (auto& v : thickness.data) v = gis::isNoData(v) ? 0.0f : std::max(0.0f, v);
    d.input.layersM.push_back(std::move(thickness));
    d.input.materials.push_back(table[size_t(layer.material)]);
  }
  if (d.input.layersM.empty() && s.terrain.layers.empty()) {
    // Bare rock: one layer of zero thickness so erosion has a material to read.
    d.input.layersM.push_back(gis::Grid<float>(w, h, 0.0f));
    d.input.materials.push_back(table[size_t(findMaterial(table, "rock"))]);
  }
  for (size_t l = 0; l < s.terrain.layers.size(); ++l) {
    const auto& spec = s.terrain.layers[l];
    const int m = findMaterial(table, spec.material);
    if (m < 0) {
      std::string names;
      for (const auto& mat : table) names += (names.empty() ? "" : ", ") + mat.name;
      return fail(s.file.string() + ": key 'terrain.layer[" + std::to_string(l) + "].material': unknown material \"" +
                  spec.material + "\" (" + names + ")");
    }
    gis::Grid<float> thickness(w, h, float(spec.thicknessM));
    if (!spec.raster.empty()) {
      STRATA_TRY(auto r, gis::warpToGrid({spec.raster, std::nullopt}, g));
      for (size_t i = 0; i < thickness.size(); ++i) {
        const float v = r.values.data[i];
        thickness.data[i] = gis::isNoData(v) ? 0.0f : std::max(0.0f, v);
      }
    }
    d.input.layersM.push_back(std::move(thickness));
    d.input.materials.push_back(table[size_t(m)]);
  }

  // Parameters.
  auto& p = d.params;
  p.waterModel =
      int32_t(s.model.kind == WaterModel::Flood ? sim::WaterModel::kFiniteVolume : sim::WaterModel::kVirtualPipes);
  p.cflAlpha = float(s.model.cfl);
  // The CFL step (W10) is computed before the step's sources pour in, and on steep dry slopes a
  // long step lets a thin sheet overshoot (volume is then created where depths are clipped):
  // capped, by default at 2 s (docs/scenario.md).
  p.maxDtS = float(s.model.maxStepS);
  p.manningN = float(s.model.manningN);
  p.slopeLimiter = int32_t(s.model.sharpSlopes ? sim::SlopeLimiter::kMonotonizedCentral : sim::SlopeLimiter::kMinmod);
  const uint32_t bits[4] = {sim::kEdgeWest, sim::kEdgeEast, sim::kEdgeSouth, sim::kEdgeNorth};
  p.openEdges = 0;
  for (int e = 0; e < 4; ++e) {
    if (s.model.boundaries[size_t(e)] == Boundary::Open) p.openEdges |= bits[e];
  }
  p.evaporationMmPerHour = float(s.water.evaporationMPerS * 3.6e6);
  if (s.erosion.enabled) {
    p.erosionEnabled = 1;
    p.thermalEnabled = s.erosion.thermal ? 1 : 0;
    p.capacityK = float(s.erosion.capacity);
    p.erosionRate = float(s.erosion.erosionRate);
    p.depositionRate = float(s.erosion.depositionRate);
  }

  // Sources.
  for (size_t i = 0; i < s.water.inflows.size(); ++i) {
    const auto& in = s.water.inflows[i];
    STRATA_TRY(auto demPx, mapper.pixels(s, in.place));
    const auto px = toRegion(demPx);
    for (const auto& pt : px) {
      const int cx = int(std::floor(pt[0])), cy = int(std::floor(pt[1]));
      if (cx < 0 || cy < 0 || cx >= w || cy >= h || !d.inside.at(cx, cy)) {
        return placeError(s, in.place, "the source \"" + in.name + "\" is outside the region");
      }
    }
    sim::Source src;
    src.cells = cellsAlong(px, w, h);
    std::erase_if(src.cells, [&](auto c) { return !d.inside.at(c.first, c.second); });
    // Zero outside the curve's span (the solver holds the end values): pad with zeros.
    const auto& pts = in.hydrograph.points;
    if (pts.front()[0] > 0) src.hydrographM3S.push_back({0.0, 0.0});
    if (pts.front()[1] != 0 && pts.front()[0] > 0) src.hydrographM3S.push_back({pts.front()[0] * (1 - 1e-9), 0.0});
    for (const auto& q : pts) src.hydrographM3S.push_back({q[0], q[1]});
    if (pts.back()[1] != 0) src.hydrographM3S.push_back({pts.back()[0] * (1 + 1e-9) + 1e-6, 0.0});
    d.sources.push_back(std::move(src));
    d.sourceNames.push_back(in.name);
  }

  // Fixed levels: the cells of a line (as inflow lines) or of a polygon (centres inside), which
  // must lie in the region, and a stage that rises above the bed of at least one of them.
  for (size_t i = 0; i < s.water.levels.size(); ++i) {
    const auto& lv = s.water.levels[i];
    STRATA_TRY(auto demPx, mapper.pixels(s, lv.place));
    const auto px = toRegion(demPx);
    sim::LevelBoundary level;
    if (lv.polygon) {
      for (int y = 0; y < h; ++y) {
        for (int x = 0; x < w; ++x) {
          if (d.inside.at(x, y) && insidePolygon(px, x + 0.5, y + 0.5)) level.cells.push_back({x, y});
        }
      }
      if (level.cells.empty()) {
        return placeError(s, lv.place, "the level \"" + lv.name + "\" covers no cell of the region");
      }
    } else {
      for (const auto& pt : px) {
        const int cx = int(std::floor(pt[0])), cy = int(std::floor(pt[1]));
        if (cx < 0 || cy < 0 || cx >= w || cy >= h || !d.inside.at(cx, cy)) {
          return placeError(s, lv.place, "the level \"" + lv.name + "\" is outside the region");
        }
      }
      level.cells = cellsAlong(px, w, h);
      std::erase_if(level.cells, [&](auto c) { return !d.inside.at(c.first, c.second); });
    }
    double lowestBed = 1e300, highestStage = -1e300;
    for (auto [x, y] : level.cells) {
      double b = d.input.baseM.at(x, y);
      for (const auto& l : d.input.layersM) b += l.at(x, y);
      lowestBed = std::min(lowestBed, b);
    }
    for (const auto& st : lv.stage) highestStage = std::max(highestStage, st[1]);
    if (highestStage <= lowestBed) {
      char msg[200];
      std::snprintf(msg, sizeof msg,
                    "the stage (at most %.2f m) never rises above the bed of the level's cells (lowest %.2f m): "
                    "it would hold no water",
                    highestStage, lowestBed);
      return fail(s.file.string() + ":" + std::to_string(lv.stageLine) + ": key 'water.level[" + std::to_string(i) +
                  "].stage': " + msg);
    }
    for (const auto& st : lv.stage) level.stageM.push_back({st[0], st[1]});
    d.levels.push_back(std::move(level));
    d.levelNames.push_back(lv.name);
  }

  // Rain.
  if (s.water.rain) {
    d.rainMmPerHour = s.water.rain->rateMPerS * 3.6e6;
    d.rainStartS = s.water.rain->startS;
    d.rainEndS = s.water.rain->endS < 0 ? s.durationS : s.water.rain->endS;
    if (!s.water.rain->raster.empty()) {
      if (s.water.rain->startS > 0 || s.water.rain->endS >= 0) {
        return fail(s.file.string() +
                    ": key 'water.rain.raster': a rain raster falls for the whole run; "
                    "start and end apply to a uniform rate only");
      }
      STRATA_TRY(auto r, gis::warpToGrid({s.water.rain->raster, std::nullopt}, g));
      d.input.rainMmPerHour = gis::Grid<float>(w, h, 0.0f);
      for (size_t i = 0; i < r.values.size(); ++i) {
        const float v = r.values.data[i];
        d.input.rainMmPerHour.data[i] = gis::isNoData(v) ? 0.0f : float(std::max(0.0f, v) * d.rainMmPerHour);
      }
      d.rainMmPerHour = 0;  // the raster carries the rate
    }
  }

  // Dam breaks: water standing up to the given surface inside each polygon.
  for (const auto& db : s.water.damBreaks) {
    STRATA_TRY(auto demPx, mapper.pixels(s, db.polygon));
    const auto px = toRegion(demPx);
    if (d.input.waterDepthM.size() == 0) d.input.waterDepthM = gis::Grid<float>(w, h, 0.0f);
    bool any = false;
    for (int y = 0; y < h; ++y) {
      for (int x = 0; x < w; ++x) {
        if (!d.inside.at(x, y) || !insidePolygon(px, x + 0.5, y + 0.5)) continue;
        any = true;
        const float depth = std::max(0.0f, float(db.surfaceElevationM) - d.bed.values.at(x, y));
        d.input.waterDepthM.at(x, y) = std::max(d.input.waterDepthM.at(x, y), depth);
      }
    }
    if (!any) return placeError(s, db.polygon, "the dam-break polygon covers no cell of the region");
  }
  if (d.input.waterDepthM.size() > 0) {
    for (int y = 0; y < h; ++y) {
      for (int x = 0; x < w; ++x) d.damBreakVolumeM3 += double(d.input.waterDepthM.at(x, y)) * d.cellAreaM2.at(x, y);
    }
  }
  return d;
}

}  // namespace strata::terrain
