// Binding slots declared once in C++: defines reach GLSL, the program interface query reports
// every block, sampler and image with its binding, and checkBindings catches a shader that puts a
// resource on another slot than the C++ table.
#include <gtest/gtest.h>

#include <strata/gl/objects.hpp>
#include <strata/gl/state.hpp>

#include "gl_fixture.hpp"

namespace strata::gl {
namespace {

using test::GlTest;

constexpr Binding kTable[] = {
    {"SLOT_VALUES", ResourceKind::kStorageBuffer, 5, "Values"},
    {"SLOT_SCALE", ResourceKind::kUniformBuffer, 2, "Scale"},
    {"SLOT_HEIGHT", ResourceKind::kSampler, 3, "uHeight"},
    {"SLOT_OUT", ResourceKind::kImage, 1, "uOut"},
};

// Line 8 writes through every slot, so none is optimised away.
constexpr const char* kShader =
    "#version 450\n"
    "layout(local_size_x = 1) in;\n"
    "layout(std430, binding = SLOT_VALUES) buffer Values { float values[]; };\n"
    "layout(std140, binding = SLOT_SCALE) uniform Scale { float scale; };\n"
    "layout(binding = SLOT_HEIGHT) uniform sampler2D uHeight;\n"
    "layout(r32f, binding = SLOT_OUT) uniform writeonly image2D uOut;\n"
    "void main() {\n"
    "  values[0] = scale * texelFetch(uHeight, ivec2(0), 0).r; imageStore(uOut, ivec2(0), vec4(values[1]));\n"
    "}\n";

Result<Program> compile(const std::string& text, std::span<const Binding> table) {
  const auto defines = definesFor(table);
  return Program::link({{ShaderStage::kCompute, text, {"probe.comp"}}}, "probe.comp", defines);
}

TEST_F(GlTest, ProgramReportsEachBlockSamplerAndImageWithItsBinding) {
  auto prog = compile(kShader, kTable);
  ASSERT_TRUE(prog) << prog.message();
  auto resources = prog->resources();
  std::sort(resources.begin(), resources.end(), [](const auto& a, const auto& b) { return a.name < b.name; });
  ASSERT_EQ(resources.size(), 4u);
  EXPECT_EQ(resources[0].name, "Scale");
  EXPECT_EQ(resources[0].kind, ResourceKind::kUniformBuffer);
  EXPECT_EQ(resources[0].binding, 2);
  EXPECT_EQ(resources[1].name, "Values");
  EXPECT_EQ(resources[1].kind, ResourceKind::kStorageBuffer);
  EXPECT_EQ(resources[1].binding, 5);
  EXPECT_EQ(resources[2].name, "uHeight");
  EXPECT_EQ(resources[2].kind, ResourceKind::kSampler);
  EXPECT_EQ(resources[2].binding, 3);
  EXPECT_EQ(resources[3].name, "uOut");
  EXPECT_EQ(resources[3].kind, ResourceKind::kImage);
  EXPECT_EQ(resources[3].binding, 1);
  EXPECT_TRUE(checkBindings(*prog, kTable, "probe.comp"));
}

TEST_F(GlTest, DefinedSlotsAreWhereTheKernelReadsAndWrites) {
  // The same program run: the buffer on SLOT_VALUES, the block on SLOT_SCALE, the texture on
  // SLOT_HEIGHT and the image on SLOT_OUT, all bound through the table.
  auto prog = compile(kShader, kTable);
  ASSERT_TRUE(prog) << prog.message();
  const float init[2] = {0.0f, 7.0f}, scale = 3.0f, height = 5.0f;
  Buffer values(sizeof init, init), uniform(16, nullptr);
  uniform.upload(0, sizeof scale, &scale);
  auto tex = Texture::create2D(TextureFormat::kR32F, 1, 1);
  tex.upload(&height);
  auto out = Texture::create2D(TextureFormat::kR32F, 1, 1);
  values.bind(kTable[0]);
  uniform.bind(kTable[1]);
  tex.bind(kTable[2]);
  out.bindImage(kTable[3], Access::kWrite);
  prog->dispatchCovering(1);
  memoryBarrier(Barrier::kBufferUpdate | Barrier::kTextureUpdate);
  EXPECT_EQ(values.read<float>()[0], 15.0f);
  EXPECT_EQ(out.read<float>()[0], 7.0f);
}

TEST_F(GlTest, CheckBindingsNamesAResourceOnTheWrongSlot) {
  // The shader uses SLOT_OUT for the sampler by mistake: both compile, the check says which.
  std::string wrong = kShader;
  wrong.replace(wrong.find("binding = SLOT_HEIGHT"), 21, "binding = SLOT_OUT");
  auto prog = compile(wrong, kTable);
  ASSERT_TRUE(prog) << prog.message();
  const auto status = checkBindings(*prog, kTable, "probe.comp");
  ASSERT_FALSE(status);
  EXPECT_EQ(status.message(), "probe.comp: sampler 'uHeight' is on binding 1, the C++ table declares SLOT_HEIGHT = 3");
  // A resource the table does not list at all.
  auto right = compile(kShader, kTable);
  ASSERT_TRUE(right) << right.message();
  const auto missing = checkBindings(*right, std::span(kTable).first(3), "probe.comp");
  ASSERT_FALSE(missing);
  EXPECT_EQ(missing.message(), "probe.comp: image 'uOut' (binding 1) is not in the C++ binding table");
}

TEST_F(GlTest, CompileErrorsKeepTheirLineWithDefinesInserted) {
  // Line 4 is broken; two defines went in after line 1: the message still says probe.comp:4.
  auto prog = compile("#version 450\nlayout(local_size_x = 1) in;\n\nvoid main() { undeclared = SLOT_OUT; }\n", kTable);
  ASSERT_FALSE(prog);
  EXPECT_NE(prog.message().find("probe.comp:4"), std::string::npos) << prog.message();
}

}  // namespace
}  // namespace strata::gl
