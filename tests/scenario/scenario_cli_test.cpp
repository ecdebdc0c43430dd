// Issue 19 through the `strata` program, as a user (or a terminal) meets it: two floods into
// one run folder, a re-run into a folder with outputs, Ctrl-C while the plots are drawn, the file
// size limit (SIGXFSZ), and render onto an existing file. CPU only: no GL context is needed.
#include <dlfcn.h>
#include <fcntl.h>
#include <gtest/gtest.h>
#include <link.h>
#include <sys/resource.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <csignal>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <functional>
#include <sstream>
#include <thread>
#include <tuple>

#include "scenario_fixture.hpp"
#include "strata_test.hpp"

namespace strata::scenario {
namespace {

using namespace test_support;
namespace fs = std::filesystem;

// `strata ARGS...` in `cwd`, in its own process group (as a terminal's foreground job), its
// output in `log`; with a file size limit when `fsizeBytes` > 0, and `env` ("NAME=value") set;
// `wrapper` (a program and its arguments) runs strata when given.
pid_t spawn(const std::vector<std::string>& args, const fs::path& cwd, const fs::path& log, rlim_t fsizeBytes = 0,
            const std::vector<std::string>& env = {}, const std::vector<std::string>& wrapper = {}) {
  const pid_t pid = ::fork();
  if (pid != 0) return pid;
  for (const auto& e : env) ::putenv(const_cast<char*>(e.c_str()));
  ::setpgid(0, 0);
  if (::chdir(cwd.c_str()) != 0) ::_exit(126);
  const int fd = ::open(log.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
  ::dup2(fd, 1);
  ::dup2(fd, 2);
  if (fsizeBytes > 0) {
    const rlimit limit{fsizeBytes, fsizeBytes};
    ::setrlimit(RLIMIT_FSIZE, &limit);
  }
  std::vector<char*> argv;
  for (const auto& w : wrapper) argv.push_back(const_cast<char*>(w.c_str()));
  argv.push_back(const_cast<char*>(STRATA_CLI));
  for (const auto& a : args) argv.push_back(const_cast<char*>(a.c_str()));
  argv.push_back(nullptr);
  ::execv(argv[0], argv.data());
  ::_exit(127);
}

// The exit code, or 128 + the signal that killed it.
int waitFor(pid_t pid) {
  int status = 0;
  while (::waitpid(pid, &status, 0) < 0 && errno == EINTR) {
  }
  return WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
}

int strata(const std::vector<std::string>& args, const fs::path& cwd, std::string& output, rlim_t fsize = 0,
           const std::vector<std::string>& env = {}, const std::vector<std::string>& wrapper = {}) {
  const auto log = cwd / "strata.log";
  const int code = waitFor(spawn(args, cwd, log, fsize, env, wrapper));
  output = slurp(log);
  return code;
}

bool waitUntil(const std::function<bool()>& ready, double seconds) {
  const auto end = std::chrono::steady_clock::now() + std::chrono::duration<double>(seconds);
  while (std::chrono::steady_clock::now() < end) {
    if (ready()) return true;
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
  }
  return false;
}

// The fixture scenario with the CPU backend (the CLI's default picks GL when there is one).
void writeCpuScenario(const fs::path& dir) {
  std::string text = scenarioText();
  text.replace(text.find("kind = \"flood\""), 14, "kind = \"flood\"\nbackend = \"cpu\"");
  std::ofstream(dir / "flood.toml") << text;
}

// The dam break at 60 m cells on the CPU (~5 s of stepping), an output every `interval`
// ("1 min", "20 min"), as dir/dam.toml.
void writeLongDamBreak(const fs::path& dir, const std::string& interval, const std::string& cell = "60 m") {
  std::string text = damBreakText();
  text.replace(text.find("cell_size = \"600 m\""), 19, "cell_size = \"" + cell + "\"");
  text.replace(text.find("output_interval = \"5 min\""), 25, "output_interval = \"" + interval + "\"");
  text.replace(text.find("kind = \"flood\""), 14, "kind = \"flood\"\nbackend = \"cpu\"");
  std::ofstream(dir / "dam.toml") << text;
}

// Issue 31: `strata check SCENARIO` prints every problem of the file in one pass, in file order,
// each with its line and key (a raster path included), and exits 1; a good file exits 0. A key
// spelt one letter off ("duraton") is reported once, and read on as the key it meant.
TEST(StrataCli, CheckFindsEveryProblemOfAScenarioInOnePass) {
  const auto dir = strata::test::tempDir("cli-check");
  std::string text = scenarioText();
  // Seven mistakes a user makes, top to bottom.
  auto plant = [&](const std::string& from, const std::string& to) {
    const size_t at = text.find(from);
    ASSERT_NE(at, std::string::npos) << from;
    text.replace(at, from.size(), to);
  };
  plant("cell_size = \"600 m\"", "cell_size = \"600 meters\"");               // a unit
  plant("kind = \"flood\"", "kind = \"flod\"");                               // a name
  plant("east = \"closed\"", "east = \"shut\"");                              // a choice
  plant("[20, 20000]]", "[20, -5]]");                                         // a negative discharge
  plant("duration = \"20 min\"", "duraton = \"20 min\"");                     // a typo of a key
  plant("[outputs]\n", "[outputs]\nmaps = [\"max_depth\", \"max_sped\"]\n");  // an unknown map
  text += "[water.rain]\nrate = \"10 mm/h\"\nraster = \"radar.tif\"\n";       // a missing raster
  std::ofstream(dir / "seven.toml") << text;
  std::string out;
  EXPECT_EQ(strata({"check", "seven.toml"}, dir, out), 1) << out;
  std::vector<std::string> lines;
  std::stringstream ss(out);
  for (std::string l; std::getline(ss, l);) {
    if (l.starts_with("strata check: ")) lines.push_back(l);
  }
  const std::vector<std::string> keys{"region.cell_size",           "model.kind",   "model.boundary.east",
                                      "water.inflow[0].hydrograph", "time.duraton", "outputs.maps",
                                      "water.rain.raster"};
  ASSERT_EQ(lines.size(), keys.size()) << out;
  int previous = 0;
  for (size_t i = 0; i < keys.size(); ++i) {
    EXPECT_TRUE(lines[i].starts_with("strata check: seven.toml:")) << lines[i];
    EXPECT_NE(lines[i].find("key '" + keys[i] + "'"), std::string::npos) << lines[i];
    const int line = std::stoi(lines[i].substr(std::string("strata check: seven.toml:").size()));
    EXPECT_GT(line, previous) << "in file order: " << lines[i];
    previous = line;
  }
  EXPECT_NE(out.find("did you mean 'duration'?"), std::string::npos) << out;
  EXPECT_NE(out.find("radar.tif: no such file"), std::string::npos) << out;
  EXPECT_NE(out.find("result    7 problem(s)"), std::string::npos) << out;

  writeCpuScenario(dir);
  EXPECT_EQ(strata({"check", "flood.toml"}, dir, out), 0) << out;
  EXPECT_NE(out.find("result    OK: flood.toml would run"), std::string::npos) << out;
  EXPECT_FALSE(fs::exists(dir / "runs")) << "check runs nothing";
}

// mpirun and its flags, running `np` ranks (what STRATA_MPIEXEC_FLAGS holds, ';'-separated).
std::vector<std::string> mpirun(int np) {
  std::vector<std::string> w{STRATA_MPIEXEC, "-np", std::to_string(np)};
  std::stringstream flags(STRATA_MPIEXEC_FLAGS);
  for (std::string f; std::getline(flags, f, ';');) {
    if (!f.empty()) w.push_back(f);
  }
  return w;
}
// Open MPI as root (containers, CI) needs the first two; harmless otherwise. In the sanitizer
// build the ranks run without LeakSanitizer, as the other multi-rank tests (tests/CMakeLists.txt:
// Open MPI 4.1 keeps its plugins' allocations past MPI_Finalize, in frames no suppression matches).
std::vector<std::string> mpiEnv() {
  const char* asan = std::getenv("ASAN_OPTIONS");
  return {"OMPI_ALLOW_RUN_AS_ROOT=1", "OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1", "OMPI_MCA_mpi_yield_when_idle=1",
          "OMP_NUM_THREADS=1", "ASAN_OPTIONS=" + std::string(asan ? asan : "") + ":detect_leaks=0"};
}

// `mpirun -np 2 strata flood` as a user types it: the same scenario file, the same maps as one
// process, bit for bit; one progress and one "finished" line; the ranks' checkpoint parts; a
// resume without mpirun is refused saying how to resume; other commands are refused over ranks.
TEST(StrataCli, AFloodRunsOverMpiRanks) {
  const auto dir = strata::test::tempDir("cli-mpi");
  writeCpuScenario(dir);
  std::string out;
  ASSERT_EQ(strata({"flood", "flood.toml", "-o", "one", "--no-pictures", "--no-plots"}, dir, out), 0) << out;
  ASSERT_EQ(
      strata({"flood", "flood.toml", "-o", "two", "--no-pictures", "--no-plots"}, dir, out, 0, mpiEnv(), mpirun(2)), 0)
      << out;
  auto count = [&](const std::string& what) {
    size_t n = 0;
    for (size_t at = out.find(what); at != std::string::npos; at = out.find(what, at + 1)) ++n;
    return n;
  };
  EXPECT_EQ(count("finished: two/report.md"), 1u) << out;
  EXPECT_EQ(count("running on 2 MPI ranks"), 1u) << out;
  for (const char* f : {"checkpoint.0-of-2.bin", "checkpoint.1-of-2.bin", "input/base.tif", "report.md"}) {
    EXPECT_TRUE(fs::exists(dir / "two" / f)) << f;
  }
  for (const char* m : {"max_depth", "arrival_time", "final_depth"}) {
    auto a = gis::readDem((dir / "one" / "maps" / (std::string(m) + ".tif")).string(), allowEmpty());
    auto b = gis::readDem((dir / "two" / "maps" / (std::string(m) + ".tif")).string(), allowEmpty());
    ASSERT_TRUE(a && b);
    ASSERT_EQ(a->values.size(), b->values.size());
    EXPECT_EQ(std::memcmp(a->values.data.data(), b->values.data.data(), a->values.size() * sizeof(float)), 0) << m;
  }
  EXPECT_NE(slurp(dir / "two" / "report.md").find("on 2 MPI ranks"), std::string::npos);
  // Resumed by one process: refused, saying how.
  EXPECT_EQ(strata({"flood", "flood.toml", "-o", "two", "--resume", "--no-pictures", "--no-plots"}, dir, out), 1);
  EXPECT_NE(out.find("checkpoint.bin: no checkpoint to resume from (the run was checkpointed on 2 MPI ranks: "
                     "resume it with mpirun -np 2)"),
            std::string::npos)
      << out;
  // Only the run commands spread over ranks; the message comes once.
  EXPECT_EQ(strata({"info", "flood.toml"}, dir, out, 0, mpiEnv(), mpirun(2)), 2) << out;
  EXPECT_EQ(count("strata: only `strata flood` and `strata erode` run over MPI ranks (2 ranks given)"), 1u) << out;
}

// Issue 33: Ctrl-C to `mpirun` left no report. Open MPI's mpirun answers a Ctrl-C (or SIGTERM)
// by sending the ranks SIGTERM and, a second later, SIGKILL, and exits 1 whatever the ranks do
// (orterun's abort path; `mpirun sh -c 'exit 130'` exits 130, the same interrupted exits 1). The
// ranks stop after the step they are in and the lead writes the report before the plots (a
// second and more of matplotlib, which the SIGKILL cut short: no report before); the folder
// resumes.
TEST(StrataCli, CtrlCToMpirunLeavesTheStoppedRunsReport) {
  const auto dir = strata::test::tempDir("cli-mpi-ctrl-c");
  writeLongDamBreak(dir, "1 min");
  const pid_t pid =
      spawn({"flood", "dam.toml", "-o", "run", "--no-pictures"}, dir, dir / "run.log", 0, mpiEnv(), mpirun(2));
  // Two intervals closed (the series has a header and a row per interval).
  ASSERT_TRUE(waitUntil([&] { return readCsv(dir / "run" / "series.csv").size() >= 2; }, 120))
      << slurp(dir / "run.log");
  ASSERT_EQ(::kill(-pid, SIGINT), 0);  // what the terminal does: mpirun's foreground group
  const int code = waitFor(pid);
  const std::string log = slurp(dir / "run.log");
  EXPECT_EQ(code, 1) << log;  // Open MPI's, see above
  EXPECT_NE(log.find("stopping after this interval"), std::string::npos) << log;
  const std::string report = slurp(dir / "run" / "report.md");
  EXPECT_NE(report.find("The run was stopped before the end"), std::string::npos) << log;
  EXPECT_NE(report.find("on 2 MPI ranks"), std::string::npos) << report;
  // The plotting child (its own process group) may outlive the killed lead: wait until no
  // process names the run folder, so that it does not write beside the resume.
  const std::string folder = (dir / "run").string();
  auto plotting = [&] {
    for (const auto& e : fs::directory_iterator("/proc")) {
      if (slurp(e.path() / "cmdline").find(folder) != std::string::npos) return true;
    }
    return false;
  };
  EXPECT_TRUE(waitUntil([&] { return !plotting(); }, 60));
  std::string out;
  EXPECT_EQ(strata({"flood", "dam.toml", "-o", "run", "--resume", "--no-pictures", "--no-plots"}, dir, out, 0, mpiEnv(),
                   mpirun(2)),
            0)
      << out;
  EXPECT_NE(out.find("resuming at"), std::string::npos) << out;
  EXPECT_EQ(slurp(dir / "run" / "report.md").find("stopped before the end"), std::string::npos);
}

// Issue 33: a FIFO named as an input (a DEM to describe, a drape, a scenario's DEM, the scenario
// itself) is refused at once in one line naming it; opening it would wait for a writer forever.
TEST(StrataCli, AFifoGivenAsAnInputIsRefusedAtOnce) {
  const auto dir = strata::test::tempDir("cli-fifo");
  ASSERT_EQ(::mkfifo((dir / "f.tif").c_str(), 0644), 0) << std::strerror(errno);
  std::string text = scenarioText();
  const auto dem = text.find("dem = \"") + 7;
  text.replace(dem, text.find('"', dem) - dem, (dir / "f.tif").string());
  std::ofstream(dir / "fifo-dem.toml") << text;
  ASSERT_EQ(::mkfifo((dir / "fifo.toml").c_str(), 0644), 0) << std::strerror(errno);
  const std::vector<std::vector<std::string>> runs = {
      {"info", "f.tif"},
      {"render", "synthetic:16", "-o", "x.png", "--drape", "f.tif"},
      {"flood", "fifo-dem.toml", "-o", "run", "--no-pictures", "--no-plots"},
      {"flood", "fifo.toml", "-o", "run2", "--no-pictures", "--no-plots"},
  };
  for (const auto& args : runs) {
    const pid_t pid = spawn(args, dir, dir / "fifo.log");
    int status = 0;
    // A FIFO's open never returns without a writer: ending at all is the check. 0.4 s for info in
    // the normal build; the sanitizer build under a loaded machine took over 2 s to start a render.
    const bool ended = waitUntil([&] { return ::waitpid(pid, &status, WNOHANG) == pid; }, 10.0);
    if (!ended) {
      ::kill(pid, SIGKILL);
      waitFor(pid);
    }
    ASSERT_TRUE(ended) << args[0] << " " << args[1] << ": still running after 10 s";
    EXPECT_TRUE(WIFEXITED(status) && WEXITSTATUS(status) != 0) << args[0];
    const std::string out = slurp(dir / "fifo.log");
    const std::string fifo = args[1] == "fifo.toml" ? "fifo.toml" : "f.tif";
    EXPECT_NE(out.find(fifo + ": is not a regular file (a FIFO, socket or device)"), std::string::npos)
        << args[0] << ": " << out;
    EXPECT_EQ(std::count(out.begin(), out.end(), '\n'), 1) << args[0] << ": " << out;
  }
}

TEST(StrataCli, TwoFloodsIntoOneFolderOneIsRefused) {
  const auto dir = strata::test::tempDir("cli-two");
  writeCpuScenario(dir);
  const pid_t first = spawn({"flood", "flood.toml", "-o", "run", "--no-pictures"}, dir, dir / "first.log");
  // The first holds the lock once its file names its process.
  ASSERT_TRUE(waitUntil([&] { return slurp(dir / "run" / "run.lock") == std::to_string(first) + "\n"; }, 60))
      << slurp(dir / "first.log");
  std::string out;
  const int second = strata({"flood", "flood.toml", "-o", "run", "--no-pictures"}, dir, out);
  EXPECT_EQ(second, 1) << out;
  EXPECT_NE(out.find("strata flood: run: another run is writing into this run folder (run/run.lock: is locked by "
                     "process " +
                     std::to_string(first) + ")"),
            std::string::npos)
      << out;
  EXPECT_EQ(waitFor(first), 0) << slurp(dir / "first.log");
  EXPECT_TRUE(fs::exists(dir / "run" / "report.md"));
}

TEST(StrataCli, ARerunIntoAFolderWithOutputsNeedsOverwrite) {
  const auto dir = strata::test::tempDir("cli-rerun");
  writeCpuScenario(dir);
  std::string out;
  ASSERT_EQ(strata({"flood", "flood.toml", "-o", "run", "--no-pictures", "--no-plots"}, dir, out), 0) << out;
  const std::string series = slurp(dir / "run" / "series.csv");
  EXPECT_EQ(strata({"flood", "flood.toml", "-o", "run", "--no-pictures", "--no-plots"}, dir, out), 1);
  EXPECT_NE(out.find("strata flood: run: holds the outputs of an earlier run (scenario.toml, series.csv, "
                     "checkpoint.bin, report.md, ...); continue it with --resume or replace them with --overwrite"),
            std::string::npos)
      << out;
  EXPECT_EQ(slurp(dir / "run" / "series.csv"), series);
  EXPECT_NE(strata({"flood", "flood.toml", "-o", "run", "--resume", "--overwrite"}, dir, out), 0);
  EXPECT_NE(out.find("--resume excludes --overwrite"), std::string::npos) << out;
  EXPECT_EQ(strata({"erode", "flood.toml", "-o", "run", "--resume", "--no-pictures", "--no-plots"}, dir, out), 1);
  EXPECT_NE(out.find("erosion needs loose material"), std::string::npos) << out;
  EXPECT_EQ(strata({"flood", "flood.toml", "-o", "run", "--overwrite", "--no-pictures", "--no-plots"}, dir, out), 0)
      << out;
}

// The plotting child runs in its own process group: a Ctrl-C at the terminal reaches strata
// (which finishes the plots and writes the report), not python in the middle of a plot.
TEST(StrataCli, CtrlCWhilePlotsAreDrawnKeepsTheReport) {
  const auto dir = strata::test::tempDir("cli-ctrl-c");
  writeCpuScenario(dir);
  const pid_t pid = spawn({"flood", "flood.toml", "-o", "run", "--no-pictures"}, dir, dir / "run.log");
  // The plots folder is made just before the first plotting script starts.
  ASSERT_TRUE(waitUntil([&] { return fs::exists(dir / "run" / "plots"); }, 120)) << slurp(dir / "run.log");
  ASSERT_EQ(::kill(-pid, SIGINT), 0);  // what the terminal does: the whole foreground group
  const int code = waitFor(pid);
  const std::string log = slurp(dir / "run.log");
  EXPECT_EQ(code, 0) << log;
  EXPECT_NE(log.find("stopping after this interval"), std::string::npos) << "strata did not get the signal: " << log;
  EXPECT_NE(log.find("finished: run/report.md"), std::string::npos) << log;
  EXPECT_TRUE(fs::exists(dir / "run" / "report.md"));
  EXPECT_TRUE(fs::exists(dir / "run" / "plots" / "water.png"));
  EXPECT_TRUE(fs::exists(dir / "run" / "plots" / "max_depth.png"));
}

// Issue 31: a Ctrl-C before the first output interval ended left a Python traceback (no
// series to plot) and nothing to resume. Now the run's t = 0 state is checkpointed when it
// starts: the report is written, marked stopped, and --resume runs it to the end.
TEST(StrataCli, CtrlCBeforeTheFirstOutputLeavesAResumableRun) {
  const auto dir = strata::test::tempDir("cli-ctrl-c-early");
  // The interval must outlast the wait before the signal many times over: at 60 m cells it took
  // 0.4 s on this 2-core machine once the CPU backend ran only the cells a step reaches, and the
  // run ended before a Ctrl-C sent 0.5 s after it started. At 30 m: 1.8 s (2,391 steps).
  writeLongDamBreak(dir, "20 min", "30 m");
  const pid_t pid = spawn({"flood", "dam.toml", "-o", "run", "--no-pictures"}, dir, dir / "run.log");
  ASSERT_TRUE(waitUntil([&] { return slurp(dir / "run.log").find("running on") != std::string::npos; }, 120))
      << slurp(dir / "run.log");
  std::this_thread::sleep_for(std::chrono::milliseconds(200));
  ASSERT_EQ(::kill(-pid, SIGINT), 0);
  const int code = waitFor(pid);
  const std::string log = slurp(dir / "run.log");
  EXPECT_EQ(code, 130) << log;  // a run the user stopped (128 + SIGINT, the shell's convention)
  EXPECT_NE(log.find("stopped before the first output interval ended: no outputs yet; --resume continues from t = 0"),
            std::string::npos)
      << log;
  EXPECT_EQ(log.find("Traceback"), std::string::npos) << log;
  EXPECT_TRUE(fs::exists(dir / "run" / "checkpoint.bin"));
  const std::string report = slurp(dir / "run" / "report.md");
  EXPECT_NE(report.find("The run was stopped before the end"), std::string::npos) << report;
  EXPECT_NE(report.find("No interval finished."), std::string::npos) << report;

  std::string out;
  EXPECT_EQ(strata({"flood", "dam.toml", "-o", "run", "--resume", "--no-pictures", "--no-plots"}, dir, out), 0) << out;
  EXPECT_NE(out.find("resuming at 0.0 s (interval 0)"), std::string::npos) << out;
  EXPECT_EQ(readCsv(dir / "run" / "series.csv").size(), 1u) << out;
}

// SIGXFSZ killed strata silently at the file size limit; now the write fails and says where.
TEST(StrataCli, OverTheFileSizeLimitTheFileIsNamed) {
  const auto dir = strata::test::tempDir("cli-fsize");
  writeCpuScenario(dir);
  std::string out;
  // 100 KiB: the maps, the series and the outline's GeoPackage (96 KiB) fit, the checkpoint
  // (~100 B a cell, 113 KiB) does not.
  const int code = strata({"flood", "flood.toml", "-o", "run", "--no-pictures", "--no-plots"}, dir, out, 102400);
  EXPECT_EQ(code, 1) << "killed by signal " << code - 128 << ": " << out;
  EXPECT_NE(out.find("strata flood: run/checkpoint.bin: cannot write: File too large"), std::string::npos) << out;
  EXPECT_FALSE(fs::exists(dir / "run" / "checkpoint.bin"));
}

// render -o onto an existing file replaced it silently.
TEST(StrataCli, RenderOntoAnExistingFileNeedsOverwrite) {
  const auto dir = strata::test::tempDir("cli-render");
  std::ofstream(dir / "mine.png") << "mine";
  std::string out;
  EXPECT_EQ(strata({"render", "synthetic:16", "-o", "mine.png"}, dir, out), 1);
  EXPECT_NE(out.find("strata render: mine.png: exists (use --overwrite to replace it)"), std::string::npos) << out;
  std::ofstream(dir / "depth.exr") << "mine";
  EXPECT_EQ(strata({"render", "synthetic:16", "-o", "new.png", "--depth", "depth.exr"}, dir, out), 1);
  EXPECT_NE(out.find("strata render: depth.exr: exists"), std::string::npos) << out;
  std::ofstream(dir / "frame_01.png") << "mine";
  std::ofstream(dir / "keys.txt") << "0 0 100 0 -20\n1 1 100 0 -20\n";
  EXPECT_EQ(strata({"render", "synthetic:16", "--path", "keys.txt", "--frames", "3", "-o", "frame_%02d.png"}, dir, out),
            1);
  EXPECT_NE(out.find("strata render: frame_01.png: exists"), std::string::npos) << out;
  EXPECT_EQ(slurp(dir / "mine.png"), "mine");
  EXPECT_EQ(slurp(dir / "depth.exr"), "mine");
  // Numbers: NaN passed CLI11's range checks (--fov nan crashed with a segmentation fault).
  for (const auto& [option, value, message] : std::vector<std::tuple<std::string, std::string, std::string>>{
           {"--fov", "nan", "--fov nan: not a finite number"},
           {"--height", "inf", "--height inf: not a finite number"},
           {"--exaggeration", "0", "--exaggeration 0: expected 0.001 to 1000"}}) {
    EXPECT_EQ(strata({"render", "synthetic:16", "-o", "x.png", option, value}, dir, out), 1) << option;
    EXPECT_NE(out.find("strata render: " + message), std::string::npos) << out;
  }
  EXPECT_FALSE(fs::exists(dir / "x.png"));
}

// A GL failure is a Strata message naming what was tried: STRATA_EGL_DEVICE=bogus was taken as
// device 0, and a missing libEGL aborted inside libepoxy ("Couldn't open libEGL.so.1", SIGABRT).
TEST(StrataCli, GlFailuresAreStrataMessages) {
  const auto dir = strata::test::tempDir("cli-gl");
  std::string out;
  EXPECT_EQ(strata({"gpu-info"}, dir, out, 0, {"STRATA_EGL_DEVICE=bogus"}), 1) << out;
  EXPECT_NE(out.find("strata gpu-info: egl: STRATA_EGL_DEVICE=bogus: expected auto, surfaceless, an EGL device "
                     "number or gpu:<k>"),
            std::string::npos)
      << out;
  EXPECT_EQ(strata({"gpu-info"}, dir, out, 0, {"STRATA_EGL_DEVICE=99"}), 1) << out;
  EXPECT_NE(out.find("strata gpu-info: egl: STRATA_EGL_DEVICE=99: EGL device 99 asked for, but there"),
            std::string::npos)
      << out;

  // No libEGL: in a user and mount namespace of its own, the library is replaced by an empty file.
  void* egl = ::dlopen("libEGL.so.1", RTLD_LAZY | RTLD_NOLOAD);
  if (!egl) egl = ::dlopen("libEGL.so.1", RTLD_LAZY);
  ASSERT_NE(egl, nullptr) << "this test needs libEGL to hide it";
  link_map* map = nullptr;
  ASSERT_EQ(::dlinfo(egl, RTLD_DI_LINKMAP, &map), 0);
  const std::string lib = fs::canonical(map->l_name).string();
  if (strata({}, dir, out, 0, {}, {"/usr/bin/unshare", "-rm", "true"}) != 0) {
    GTEST_SKIP() << "no unprivileged user namespaces here (unshare -rm): " << out;
  }
  const std::vector<std::string> hidden{"/usr/bin/unshare", "-rm", "/bin/sh", "-c",
                                        "mount --bind /dev/null '" + lib + "' && exec \"$0\" \"$@\""};
  EXPECT_EQ(strata({"gpu-info"}, dir, out, 0, {}, hidden), 1) << out;
  EXPECT_NE(out.find("strata gpu-info: egl: cannot load libEGL.so.1 ("), std::string::npos) << out;
  EXPECT_NE(out.find("install libegl1"), std::string::npos) << out;
  // A flood on the CPU without pictures needs no GL at all; with pictures the message says why.
  writeCpuScenario(dir);
  EXPECT_EQ(strata({"flood", "flood.toml", "-o", "run", "--no-plots"}, dir, out, 0, {}, hidden), 1) << out;
  EXPECT_NE(out.find("pictures need a GL 4.5 context (run with --no-pictures without one): egl: cannot load "
                     "libEGL.so.1"),
            std::string::npos)
      << out;
  EXPECT_EQ(strata({"flood", "flood.toml", "-o", "run", "--no-plots", "--no-pictures"}, dir, out, 0, {}, hidden), 0)
      << out;
}

}  // namespace
}  // namespace strata::scenario
