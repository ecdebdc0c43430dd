#include "tile_files.hpp"

#include <fcntl.h>
#include <sys/file.h>
#include <unistd.h>
#include <zlib.h>

#include <cctype>
#include <cerrno>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <iterator>

#include <strata/core/log.hpp>

namespace strata::terrain::detail {

namespace fs = std::filesystem;

uint32_t crc32Of(const char* data, size_t size) {
  return uint32_t(crc32_z(crc32_z(0L, Z_NULL, 0), reinterpret_cast<const Bytef*>(data), size));
}

Result<std::vector<char>> readTileBytes(const fs::path& dir, const TileRef& ref) {
  std::ifstream in(dir / ref.file, std::ios::binary);
  if (!in) return fail(ref.file + ": missing or unreadable");
  std::vector<char> bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  if (bytes.size() != ref.bytes) {
    return fail(ref.file + ": " + std::to_string(bytes.size()) + " bytes, the manifest says " +
                std::to_string(ref.bytes) + " (truncated or replaced; corrupt tile not used)");
  }
  const uint32_t crc = crc32Of(bytes.data(), bytes.size());
  if (crc != ref.crc32) {
    char msg[96];
    std::snprintf(msg, sizeof msg, ": checksum mismatch (crc32 %08x, manifest %08x); corrupt tile not used", crc,
                  ref.crc32);
    return fail(ref.file + msg);
  }
  return bytes;
}

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

void syncDir(const fs::path& dir, bool wholeFileSystem) {
  const int fd = ::open(dir.c_str(), O_RDONLY | O_DIRECTORY | O_CLOEXEC);
  if (fd >= 0) {
    wholeFileSystem ? ::syncfs(fd) : ::fsync(fd);
    ::close(fd);
  }
}

namespace {

// Parses the digits at s[i..] into v; false when there are none.
bool digits(const std::string& s, size_t& i, uint64_t& v) {
  const size_t start = i;
  v = 0;
  while (i < s.size() && std::isdigit(static_cast<unsigned char>(s[i])) && i - start < 19)
    v = v * 10 + uint64_t(s[i++] - '0');
  return i > start && (i == s.size() || !std::isdigit(static_cast<unsigned char>(s[i])));
}

}  // namespace

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

WriterLock::~WriterLock() {
  if (fd_ >= 0) ::close(fd_);  // releases the lock
}

Status WriterLock::take(const fs::path& dir) {
  if (fd_ >= 0) return {};
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
  fd_ = fd;
  return {};
}

}  // namespace strata::terrain::detail
