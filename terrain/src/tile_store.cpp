#include <strata/terrain/tile_store.hpp>

#include <fcntl.h>
#include <sys/file.h>
#include <unistd.h>
#include <zlib.h>

#include <algorithm>
#include <bit>
#include <cctype>
#include <cerrno>
#include <charconv>
#include <chrono>
#include <cmath>
#include <condition_variable>
#include <cstring>
#include <deque>
#include <fstream>
#include <list>
#include <mutex>
#include <set>
#include <sstream>
#include <thread>
#include <unordered_map>
#include <unordered_set>

#include <strata/core/files.hpp>
#include <strata/core/log.hpp>
#include <strata/gis/geodesy.hpp>

#include "exr_codec.hpp"
#include "manifest.hpp"

namespace strata::terrain {

namespace fs = std::filesystem;
using gis::Grid;

int chooseTileExp(const std::vector<float>& tileRange, const std::vector<float>& globalRange, int minExp, int maxExp) {
  STRATA_CHECK(minExp <= maxExp) << "minExp " << minExp << " > maxExp " << maxExp;
  double m = 0;
  for (size_t f = 0; f < tileRange.size() && f < globalRange.size(); ++f) {
    const double t = tileRange[f], g = globalRange[f];
    if (!(t > 0) || !(g > 0)) continue;  // also skips NaN: a field without data is not complex
    m = std::max(m, std::min(1.0, t / g));
  }
  const int bins = maxExp - minExp + 1;
  return minExp + std::min(bins - 1, int(std::floor(m * bins)));
}

Grid<float> boxDownsample(const Grid<float>& src, int factor) {
  STRATA_CHECK(factor >= 1 && src.width % factor == 0 && src.height % factor == 0)
      << src.width << "x" << src.height << " by " << factor;
  if (factor == 1) return src;
  Grid<float> out(src.width / factor, src.height / factor, gis::kNoData);
  std::vector<double> sum(size_t(out.width));
  std::vector<int> count(size_t(out.width));
  for (int oy = 0; oy < out.height; ++oy) {
    std::fill(sum.begin(), sum.end(), 0.0);
    std::fill(count.begin(), count.end(), 0);
    for (int y = oy * factor; y < (oy + 1) * factor; ++y) {
      const float* row = &src.data[src.index(0, y)];
      for (int x = 0; x < src.width; ++x) {
        if (!std::isnan(row[x])) {
          sum[size_t(x / factor)] += row[x];
          ++count[size_t(x / factor)];
        }
      }
    }
    for (int ox = 0; ox < out.width; ++ox) {
      if (count[size_t(ox)]) out.at(ox, oy) = float(sum[size_t(ox)] / count[size_t(ox)]);
    }
  }
  return out;
}

Grid<float> replicateUpsample(const Grid<float>& src, int factor) {
  STRATA_CHECK(factor >= 1) << "factor " << factor;
  if (factor == 1) return src;
  Grid<float> out(src.width * factor, src.height * factor);
  for (int y = 0; y < out.height; ++y) {
    for (int x = 0; x < out.width; ++x) out.at(x, y) = src.at(x / factor, y / factor);
  }
  return out;
}

namespace {

// One decoded mip level of one tile: every field at that level.
struct Decoded {
  std::vector<Grid<float>> fields;
  size_t bytes = 0;
};
using DecodedPtr = std::shared_ptr<const Decoded>;

struct CacheKey {
  int tx = 0, ty = 0;
  uint64_t generation = 0;  // a rewritten tile is a new key; stale entries age out
  int mip = 0;
  bool operator==(const CacheKey&) const = default;
};
struct CacheKeyHash {
  size_t operator()(const CacheKey& k) const {
    size_t h = std::hash<uint64_t>()(k.generation);
    h ^= std::hash<int64_t>()((int64_t(k.tx) << 32) ^ (int64_t(k.ty) << 8) ^ k.mip) + 0x9e3779b97f4a7c15ULL + (h << 6);
    return h;
  }
};

// Who decoded a tile: a blocking read on the caller's thread, the neighbour prefetcher, or the
// background loader serving tryReadWindow's requests.
enum class LoadSource { Sync, Prefetch, Request };

// LRU of decoded tile levels under a byte budget. Thread-safe (the loader thread inserts).
class TileCache {
 public:
  explicit TileCache(size_t budget) : budget_(budget) {}

