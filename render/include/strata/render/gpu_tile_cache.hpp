#pragma once
// The GPU side of the terrain store's caches: square pages of one field at one level of detail,
// resident in one r32f 2D texture array (one page per layer), with an LRU over the pages and a
// byte budget. Pages are uploaded from strata::terrain::TileStore::readWindow, i.e. from the
// store's RAM cache (which decodes a tile file on its own miss), or without waiting through
// tryReadWindow (whose background loader decodes it); nothing here reads the disk.
// docs/render-rings.md, "Streaming".
//
// Pages: page (x, y) of level `lod` holds the level-lod cells [x P, x P + P) x [y P, y P + P)
// (P = pageSize). With P = footprint() >> lod a page is exactly store tile (x, y) at that level;
// finer levels cut a tile into (footprint() >> lod) / P pages a side, coarser ones gather several
// tiles into one page.

#include <cstdint>
#include <functional>
#include <list>
#include <optional>
#include <unordered_map>
#include <vector>

#include <strata/core/result.hpp>
#include <strata/gis/raster.hpp>
#include <strata/gl/objects.hpp>

namespace strata::terrain {
class TileStore;
}

namespace strata::render {

/// One page: a field of the store, the page's column and row at its level, the level.
struct PageKey {
  int field = 0, x = 0, y = 0, lod = 0;
  bool operator==(const PageKey&) const = default;
};

/// GPU cache settings.
struct GpuCacheOptions {
  int pageSize = 64;                      ///< P: texels a page side (a power of two, 8..1024)
  size_t budgetBytes = size_t(32) << 20;  ///< GPU bytes of the page array; capacity = budget / (P^2 * 4)
  /// Fills the NaN samples of a page (p x p, read at the key's level) before it is uploaded;
  /// `wait` as acquire's. Returns false when it needs samples not in RAM yet (wait false: asked
  /// for; acquire then answers -1 and the page is read again later). Unset: NaN kept.
  std::function<Result<bool>(const PageKey&, gis::Grid<float>&, bool wait)> fillVoids;
};

/// Lookups and traffic since creation (or resetStats()).
struct GpuCacheStats {
  uint64_t hits = 0, misses = 0;
  uint64_t uploads = 0;       ///< pages uploaded from the store's RAM cache
  uint64_t evictions = 0;     ///< pages dropped to make room
  size_t bytesResident = 0;   ///< pages held x page bytes (never above budgetBytes)
  size_t bytesAllocated = 0;  ///< the texture array's storage (capacity x page bytes <= budgetBytes)
  size_t budgetBytes = 0;
};

class GpuTileCache {
 public:
  /// A cache over `store` (which must outlive it). Fails when the budget holds no page.
  static Result<GpuTileCache> create(strata::terrain::TileStore& store, const GpuCacheOptions& options = {});

  /// The layer holding `key`, uploading the page on a miss (evicting the least recently used
  /// page when full). A hit or an upload makes the page the most recently used. Fails (naming
  /// the tile) when the store cannot read it. `wait` false: never waits for the disk; a page
  /// whose tiles are not decoded in RAM yet is requested from the store's background loader
  /// (TileStore::tryReadWindow) and -1 returned.
  Result<int> acquire(const PageKey& key, bool wait = true);
  /// The layer holding `key` if resident, else -1; changes neither the LRU order nor the stats.
  int find(const PageKey& key) const;

  /// The page array: r32f, pageSize() x pageSize() x capacity() layers, no mip levels.
  const gl::Texture& pages() const { return pages_; }
  int pageSize() const { return options_.pageSize; }
  int capacity() const { return pages_.layers(); }
  size_t pageBytes() const { return size_t(options_.pageSize) * size_t(options_.pageSize) * sizeof(float); }
  int resident() const { return int(lru_.size()); }
  /// Resident pages, most recently used first.
  std::vector<PageKey> lruOrder() const;
  GpuCacheStats stats() const;
  void resetStats();
  strata::terrain::TileStore& store() const { return *store_; }

 private:
  struct KeyHash {
    size_t operator()(const PageKey& k) const {
      uint64_t h = uint64_t(uint32_t(k.x)) * 0x9E3779B97F4A7C15ull ^ uint64_t(uint32_t(k.y)) * 0xC2B2AE3D27D4EB4Full;
      return size_t(h ^ (uint64_t(uint32_t(k.lod)) << 48) ^ (uint64_t(uint32_t(k.field)) << 56));
    }
  };
  struct Entry {
    std::list<PageKey>::iterator pos;
    int layer = 0;
  };
  strata::terrain::TileStore* store_ = nullptr;
  GpuCacheOptions options_;
  gl::Texture pages_;
  std::list<PageKey> lru_;  // front: most recently used
  std::unordered_map<PageKey, Entry, KeyHash> map_;
  std::vector<int> freeLayers_;
  GpuCacheStats stats_;
};

}  // namespace strata::render
