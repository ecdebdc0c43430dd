#pragma once
// Private: what a TileStore holds (its folder, manifest, loader and writer lock) and the steps its
// reads, writes and checks share. tile_store.cpp reads and writes through it; tile_checks.cpp
// checks and summarises what it holds.

#include <algorithm>
#include <charconv>
#include <cmath>
#include <filesystem>
#include <set>
#include <string>
#include <utility>
#include <vector>

#include <strata/terrain/tile_store.hpp>

#include "manifest.hpp"
#include "tile_files.hpp"
#include "tile_fit.hpp"
#include "tile_loader.hpp"

namespace strata::terrain {

namespace detail {

inline bool sameValue(float a, float b) { return (std::isnan(a) && std::isnan(b)) || a == b; }

/// Shortest round-trip text of a double.
inline std::string shortest(double v) {
  char buf[40];
  return std::string(buf, std::to_chars(buf, buf + sizeof buf, v).ptr);
}

}  // namespace detail

struct TileStore::Impl {
  std::filesystem::path dir;
  detail::Manifest man;  ///< touched by the user's thread only
  std::vector<std::string> fieldNames;
  int footprint = 0;
  detail::TileLoader loader;
  detail::WriterLock writerLock;  ///< taken by the first write

  Impl(std::filesystem::path d, detail::Manifest m, CacheOptions c);

  int maxExp() const { return man.desc.metric.maxExp; }
  int minExp() const { return man.desc.metric.minExp; }
  size_t nf() const { return fieldNames.size(); }
  TileRecord& rec(int tx, int ty) { return man.tiles[size_t(ty) * size_t(man.tilesX) + size_t(tx)]; }
  detail::TileRef ref(int tx, int ty) {
    const auto& r = rec(tx, ty);
    return {tx, ty, r.generation, r.file, r.crc32, r.bytes};
  }
  /// The cells of tile (tx, ty) inside the grid: its first wIn x hIn cells.
  std::pair<int, int> inGrid(int tx, int ty) const {
    return {std::min(footprint, man.desc.georef.width - tx * footprint),
            std::min(footprint, man.desc.georef.height - ty * footprint)};
  }
  /// Where tile (tx, ty) belongs, as written into its file and compared by verify(): its place,
  /// resolution, the georeference of its first cell and the CRS.
  std::string tileTag(int tx, int ty, int exp) const;

  // Reading.
  /// The level of tile (tx, ty) closest to resolution 2^need from above (its finest when
  /// coarser). With `missing` set (tryReadWindow), a tile level not in RAM is requested instead
  /// of read: *missing becomes true and the result is null.
  Result<detail::DecodedPtr> get(int tx, int ty, int need, bool prefetch, bool* missing = nullptr);
  void prefetchAround(int tx, int ty, int need);
  /// Copies rows [sy, sy+h) x cols [sx, sx+w) of level `lod` (inside the level grid) into dst at (dx, dy).
  Status readRect(int field, int lod, int sx, int sy, int w, int h, gis::Grid<float>& dst, int dx, int dy,
                  bool* missing);
  /// All fields of tile (tx, ty) at full resolution (footprint^2; NaN where absent).
  Result<std::vector<gis::Grid<float>>> loadFull(int tx, int ty);

  // Writing.
  /// Writes a fitted tile (its samples and their mip chain) as a new file for tile (tx, ty).
  Status store(int tx, int ty, detail::Fit f);
  std::vector<float> evalRange() const;
  /// Per-field min/max over the cells of tile (tx, ty) inside the grid (NaN: none).
  void stats(int tx, int ty, const std::vector<gis::Grid<float>>& fields, std::vector<float>& lo,
             std::vector<float>& hi) const;
  /// Stores tile (tx, ty) from its full-resolution fields at the exponent the metric gives.
  /// `edit`: the fields are the tile's reconstruction with some cells changed, so its earlier
  /// error adds to the new one (a bound). `keep`: resampling (Range metric) from the tile's own
  /// reconstruction, keeping its statistics; nothing is written if the exponent stays.
  Status put(int tx, int ty, const std::vector<gis::Grid<float>>& full, bool edit, bool keep = false);
  /// Rewrites a tile whose exponent the Range metric changes, from what it stores (detail it
  /// never stored cannot come back); its error bound grows by the resampling's.
  Status resample(int tx, int ty);
  /// Sets the evaluation range; under the Range metric every tile not in `skip` whose exponent
  /// changes is resampled (the MaxError metric does not depend on it).
  Status applyRange(const std::vector<float>& lo, const std::vector<float>& hi, const std::set<size_t>& skip);
  /// The union of the tiles' ranges, with `extraLo/Hi` (new stats of tiles in `skip`) instead of
  /// the records of the tiles in `skip`.
  void unionRange(const std::set<size_t>& skip, const std::vector<std::vector<float>>& extraLo,
                  const std::vector<std::vector<float>>& extraHi, std::vector<float>& lo, std::vector<float>& hi);
};

}  // namespace strata::terrain
