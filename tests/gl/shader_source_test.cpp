#include <gtest/gtest.h>

#include <map>

#include <strata/gl/bindings.hpp>
#include <strata/gl/shader_source.hpp>

namespace strata::gl {
namespace {

ShaderFileReader mapReader(std::map<std::string, std::string> files) {
  return [files = std::move(files)](const std::string& p) -> std::optional<std::string> {
    auto it = files.find(p);
    if (it == files.end()) return std::nullopt;
    return it->second;
  };
}

TEST(ShaderSource, ResolvesIncludesOnceWithLineDirectives) {
  auto reader = mapReader({
      {"sim/step.comp", "#version 450\n#include \"../common/a.glsl\"\n#include \"common/b.glsl\"\nvoid main() {}\n"},
      {"common/a.glsl", "#include \"b.glsl\"\nfloat a() { return b(); }\n"},
      {"common/b.glsl", "float b() { return 1.0; }\n"},
  });
  auto src = preprocessShader("sim/step.comp", reader);
  ASSERT_TRUE(src) << src.message();
  EXPECT_EQ(src->files, (std::vector<std::string>{"sim/step.comp", "common/a.glsl", "common/b.glsl"}));
  // b.glsl appears once (include-once), reached from a.glsl relative to its own folder.
  EXPECT_EQ(src->text,
            "#version 450\n#line 2 0\n"
            "#line 1 1\n#line 1 2\nfloat b() { return 1.0; }\n#line 2 1\nfloat a() { return b(); }\n#line 3 0\n"
            "#line 4 0\n"
            "void main() {}\n");
}

TEST(ShaderSource, MissingIncludeNamesTheIncludingFileAndLine) {
  auto reader = mapReader({{"x.comp", "#version 450\n\nvoid f();\n#include \"nope.glsl\"\n"}});
  auto src = preprocessShader("x.comp", reader);
  ASSERT_FALSE(src);
  EXPECT_EQ(src.message(), "x.comp:4: cannot find included file \"nope.glsl\"");
}

TEST(ShaderSource, VersionMustComeFirst) {
  auto src = preprocessShader("x.comp", mapReader({{"x.comp", "void main() {}\n#version 450\n"}}));
  ASSERT_FALSE(src);
  EXPECT_EQ(src.message(), "x.comp:1: the first line must be #version");
}

TEST(ShaderSource, InfoLogMapsSourceNumbersToFiles) {
  const std::vector<std::string> files{"sim/step.comp", "common/grid.glsl"};
  // Mesa's format, then NVIDIA's.
  EXPECT_EQ(mapInfoLog("1:12(5): error: syntax error\n0:3(1): warning: x", files),
            "common/grid.glsl:12(5): error: syntax error\nsim/step.comp:3(1): warning: x\n");
  EXPECT_EQ(mapInfoLog("1(12) : error C0000: syntax error", files),
            "common/grid.glsl:12 : error C0000: syntax error\n");
}

TEST(ShaderSource, DefinesGoRightAfterTheVersionLineAndKeepLineNumbers) {
  const std::vector<ShaderDefine> defines{{"SLOT_A", 3}, {"N_2", -1}};
  // Blank lines before #version (as preprocessShader keeps them): the #line names the line after it.
  EXPECT_EQ(insertDefines("\n#version 450\n#line 3 0\nvoid main() {}\n", defines),
            "\n#version 450\n#define SLOT_A 3\n#define N_2 -1\n#line 3 0\n#line 3 0\nvoid main() {}\n");
  // A source without a #line of its own still maps: line 2 stays line 2.
  EXPECT_EQ(
      insertDefines("#version 450 core\nlayout(binding = SLOT_A) buffer B { int b; };", defines),
      "#version 450 core\n#define SLOT_A 3\n#define N_2 -1\n#line 2 0\nlayout(binding = SLOT_A) buffer B { int b; };");
  // No #version: at the top, numbering from 1.
  EXPECT_EQ(insertDefines("void f();\n", defines), "#define SLOT_A 3\n#define N_2 -1\n#line 1 0\nvoid f();\n");
  EXPECT_EQ(insertDefines("#version 450\nx\n", {}), "#version 450\nx\n");
}

TEST(ShaderSource, BindingTablesBecomeDefines) {
  static constexpr Binding kTable[] = {{"SLOT_STATE", ResourceKind::kStorageBuffer, 6, "State"},
                                       {"SLOT_HEIGHT", ResourceKind::kSampler, 0, "uHeight"}};
  const auto defines = definesFor(kTable);
  ASSERT_EQ(defines.size(), 2u);
  EXPECT_EQ(defines[0].name, "SLOT_STATE");
  EXPECT_EQ(defines[0].value, 6);
  EXPECT_EQ(defines[1].name, "SLOT_HEIGHT");
  EXPECT_EQ(defines[1].value, 0);
}

TEST(ShaderSource, EmbeddedShadersIncludeTheTestKernels) {
  const auto names = embeddedShaderNames();
  EXPECT_NE(std::find(names.begin(), names.end(), "tests/gl/shaders/reduce.comp"), names.end());
  auto src = loadShader("tests/gl/shaders/laplacian.comp");
  ASSERT_TRUE(src) << src.message();
  EXPECT_EQ(src->files.at(1), "tests/gl/shaders/grid.glsl");
  EXPECT_NE(src->text.find("struct GridParams"), std::string::npos);
  EXPECT_FALSE(loadShader("no/such.comp"));
}

}  // namespace
}  // namespace strata::gl
