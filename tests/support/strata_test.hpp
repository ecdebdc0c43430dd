#pragma once
// Test helpers: where the shared real data and the test outputs live; running a program.
#include <chrono>
#include <filesystem>
#include <string>
#include <vector>

namespace strata::test {

/// Seconds of wall time since `t0`.
inline double secondsSince(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

/// ../shared/data/<relative> (compiled in as STRATA_DATA_DIR).
std::string dataPath(const std::string& relative);
/// build/test-output/<suite>/ , created on demand: images and reports a test leaves behind.
std::filesystem::path outputDir(const std::string& suite);
/// A fresh empty temporary folder for this test (removed at exit unless STRATA_KEEP_TMP=1).
std::filesystem::path tempDir(const std::string& name);

/// A program a test ran: its exit status (128 + the signal that ended it; 127: it could not be
/// started) and what it printed, stdout and stderr together.
struct ProgramRun {
  int status = -1;
  std::string output;
};
/// Runs `argv` (argv[0] a path, or a name looked up in PATH) with no shell between: every
/// argument reaches the program as it is, whatever characters a file name holds. `input` goes to
/// its stdin (small: written before the output is read); without `keepStderr` only stdout is kept.
ProgramRun runProgram(const std::vector<std::string>& argv, const std::string& input = {}, bool keepStderr = true);

}  // namespace strata::test