  DecodedPtr lookup(const CacheKey& k) {
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
  bool contains(const CacheKey& k) {
    std::lock_guard lock(m_);
    return map_.count(k) != 0;
  }
  void insert(const CacheKey& k, DecodedPtr tile, LoadSource source) {
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
    // Never evicts the entry just inserted: a caller holds it anyway, through its shared_ptr.
    while (bytes_ > budget_ && lru_.size() > 1) {
      bytes_ -= lru_.back().tile->bytes;
      map_.erase(lru_.back().key);
      lru_.pop_back();
      ++stats_.evictions;
    }
  }
  CacheStats stats() {
    std::lock_guard lock(m_);
    CacheStats s = stats_;
    s.bytes = bytes_;
    return s;
  }
  void resetStats() {
    std::lock_guard lock(m_);
    stats_ = {};
  }
  void clear() {
    std::lock_guard lock(m_);
    lru_.clear();
    map_.clear();
    bytes_ = 0;
  }

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

// What a loader needs to know about a tile, copied so that a background load never reads the
// (user-thread owned) records.
struct TileRef {
  int tx = 0, ty = 0;
  uint64_t generation = 0;
  std::string file;
  uint32_t crc32 = 0;
  uint64_t bytes = 0;
};

Result<std::vector<char>> readTileBytes(const fs::path& dir, const TileRef& ref) {
  std::ifstream in(dir / ref.file, std::ios::binary);
  if (!in) return fail(ref.file + ": missing or unreadable");
  std::vector<char> bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  if (bytes.size() != ref.bytes) {
    return fail(ref.file + ": " + std::to_string(bytes.size()) + " bytes, the manifest says " +
                std::to_string(ref.bytes) + " (truncated or replaced; corrupt tile not used)");
  }
  const uint32_t crc =
      uint32_t(crc32_z(crc32_z(0L, Z_NULL, 0), reinterpret_cast<const Bytef*>(bytes.data()), bytes.size()));
  if (crc != ref.crc32) {
    char msg[96];
    std::snprintf(msg, sizeof msg, ": checksum mismatch (crc32 %08x, manifest %08x); corrupt tile not used", crc,
                  ref.crc32);
    return fail(ref.file + msg);
  }
  return bytes;
}

Result<DecodedPtr> loadTileLevel(const fs::path& dir, const std::vector<std::string>& fieldNames, const TileRef& ref,
                                 int mip, double delayMs) {
  if (delayMs > 0) std::this_thread::sleep_for(std::chrono::duration<double, std::milli>(delayMs));
  STRATA_TRY(auto bytes, readTileBytes(dir, ref));
  STRATA_TRY(auto fields, detail::decodeTileExrLevel(ref.file, bytes, fieldNames, mip));
  auto d = std::make_shared<Decoded>();
  for (const auto& g : fields) d->bytes += g.size() * sizeof(float);
  d->fields = std::move(fields);
  return DecodedPtr(std::move(d));
}

// Writes a tile file through a temporary and a rename, so its name never shows a partial file.
// No fsync per tile (it would dominate an ingest): commit() flushes the whole file system before
// the manifest that names the new tiles is renamed into place.
Status writeTileFile(const fs::path& path, const char* data, size_t size) {
  fs::path tmp = path;
  tmp += ".tmp-" + std::to_string(::getpid());
  const int fd = ::open(tmp.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0644);
  if (fd < 0) return fail(tmp.string() + ": cannot create: " + std::strerror(errno));
  size_t done = 0;
  while (done < size) {
    const ssize_t n = ::write(fd, data + done, size - done);
    if (n < 0) {
      if (errno == EINTR) continue;
      const std::string err = std::strerror(errno);
      ::close(fd);
      return fail(tmp.string() + ": write failed: " + err);
    }
    done += size_t(n);
  }
  if (::close(fd) != 0) return fail(tmp.string() + ": close failed: " + std::strerror(errno));
  if (::rename(tmp.c_str(), path.c_str()) != 0) {
    return fail(path.string() + ": rename from temporary failed: " + std::strerror(errno));
  }
  return {};
}

// fsync of a folder (its entries), or syncfs of its whole file system.
void syncDir(const fs::path& dir, bool wholeFileSystem) {
  const int fd = ::open(dir.c_str(), O_RDONLY | O_DIRECTORY | O_CLOEXEC);
  if (fd >= 0) {
    wholeFileSystem ? ::syncfs(fd) : ::fsync(fd);
    ::close(fd);
  }
}

bool sameValue(float a, float b) { return (std::isnan(a) && std::isnan(b)) || a == b; }

// Parses the digits at s[i..] into v; false when there are none.
bool digits(const std::string& s, size_t& i, uint64_t& v) {
  const size_t start = i;
  v = 0;
  while (i < s.size() && std::isdigit(static_cast<unsigned char>(s[i])) && i - start < 19)
    v = v * 10 + uint64_t(s[i++] - '0');
  return i > start && (i == s.size() || !std::isdigit(static_cast<unsigned char>(s[i])));
}

// Whether `name` (a file in tiles/) is named like a tile of a store, x<X>_y<Y>_g<G>.exr, or a
// writer's temporary of one (.exr.tmp, .exr.tmp-<pid>): the only files commit() may remove.
bool isTileFileName(const std::string& name) {
  size_t i = 0;
  uint64_t v = 0;
  auto lit = [&](const char* l) {
    const size_t n = std::strlen(l);
    if (name.compare(i, n, l) != 0) return false;
    i += n;
    return true;
  };
  if (!lit("x") || !digits(name, i, v) || !lit("_y") || !digits(name, i, v) || !lit("_g") || !digits(name, i, v) ||
      !lit(".exr")) {
    return false;
  }
  if (i == name.size()) return true;
  if (!lit(".tmp")) return false;
  if (i == name.size()) return true;
  return lit("-") && digits(name, i, v) && i == name.size();
}

// Shortest round-trip text of a double.
std::string shortest(double v) {
  char buf[40];
  return std::string(buf, std::to_chars(buf, buf + sizeof buf, v).ptr);
}

constexpr const char* kLockName = "writer.lock";

// The exponent, samples and error of one tile under the store's metric (see fitTile).
struct Fit {
  int exp = 0;
  std::vector<Grid<float>> samples;  // per field, 2^exp a side
  std::vector<float> lo, hi, maxErr, rmsErr;
  std::vector<uint64_t> valid;
  bool empty() const {
    return std::all_of(valid.begin(), valid.end(), [](uint64_t v) { return v == 0; });
  }
};

// Block sums of one field: level j has (F >> j)^2 blocks of 2^j x 2^j base cells, counting only
// cells inside the grid (the tile's first wIn x hIn cells).
struct Pyramid {
  struct Level {
    int n = 0;
    std::vector<double> sum;
    std::vector<uint32_t> cnt;
    std::vector<float> mn, mx;
  };
  std::vector<Level> levels;  // levels[j - 1] is level j (level 0 is the tile itself)
};

Pyramid buildPyramid(const Grid<float>& full, int wIn, int hIn, int top) {
  Pyramid p;
  const int F = full.width;
  for (int j = 1; j <= top; ++j) {
    Pyramid::Level L;
    L.n = F >> j;
    const size_t nb = size_t(L.n) * size_t(L.n);
    L.sum.assign(nb, 0.0);
    L.cnt.assign(nb, 0);
    L.mn.assign(nb, std::numeric_limits<float>::infinity());
    L.mx.assign(nb, -std::numeric_limits<float>::infinity());
    for (int by = 0; by < L.n; ++by) {
      for (int bx = 0; bx < L.n; ++bx) {
        const size_t b = size_t(by) * size_t(L.n) + size_t(bx);
        for (int k = 0; k < 4; ++k) {
          const int cx = 2 * bx + (k & 1), cy = 2 * by + (k >> 1);
          if (j == 1) {
            if (cx >= wIn || cy >= hIn) continue;
            const float v = full.at(cx, cy);
            if (std::isnan(v)) continue;
            L.sum[b] += v;
            ++L.cnt[b];
            L.mn[b] = std::min(L.mn[b], v);
            L.mx[b] = std::max(L.mx[b], v);
          } else {
            const auto& c = p.levels.back();
            const size_t ci = size_t(cy) * size_t(c.n) + size_t(cx);
            if (!c.cnt[ci]) continue;
            L.sum[b] += c.sum[ci];
            L.cnt[b] += c.cnt[ci];
            L.mn[b] = std::min(L.mn[b], c.mn[ci]);
            L.mx[b] = std::max(L.mx[b], c.mx[ci]);
          }
        }
      }
    }
    p.levels.push_back(std::move(L));
  }
  return p;
}

// Base cells of block (bx, by) of side b inside the grid's first wIn x hIn cells.
uint64_t cellsInGrid(int bx, int by, int b, int wIn, int hIn) {
  const int64_t cx = std::clamp<int64_t>(int64_t(wIn) - int64_t(bx) * b, 0, b);
  const int64_t cy = std::clamp<int64_t>(int64_t(hIn) - int64_t(by) * b, 0, b);
  return uint64_t(cx * cy);
}

// The stored sample of a block: the float mean, NaN when it has no data.
float blockSample(const Pyramid::Level& L, size_t b) { return L.cnt[b] ? float(L.sum[b] / L.cnt[b]) : gis::kNoData; }

// Whether level j of every field keeps voids void (no block mixes data and no data inside the
// grid) and, when `tolM` is set, reconstructs every cell within tolM.
bool levelFits(const std::vector<Pyramid>& pyr, int j, int wIn, int hIn, std::optional<double> tolM) {
  if (j == 0) return true;
  for (const auto& p : pyr) {
    const auto& L = p.levels[size_t(j - 1)];
    for (int by = 0; by < L.n; ++by) {
      for (int bx = 0; bx < L.n; ++bx) {
        const size_t b = size_t(by) * size_t(L.n) + size_t(bx);
        if (!L.cnt[b]) continue;
        if (L.cnt[b] != cellsInGrid(bx, by, 1 << j, wIn, hIn)) return false;
        if (tolM) {
          const double m = blockSample(L, b);
          if (std::max(double(L.mx[b]) - m, m - double(L.mn[b])) > *tolM) return false;
        }
      }
    }
  }
  return true;
}

}  // namespace

struct TileStore::Impl {
  fs::path dir;
  detail::Manifest man;
  std::vector<std::string> fieldNames;
  int footprint = 0;
  CacheOptions cacheOptions;
  TileCache cache;

  // The background loader: one thread decoding tile levels into the cache, requests (from
  // tryReadWindow) first, then neighbour prefetches. Locking: the thread reads only `dir`,
  // `fieldNames`, `cacheOptions` (never written after construction), the TileRef copied into
  // its job and `cache` (its own mutex); `requests`, `requested`, `failed`, `queue`, `stopping`
  // and `worker` are guarded by queueMutex. The manifest (`man`) is touched by the user's
  // thread only.
  struct Job {
    TileRef ref;
    int mip = 0;
    CacheKey key() const { return {ref.tx, ref.ty, ref.generation, mip}; }
  };
  mutable std::mutex queueMutex;
  std::condition_variable queueCv;
  std::deque<Job> requests;                                        // tryReadWindow's, in order
  std::unordered_set<CacheKey, CacheKeyHash> requested;            // queued or being decoded
  std::unordered_map<CacheKey, std::string, CacheKeyHash> failed;  // requests that failed, why
  std::deque<Job> queue;                                           // neighbour prefetches
  bool stopping = false;
  std::thread worker;
  int lockFd = -1;  // the writer lock (flock on writer.lock), taken by the first write

