#include <strata/render/gpu_tile_cache.hpp>

#include <algorithm>
#include <cmath>
#include <string>

#include <strata/core/check.hpp>
#include <strata/gl/context.hpp>
#include <strata/terrain/tile_store.hpp>

namespace strata::render {

Result<GpuTileCache> GpuTileCache::create(strata::terrain::TileStore& store, const GpuCacheOptions& options) {
  const int p = options.pageSize;
  if (p < 8 || p > 1024 || (p & (p - 1)) != 0) {
    return fail("render: GPU tile cache page size " + std::to_string(p) + " is not a power of two in 8..1024");
  }
  GpuTileCache c;
  c.store_ = &store;
  c.options_ = options;
  const size_t capacity = options.budgetBytes / c.pageBytes();
  if (capacity < 1) {
    return fail("render: GPU tile cache budget of " + std::to_string(options.budgetBytes) + " bytes holds no " +
                std::to_string(p) + "^2 page (" + std::to_string(c.pageBytes()) + " bytes)");
  }
  const int maxLayers = gl::queryContextLimits().maxArrayTextureLayers;
  const int layers = int(std::min<size_t>(capacity, size_t(std::max(maxLayers, 1))));
  c.pages_ = gl::Texture::create2DArray(gl::TextureFormat::kR32F, p, p, layers, 1);
  c.freeLayers_.reserve(size_t(layers));
  for (int l = layers - 1; l >= 0; --l) c.freeLayers_.push_back(l);
  c.stats_.budgetBytes = options.budgetBytes;
  c.stats_.bytesAllocated = size_t(layers) * c.pageBytes();
  return c;
}

Result<int> GpuTileCache::acquire(const PageKey& key, bool wait) {
  if (auto it = map_.find(key); it != map_.end()) {
    ++stats_.hits;
    lru_.splice(lru_.begin(), lru_, it->second.pos);
    return it->second.layer;
  }
  const int p = options_.pageSize;
  const strata::gis::CellRect window{key.x * p, key.y * p, p, p};
  gis::Grid<float> grid;
  if (wait) {
    STRATA_TRY(grid, store_->readWindow(key.field, window, key.lod));
  } else {
    STRATA_TRY(auto ready, store_->tryReadWindow(key.field, window, key.lod));
    if (!ready) return -1;  // requested; counted as a miss when it is uploaded
    grid = std::move(*ready);
  }
  STRATA_CHECK(grid.width == p && grid.height == p) << "readWindow returned " << grid.width << "x" << grid.height;
  if (options_.fillVoids && std::any_of(grid.data.begin(), grid.data.end(), [](float v) { return std::isnan(v); })) {
    STRATA_TRY(const bool filled, options_.fillVoids(key, grid, wait));
    if (!filled) return -1;  // its neighbours requested
  }
  ++stats_.misses;
  int layer = 0;
  if (freeLayers_.empty()) {
    const PageKey victim = lru_.back();
    auto vit = map_.find(victim);
    layer = vit->second.layer;
    map_.erase(vit);
    lru_.pop_back();
    ++stats_.evictions;
  } else {
    layer = freeLayers_.back();
    freeLayers_.pop_back();
  }
  pages_.upload(grid.data.data(), 0, 0, 0, p, p, layer);
  ++stats_.uploads;
  lru_.push_front(key);
  map_.emplace(key, Entry{lru_.begin(), layer});
  return layer;
}

int GpuTileCache::find(const PageKey& key) const {
  const auto it = map_.find(key);
  return it == map_.end() ? -1 : it->second.layer;
}

std::vector<PageKey> GpuTileCache::lruOrder() const { return {lru_.begin(), lru_.end()}; }

GpuCacheStats GpuTileCache::stats() const {
  GpuCacheStats s = stats_;
  s.bytesResident = lru_.size() * pageBytes();
  return s;
}

void GpuTileCache::resetStats() { stats_.hits = stats_.misses = stats_.uploads = stats_.evictions = 0; }

}  // namespace strata::render
