#include "strata_test.hpp"

#include <gtest/gtest.h>

#include <fcntl.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cerrno>
#include <csignal>
#include <cstdlib>
#include <vector>

#include <strata/core/log.hpp>

#ifndef STRATA_DATA_DIR
#define STRATA_DATA_DIR "../shared/data"
#endif

namespace strata::test {
namespace {
std::vector<std::filesystem::path>& tempDirs() {
  static std::vector<std::filesystem::path> dirs;
  return dirs;
}
}  // namespace

std::string dataPath(const std::string& relative) { return std::string(STRATA_DATA_DIR) + "/" + relative; }

std::filesystem::path outputDir(const std::string& suite) {
  auto dir = std::filesystem::path(STRATA_TEST_OUTPUT_DIR) / suite;
  std::filesystem::create_directories(dir);
  return dir;
}

std::filesystem::path tempDir(const std::string& name) {
  const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
  std::string tag = info ? std::string(info->test_suite_name()) + "." + info->name() : "strata";
  for (char& c : tag) {
    if (c == '/') c = '_';
  }
  auto dir =
      std::filesystem::temp_directory_path() / ("strata-test-" + tag + "-" + name + "-" + std::to_string(::getpid()));
  std::filesystem::remove_all(dir);
  std::filesystem::create_directories(dir);
  tempDirs().push_back(dir);
  return dir;
}

ProgramRun runProgram(const std::vector<std::string>& argv, const std::string& input, bool keepStderr) {
  ProgramRun r;
  int fds[2], in[2];
  if (argv.empty() || ::pipe(fds) != 0) return r;
  if (::pipe(in) != 0) {
    ::close(fds[0]);
    ::close(fds[1]);
    return r;
  }
  std::vector<char*> args;
  for (const auto& a : argv) args.push_back(const_cast<char*>(a.c_str()));
  args.push_back(nullptr);
  const pid_t pid = ::fork();
  if (pid == 0) {
    ::close(fds[0]);
    ::close(in[1]);
    ::dup2(in[0], 0);
    ::dup2(fds[1], 1);
    if (keepStderr) {
      ::dup2(fds[1], 2);
    } else {
      const int devnull = ::open("/dev/null", O_WRONLY);
      ::dup2(devnull, 2);
    }
    ::execvp(args[0], args.data());
    ::_exit(127);
  }
  ::close(fds[1]);
  ::close(in[0]);
  for (size_t at = 0; pid > 0 && at < input.size();) {
    const ssize_t n = ::write(in[1], input.data() + at, input.size() - at);
    if (n > 0) {
      at += size_t(n);
    } else if (errno != EINTR) {
      break;
    }
  }
  ::close(in[1]);
  char buf[4096];
  for (ssize_t n; (n = ::read(fds[0], buf, sizeof buf)) != 0;) {
    if (n > 0) {
      r.output.append(buf, size_t(n));
    } else if (errno != EINTR) {
      break;
    }
  }
  ::close(fds[0]);
  int status = 0;
  if (pid > 0) {
    while (::waitpid(pid, &status, 0) < 0 && errno == EINTR) {
    }
    r.status = WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
  }
  return r;
}

}  // namespace strata::test

int main(int argc, char** argv) {
  ::testing::InitGoogleTest(&argc, argv);
  // A child of runProgram that exits before reading its input fails the write, not the test.
  std::signal(SIGPIPE, SIG_IGN);
  if (!std::getenv("STRATA_LOG")) strata::log::setLevel(strata::log::Level::Warn);
  const int rc = RUN_ALL_TESTS();
  const char* keep = std::getenv("STRATA_KEEP_TMP");
  if (!keep || std::string(keep) != "1") {
    std::error_code ec;
    for (const auto& d : strata::test::tempDirs()) std::filesystem::remove_all(d, ec);
  }
  return rc;
}
