#pragma once
// Private: reading tiles into RAM. The decoded tile levels live in an LRU cache under a byte
// budget; a background thread decodes the levels a non-blocking reader asks for (first) and the
// neighbours a blocking read prefetches.

#include <condition_variable>
#include <deque>
#include <filesystem>
#include <list>
#include <memory>
#include <mutex>
#include <string>
#include <thread>
#include <unordered_map>
#include <unordered_set>
#include <vector>

#include <strata/core/result.hpp>
#include <strata/gis/raster.hpp>
#include <strata/terrain/tile_store.hpp>

#include "tile_files.hpp"

namespace strata::terrain::detail {

/// One decoded mip level of one tile: every field at that level.
struct Decoded {
  std::vector<gis::Grid<float>> fields;
  size_t bytes = 0;
};
using DecodedPtr = std::shared_ptr<const Decoded>;

struct CacheKey {
  int tx = 0, ty = 0;
  uint64_t generation = 0;  ///< a rewritten tile is a new key; stale entries age out
  int mip = 0;
  bool operator==(const CacheKey&) const = default;
};
struct CacheKeyHash {
  size_t operator()(const CacheKey& k) const;
};

/// Who decoded a tile: a blocking read on the caller's thread, the neighbour prefetcher, or the
/// background loader serving non-blocking reads.
enum class LoadSource { Sync, Prefetch, Request };

/// LRU of decoded tile levels under a byte budget. Thread-safe (the loader thread inserts).
class TileCache {
 public:
  explicit TileCache(size_t budget) : budget_(budget) {}
  DecodedPtr lookup(const CacheKey& k);
  bool contains(const CacheKey& k);
  /// Never evicts the entry just inserted: a caller holds it anyway, through its shared_ptr.
  void insert(const CacheKey& k, DecodedPtr tile, LoadSource source);
  CacheStats stats();
  void resetStats();
  void clear();

 private:
  struct Entry {
    CacheKey key;
    DecodedPtr tile;
    bool prefetched = false;
  };
  std::mutex m_;
  size_t budget_;
  size_t bytes_ = 0;
  std::list<Entry> lru_;
  std::unordered_map<CacheKey, std::list<Entry>::iterator, CacheKeyHash> map_;
  CacheStats stats_;
};

/// The cache and its background loader for one store. Locking: the loader thread reads only
/// `dir_`, `fieldNames_`, `options_` (never written after construction), the TileRef copied into
/// its job and `cache_` (its own mutex); the queues, `stopping_` and `worker_` are guarded by
/// `queueMutex_`.
class TileLoader {
 public:
  TileLoader(std::filesystem::path dir, std::vector<std::string> fieldNames, CacheOptions options);
  TileLoader(const TileLoader&) = delete;
  TileLoader& operator=(const TileLoader&) = delete;
  ~TileLoader();

  /// Level `mip` of a tile: from the cache, else decoded now on this thread (`*decoded` set).
  /// With `missing` set (a non-blocking read), a level not in RAM is requested instead:
  /// *missing becomes true and the result is null; fails with the loader's message if an earlier
  /// request of it failed.
  Result<DecodedPtr> get(const TileRef& ref, int mip, bool* missing, bool* decoded);
  /// Queues background decodes of levels not in RAM; old prefetches give way to new ones.
  void prefetch(std::vector<std::pair<TileRef, int>> levels);
  /// Whether prefetching neighbours is on (CacheOptions::prefetch).
  bool prefetching() const { return options_.prefetch; }
  /// Drops the requests not yet started.
  void clearRequests();
  /// Requests queued or being decoded.
  int requestsPending() const;
  TileCache& cache() { return cache_; }

 private:
  struct Job {
    TileRef ref;
    int mip = 0;
    CacheKey key() const { return {ref.tx, ref.ty, ref.generation, mip}; }
  };
  Result<DecodedPtr> load(const TileRef& r, int mip) const;
  Status request(const TileRef& ref, int mip);
  void workerLoop();
  void startWorker();  ///< precondition: queueMutex_ held

  std::filesystem::path dir_;
  std::vector<std::string> fieldNames_;
  CacheOptions options_;
  TileCache cache_;
  mutable std::mutex queueMutex_;
  std::condition_variable queueCv_;
  std::deque<Job> requests_;                                        ///< non-blocking reads', in order
  std::unordered_set<CacheKey, CacheKeyHash> requested_;            ///< queued or being decoded
  std::unordered_map<CacheKey, std::string, CacheKeyHash> failed_;  ///< requests that failed, why
  std::deque<Job> queue_;                                           ///< neighbour prefetches
  bool stopping_ = false;
  std::thread worker_;
};

}  // namespace strata::terrain::detail