  Impl(fs::path d, detail::Manifest m, CacheOptions c)
      : dir(std::move(d)), man(std::move(m)), cacheOptions(c), cache(c.budgetBytes) {
    for (const auto& f : man.desc.fields) fieldNames.push_back(f.name);
    footprint = 1 << man.desc.metric.maxExp;
  }
  ~Impl() {
    {
      std::lock_guard lock(queueMutex);
      stopping = true;
    }
    queueCv.notify_all();
    if (worker.joinable()) worker.join();
    if (lockFd >= 0) ::close(lockFd);  // releases the lock
  }

  int maxExp() const { return man.desc.metric.maxExp; }
  int minExp() const { return man.desc.metric.minExp; }
  size_t nf() const { return fieldNames.size(); }
  TileRecord& rec(int tx, int ty) { return man.tiles[size_t(ty) * size_t(man.tilesX) + size_t(tx)]; }
  TileRef ref(int tx, int ty) {
    const auto& r = rec(tx, ty);
    return {tx, ty, r.generation, r.file, r.crc32, r.bytes};
  }
  Result<DecodedPtr> load(const TileRef& r, int mip) const {
    return loadTileLevel(dir, fieldNames, r, mip, cacheOptions.loadDelayMs);
  }

  void workerLoop() {
    for (;;) {
      Job job;
      bool isRequest = false;
      {
        std::unique_lock lock(queueMutex);
        queueCv.wait(lock, [&] { return stopping || !requests.empty() || !queue.empty(); });
        if (stopping) return;
        isRequest = !requests.empty();
        auto& from = isRequest ? requests : queue;
        job = std::move(from.front());
        from.pop_front();
      }
      const CacheKey key = job.key();
      if (!cache.contains(key)) {
        auto d = load(job.ref, job.mip);
        if (d) {
          cache.insert(key, std::move(*d), isRequest ? LoadSource::Request : LoadSource::Prefetch);
        } else if (isRequest) {
          std::lock_guard lock(queueMutex);
          failed[key] = d.message();
        }
        // A failed prefetch (corrupt tile, file superseded by a commit) is not reported: the
        // demand read of that tile reports it.
      }
      if (isRequest) {
        // Erased after the insert: a reader that finds the key neither cached nor requested
        // asks again, at worst decoding a tile twice, never waiting for one nobody loads.
        std::lock_guard lock(queueMutex);
        requested.erase(key);
      }
    }
  }
  // Precondition: queueMutex held.
  void startWorker() {
    if (!worker.joinable()) worker = std::thread([this] { workerLoop(); });
  }

  // Asks the loader for level `mip` of tile (tx, ty) unless it is already asked for; fails with
  // the loader's message if an earlier request of it failed.
  Status request(int tx, int ty, int mip) {
    Job job{ref(tx, ty), mip};
    const CacheKey key = job.key();
    {
      std::lock_guard lock(queueMutex);
      if (auto it = failed.find(key); it != failed.end()) return fail(it->second);
      if (!requested.insert(key).second) return {};
      requests.push_back(std::move(job));
      startWorker();
    }
    queueCv.notify_one();
    return {};
  }

  void prefetchAround(int tx, int ty, int need) {
    std::vector<Job> jobs;
    for (int dy = -1; dy <= 1; ++dy) {
      for (int dx = -1; dx <= 1; ++dx) {
        if (!dx && !dy) continue;
        int nx = tx + dx;
        const int ny = ty + dy;
        if (man.desc.layout == TileLayout::Global) nx = (nx + man.tilesX) % man.tilesX;
        if (nx < 0 || ny < 0 || nx >= man.tilesX || ny >= man.tilesY || !rec(nx, ny).present) continue;
        const int mip = std::max(0, rec(nx, ny).exp - need);
        if (cache.contains({nx, ny, rec(nx, ny).generation, mip})) continue;
        jobs.push_back({ref(nx, ny), mip});
      }
    }
    if (jobs.empty()) return;
    {
      std::lock_guard lock(queueMutex);
      for (auto& j : jobs) queue.push_back(std::move(j));
      // Old requests are for where the reader was, not where it is: keep the queue short.
      while (queue.size() > 32) queue.pop_front();
      startWorker();
    }
    queueCv.notify_one();
  }

  // The level of tile (tx, ty) closest to resolution 2^need from above (its finest when coarser).
  // With `missing` set (tryReadWindow), a tile level not in RAM is requested instead of read:
  // *missing becomes true and the result is null.
  Result<DecodedPtr> get(int tx, int ty, int need, bool prefetch, bool* missing = nullptr) {
    const auto& r = rec(tx, ty);
    const int mip = std::max(0, r.exp - need);
    const CacheKey key{tx, ty, r.generation, mip};
    if (auto hit = cache.lookup(key)) return hit;
    if (missing) {
      STRATA_TRY_STATUS(request(tx, ty, mip));
      *missing = true;
      return DecodedPtr();
    }
    STRATA_TRY(DecodedPtr d, load(ref(tx, ty), mip));
    cache.insert(key, d, LoadSource::Sync);
    if (prefetch && cacheOptions.prefetch) prefetchAround(tx, ty, need);
    return d;
  }

  // Copies rows [sy, sy+h) x cols [sx, sx+w) of level `lod` (inside the level grid) into dst at (dx, dy).
  Status readRect(int field, int lod, int sx, int sy, int w, int h, Grid<float>& dst, int dx, int dy, bool* missing) {
    const int tileCells = footprint >> lod;
    const int need = maxExp() - lod;
    for (int ty = sy / tileCells; ty <= (sy + h - 1) / tileCells; ++ty) {
      for (int tx = sx / tileCells; tx <= (sx + w - 1) / tileCells; ++tx) {
        const auto& r = rec(tx, ty);
        const int x0 = std::max(sx, tx * tileCells), x1 = std::min(sx + w, (tx + 1) * tileCells);
        const int y0 = std::max(sy, ty * tileCells), y1 = std::min(sy + h, (ty + 1) * tileCells);
        if (!r.present) {
          for (int y = y0; y < y1; ++y) {
            for (int x = x0; x < x1; ++x) dst.at(dx + x - sx, dy + y - sy) = gis::kNoData;
          }
          continue;
        }
        const int rep = r.exp >= need ? 1 : 1 << (need - r.exp);  // piecewise-constant upsampling
        STRATA_TRY(DecodedPtr d, get(tx, ty, need, true, missing));
        if (!d) continue;  // requested: the read is not complete anyway
        const auto& g = d->fields[size_t(field)];
        for (int y = y0; y < y1; ++y) {
          const float* src = &g.data[g.index(0, (y - ty * tileCells) / rep)];
          float* out = &dst.data[dst.index(dx + x0 - sx, dy + y - sy)];
          if (rep == 1) {
            std::copy(src + (x0 - tx * tileCells), src + (x1 - tx * tileCells), out);
          } else {
            const int shift = std::countr_zero(unsigned(rep));  // rep is a power of two
            for (int x = x0; x < x1; ++x) out[x - x0] = src[(x - tx * tileCells) >> shift];
          }
        }
      }
    }
    return {};
  }

