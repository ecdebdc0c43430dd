#include <gtest/gtest.h>

#include <map>

#include <strata/render/gl/shader_source.hpp>

namespace strata::render::gl {
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

TEST(ShaderSource, EmbeddedShadersIncludeTheTestKernels) {
  const auto names = embeddedShaderNames();
  EXPECT_NE(std::find(names.begin(), names.end(), "test/reduce.comp"), names.end());
  auto src = loadShader("test/laplacian.comp");
  ASSERT_TRUE(src) << src.message();
  EXPECT_EQ(src->files.at(1), "common/grid.glsl");
  EXPECT_NE(src->text.find("struct GridParams"), std::string::npos);
  EXPECT_FALSE(loadShader("no/such.comp"));
}

}  // namespace
}  // namespace strata::render::gl
