#include <strata/core/files.hpp>

#include <fcntl.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <cerrno>
#include <cstdio>
#include <cstring>

namespace strata {

Status requireRegularFile(const std::filesystem::path& path, std::string_view what) {
  std::error_code ec;
  const auto st = std::filesystem::status(path, ec);
  if (!std::filesystem::exists(st)) return fail(path.string() + ": no such file");
  if (std::filesystem::is_directory(st)) return fail(path.string() + ": is a directory, not " + std::string(what));
  if (!std::filesystem::is_regular_file(st)) {
    return fail(path.string() + ": is not a regular file (a FIFO, socket or device), not " + std::string(what));
  }
  return {};
}

std::filesystem::path temporaryPathFor(const std::filesystem::path& target) {
  static std::atomic<int> counter{0};
  auto tmp = target;
  tmp += ".tmp-" + std::to_string(::getpid()) + "-" + std::to_string(counter++);
  return tmp;
}

bool isTemporaryNameOf(std::string_view name, std::string_view file) {
  if (!name.starts_with(file) || !name.substr(file.size()).starts_with(".tmp-")) return false;
  const std::string_view rest = name.substr(file.size() + 5);
  auto digits = [](std::string_view v) {
    return !v.empty() && std::all_of(v.begin(), v.end(), [](char c) { return c >= '0' && c <= '9'; });
  };
  const auto dash = rest.find('-');
  return dash != std::string_view::npos && digits(rest.substr(0, dash)) && digits(rest.substr(dash + 1));
}

Status commitTemporary(const std::filesystem::path& temporary, const std::filesystem::path& target) {
  const int fd = ::open(temporary.c_str(), O_RDONLY);
  if (fd < 0)
    return fail(target.string() + ": cannot reopen temporary " + temporary.string() + ": " + std::strerror(errno));
  const bool synced = ::fsync(fd) == 0;
  ::close(fd);
  if (!synced || std::rename(temporary.c_str(), target.c_str()) != 0) {
    const std::string why = std::strerror(errno);
    std::error_code ec;
    std::filesystem::remove(temporary, ec);
    return fail(target.string() + ": cannot write: " + why);
  }
  // Make the rename itself durable.
  if (const int dir = ::open(target.parent_path().empty() ? "." : target.parent_path().c_str(), O_RDONLY); dir >= 0) {
    ::fsync(dir);
    ::close(dir);
  }
  return {};
}

Status writeFileAtomic(const std::filesystem::path& target, std::string_view content) {
  const auto tmp = temporaryPathFor(target);
  FILE* f = std::fopen(tmp.c_str(), "wb");
  if (!f) return fail(target.string() + ": cannot write: " + std::strerror(errno));
  const bool ok = std::fwrite(content.data(), 1, content.size(), f) == content.size();
  int err = ok ? 0 : errno;
  const bool closed = std::fclose(f) == 0;
  if (!closed && err == 0) err = errno;
  if (!ok || !closed) {
    std::error_code ec;
    std::filesystem::remove(tmp, ec);
    // ENOSPC: the disk is full; EFBIG: over the file size limit (ulimit -f; SIGXFSZ is ignored).
    return fail(target.string() + ": cannot write: " + (err ? std::strerror(err) : "disk full?"));
  }
  return commitTemporary(tmp, target);
}

}  // namespace strata
