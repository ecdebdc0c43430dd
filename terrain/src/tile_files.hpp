#pragma once
// Private: a store's files on disk: tile file names, reading a tile's bytes against the manifest's
// size and checksum, writing a file so that its name never shows a partial one, and the writer
// lock.

#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

#include <strata/core/result.hpp>

namespace strata::terrain::detail {

inline constexpr const char* kLockName = "writer.lock";

/// What a reader needs to know about a tile's file, copied so that a background load never reads
/// the (user-thread owned) manifest records.
struct TileRef {
  int tx = 0, ty = 0;
  uint64_t generation = 0;
  std::string file;  ///< relative to the store's folder
  uint32_t crc32 = 0;
  uint64_t bytes = 0;
};

/// zlib's CRC-32 of `size` bytes.
uint32_t crc32Of(const char* data, size_t size);

/// The bytes of a tile's file, checked against the size and checksum the manifest records.
Result<std::vector<char>> readTileBytes(const std::filesystem::path& dir, const TileRef& ref);

/// Writes a file through a temporary and a rename, so its name never shows a partial file. No
/// fsync (it would dominate an ingest): commit() flushes the whole file system before the
/// manifest that names new tiles is renamed into place.
Status writeTileFile(const std::filesystem::path& path, const char* data, size_t size);

/// fsync of a folder (its entries), or syncfs of its whole file system.
void syncDir(const std::filesystem::path& dir, bool wholeFileSystem);

/// Whether `name` (a file in tiles/) is named like a tile of a store, x<X>_y<Y>_g<G>.exr, or a
/// writer's temporary of one (.exr.tmp, .exr.tmp-<pid>): the only files commit() may remove.
bool isTileFileName(const std::string& name);

/// The store's writer lock: an exclusive flock on <dir>/writer.lock holding the writer's pid,
/// taken once and held until this object is destroyed.
class WriterLock {
 public:
  WriterLock() = default;
  WriterLock(const WriterLock&) = delete;
  WriterLock& operator=(const WriterLock&) = delete;
  ~WriterLock();
  /// Takes the lock unless held; fails naming the holder's pid when another writer has it.
  Status take(const std::filesystem::path& dir);

 private:
  int fd_ = -1;
};

}  // namespace strata::terrain::detail
