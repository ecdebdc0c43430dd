#pragma once
// One writer at a time: an exclusive advisory lock (flock) on a lock file, held as long as the
// object lives, released by the kernel when the process ends however it ends (kill -9 included),
// so a stale lock never blocks the next run. flock locks belong to the open file, so a second
// lock on the same file is refused within one process too.

#include <filesystem>

#include <strata/core/result.hpp>

namespace strata {

class FileLock {
 public:
  /// Takes the lock on `path` (created if missing; its content becomes this process's id)
  /// without waiting. Fails when another holder has it, saying which process when it can
  /// ("... is locked by process 1234"), or when the file cannot be created.
  static Result<FileLock> acquire(const std::filesystem::path& path);

  FileLock() = default;
  FileLock(FileLock&& other) noexcept;
  FileLock& operator=(FileLock&& other) noexcept;
  FileLock(const FileLock&) = delete;
  FileLock& operator=(const FileLock&) = delete;
  ~FileLock();

  bool held() const { return fd_ >= 0; }

 private:
  int fd_ = -1;
};

}  // namespace strata