  // All fields of tile (tx, ty) at full resolution (footprint^2; NaN where absent).
  Result<std::vector<Grid<float>>> loadFull(int tx, int ty) {
    const auto& r = rec(tx, ty);
    if (!r.present) return std::vector<Grid<float>>(nf(), Grid<float>(footprint, footprint, gis::kNoData));
    STRATA_TRY(DecodedPtr d, get(tx, ty, maxExp(), false));
    std::vector<Grid<float>> out;
    for (const auto& g : d->fields) out.push_back(replicateUpsample(g, 1 << (maxExp() - r.exp)));
    return out;
  }

  // The cells of tile (tx, ty) inside the grid: its first wIn x hIn cells.
  std::pair<int, int> inGrid(int tx, int ty) const {
    return {std::min(footprint, man.desc.georef.width - tx * footprint),
            std::min(footprint, man.desc.georef.height - ty * footprint)};
  }

  // Where tile (tx, ty) belongs, as written into its file and compared by verify(): its place,
  // resolution, the georeference of its first cell and the CRS.
  std::string tileTag(int tx, int ty, int exp) const {
    const auto& g = man.desc.georef;
    const double col = double(tx) * footprint, row = double(ty) * footprint;
    const auto& c = g.transform.c;
    const std::string& crs = g.crsWkt;
    char crc[16];
    std::snprintf(crc, sizeof crc, "%08x",
                  unsigned(crc32_z(crc32_z(0L, Z_NULL, 0), reinterpret_cast<const Bytef*>(crs.data()), crs.size())));
    return "x=" + std::to_string(tx) + " y=" + std::to_string(ty) + " exp=" + std::to_string(exp) +
           " footprint=" + std::to_string(footprint) + " origin=" + shortest(g.transform.x(col, row)) + "," +
           shortest(g.transform.y(col, row)) + " cell=" + shortest(c[1]) + "," + shortest(c[2]) + "," + shortest(c[4]) +
           "," + shortest(c[5]) + " epsg=" + std::to_string(g.epsg.value_or(0)) + " wkt_crc32=" + crc;
  }

  // Fits a tile's full-resolution fields (footprint^2 each; only the first wIn x hIn cells are
  // inside the grid, the rest is ignored) to the metric: the coarsest exponent allowed, its
  // samples (block means), and its error against `full`. Range metric: `keep` supplies the
  // min/max the exponent is chosen from (a resampled tile keeps its source's statistics).
  Fit fit(const std::vector<Grid<float>>& full, int wIn, int hIn, const TileRecord* keep) const {
    Fit f;
    const size_t n = nf();
    f.lo.assign(n, gis::kNoData);
    f.hi.assign(n, gis::kNoData);
    f.valid.assign(n, 0);
    f.maxErr.assign(n, 0.0f);
    f.rmsErr.assign(n, 0.0f);
    for (size_t k = 0; k < n; ++k) {
      float a = std::numeric_limits<float>::infinity(), b = -a;
      for (int y = 0; y < hIn; ++y) {
        for (int x = 0; x < wIn; ++x) {
          const float v = full[k].at(x, y);
          if (std::isnan(v)) continue;
          a = std::min(a, v);
          b = std::max(b, v);
          ++f.valid[k];
        }
      }
      if (f.valid[k]) f.lo[k] = a, f.hi[k] = b;
    }
    if (f.empty()) return f;
    const int top = maxExp() - minExp();  // coarsest level considered
    std::vector<Pyramid> pyr;
    for (size_t k = 0; k < n; ++k) pyr.push_back(buildPyramid(full[k], wIn, hIn, top));
    int j = 0;
    if (man.desc.metric.kind == TileMetric::MaxError) {
      for (j = top; j > 0 && !levelFits(pyr, j, wIn, hIn, man.desc.metric.maxErrorM); --j) {
      }
    } else {
      std::vector<float> range(n);
      for (size_t k = 0; k < n; ++k) range[k] = keep ? keep->maxV[k] - keep->minV[k] : f.hi[k] - f.lo[k];
      j = maxExp() - chooseTileExp(range, evalRange(), minExp(), maxExp());
      while (j > 0 && !levelFits(pyr, j, wIn, hIn, std::nullopt)) --j;
    }
    f.exp = maxExp() - j;
    for (size_t k = 0; k < n; ++k) {
      if (j == 0) {
        Grid<float> g(footprint, footprint, gis::kNoData);
        for (int y = 0; y < hIn; ++y) std::copy_n(&full[k].data[full[k].index(0, y)], wIn, &g.data[g.index(0, y)]);
        f.samples.push_back(std::move(g));
        continue;
      }
      const auto& L = pyr[k].levels[size_t(j - 1)];
      Grid<float> g(L.n, L.n, gis::kNoData);
      double maxE = 0;
      for (size_t b = 0; b < g.data.size(); ++b) {
        g.data[b] = blockSample(L, b);
        if (L.cnt[b]) maxE = std::max({maxE, double(L.mx[b]) - g.data[b], double(g.data[b]) - L.mn[b]});
      }
      double sumSq = 0;
      for (int y = 0; y < hIn; ++y) {
        for (int x = 0; x < wIn; ++x) {
          const float v = full[k].at(x, y);
          if (std::isnan(v)) continue;
          const double e = double(v) - double(g.at(x >> j, y >> j));
          sumSq += e * e;
        }
      }
      f.maxErr[k] = float(maxE);
      f.rmsErr[k] = float(f.valid[k] ? std::sqrt(sumSq / double(f.valid[k])) : 0.0);
      f.samples.push_back(std::move(g));
    }
    if (keep) f.lo = keep->minV, f.hi = keep->maxV;
    return f;
  }

  // Writes a fitted tile (its samples and their mip chain) as a new file for tile (tx, ty).
  Status store(int tx, int ty, Fit f) {
    std::vector<std::vector<Grid<float>>> levels;
    levels.push_back(std::move(f.samples));
    while (levels.back()[0].width > 1) {
      std::vector<Grid<float>> next;
      for (const auto& g : levels.back()) next.push_back(boxDownsample(g, 2));
      levels.push_back(std::move(next));
    }
    const auto bytes = detail::encodeTileExr(fieldNames, levels, tileTag(tx, ty, f.exp));
    auto& r = rec(tx, ty);
    const uint64_t gen = man.nextGeneration++;
    const std::string file = detail::tileFileName(tx, ty, gen);
    STRATA_TRY_STATUS(writeTileFile(dir / file, bytes.data(), bytes.size()));
    r.present = true;
    r.exp = f.exp;
    r.generation = gen;
    r.file = file;
    r.crc32 = uint32_t(crc32_z(crc32_z(0L, Z_NULL, 0), reinterpret_cast<const Bytef*>(bytes.data()), bytes.size()));
    r.bytes = bytes.size();
    r.minV = std::move(f.lo);
    r.maxV = std::move(f.hi);
    r.validCells = std::move(f.valid);
    r.maxErrorM = std::move(f.maxErr);
    r.rmsErrorM = std::move(f.rmsErr);
    return {};
  }

  std::vector<float> evalRange() const {
    std::vector<float> g(nf());
    for (size_t f = 0; f < nf(); ++f) g[f] = man.rangeHi[f] - man.rangeLo[f];
    return g;
  }

  // Per-field min/max over the cells of tile (tx, ty) inside the grid (NaN: none).
  void stats(int tx, int ty, const std::vector<Grid<float>>& fields, std::vector<float>& lo,
             std::vector<float>& hi) const {
    const auto [wIn, hIn] = inGrid(tx, ty);
    lo.assign(fields.size(), gis::kNoData);
    hi.assign(fields.size(), gis::kNoData);
    for (size_t f = 0; f < fields.size(); ++f) {
      float a = std::numeric_limits<float>::infinity(), b = -a;
      for (int y = 0; y < hIn; ++y) {
        for (int x = 0; x < wIn; ++x) {
          const float v = fields[f].at(x, y);
          if (std::isnan(v)) continue;
          a = std::min(a, v);
          b = std::max(b, v);
        }
      }
      if (a <= b) lo[f] = a, hi[f] = b;
    }
  }

