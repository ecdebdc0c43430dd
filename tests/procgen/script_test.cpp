// Script files and the splicing of user GLSL into the template (no GL needed).
#include <gtest/gtest.h>

#include <fstream>
#include <regex>
#include <sstream>

#include <strata/procgen/script_file.hpp>

#include "strata_test.hpp"

namespace strata::procgen {
namespace {

std::string examplePath(const std::string& name) { return std::string(STRATA_SOURCE_DIR) + "/docs/examples/" + name; }

std::vector<std::string> fileLines(const std::string& path) {
  std::ifstream f(path);
  std::vector<std::string> lines;
  for (std::string l; std::getline(f, l);) lines.push_back(l);
  return lines;
}

// The (file, line) the compiler attributes to each line of a spliced source.
struct Origin {
  int file, line;
};
std::vector<Origin> origins(const std::string& text) {
  std::vector<Origin> out;
  std::istringstream in(text);
  int file = 0, line = 0;
  static const std::regex kLine(R"(^#line (\d+) (\d+))");
  for (std::string l; std::getline(in, l);) {
    std::smatch m;
    if (std::regex_search(l, m, kLine)) {
      line = std::stoi(m[1]) - 1;
      file = std::stoi(m[2]);
      out.push_back({-1, -1});
      continue;
    }
    out.push_back({file, ++line});
  }
  return out;
}

TEST(ProcgenScript, DetectsTheForm) {
  EXPECT_EQ(*detectForm({"a", "float height(vec2 p) { return 0.0; }"}), ScriptForm::Height);
  EXPECT_EQ(*detectForm({"a", "float level( vec2 q , int l ) { return 0.0; }"}), ScriptForm::Level);
  auto neither = detectForm({"mine.toml", "float h(vec2 p) { return 0.0; }"});
  ASSERT_FALSE(neither);
  EXPECT_NE(neither.message().find("mine.toml"), std::string::npos) << neither.message();
  EXPECT_FALSE(detectForm({"a", "float height(vec2 p) {return 0.0;}\nfloat level(vec2 p, int l) {return 0.0;}"}));
}

TEST(ProcgenScript, SplicedUserLinesKeepTheirFileAndLineNumbers) {
  const UserScript script{"mine.toml", "float height(vec2 p) {\n  return 1.0;\n}\n", 12};
  auto src = spliceScript(script, ScriptForm::Height);
  ASSERT_TRUE(src) << src.message();
  ASSERT_FALSE(src->files.empty());
  EXPECT_EQ(src->files.back(), "mine.toml");
  const int userFile = int(src->files.size()) - 1;
  const auto where = origins(src->text);
  std::istringstream in(src->text);
  std::vector<std::string> lines;
  for (std::string l; std::getline(in, l);) lines.push_back(l);
  ASSERT_EQ(lines.size(), where.size());
  // The user's "return 1.0;" is line 13 of mine.toml; the template's main() is where it is in
  // procgen/shaders/generate.comp (numbering resumes after the user's text).
  const auto templateLines = fileLines(std::string(STRATA_SOURCE_DIR) + "/procgen/shaders/generate.comp");
  int templateMain = 0;
  for (size_t i = 0; i < templateLines.size(); ++i) {
    if (templateLines[i].rfind("void main()", 0) == 0) templateMain = int(i) + 1;
  }
  ASSERT_GT(templateMain, 0);
  bool sawReturn = false, sawMain = false;
  for (size_t i = 0; i < lines.size(); ++i) {
    if (lines[i] == "  return 1.0;") {
      sawReturn = true;
      EXPECT_EQ(where[i].file, userFile);
      EXPECT_EQ(where[i].line, 13);
    }
    if (lines[i].rfind("void main()", 0) == 0) {
      sawMain = true;
      EXPECT_EQ(where[i].file, 0);
      EXPECT_EQ(where[i].line, templateMain);
    }
  }
  EXPECT_TRUE(sawReturn && sawMain);
  // The level form defines the switch the template's main() tests.
  auto level = spliceScript({"l.toml", "float level(vec2 p, int l) { return 0.0; }", 1}, ScriptForm::Level);
  ASSERT_TRUE(level);
  EXPECT_NE(level->text.find("#define STRATA_FORM_LEVEL"), std::string::npos);
  EXPECT_EQ(src->text.find("#define STRATA_FORM_LEVEL"), std::string::npos);
}

TEST(ProcgenScript, ExamplesParseWithTheGlslLineNumbersOfTheFile) {
  for (const char* name :
       {"fbm_waves_mountain.toml", "dem_coarse_fbm_detail.toml", "dem_band_blend.toml", "dem_like.toml"}) {
    SCOPED_TRACE(name);
    const std::string path = examplePath(name);
    auto file = loadScriptFile(path);
    ASSERT_TRUE(file) << file.message();
    ASSERT_FALSE(file->layers.empty());
    const auto lines = fileLines(path);
    for (const auto& layer : file->layers) {
      EXPECT_EQ(layer.script.fileName, path);
      // The first GLSL line must be the file line firstLine.
      const std::string first = layer.script.glsl.substr(0, layer.script.glsl.find('\n'));
      ASSERT_GE(layer.script.firstLine, 1);
      EXPECT_EQ(lines[size_t(layer.script.firstLine - 1)], first);
      EXPECT_TRUE(detectForm(layer.script).ok());
    }
    for (const auto& dem : file->demPaths) EXPECT_TRUE(std::filesystem::exists(dem)) << dem;
  }
  auto first = loadScriptFile(examplePath("fbm_waves_mountain.toml"));
  ASSERT_TRUE(first);
  ASSERT_EQ(first->layers.size(), 2u);
  EXPECT_EQ(first->layers[1].name, "sediment");
  ASSERT_TRUE(first->georef.has_value());
  EXPECT_EQ(first->georef->epsg, 32612);
  EXPECT_DOUBLE_EQ(first->georef->originY, 4030000.0);
  EXPECT_DOUBLE_EQ(first->georef->cellSize, 30.0);
  auto like = loadScriptFile(examplePath("dem_like.toml"));
  ASSERT_TRUE(like);
  EXPECT_EQ(like->layers[0].matchDem, 0);
  EXPECT_EQ(like->levels, 5);
  EXPECT_EQ(like->wavelet, procgen::Wavelet::Cdf53);  // the default
}

TEST(ProcgenScript, BadFilesNameTheFileAndTheField) {
  const auto dir = test::tempDir("procgen_script");
  auto check = [&](const std::string& text, const std::string& expected) {
    const auto path = (dir / "bad.toml").string();
    std::ofstream(path) << text;
    auto r = loadScriptFile(path);
    ASSERT_FALSE(r) << text;
    EXPECT_NE(r.message().find("bad.toml"), std::string::npos) << r.message();
    EXPECT_NE(r.message().find(expected), std::string::npos) << r.message();
  };
  check("levels = 3\n", "[[layer]]");
  check("[[layer]]\nname = \"a\"\n", "glsl");
  check("[[layer]]\nname = \"a b\"\nglsl = \"\"\n", "name");
  check("[georef]\nepsg = 4326\norigin = [1.0]\ncell_size = 1.0\n[[layer]]\nname = \"a\"\nglsl = \"\"\n",
        "georef.origin");
  check("[[layer]]\nname = \"a\"\nglsl = \"\"\nmatch_dem = 0\n", "match_dem");
  check("wavelet = \"haar\"\n[[layer]]\nname = \"a\"\nglsl = \"\"\n", "'wavelet'");
  check("levels = [\n", "bad.toml:");
  EXPECT_FALSE(loadScriptFile((dir / "missing.toml").string()));
}

}  // namespace
}  // namespace strata::procgen
