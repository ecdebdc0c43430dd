#include <strata/render/streamed_elevation.hpp>

#include <strata/gis/fill_nodata.hpp>

#include <algorithm>
#include <cmath>
#include <optional>
#include <string>

#include <strata/core/check.hpp>
#include <strata/terrain/tile_store.hpp>

namespace strata::render {

namespace {
int wrap(int a, int n) { return ((a % n) + n) % n; }
}  // namespace

StreamedElevation::~StreamedElevation() = default;

Result<std::unique_ptr<StreamedElevation>> StreamedElevation::create(strata::terrain::TileStore store,
                                                                     const StreamParams& params, bool wrapLongitude) {
  const std::string where = "render: streaming " + store.dir().string() + ": ";
  if (wrapLongitude && store.desc().layout != strata::terrain::TileLayout::Global) {
    return fail(where + "wrapping in longitude needs a global store (this one is planar)");
  }
  const int p = params.pageSize, n = params.clipSize;
  if (p < 8 || p > 1024 || (p & (p - 1)) != 0) {
    return fail(where + "page size " + std::to_string(p) + " is not a power of two in 8..1024");
  }
  if (n < p || n % p != 0 || n > 8192) {
    return fail(where + "clip size " + std::to_string(n) + " is not a multiple of the page size " + std::to_string(p) +
                " in " + std::to_string(p) + "..8192");
  }
  if (params.uploadPagesPerFrame < 0) return fail(where + "negative upload budget");
  const int field = store.fieldIndex(params.field);
  if (field < 0) return fail(where + "no field '" + params.field + "'");

  std::unique_ptr<StreamedElevation> s(new StreamedElevation());
  s->params_ = params;
  s->field_ = field;
  s->wrapX_ = wrapLongitude;
  s->store_ = std::make_unique<strata::terrain::TileStore>(std::move(store));
  auto& st = *s->store_;
  const auto [lo, hi] = st.globalRange(field);
  if (!(lo <= hi)) return fail(where + "field '" + params.field + "' has no valid elevation");
  s->minM_ = lo;
  s->maxM_ = hi;

  // The coarse level: the finest whose whole extent fits in one window.
  int c = 0;
  while (st.levelWidth(c) > n || st.levelHeight(c) > n) ++c;
  if (c > st.maxLod()) {
    return fail(where + "clip size " + std::to_string(n) + " is too small: level " + std::to_string(st.maxLod()) +
                " (the store's coarsest) is " + std::to_string(st.levelWidth(st.maxLod())) + " cells wide");
  }
  // terrain_common.glsl holds 16 window origins.
  if (c > 16) {
    return fail(where + "clip size " + std::to_string(n) + " needs " + std::to_string(c) +
                " streamed levels for this grid, more than 16: use a larger one");
  }
  s->coarse_ = c;
  const int cw = st.levelWidth(c), ch = st.levelHeight(c);
  STRATA_TRY(auto coarse, st.readWindow(field, {0, 0, cw, ch}, c));
  // Voids of the coarse level filled from the cells around them, not pits. A streamed page's
  // voids are filled the same way from the page and a margin around it (fillPage); what that
  // cannot reach takes the filled coarse level's surface (voidFill; docs/render-rings.md,
  // "Voids"), never the lowest elevation (shafts down to it).
  STRATA_TRY(const size_t filled, gis::fillVoids(coarse));
  (void)filled;
  s->coarseCpu_ = std::move(coarse);
  s->coarseTex_ = gl::Texture::create2D(gl::TextureFormat::kR32F, cw, ch, 0);
  s->coarseTex_.upload(s->coarseCpu_.data.data());
  s->coarseTex_.generateMipmap();
  if (wrapLongitude) s->coarseTex_.setWrap(gl::Wrap::kRepeat, gl::Wrap::kClampToEdge);

  // The stack: one toroidal layer per level 0..C-1 (one unused layer when C = 0, so that the
  // sampler always has a texture), bilinear with wrap-around addressing.
  const int layers = std::max(c, 1);
  s->clip_ = gl::Texture::create2DArray(gl::TextureFormat::kR32F, n, n, layers, 1);
  s->clip_.setWrap(gl::Wrap::kRepeat);
  const int k = n / p;
  s->flags_ = gl::Texture::create2DArray(gl::TextureFormat::kR32UI, k, k, layers, 1);
  s->flags_.setFilter(gl::Filter::kNearest);  // integer textures are incomplete with linear filtering
  s->flagsCpu_.assign(size_t(k) * size_t(k) * size_t(layers), 0u);
  s->origins_.assign(size_t(layers), glm::ivec2(0));

  size_t fixed = 0;
  for (int l = 0; l < s->coarseTex_.levels(); ++l) {
    fixed += size_t(std::max(1, cw >> l)) * size_t(std::max(1, ch >> l)) * sizeof(float);
  }
  fixed += size_t(n) * size_t(n) * size_t(layers) * sizeof(float) + s->flagsCpu_.size() * sizeof(uint32_t);
  const size_t page = size_t(p) * size_t(p) * sizeof(float);
  if (params.gpuBudgetBytes < fixed + page) {
    return fail(where + "GPU budget of " + std::to_string(params.gpuBudgetBytes) + " bytes is below the stack's " +
                std::to_string(fixed) + " bytes plus one " + std::to_string(page) + "-byte page");
  }
  STRATA_TRY(
      auto cache,
      GpuTileCache::create(st, {.pageSize = p,
                                .budgetBytes = params.gpuBudgetBytes - fixed,
                                .fillVoids = [raw = s.get()](const PageKey& key, gis::Grid<float>& values, bool wait) {
                                  return raw->fillPage(key, values, wait);
                                }}));
  s->cache_ = std::make_unique<GpuTileCache>(std::move(cache));
  s->stats_.gpuBudgetBytes = params.gpuBudgetBytes;
  return s;
}

int StreamedElevation::width() const { return store_->width(); }
int StreamedElevation::height() const { return store_->height(); }

glm::ivec2 StreamedElevation::levelSize(int level) const {
  return {store_->levelWidth(level), store_->levelHeight(level)};
}

size_t StreamedElevation::flagIndex(int level, int px, int py) const {
  const int k = slots();
  return (size_t(level) * size_t(k) + size_t(wrap(py, k))) * size_t(k) + size_t(wrap(px, k));
}

bool StreamedElevation::inWindow(int level, int px, int py) const {
  const glm::ivec2 o = origins_[size_t(level)] / params_.pageSize;
  return px >= o.x && py >= o.y && px < o.x + slots() && py < o.y + slots();
}

bool StreamedElevation::pageReady(int level, int px, int py) const {
  if (level >= coarse_) return true;
  if (!placed_ || !inWindow(level, px, py)) return false;
  return flagsCpu_[flagIndex(level, px, py)] != 0;
}

void StreamedElevation::moveWindow(int level, glm::ivec2 origin) {
  const int p = params_.pageSize, k = slots();
  const glm::ivec2 o = origin / p;  // origin is a multiple of p
  const glm::ivec2 ext = levelSize(level);
  const bool had = placed_;
  for (int py = o.y; py < o.y + k; ++py) {
    for (int px = o.x; px < o.x + k; ++px) {
      if (had && inWindow(level, px, py)) continue;  // stays resident in its slot
      // Pages wholly outside the level's cells are never sampled (the shader clamps to the
      // level's extent): ready at once, nothing to copy. Wrapping in longitude, columns past
      // the seam are real pages (the store's global reads take them modulo the grid).
      const bool outside = (!wrapX_ && (px < 0 || px * p >= ext.x)) || py < 0 || py * p >= ext.y;
      flagsCpu_[flagIndex(level, px, py)] = outside ? 1u : 0u;
      if (!outside) pending_.push_back({level, px, py});
    }
  }
  origins_[size_t(level)] = origin;
  flagsDirty_ = true;
}

Status StreamedElevation::update(glm::dvec2 cell) {
  const int p = params_.pageSize, half = slots() / 2;
  ++stats_.frames;
  std::vector<glm::ivec2> wanted(static_cast<size_t>(coarse_));
  for (int l = 0; l < coarse_; ++l) {
    // The page corner nearest to the viewer, half a window from the window's corner.
    const glm::dvec2 c = cell / std::exp2(double(l));
    wanted[size_t(l)] = p * glm::ivec2(int(std::lround(c.x / p)) - half, int(std::lround(c.y / p)) - half);
  }
  for (int l = 0; l < coarse_; ++l) {
    if (!placed_ || wanted[size_t(l)] != origins_[size_t(l)]) {
      // Pages that leave lose their slot; those still pending are dropped below.
      moveWindow(l, wanted[size_t(l)]);
    }
  }
  placed_ = true;
  std::erase_if(pending_, [&](const Pending& q) { return !inWindow(q.level, q.px, q.py); });
  // Coarse levels first (they stand in for the finer ones), then nearest to the viewer.
  auto distance = [&](const Pending& q) {
    const glm::dvec2 c = cell / std::exp2(double(q.level));
    return glm::length(glm::dvec2((q.px + 0.5) * p, (q.py + 0.5) * p) - c);
  };
  std::sort(pending_.begin(), pending_.end(), [&](const Pending& a, const Pending& b) {
    if (a.level != b.level) return a.level > b.level;
    return distance(a) < distance(b);
  });
  // Requests of earlier frames are for where the viewer was: ask again, in this frame's order.
  if (!params_.waitForDisk) store_->clearRequests();
  int count = 0;
  size_t next = 0;
  std::vector<Pending> waiting;
  for (; next < pending_.size() && count < params_.uploadPagesPerFrame; ++next) {
    const Pending q = pending_[next];
    STRATA_TRY(const int layer, cache_->acquire({field_, q.px, q.py, q.level}, params_.waitForDisk));
    if (layer < 0) {  // its tiles are being decoded: a coarser level stands in meanwhile
      waiting.push_back(q);
      continue;
    }
    const int k = slots();
    gl::copyTexels(cache_->pages(), {.layer = layer}, clip_,
                   {.x = wrap(q.px, k) * p, .y = wrap(q.py, k) * p, .layer = q.level}, p, p);
    flagsCpu_[flagIndex(q.level, q.px, q.py)] = 1u;
    flagsDirty_ = true;
    ++count;
  }
  stats_.lastFramePagesWaiting = int(waiting.size());
  waiting.insert(waiting.end(), pending_.begin() + std::ptrdiff_t(next), pending_.end());
  pending_ = std::move(waiting);
  stats_.pagesCopied += uint64_t(count);
  stats_.lastFramePagesCopied = count;
  if (flagsDirty_) {
    for (int l = 0; l < flags_.layers(); ++l) {
      flags_.upload(flagsCpu_.data() + size_t(l) * size_t(slots()) * size_t(slots()), 0, 0, 0, slots(), slots(), l);
    }
    flagsDirty_ = false;
  }
  return {};
}

Result<bool> StreamedElevation::fillPage(const PageKey& key, gis::Grid<float>& page, bool wait) {
  // The page with a margin of a page on each side, within the level on a planar store (outside
  // it there is nothing to fill from; a global store's reads wrap): GDAL's fill there, as the
  // whole-DEM render fills the whole grid (gis::fillVoids), gives a void the same surface
  // wherever its nearest cells are within the margin.
  const int p = page.width, lw = store_->levelWidth(key.lod), lh = store_->levelHeight(key.lod);
  int x0 = key.x * p - p, y0 = key.y * p - p, x1 = key.x * p + 2 * p, y1 = key.y * p + 2 * p;
  if (!wrapX_) {
    x0 = std::max(x0, 0);
    y0 = std::max(y0, 0);
    x1 = std::min(x1, lw);
    y1 = std::min(y1, lh);
  }
  const auto inside = [&](int x, int y) {  // texel (x, y) of the page inside the margin's window
    const int gx = key.x * p + x, gy = key.y * p + y;
    return gx >= x0 && gx < x1 && gy >= y0 && gy < y1;
  };
  bool voidInside = false;
  for (int y = 0; y < p && !voidInside; ++y) {
    for (int x = 0; x < p && !voidInside; ++x) voidInside = std::isnan(page.at(x, y)) && inside(x, y);
  }
  if (voidInside) {
    const gis::CellRect window{x0, y0, x1 - x0, y1 - y0};
    std::optional<gis::Grid<float>> around;
    if (wait) {
      STRATA_TRY(around, store_->readWindow(key.field, window, key.lod));
    } else {
      STRATA_TRY(around, store_->tryReadWindow(key.field, window, key.lod));
      if (!around) return false;
    }
    const bool anyData = std::any_of(around->data.begin(), around->data.end(), [](float v) { return !std::isnan(v); });
    if (anyData) {
      STRATA_TRY_STATUS(gis::fillVoids(*around));
      for (int y = 0; y < p; ++y) {
        for (int x = 0; x < p; ++x) {
          if (std::isnan(page.at(x, y)) && inside(x, y))
            page.at(x, y) = around->at(key.x * p + x - x0, key.y * p + y - y0);
        }
      }
    }
  }
  for (int y = 0; y < p; ++y) {  // outside the level, or no data around: the coarse surface
    for (int x = 0; x < p; ++x) {
      if (float& v = page.at(x, y); std::isnan(v)) {
        v = voidFill((key.x * p + x + 0.5) * double(1 << key.lod), (key.y * p + y + 0.5) * double(1 << key.lod));
      }
    }
  }
  return true;
}

float StreamedElevation::voidFill(double x, double y) const {
  // Bilinear on the filled coarse grid, whose cell (i, j) is centred at ((i + 0.5) s, (j + 0.5) s).
  const double s = double(1 << coarse_);
  const double u = std::clamp(x / s - 0.5, 0.0, double(coarseCpu_.width - 1));
  const double v = std::clamp(y / s - 0.5, 0.0, double(coarseCpu_.height - 1));
  const int i0 = int(u), j0 = int(v);
  const int i1 = std::min(i0 + 1, coarseCpu_.width - 1), j1 = std::min(j0 + 1, coarseCpu_.height - 1);
  const double fu = u - i0, fv = v - j0;
  const double top = (1 - fu) * coarseCpu_.at(i0, j0) + fu * coarseCpu_.at(i1, j0);
  const double bottom = (1 - fu) * coarseCpu_.at(i0, j1) + fu * coarseCpu_.at(i1, j1);
  const double h = (1 - fv) * top + fv * bottom;
  return std::isfinite(h) ? float(h) : minM_;  // a grid with no data at all
}

std::array<float, 4> StreamedElevation::cellQuad(int i, int j) {
  // Without waitForDisk a tile not in RAM yet is requested, and the coarse level answers
  // meanwhile (draw() asks for the ground under the viewer every frame).
  std::optional<gis::Grid<float>> read;
  if (params_.waitForDisk) {
    if (auto r = store_->readWindow(field_, {i, j, 2, 2}, 0)) read = std::move(*r);
  } else if (auto r = store_->tryReadWindow(field_, {i, j, 2, 2}, 0)) {
    read = std::move(*r);
  }
  std::array<float, 4> q{};
  if (read) {
    for (size_t k = 0; k < 4; ++k) {
      const int x = i + int(k & 1), y = j + int(k >> 1);
      q[k] = std::isnan(read->data[k]) ? voidFill(x + 0.5, y + 0.5) : read->data[k];
    }
    return q;
  }
  const int s = 1 << coarse_;
  const auto at = [&](int x, int y) {
    return coarseCpu_.at(std::clamp(x / s, 0, coarseCpu_.width - 1), std::clamp(y / s, 0, coarseCpu_.height - 1));
  };
  return {at(i, j), at(i + 1, j), at(i, j + 1), at(i + 1, j + 1)};
}

size_t StreamedElevation::gpuBytes() const {
  size_t b = 0;
  for (int l = 0; l < coarseTex_.levels(); ++l) {
    b += size_t(std::max(1, coarseTex_.width() >> l)) * size_t(std::max(1, coarseTex_.height() >> l)) * sizeof(float);
  }
  b += size_t(clip_.width()) * size_t(clip_.height()) * size_t(clip_.layers()) * sizeof(float);
  b += flagsCpu_.size() * sizeof(uint32_t);
  return b + cache_->stats().bytesAllocated;
}

int StreamedElevation::overviewLevel(int maxSide) const {
  const auto& st = *store_;
  int level = 0;
  while (level < st.maxLod() && (st.levelWidth(level) > maxSide || st.levelHeight(level) > maxSide)) ++level;
  return level;
}

gis::Georef StreamedElevation::overviewGrid(int maxSide) const {
  const int level = overviewLevel(maxSide);
  gis::Georef g = store_->desc().georef;
  g.width = store_->levelWidth(level);
  g.height = store_->levelHeight(level);
  for (int k : {1, 2, 4, 5}) g.transform.c[k] *= double(1 << level);
  return g;
}

Result<gis::Raster> StreamedElevation::overview(int maxSide) {
  gis::Raster r;
  r.georef = overviewGrid(maxSide);
  const int level = overviewLevel(maxSide);
  STRATA_TRY(r.values, store_->readWindow(field_, {0, 0, r.georef.width, r.georef.height}, level));
  STRATA_TRY(const size_t filled, gis::fillVoids(r.values));
  (void)filled;
  return r;
}

StreamStats StreamedElevation::stats() const {
  StreamStats s = stats_;
  s.pending = int(pending_.size());
  s.gpuBytes = gpuBytes();
  s.cache = cache_->stats();
  return s;
}

}  // namespace strata::render
