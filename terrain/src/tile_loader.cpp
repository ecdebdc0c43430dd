#include "tile_loader.hpp"

#include <chrono>

#include "exr_codec.hpp"

namespace strata::terrain::detail {

namespace fs = std::filesystem;

size_t CacheKeyHash::operator()(const CacheKey& k) const {
  size_t h = std::hash<uint64_t>()(k.generation);
  h ^= std::hash<int64_t>()((int64_t(k.tx) << 32) ^ (int64_t(k.ty) << 8) ^ k.mip) + 0x9e3779b97f4a7c15ULL + (h << 6);
  return h;
}

DecodedPtr TileCache::lookup(const CacheKey& k) {
  std::lock_guard lock(m_);
  auto it = map_.find(k);
  if (it == map_.end()) {
    ++stats_.misses;
    return nullptr;
  }
  ++stats_.hits;
  if (it->second->prefetched) {
    ++stats_.prefetchHits;
    it->second->prefetched = false;
  }
  lru_.splice(lru_.begin(), lru_, it->second);
  return it->second->tile;
}

bool TileCache::contains(const CacheKey& k) {
  std::lock_guard lock(m_);
  return map_.count(k) != 0;
}

void TileCache::insert(const CacheKey& k, DecodedPtr tile, LoadSource source) {
  const bool prefetched = source == LoadSource::Prefetch;
  std::lock_guard lock(m_);
  if (auto it = map_.find(k); it != map_.end()) {
    bytes_ -= it->second->tile->bytes;
    lru_.erase(it->second);
    map_.erase(it);
  }
  if (prefetched) ++stats_.prefetchLoads;
  if (source == LoadSource::Sync) ++stats_.syncLoads;
  if (source == LoadSource::Request) ++stats_.requestLoads;
  bytes_ += tile->bytes;
  lru_.push_front({k, std::move(tile), prefetched});
  map_[k] = lru_.begin();
  while (bytes_ > budget_ && lru_.size() > 1) {
    bytes_ -= lru_.back().tile->bytes;
    map_.erase(lru_.back().key);
    lru_.pop_back();
    ++stats_.evictions;
  }
}

CacheStats TileCache::stats() {
  std::lock_guard lock(m_);
  CacheStats s = stats_;
  s.bytes = bytes_;
  return s;
}

void TileCache::resetStats() {
  std::lock_guard lock(m_);
  stats_ = {};
}

void TileCache::clear() {
  std::lock_guard lock(m_);
  lru_.clear();
  map_.clear();
  bytes_ = 0;
}

TileLoader::TileLoader(fs::path dir, std::vector<std::string> fieldNames, CacheOptions options)
    : dir_(std::move(dir)), fieldNames_(std::move(fieldNames)), options_(options), cache_(options.budgetBytes) {}

TileLoader::~TileLoader() {
  {
    std::lock_guard lock(queueMutex_);
    stopping_ = true;
  }
  queueCv_.notify_all();
  if (worker_.joinable()) worker_.join();
}

Result<DecodedPtr> TileLoader::load(const TileRef& r, int mip) const {
  if (options_.loadDelayMs > 0) {
    std::this_thread::sleep_for(std::chrono::duration<double, std::milli>(options_.loadDelayMs));
  }
  STRATA_TRY(auto bytes, readTileBytes(dir_, r));
  STRATA_TRY(auto fields, decodeTileExrLevel(r.file, bytes, fieldNames_, mip));
  auto d = std::make_shared<Decoded>();
  for (const auto& g : fields) d->bytes += g.size() * sizeof(float);
  d->fields = std::move(fields);
  return DecodedPtr(std::move(d));
}

Result<DecodedPtr> TileLoader::get(const TileRef& ref, int mip, bool* missing, bool* decoded) {
  const CacheKey key{ref.tx, ref.ty, ref.generation, mip};
  if (auto hit = cache_.lookup(key)) return hit;
  if (missing) {
    STRATA_TRY_STATUS(request(ref, mip));
    *missing = true;
    return DecodedPtr();
  }
  STRATA_TRY(DecodedPtr d, load(ref, mip));
  cache_.insert(key, d, LoadSource::Sync);
  if (decoded) *decoded = true;
  return d;
}

void TileLoader::workerLoop() {
  for (;;) {
    Job job;
    bool isRequest = false;
    {
      std::unique_lock lock(queueMutex_);
      queueCv_.wait(lock, [&] { return stopping_ || !requests_.empty() || !queue_.empty(); });
      if (stopping_) return;
      isRequest = !requests_.empty();
      auto& from = isRequest ? requests_ : queue_;
      job = std::move(from.front());
      from.pop_front();
    }
    const CacheKey key = job.key();
    if (!cache_.contains(key)) {
      auto d = load(job.ref, job.mip);
      if (d) {
        cache_.insert(key, std::move(*d), isRequest ? LoadSource::Request : LoadSource::Prefetch);
      } else if (isRequest) {
        std::lock_guard lock(queueMutex_);
        failed_[key] = d.message();
      }
      // A failed prefetch (corrupt tile, file superseded by a commit) is not reported: the
      // demand read of that tile reports it.
    }
    if (isRequest) {
      // Erased after the insert: a reader that finds the key neither cached nor requested
      // asks again, at worst decoding a tile twice, never waiting for one nobody loads.
      std::lock_guard lock(queueMutex_);
      requested_.erase(key);
    }
  }
}

void TileLoader::startWorker() {
  if (!worker_.joinable()) worker_ = std::thread([this] { workerLoop(); });
}

Status TileLoader::request(const TileRef& ref, int mip) {
  Job job{ref, mip};
  const CacheKey key = job.key();
  {
    std::lock_guard lock(queueMutex_);
    if (auto it = failed_.find(key); it != failed_.end()) return fail(it->second);
    if (!requested_.insert(key).second) return {};
    requests_.push_back(std::move(job));
    startWorker();
  }
  queueCv_.notify_one();
  return {};
}

void TileLoader::prefetch(std::vector<std::pair<TileRef, int>> levels) {
  std::vector<Job> jobs;
  for (auto& [ref, mip] : levels) {
    Job job{std::move(ref), mip};
    if (!cache_.contains(job.key())) jobs.push_back(std::move(job));
  }
  if (jobs.empty()) return;
  {
    std::lock_guard lock(queueMutex_);
    for (auto& j : jobs) queue_.push_back(std::move(j));
    // Old prefetches are for where the reader was, not where it is: keep the queue short.
    while (queue_.size() > 32) queue_.pop_front();
    startWorker();
  }
  queueCv_.notify_one();
}

void TileLoader::clearRequests() {
  std::lock_guard lock(queueMutex_);
  for (const auto& j : requests_) requested_.erase(j.key());
  requests_.clear();
}

int TileLoader::requestsPending() const {
  std::lock_guard lock(queueMutex_);
  return int(requested_.size());
}

}  // namespace strata::terrain::detail
