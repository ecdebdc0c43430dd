// Issue 19: run folders. One writer at a time; an earlier run's outputs are never mixed with a
// new run's or removed unasked (--resume continues them, --overwrite replaces only the files a
// run writes); a checkpoint belongs to one command and scenario and carries a checksum; a resume
// removes the temporaries of the run that was killed, and its report lists every map and the
// wall time of the whole run.
#include <gtest/gtest.h>

#include <fstream>
#include <sstream>

#include <strata/core/file_lock.hpp>
#include <strata/core/log.hpp>
#include <strata/core/progress.hpp>
#include <strata/scenario/run.hpp>

#include "scenario_fixture.hpp"
#include "strata_test.hpp"

namespace strata::scenario {
namespace {

using namespace test_support;
namespace fs = std::filesystem;

TEST(RunFolder, AnEarlierRunIsNeitherMixedNorRemovedUnasked) {
  const auto dir = strata::test::tempDir("rerun");
  const auto s = writeScenario(dir);
  auto opt = cpuOptions(dir / "run");
  opt.stopAfterIntervals = 1;
  ASSERT_TRUE(runScenario(s, opt));
  // What a user keeps there, and what an earlier erode run left (the issue: a stale
  // terrain_change.tif listed in a new flood's report).
  std::ofstream(opt.outDir / "notes.txt") << "mine";
  std::ofstream(opt.outDir / "maps" / "my_map.tif") << "mine";
  std::ofstream(opt.outDir / "maps" / "terrain_change.tif") << "stale";
  std::ofstream(opt.outDir / "series.csv.tmp-999999-1") << "half";  // of a killed run
  const std::string series = slurp(opt.outDir / "series.csv");

  opt.stopAfterIntervals = -1;
  auto again = runScenario(s, opt);
  ASSERT_FALSE(again);
  EXPECT_EQ(again.message(), opt.outDir.string() +
                                 ": holds the outputs of an earlier run (scenario.toml, series.csv, checkpoint.bin, "
                                 "report.md, ...); continue it with --resume or replace them with --overwrite");
  EXPECT_EQ(slurp(opt.outDir / "series.csv"), series) << "refused, and still something was touched";
  EXPECT_TRUE(fs::exists(opt.outDir / "series.csv.tmp-999999-1")) << "refused, and still something was removed";

  opt.overwrite = true;
  auto replaced = runScenario(s, opt);
  ASSERT_TRUE(replaced) << replaced.message();
  EXPECT_TRUE(replaced->completed);
  EXPECT_EQ(slurp(opt.outDir / "notes.txt"), "mine");
  EXPECT_EQ(slurp(opt.outDir / "maps" / "my_map.tif"), "mine");
  EXPECT_FALSE(fs::exists(opt.outDir / "maps" / "terrain_change.tif"));
  EXPECT_FALSE(fs::exists(opt.outDir / "series.csv.tmp-999999-1"));
  const std::string report = slurp(opt.outDir / "report.md");
  EXPECT_EQ(report.find("terrain_change"), std::string::npos);
  EXPECT_EQ(report.find("my_map"), std::string::npos);
  EXPECT_EQ(readCsv(opt.outDir / "series.csv").size(), 4u);

  // Resume and overwrite at once make no sense.
  opt.resume = true;
  auto both = runScenario(s, opt);
  ASSERT_FALSE(both);
  EXPECT_EQ(both.message(), opt.outDir.string() + ": resume or overwrite a run folder, not both");
}

TEST(RunFolder, ASecondWriterIsRefused) {
  const auto dir = strata::test::tempDir("second-writer");
  const auto s = writeScenario(dir);
  auto opt = cpuOptions(dir / "run");
  fs::create_directories(opt.outDir);
  auto lock = FileLock::acquire(opt.outDir / "run.lock");  // a run in progress
  ASSERT_TRUE(lock) << lock.message();
  FileLock holder = std::move(lock).value();
  auto second = runScenario(s, opt);
  ASSERT_FALSE(second);
  EXPECT_EQ(second.message(), opt.outDir.string() + ": another run is writing into this run folder (" +
                                  (opt.outDir / "run.lock").string() + ": is locked by process " +
                                  std::to_string(::getpid()) + ")");
  EXPECT_FALSE(fs::exists(opt.outDir / "series.csv"));
  holder = {};
  EXPECT_TRUE(runScenario(s, opt));
}

// The checkpoint names the command: `erode --resume` does not continue a flood.
TEST(RunFolder, ErodeDoesNotResumeAFloodsCheckpoint) {
  const auto dir = strata::test::tempDir("erode-resume");
  auto s = writeScenario(dir);
  auto opt = cpuOptions(dir / "run");
  opt.stopAfterIntervals = 2;
  ASSERT_TRUE(runScenario(s, opt));
  auto erode = opt;
  erode.command = "erode";
  erode.resume = true;
  erode.stopAfterIntervals = -1;
  auto resumed = runScenario(s, erode);
  ASSERT_FALSE(resumed);
  EXPECT_EQ(resumed.message(),
            (opt.outDir / "checkpoint.bin").string() + ": written by `strata flood`, not `strata erode`");
  // The flood resumes it.
  auto flood = erode;
  flood.command = "flood";
  auto ok = runScenario(s, flood);
  ASSERT_TRUE(ok) << ok.message();
  EXPECT_TRUE(ok->completed);
}

// One float changed in the checkpoint resumed silently; the checksum refuses it, and a truncated
// or changed-scenario checkpoint too.
TEST(RunFolder, ACorruptedCheckpointIsRefused) {
  const auto dir = strata::test::tempDir("corrupt");
  auto s = writeScenario(dir);
  auto opt = cpuOptions(dir / "run");
  opt.stopAfterIntervals = 2;
  ASSERT_TRUE(runScenario(s, opt));
  const auto path = opt.outDir / "checkpoint.bin";
  const std::string good = slurp(path);
  auto resume = opt;
  resume.resume = true;
  resume.stopAfterIntervals = -1;
  auto resumeWith = [&](const std::string& bytes) {
    std::ofstream(path, std::ios::binary | std::ios::trunc) << bytes;
    return runScenario(s, resume);
  };
  std::string flipped = good;
  flipped[flipped.size() / 2] ^= 0x01;  // one bit of one float of the state
  auto r = resumeWith(flipped);
  ASSERT_FALSE(r);
  EXPECT_EQ(r.message(), path.string() + ": the checkpoint is damaged (its checksum does not match)");
  r = resumeWith(good.substr(0, good.size() - 100));
  ASSERT_FALSE(r);
  EXPECT_EQ(r.message(), path.string() + ": the checkpoint is damaged (its checksum does not match)");
  r = resumeWith("STRATAC1 an old format");
  ASSERT_FALSE(r);
  EXPECT_EQ(r.message(), path.string() + ": not a Strata checkpoint (or one of an older format)");
  // The scenario changed since (read again, as `strata flood --resume` reads it).
  std::ofstream(s.file, std::ios::app) << "# edited\n";
  auto edited = loadScenario(s.file);
  ASSERT_TRUE(edited) << edited.message();
  s = std::move(edited).value();
  r = resumeWith(good);
  ASSERT_FALSE(r);
  EXPECT_EQ(r.message(), path.string() + ": written by a different scenario (the file changed)");
}

// A run killed while writing left its temporaries (checkpoint.bin.tmp-PID-N, 0.9 MB in the
// issue); one resumed after its last interval listed no maps and counted only its own wall time.
TEST(RunFolder, AResumeIsTidyAndItsReportComplete) {
  const auto dir = strata::test::tempDir("resume-tidy");
  const auto s = writeScenario(dir);
  auto opt = cpuOptions(dir / "run");
  auto first = runScenario(s, opt);
  ASSERT_TRUE(first) << first.message();
  // Killed after its last checkpoint, while writing the report and plots.
  fs::remove(opt.outDir / "report.md");
  const std::vector<std::string> leftovers{"checkpoint.bin.tmp-999999-0", "series.csv.tmp-999999-12",
                                           "maps/max_depth.tif.tmp999999", "pictures/peak.png.tmp-999999-3.png",
                                           "plots/water.tmp.png"};
  fs::create_directories(opt.outDir / "pictures");
  fs::create_directories(opt.outDir / "plots");
  for (const auto& f : leftovers) std::ofstream(opt.outDir / f) << "half";
  std::ofstream(opt.outDir / "notes.tmp-1-2") << "mine";  // not a temporary of a run file
  EXPECT_EQ(runFolderTemporaries(opt.outDir).size(), leftovers.size());

  auto resume = opt;
  resume.resume = true;
  auto resumed = runScenario(s, resume);
  ASSERT_TRUE(resumed) << resumed.message();
  EXPECT_TRUE(resumed->completed);
  for (const auto& f : leftovers) EXPECT_FALSE(fs::exists(opt.outDir / f)) << f;
  EXPECT_TRUE(fs::exists(opt.outDir / "notes.tmp-1-2"));
  EXPECT_EQ(resumed->series.size(), 4u);
  const std::string report = slurp(opt.outDir / "report.md");
  for (const char* m : {"max_depth", "max_speed", "arrival_time", "inundation_duration", "final_depth"}) {
    EXPECT_NE(report.find("- `maps/" + std::string(m) + ".tif`"), std::string::npos) << m;
  }
  // The wall time is the whole run's: the first session's (up to its last checkpoint) and this one.
  EXPECT_GE(resumed->wallS, 0.9 * first->wallS);
  EXPECT_NE(report.find(formatDuration(resumed->wallS) + " of wall time"), std::string::npos);

  // Stopped half-way and resumed: the sessions add up.
  const auto dir2 = strata::test::tempDir("resume-wall");
  auto half = cpuOptions(dir2 / "run");
  half.stopAfterIntervals = 2;
  auto part1 = runScenario(s, half);
  ASSERT_TRUE(part1);
  half.stopAfterIntervals = -1;
  half.resume = true;
  auto part2 = runScenario(s, half);
  ASSERT_TRUE(part2);
  EXPECT_TRUE(part2->completed);
  EXPECT_GE(part2->wallS, part1->wallS);
}

// A 50 MB name was repeated in every progress line; lines show at most 60 characters of it.
TEST(RunFolder, AHugeNameIsNotRepeatedInEveryLine) {
  const auto dir = strata::test::tempDir("huge-name");
  std::string text = scenarioText();
  const std::string name(5'000'000, 'n');
  text.replace(text.find("test flood"), 10, name + "\\n\\t\\u001b[31m");
  std::ofstream(dir / "flood.toml") << text;
  auto s = loadScenario(dir / "flood.toml");
  ASSERT_TRUE(s) << s.message();
  EXPECT_EQ(s->name.size(), name.size() + 7);
  auto opt = cpuOptions(dir / "run");
  const auto level = log::level();
  log::setLevel(log::Level::Info);  // the run's log lines and progress lines
  ::testing::internal::CaptureStderr();
  ::testing::internal::CaptureStdout();
  auto run = runScenario(*s, opt);
  const std::string err = ::testing::internal::GetCapturedStderr();
  const std::string out = ::testing::internal::GetCapturedStdout();
  log::setLevel(level);
  ASSERT_TRUE(run) << run.message();
  EXPECT_LT(err.size() + out.size(), 20000u) << err.substr(0, 2000);
  EXPECT_EQ(err.find('\x1b'), std::string::npos) << "a control character of the name reached the terminal";
  EXPECT_NE(err.find(std::string(60, 'n') + "..."), std::string::npos) << err.substr(0, 2000);
  // Issue 33: in report.md the name is whole, its control characters escaped and visible.
  std::ifstream in(dir / "run" / "report.md");
  const std::string report((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  EXPECT_EQ(report.find('\x1b'), std::string::npos) << "a control character of the name reached report.md";
  EXPECT_NE(report.find("# " + name + "  \\u001B[31m\n"), std::string::npos) << report.substr(0, 200);
}

}  // namespace
}  // namespace strata::scenario