  // Stores tile (tx, ty) from its full-resolution fields at the exponent the metric gives.
  // `edit`: the fields are the tile's reconstruction with some cells changed, so its earlier
  // error adds to the new one (a bound). `keep`: resampling (Range metric) from the tile's own
  // reconstruction, keeping its statistics; nothing is written if the exponent stays.
  Status put(int tx, int ty, const std::vector<Grid<float>>& full, bool edit, bool keep = false) {
    STRATA_TRY_STATUS(lockForWriting());
    const auto [wIn, hIn] = inGrid(tx, ty);
    const TileRecord old = rec(tx, ty);
    Fit f = fit(full, wIn, hIn, keep ? &old : nullptr);
    if (f.empty()) {
      rec(tx, ty) = TileRecord{};
      return {};
    }
    if (keep && f.exp == old.exp) return {};
    if (edit && old.present) {
      for (size_t k = 0; k < nf(); ++k) {
        f.maxErr[k] += old.maxErrorM[k];
        f.rmsErr[k] += old.rmsErrorM[k];
      }
    }
    return store(tx, ty, std::move(f));
  }

  // Rewrites a tile whose exponent the Range metric changes, from what it stores (detail it
  // never stored cannot come back); its error bound grows by the resampling's.
  Status resample(int tx, int ty) {
    STRATA_TRY(auto full, loadFull(tx, ty));
    log::debug("terrain") << "tile " << tx << "," << ty << ": resampling from 2^" << rec(tx, ty).exp;
    return put(tx, ty, full, true, true);
  }

  // Sets the evaluation range; under the Range metric every tile not in `skip` whose exponent
  // changes is resampled (the MaxError metric does not depend on it).
  Status applyRange(const std::vector<float>& lo, const std::vector<float>& hi, const std::set<size_t>& skip) {
    bool changed = false;
    for (size_t f = 0; f < nf(); ++f) changed |= !sameValue(lo[f], man.rangeLo[f]) || !sameValue(hi[f], man.rangeHi[f]);
    if (!changed) return {};
    man.rangeLo = lo;
    man.rangeHi = hi;
    if (man.desc.metric.kind != TileMetric::Range) return {};
    const auto g = evalRange();
    for (int ty = 0; ty < man.tilesY; ++ty) {
      for (int tx = 0; tx < man.tilesX; ++tx) {
        const size_t i = size_t(ty) * size_t(man.tilesX) + size_t(tx);
        const auto& r = man.tiles[i];
        if (!r.present || skip.count(i)) continue;
        std::vector<float> range(nf());
        for (size_t f = 0; f < nf(); ++f) range[f] = r.maxV[f] - r.minV[f];
        if (chooseTileExp(range, g, minExp(), maxExp()) != r.exp) STRATA_TRY_STATUS(resample(tx, ty));
      }
    }
    return {};
  }

  // Takes the store's writer lock (once; held until this object is destroyed).
  Status lockForWriting() {
    if (lockFd >= 0) return {};
    const fs::path path = dir / kLockName;
    const int fd = ::open(path.c_str(), O_RDWR | O_CREAT | O_CLOEXEC, 0644);
    if (fd < 0) return fail(path.string() + ": cannot open the writer lock: " + std::strerror(errno));
    if (::flock(fd, LOCK_EX | LOCK_NB) != 0) {
      const int err = errno;
      char buf[32] = {};
      [[maybe_unused]] const ssize_t n = ::pread(fd, buf, sizeof buf - 1, 0);
      ::close(fd);
      if (err == EWOULDBLOCK) {
        std::string holder(buf);
        while (!holder.empty() && (holder.back() == '\n' || holder.back() == ' ')) holder.pop_back();
        return fail(dir.string() + ": another writer holds this store (" +
                    (holder.empty() ? std::string("writer.lock") : "pid " + holder) +
                    "); one writer at a time: wait for it to finish, or stop it");
      }
      return fail(path.string() + ": cannot lock: " + std::strerror(err));
    }
    const std::string pid = std::to_string(::getpid()) + "\n";
    if (::ftruncate(fd, 0) != 0 || ::pwrite(fd, pid.data(), pid.size(), 0) != ssize_t(pid.size())) {
      // The lock holds without the pid; only the message of a refused writer loses it.
      log::debug("terrain") << path.string() << ": cannot record the pid";
    }
    lockFd = fd;
    return {};
  }

