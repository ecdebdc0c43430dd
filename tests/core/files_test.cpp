#include <gtest/gtest.h>
#include <sys/resource.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include <csignal>
#include <fstream>
#include <sstream>

#include <strata/core/file_lock.hpp>
#include <strata/core/files.hpp>
#include <strata/core/memory.hpp>

#include "strata_test.hpp"

namespace strata {
namespace {

std::string slurp(const std::filesystem::path& p) {
  std::ifstream f(p);
  std::stringstream s;
  s << f.rdbuf();
  return s.str();
}

TEST(Files, AtomicWriteReplacesWholeAndLeavesNoTemporary) {
  const auto dir = test::tempDir("atomic");
  const auto target = dir / "series.csv";
  ASSERT_TRUE(writeFileAtomic(target, "old\n"));
  ASSERT_TRUE(writeFileAtomic(target, "new content\n"));
  EXPECT_EQ(slurp(target), "new content\n");
  int entries = 0;
  for ([[maybe_unused]] const auto& e : std::filesystem::directory_iterator(dir)) ++entries;
  EXPECT_EQ(entries, 1) << "a temporary was left behind";
}

TEST(Files, AnInterruptedWriteLeavesTheOldFile) {
  // A writer killed before commitTemporary: the target keeps its earlier content.
  const auto dir = test::tempDir("atomic");
  const auto target = dir / "max_depth.tif";
  ASSERT_TRUE(writeFileAtomic(target, "complete"));
  const auto tmp = temporaryPathFor(target);
  std::ofstream(tmp) << "half";
  EXPECT_EQ(slurp(target), "complete");
  EXPECT_TRUE(commitTemporary(tmp, target));
  EXPECT_EQ(slurp(target), "half");
}

TEST(Files, UnwritableTargetIsAnError) {
  auto s = writeFileAtomic("/nonexistent-dir/x.csv", "x");
  ASSERT_FALSE(s);
  EXPECT_EQ(s.message(), "/nonexistent-dir/x.csv: cannot write: No such file or directory");
}

// Issue 19: SIGXFSZ killed strata silently at the file size limit (ulimit -f). With the signal
// ignored (as the strata program does), the write fails with EFBIG and the message names the file.
TEST(Files, OverTheFileSizeLimitTheMessageNamesTheFile) {
  const auto dir = test::tempDir("fsize");
  const auto target = dir / "checkpoint.bin";
  const auto report = dir / "message.txt";
  const pid_t child = ::fork();
  ASSERT_GE(child, 0);
  if (child == 0) {  // the limit in a child only: gtest's own output must not hit it
    std::signal(SIGXFSZ, SIG_IGN);
    const rlimit limit{4096, 4096};
    ::setrlimit(RLIMIT_FSIZE, &limit);
    const auto s = writeFileAtomic(target, std::string(100000, 'x'));
    std::ofstream(report) << (s ? std::string("written") : s.message());
    ::_exit(0);
  }
  int status = 0;
  ASSERT_EQ(::waitpid(child, &status, 0), child);
  ASSERT_TRUE(WIFEXITED(status)) << "killed by signal " << WTERMSIG(status);
  EXPECT_EQ(slurp(report), target.string() + ": cannot write: File too large");
  EXPECT_FALSE(std::filesystem::exists(target));
  int entries = 0;
  for ([[maybe_unused]] const auto& e : std::filesystem::directory_iterator(dir)) ++entries;
  EXPECT_EQ(entries, 1) << "the temporary was left behind";
}

// One writer: a second lock on the same file is refused, within one process too (flock locks
// belong to the open file), naming the holder; the lock goes with its holder.
// Inputs are stat'ed, never opened, before they are read: a FIFO (whose open waits for a writer),
// a folder or a missing name is refused in a line naming it; a link to a file is a file.
TEST(Files, OnlyRegularFilesAreInputs) {
  const auto dir = test::tempDir("regular");
  std::ofstream(dir / "dem.tif") << "x";
  std::filesystem::create_symlink(dir / "dem.tif", dir / "link.tif");
  ASSERT_EQ(::mkfifo((dir / "fifo.tif").c_str(), 0644), 0);
  EXPECT_TRUE(requireRegularFile(dir / "dem.tif", "a raster file"));
  EXPECT_TRUE(requireRegularFile(dir / "link.tif", "a raster file"));
  EXPECT_EQ(requireRegularFile(dir / "fifo.tif", "a raster file").message(),
            (dir / "fifo.tif").string() + ": is not a regular file (a FIFO, socket or device), not a raster file");
  EXPECT_EQ(requireRegularFile(dir, "a raster file").message(), dir.string() + ": is a directory, not a raster file");
  EXPECT_EQ(requireRegularFile(dir / "nope.tif", "a raster file").message(),
            (dir / "nope.tif").string() + ": no such file");
  EXPECT_FALSE(requireRegularFile("/dev/null", "a colour ramp"));
}

TEST(FileLock, ASecondHolderIsRefusedUntilTheFirstLetsGo) {
  const auto dir = test::tempDir("lock");
  const auto path = dir / "run.lock";
  {
    auto first = FileLock::acquire(path);
    ASSERT_TRUE(first) << first.message();
    EXPECT_TRUE(first->held());
    auto second = FileLock::acquire(path);
    ASSERT_FALSE(second);
    EXPECT_EQ(second.message(), path.string() + ": is locked by process " + std::to_string(::getpid()));
    FileLock moved = std::move(first).value();
    EXPECT_FALSE(FileLock::acquire(path));
  }
  auto again = FileLock::acquire(path);
  EXPECT_TRUE(again) << again.message();
  EXPECT_FALSE(FileLock::acquire("/nonexistent-dir/run.lock"));
}

// A holder killed with SIGKILL leaves no stale lock: the kernel drops it with the process.
TEST(FileLock, AKilledHolderLeavesNoStaleLock) {
  const auto dir = test::tempDir("lock-kill");
  const auto path = dir / "run.lock";
  int ready[2];
  ASSERT_EQ(::pipe(ready), 0);
  const pid_t child = ::fork();
  ASSERT_GE(child, 0);
  if (child == 0) {
    auto lock = FileLock::acquire(path);
    const char c = lock ? 'y' : 'n';
    [[maybe_unused]] auto n = ::write(ready[1], &c, 1);
    ::pause();
    ::_exit(0);
  }
  char c = 0;
  ASSERT_EQ(::read(ready[0], &c, 1), 1);
  ASSERT_EQ(c, 'y');
  auto busy = FileLock::acquire(path);
  ASSERT_FALSE(busy);
  EXPECT_EQ(busy.message(), path.string() + ": is locked by process " + std::to_string(child));
  ::kill(child, SIGKILL);
  ::waitpid(child, nullptr, 0);
  ::close(ready[0]);
  ::close(ready[1]);
  EXPECT_TRUE(FileLock::acquire(path));
}

TEST(Memory, AvailableMemoryIsKnownAndBytesRead) {
  EXPECT_GT(availableMemoryBytes(), uint64_t(1) << 20);
  EXPECT_EQ(formatBytes(512), "512 B");
  EXPECT_EQ(formatBytes(101.6e9), "101.6 GB");
  EXPECT_EQ(formatBytes(8.0 * (1ull << 30)), "8.6 GB");
}

}  // namespace
}  // namespace strata
