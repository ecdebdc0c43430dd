// The store's command-line verbs, run as the real `strata` binary.
#include <gtest/gtest.h>

#include <sys/wait.h>

#include <cstdio>
#include <fstream>

#include <strata/terrain/ingest.hpp>
#include <strata/terrain/synthetic.hpp>

#include "strata_test.hpp"

namespace strata::terrain {
namespace {

namespace fs = std::filesystem;

struct Run {
  int status = -1;
  std::string output;  // stdout and stderr together
};

Run runCli(const std::string& args) {
  Run r;
  const std::string cmd = std::string(STRATA_CLI) + " " + args + " 2>&1";
  FILE* p = popen(cmd.c_str(), "r");
  STRATA_CHECK(p) << cmd;
  char buf[4096];
  size_t n = 0;
  while ((n = fread(buf, 1, sizeof buf, p)) > 0) r.output.append(buf, n);
  const int st = pclose(p);
  r.status = WIFEXITED(st) ? WEXITSTATUS(st) : -1;
  return r;
}

fs::path smallStore() {
  const auto dir = test::tempDir("store");
  gis::Georef g;
  g.width = 128;
  g.height = 64;
  SyntheticScene s;
  s.blockCells = 32;
  IngestOptions o;
  o.metric = {2, 5};
  auto rep = ingest(dir, g, {{{"bedrock", LayerKind::Bedrock, ""}, syntheticReader(s)}}, o);
  STRATA_CHECK(rep.ok()) << rep.message();
  return dir;
}

TEST(StrataCheck, PassesASoundStoreAndNamesACorruptTile) {
  const auto dir = smallStore();
  const auto ok = runCli("check " + dir.string());
  EXPECT_EQ(ok.status, 0) << ok.output;
  EXPECT_NE(ok.output.find("result    OK"), std::string::npos) << ok.output;
  EXPECT_NE(ok.output.find("4 x 2 of 32 cells"), std::string::npos) << ok.output;

  // Flip one byte in the middle of one tile file.
  fs::path victim;
  for (const auto& e : fs::directory_iterator(dir / "tiles")) victim = e.path();
  {
    std::fstream f(victim, std::ios::in | std::ios::out | std::ios::binary);
    const auto at = std::streamoff(fs::file_size(victim) / 2);
    f.seekg(at);
    char c = 0;
    f.read(&c, 1);
    c = char(~c);
    f.seekp(at);
    f.write(&c, 1);
  }
  const auto bad = runCli("check " + dir.string());
  EXPECT_EQ(bad.status, 1) << bad.output;
  EXPECT_NE(bad.output.find(victim.filename().string() + ": checksum mismatch"), std::string::npos) << bad.output;
  EXPECT_NE(bad.output.find("1 corrupt tile"), std::string::npos) << bad.output;

  const auto missing = runCli("check " + (dir / "nothing").string());
  EXPECT_EQ(missing.status, 1);
  EXPECT_NE(missing.output.find("manifest.toml: cannot read"), std::string::npos) << missing.output;
}

}  // namespace
}  // namespace strata::terrain