  // The union of the tiles' ranges, with `extraLo/Hi` (new stats of tiles in `skip`) instead of
  // the records of the tiles in `skip`.
  void unionRange(const std::set<size_t>& skip, const std::vector<std::vector<float>>& extraLo,
                  const std::vector<std::vector<float>>& extraHi, std::vector<float>& lo, std::vector<float>& hi) {
    lo.assign(nf(), std::numeric_limits<float>::infinity());
    hi.assign(nf(), -std::numeric_limits<float>::infinity());
    auto add = [&](const std::vector<float>& a, const std::vector<float>& b) {
      for (size_t f = 0; f < nf(); ++f) {
        if (std::isnan(a[f])) continue;
        lo[f] = std::min(lo[f], a[f]);
        hi[f] = std::max(hi[f], b[f]);
      }
    };
    for (size_t i = 0; i < man.tiles.size(); ++i) {
      if (man.tiles[i].present && !skip.count(i)) add(man.tiles[i].minV, man.tiles[i].maxV);
    }
    for (size_t k = 0; k < extraLo.size(); ++k) add(extraLo[k], extraHi[k]);
    for (size_t f = 0; f < nf(); ++f) {
      if (lo[f] > hi[f]) lo[f] = hi[f] = gis::kNoData;
    }
  }
};

TileStore::TileStore(std::unique_ptr<Impl> impl) : impl_(std::move(impl)) {}
TileStore::TileStore(TileStore&&) noexcept = default;
TileStore& TileStore::operator=(TileStore&&) noexcept = default;
TileStore::~TileStore() = default;

Result<TileStore> TileStore::create(const fs::path& dir, StoreDesc desc, CacheOptions cache) {
  auto valid = detail::validateDesc(desc);
  if (!valid) return fail(dir.string() + ": " + valid.message());
  std::error_code ec;
  fs::create_directories(dir / "tiles", ec);
  if (ec) return fail(dir.string() + ": cannot create: " + ec.message());
  detail::Manifest m;
  const int footprint = 1 << desc.metric.maxExp;
  m.tilesX = detail::tilesAlong(desc.georef.width, footprint);
  m.tilesY = detail::tilesAlong(desc.georef.height, footprint);
  m.rangeLo.assign(desc.fields.size(), gis::kNoData);
  m.rangeHi.assign(desc.fields.size(), gis::kNoData);
  m.tiles.assign(size_t(m.tilesX) * size_t(m.tilesY), TileRecord{});
  m.state.complete = false;
  m.state.pass = 1;
  m.desc = std::move(desc);
  TileStore s(std::make_unique<Impl>(dir, std::move(m), cache));
  // Locked before looking: two creators of one folder cannot both find it empty.
  STRATA_TRY_STATUS(s.impl_->lockForWriting());
  if (fs::exists(dir / detail::kManifestName, ec)) return fail(dir.string() + ": already holds a tile store");
  for (const auto& e : fs::directory_iterator(dir / "tiles", ec)) {
    if (isTileFileName(e.path().filename().string())) {
      return fail(dir.string() + ": tiles/ holds tile files (" + e.path().filename().string() +
                  ") but there is no manifest: not a store this ingest started; use an empty folder");
    }
  }
  STRATA_TRY_STATUS(s.commit());
  return s;
}

Result<TileStore> TileStore::open(const fs::path& dir, CacheOptions cache, OpenOptions options) {
  const fs::path path = dir / detail::kManifestName;
  std::ifstream in(path, std::ios::binary);
  if (!in) return fail(path.string() + ": cannot read (not a Strata tile store?)");
  std::stringstream text;
  text << in.rdbuf();
  STRATA_TRY(auto m, detail::parseManifest(text.str(), path.string()));
  if (!m.state.complete && !options.allowIncomplete) {
    return fail(dir.string() + ": incomplete store: its ingest stopped in pass " + std::to_string(m.state.pass) +
                " after " + std::to_string(m.state.tilesDone) + " of " + std::to_string(int64_t(m.tilesX) * m.tilesY) +
                " tiles; finish it with `strata ingest --resume` (same arguments)");
  }
  return TileStore(std::make_unique<Impl>(dir, std::move(m), cache));
}

const StoreDesc& TileStore::desc() const { return impl_->man.desc; }
const fs::path& TileStore::dir() const { return impl_->dir; }
int TileStore::width() const { return impl_->man.desc.georef.width; }
int TileStore::height() const { return impl_->man.desc.georef.height; }
int TileStore::footprint() const { return impl_->footprint; }
int TileStore::tilesX() const { return impl_->man.tilesX; }
int TileStore::tilesY() const { return impl_->man.tilesY; }
int TileStore::maxLod() const { return impl_->maxExp(); }
int TileStore::levelWidth(int lod) const { return (width() + (1 << lod) - 1) >> lod; }
int TileStore::levelHeight(int lod) const { return (height() + (1 << lod) - 1) >> lod; }

int TileStore::fieldIndex(const std::string& name) const {
  for (size_t i = 0; i < impl_->fieldNames.size(); ++i) {
    if (impl_->fieldNames[i] == name) return int(i);
  }
  return -1;
}

const TileRecord& TileStore::tile(int tx, int ty) const {
  STRATA_CHECK(tx >= 0 && ty >= 0 && tx < tilesX() && ty < tilesY()) << "tile " << tx << "," << ty;
  return impl_->rec(tx, ty);
}

std::pair<float, float> TileStore::globalRange(int field) const {
  STRATA_CHECK(field >= 0 && size_t(field) < impl_->nf()) << "field " << field;
  return {impl_->man.rangeLo[size_t(field)], impl_->man.rangeHi[size_t(field)]};
}

Result<Grid<float>> TileStore::readWindow(int field, gis::CellRect w, int lod) { return read(field, w, lod, nullptr); }

Result<std::optional<Grid<float>>> TileStore::tryReadWindow(int field, gis::CellRect w, int lod) {
  bool missing = false;
  STRATA_TRY(auto g, read(field, w, lod, &missing));
  if (missing) return std::optional<Grid<float>>();
  return std::optional<Grid<float>>(std::move(g));
}

void TileStore::clearRequests() {
  auto& I = *impl_;
  std::lock_guard lock(I.queueMutex);
  for (const auto& j : I.requests) I.requested.erase(j.key());
  I.requests.clear();
}

int TileStore::requestsPending() const {
  std::lock_guard lock(impl_->queueMutex);
  return int(impl_->requested.size());
}

Result<Grid<float>> TileStore::read(int field, gis::CellRect w, int lod, bool* missing) {
  auto& I = *impl_;
  if (field < 0 || size_t(field) >= I.nf()) return fail(I.dir.string() + ": no field " + std::to_string(field));
  if (lod < 0 || lod > maxLod()) {
    return fail(I.dir.string() + ": level " + std::to_string(lod) + " outside 0.." + std::to_string(maxLod()));
  }
  if (w.width < 0 || w.height < 0) return fail(I.dir.string() + ": window with a negative size");
  Grid<float> out(w.width, w.height, gis::kNoData);
  const int lw = levelWidth(lod), lh = levelHeight(lod);
  if (desc().layout == TileLayout::Planar) {
    const int x0 = std::max(0, w.x), y0 = std::max(0, w.y);
    const int x1 = std::min(lw, w.x + w.width), y1 = std::min(lh, w.y + w.height);
    if (x0 < x1 && y0 < y1)
      STRATA_TRY_STATUS(I.readRect(field, lod, x0, y0, x1 - x0, y1 - y0, out, x0 - w.x, y0 - w.y, missing));
    return out;
  }
  // Global: three bands of rows. Rows above the north pole (y < 0) continue down the meridian
  // half a turn away (row -1-y, longitude + 180); likewise below the south pole. Columns wrap.
  struct Band {
    int outY0, outY1;  // output rows
    bool folded;
  };
  const Band bands[3] = {{std::max(0, -lh - w.y), std::min(w.height, -w.y), true},
                         {std::max(0, -w.y), std::min(w.height, lh - w.y), false},
                         {std::max(0, lh - w.y), std::min(w.height, 2 * lh - w.y), true}};
  for (const auto& b : bands) {
    if (b.outY0 >= b.outY1) continue;
    auto srcRow = [&](int j) {
      const int y = w.y + j;
      return y < 0 ? -1 - y : y >= lh ? 2 * lh - 1 - y : y;
    };
    const int s0 = std::min(srcRow(b.outY0), srcRow(b.outY1 - 1));
    const int rows = b.outY1 - b.outY0;
    const int shift = b.folded ? lw / 2 : 0;
    Grid<float> tmp(w.width, rows, gis::kNoData);
    for (int i = 0; i < w.width;) {
      const int sx = (((w.x + i + shift) % lw) + lw) % lw;
      const int len = std::min(w.width - i, lw - sx);
      STRATA_TRY_STATUS(I.readRect(field, lod, sx, s0, len, rows, tmp, i, 0, missing));
      i += len;
    }
    for (int j = b.outY0; j < b.outY1; ++j) {
      const int tj = srcRow(j) - s0;
      std::copy_n(&tmp.data[tmp.index(0, tj)], w.width, &out.data[out.index(0, j)]);
    }
  }
  return out;
}

Status TileStore::writeWindow(int field, int x, int y, const Grid<float>& values) {
  auto& I = *impl_;
  if (field < 0 || size_t(field) >= I.nf()) return fail(I.dir.string() + ": no field " + std::to_string(field));
  if (x < 0 || y < 0 || x + values.width > width() || y + values.height > height()) {
    return fail(I.dir.string() + ": window " + std::to_string(values.width) + "x" + std::to_string(values.height) +
                " at " + std::to_string(x) + "," + std::to_string(y) + " is not inside the " + std::to_string(width()) +
                "x" + std::to_string(height()) + " grid");
  }
  if (values.size() == 0) return {};
  const int F = I.footprint;
  // 1. The affected tiles at full resolution with the new cells pasted in, and their new ranges.
  std::vector<std::pair<int, int>> tiles;
  std::vector<std::vector<Grid<float>>> merged;
  std::vector<std::vector<float>> los, his;
  std::set<size_t> touched;
  for (int ty = y / F; ty <= (y + values.height - 1) / F; ++ty) {
    for (int tx = x / F; tx <= (x + values.width - 1) / F; ++tx) {
      STRATA_TRY(auto full, I.loadFull(tx, ty));
      auto& g = full[size_t(field)];
      const int x0 = std::max(x, tx * F), x1 = std::min(x + values.width, (tx + 1) * F);
      const int y0 = std::max(y, ty * F), y1 = std::min(y + values.height, (ty + 1) * F);
      for (int yy = y0; yy < y1; ++yy) {
        for (int xx = x0; xx < x1; ++xx) g.at(xx - tx * F, yy - ty * F) = values.at(xx - x, yy - y);
      }
      std::vector<float> lo, hi;
      I.stats(tx, ty, full, lo, hi);
      tiles.emplace_back(tx, ty);
      merged.push_back(std::move(full));
      los.push_back(std::move(lo));
      his.push_back(std::move(hi));
      touched.insert(size_t(ty) * size_t(tilesX()) + size_t(tx));
    }
  }
  // 2. A moved global range re-evaluates every other tile; 3. the affected tiles are stored.
  std::vector<float> lo, hi;
  I.unionRange(touched, los, his, lo, hi);
  STRATA_TRY_STATUS(I.applyRange(lo, hi, touched));
  for (size_t k = 0; k < tiles.size(); ++k) STRATA_TRY_STATUS(I.put(tiles[k].first, tiles[k].second, merged[k], true));
  return {};
}

Status TileStore::putTile(int tx, int ty, const std::vector<Grid<float>>& fields) {
  auto& I = *impl_;
  STRATA_CHECK(tx >= 0 && ty >= 0 && tx < tilesX() && ty < tilesY()) << "tile " << tx << "," << ty;
  STRATA_CHECK(fields.size() == I.nf()) << fields.size() << " fields given, the store has " << I.nf();
  for (const auto& g : fields) {
    STRATA_CHECK(g.width == I.footprint && g.height == I.footprint) << "tile field " << g.width << "x" << g.height;
  }
  return I.put(tx, ty, fields, false);
}

void TileStore::setEvaluationRange(int field, float lo, float hi) {
  STRATA_CHECK(field >= 0 && size_t(field) < impl_->nf()) << "field " << field;
  impl_->man.rangeLo[size_t(field)] = lo;
  impl_->man.rangeHi[size_t(field)] = hi;
}

Status TileStore::reevaluate() {
  std::vector<float> lo, hi;
  impl_->unionRange({}, {}, {}, lo, hi);
  return impl_->applyRange(lo, hi, {});
}

Status TileStore::commit() {
  auto& I = *impl_;
  STRATA_TRY_STATUS(I.lockForWriting());
  const fs::path tiles = I.dir / "tiles";
  // The tile files' data and names reach the disk before the manifest that names them.
  syncDir(tiles, true);
  const std::string text = detail::manifestToToml(I.man);
  STRATA_TRY_STATUS(writeFileAtomic(I.dir / detail::kManifestName, text));
  syncDir(I.dir, false);
  // Superseded tiles, and leftovers of writers that died before their commit: only files named
  // like tiles (or their temporaries); anything else someone put in the folder stays.
  std::set<std::string> live;
  for (const auto& r : I.man.tiles) {
    if (r.present) live.insert(fs::path(r.file).filename().string());
  }
  std::error_code ec;
  for (const auto& e : fs::directory_iterator(tiles, ec)) {
    const std::string name = e.path().filename().string();
    if (e.is_regular_file(ec) && isTileFileName(name) && !live.count(name)) fs::remove(e.path(), ec);
  }
  const std::string tmpPrefix = std::string(detail::kManifestName) + ".tmp";
  for (const auto& e : fs::directory_iterator(I.dir, ec)) {
    if (e.is_regular_file(ec) && e.path().filename().string().rfind(tmpPrefix, 0) == 0) fs::remove(e.path(), ec);
  }
  return {};
}

Status TileStore::lockForWriting() { return impl_->lockForWriting(); }

const BuildState& TileStore::buildState() const { return impl_->man.state; }
void TileStore::setBuildState(BuildState state) { impl_->man.state = std::move(state); }

ErrorSummary TileStore::errorSummary(int field, std::optional<gis::CellRect> w) const {
  STRATA_CHECK(field >= 0 && size_t(field) < impl_->nf()) << "field " << field;
  const int F = footprint();
  int tx0 = 0, ty0 = 0, tx1 = tilesX() - 1, ty1 = tilesY() - 1;
  if (w) {
    tx0 = std::max(0, w->x / F);
    ty0 = std::max(0, w->y / F);
    tx1 = std::min(tilesX() - 1, (w->x + w->width - 1) / F);
    ty1 = std::min(tilesY() - 1, (w->y + w->height - 1) / F);
  }
  ErrorSummary e;
  double sumSq = 0;
  for (int ty = ty0; ty <= ty1; ++ty) {
    for (int tx = tx0; tx <= tx1; ++tx) {
      const auto& r = impl_->rec(tx, ty);
      if (!r.present) continue;
      const auto f = size_t(field);
      e.maxM = std::max(e.maxM, double(r.maxErrorM[f]));
      sumSq += double(r.rmsErrorM[f]) * double(r.rmsErrorM[f]) * double(r.validCells[f]);
      e.cells += r.validCells[f];
    }
  }
  e.rmsM = e.cells ? std::sqrt(sumSq / double(e.cells)) : 0.0;
  return e;
}

std::vector<TileProblem> TileStore::verify() const {
  auto& I = *impl_;
  std::vector<TileProblem> problems;
  const std::string manifest = detail::kManifestName;
  auto problem = [&](const std::string& file, const std::string& message) { problems.push_back({file, message}); };

  // The CRS: parseable, and the manifest's EPSG code, name, kind and body are its own.
  const auto& g = desc().georef;
  if (!g.crsWkt.empty() || g.epsg) {
    auto crs = gis::describeCrs(g.crsWkt.empty() ? "EPSG:" + std::to_string(*g.epsg) : g.crsWkt);
    if (!crs) {
      problem(manifest, manifest + ": georef.crs_wkt does not parse: " + crs.message());
    } else {
      auto differs = [&](const std::string& key, const std::string& have, const std::string& want) {
        problem(manifest, manifest + ": georef." + key + " = " + have + " but crs_wkt says " + want);
      };
      auto epsgText = [](const std::optional<int>& e) { return e ? std::to_string(*e) : std::string("none"); };
      if (!g.crsWkt.empty() && crs->epsg != g.epsg) differs("epsg", epsgText(g.epsg), epsgText(crs->epsg));
      if (!g.crsWkt.empty() && crs->crsName != g.crsName)
        differs("crs_name", "'" + g.crsName + "'", "'" + crs->crsName + "'");
      if (crs->geographic != g.geographic)
        differs("geographic", g.geographic ? "true" : "false", crs->geographic ? "true" : "false");
      if (std::abs(crs->body.semiMajorM - g.body.semiMajorM) > 1e-6 * crs->body.semiMajorM ||
          std::abs(crs->body.flattening - g.body.flattening) > 1e-9) {
        differs("body_semi_major_m / body_flattening",
                shortest(g.body.semiMajorM) + " / " + shortest(g.body.flattening),
                shortest(crs->body.semiMajorM) + " / " + shortest(crs->body.flattening));
      }
    }
  }

  // Every present tile: size, checksum, decoding, its place, its samples against its record.
  std::vector<float> lo(I.nf(), std::numeric_limits<float>::infinity()), hi(I.nf(), -lo[0]);
  std::set<std::string> live;
  for (int ty = 0; ty < tilesY(); ++ty) {
    for (int tx = 0; tx < tilesX(); ++tx) {
      const auto& r = I.rec(tx, ty);
      if (!r.present) continue;
      live.insert(fs::path(r.file).filename().string());
      for (size_t f = 0; f < I.nf(); ++f) {
        if (std::isnan(r.minV[f])) continue;
        lo[f] = std::min(lo[f], r.minV[f]);
        hi[f] = std::max(hi[f], r.maxV[f]);
      }
      const TileRef ref = I.ref(tx, ty);
      auto bytes = readTileBytes(I.dir, ref);
      if (!bytes) {
        problem(r.file, bytes.message());
        continue;
      }
      auto finest = detail::decodeTileExrLevel(r.file, *bytes, I.fieldNames, 0);
      auto coarsest = detail::decodeTileExrLevel(r.file, *bytes, I.fieldNames, r.exp);
      auto tag = detail::decodeTileExrTag(r.file, *bytes);
      if (!finest || !coarsest || !tag) {
        problem(r.file, !finest ? finest.message() : !coarsest ? coarsest.message() : tag.message());
        continue;
      }
      if ((*finest)[0].width != 1 << r.exp || (*coarsest)[0].width != 1) {
        problem(r.file, r.file + ": " + std::to_string((*finest)[0].width) + " samples a side, the manifest says 2^" +
                            std::to_string(r.exp));
        continue;
      }
      if (*tag != I.tileTag(tx, ty, r.exp)) {
        problem(r.file, r.file + ": made for another place or grid (tile says '" + *tag + "', the manifest '" +
                            I.tileTag(tx, ty, r.exp) + "')");
        continue;
      }
      // Samples are block means of cells in [min, max]; each extreme is within the tile's error of
      // some sample; the blocks with data cover exactly the valid cells.
      const int j = maxLod() - r.exp;
      const auto [wIn, hIn] = I.inGrid(tx, ty);
      for (size_t f = 0; f < I.nf(); ++f) {
        const auto& sm = (*finest)[f];
        float smin = std::numeric_limits<float>::infinity(), smax = -smin;
        uint64_t cells = 0;
        for (int y = 0; y < sm.height; ++y) {
          for (int x = 0; x < sm.width; ++x) {
            const float v = sm.at(x, y);
            if (std::isnan(v)) continue;
            smin = std::min(smin, v);
            smax = std::max(smax, v);
            cells += cellsInGrid(x, y, 1 << j, wIn, hIn);
          }
        }
        const std::string what = r.file + ": field '" + I.fieldNames[f] + "': ";
        if (cells != r.validCells[f]) {
          problem(r.file, what + std::to_string(cells) + " cells with data, the manifest says " +
                              std::to_string(r.validCells[f]));
          continue;
        }
        if (!cells) continue;
        const double tol =
            double(r.maxErrorM[f]) + 1e-6 * std::max(std::abs(double(r.maxV[f])), std::abs(double(r.minV[f]))) + 1e-6;
        if (smin < r.minV[f] || smax > r.maxV[f] || double(r.maxV[f]) - smax > tol || double(smin) - r.minV[f] > tol) {
          problem(r.file, what + "samples span " + shortest(smin) + " .. " + shortest(smax) + ", the manifest says " +
                              shortest(r.minV[f]) + " .. " + shortest(r.maxV[f]) + " within " +
                              shortest(r.maxErrorM[f]) + " m");
        }
      }
    }
  }
  for (size_t f = 0; f < I.nf(); ++f) {
    if (lo[f] > hi[f]) lo[f] = hi[f] = gis::kNoData;
    if (!sameValue(lo[f], I.man.rangeLo[f]) || !sameValue(hi[f], I.man.rangeHi[f])) {
      if (buildState().complete) {  // an ingest sets the ranges when it finishes
        problem(manifest, manifest + ": field '" + I.fieldNames[f] + "': range " + shortest(I.man.rangeLo[f]) + " .. " +
                              shortest(I.man.rangeHi[f]) + ", the tiles span " + shortest(lo[f]) + " .. " +
                              shortest(hi[f]));
      }
    }
  }
  // Tile files the manifest does not name for a tile it lists as absent: a deleted entry (its
  // data lost to readers). Other unnamed tile files are harmless leftovers of a writer that died
  // (superseded generations of listed tiles, or uncommitted writes), which its next commit
  // removes.
  std::error_code ec;
  std::vector<std::string> orphans;
  for (const auto& e : fs::directory_iterator(I.dir / "tiles", ec)) {
    const std::string name = e.path().filename().string();
    if (!isTileFileName(name) || name.find(".tmp") != std::string::npos || live.count(name)) continue;
    const auto tx = std::strtoull(name.c_str() + 1, nullptr, 10);
    const auto ty = std::strtoull(name.c_str() + name.find("_y") + 2, nullptr, 10);
    const auto gen = std::strtoull(name.c_str() + name.find("_g") + 2, nullptr, 10);
    const bool listed = tx < uint64_t(tilesX()) && ty < uint64_t(tilesY()) && I.rec(int(tx), int(ty)).present;
    if (!listed && gen < I.man.nextGeneration) orphans.push_back(name);
  }
  std::sort(orphans.begin(), orphans.end());
  for (const auto& o : orphans) {
    problem("tiles/" + o, "tiles/" + o +
                              ": a tile file for a tile the manifest lists as absent (its entry deleted from the "
                              "manifest?); its data is not read");
  }
  return problems;
}

Grid<float> TileStore::resolutionMap() const {
  Grid<float> m(tilesX(), tilesY(), gis::kNoData);
  for (int ty = 0; ty < tilesY(); ++ty) {
    for (int tx = 0; tx < tilesX(); ++tx) {
      if (impl_->rec(tx, ty).present) m.at(tx, ty) = float(impl_->rec(tx, ty).exp);
    }
  }
  return m;
}

StorageFootprint TileStore::footprintStats() const {
  StorageFootprint s;
  const uint64_t nf = impl_->nf();
  s.denseSamples = uint64_t(width()) * uint64_t(height()) * nf;
  for (int ty = 0; ty < tilesY(); ++ty) {
    for (int tx = 0; tx < tilesX(); ++tx) {
      const auto& r = impl_->rec(tx, ty);
      if (!r.present) continue;
      const auto [wIn, hIn] = impl_->inGrid(tx, ty);
      // Samples of block side b covering the wIn x hIn cells inside the grid, level by level.
      auto covering = [&](uint64_t b) { return uint64_t((wIn + b - 1) / b) * uint64_t((hIn + b - 1) / b); };
      uint64_t b = uint64_t(1) << (maxLod() - r.exp);
      s.storedSamples += covering(b) * nf;
      for (int level = r.exp; level >= 0; --level, b *= 2) s.storedWithMips += covering(b) * nf;
      s.fileBytes += r.bytes;
    }
  }
  return s;
}

gis::Georef TileStore::windowGeoref(gis::CellRect window, int lod) const {
  gis::Georef g = desc().georef;
  const double s = double(1 << lod);
  const auto& c = desc().georef.transform.c;
  g.transform.c[0] = c[0] + window.x * s * c[1] + window.y * s * c[2];
  g.transform.c[3] = c[3] + window.x * s * c[4] + window.y * s * c[5];
  g.transform.c[1] = c[1] * s;
  g.transform.c[2] = c[2] * s;
  g.transform.c[4] = c[4] * s;
  g.transform.c[5] = c[5] * s;
  g.width = window.width;
  g.height = window.height;
  return g;
}

Result<LayeredTerrain> TileStore::readTerrain(gis::CellRect window) {
  LayeredTerrain t;
  t.georef = windowGeoref(window, 0);
  t.materials = desc().materials;
  t.bedrockM = Grid<float>(window.width, window.height, 0.0f);
  t.waterM = Grid<float>(window.width, window.height, 0.0f);
  for (size_t f = 0; f < impl_->nf(); ++f) {
    const auto& sf = desc().fields[f];
    STRATA_TRY(auto g, readWindow(int(f), window, 0));
    switch (sf.kind) {
      case LayerKind::Bedrock: t.bedrockM = std::move(g); break;
      case LayerKind::Water: t.waterM = std::move(g); break;
      case LayerKind::Material:
        t.layers.push_back({sf.name, findMaterial(t.materials, sf.material), std::move(g)});
        break;
    }
  }
  return t;
}

CacheStats TileStore::cacheStats() const { return impl_->cache.stats(); }
void TileStore::resetCacheStats() { impl_->cache.resetStats(); }
void TileStore::clearCache() { impl_->cache.clear(); }

}  // namespace strata::terrain
