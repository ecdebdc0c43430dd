// The GL backend's buffer layouts agree with sim/shaders/sim.glsl: the GLSL structs are laid
// out by the std430 rules and compared with the C++ mirrors field by field (no GL needed).
#include <gtest/gtest.h>

#include <strata/sim/bookkeeping.hpp>
#include <strata/sim/gl/gl_layout.hpp>

#include "glsl_layout.hpp"

namespace strata::test {
namespace {

// The GL backend's std430 blocks (sim/gl/gl_layout.hpp, sim/bookkeeping.hpp) against
// sim/shaders/sim.glsl.
template <class T>
void expectSimLayout(const std::string& name, const std::vector<Field>& cpp, const char* file = "sim.glsl") {
  size_t size = 0;
  const auto fields = glslLayout(std::string(STRATA_SOURCE_DIR) + "/sim/shaders/" + file, name, size);
  ASSERT_EQ(fields.size(), cpp.size()) << name;
  for (size_t i = 0; i < cpp.size(); ++i) {
    EXPECT_EQ(fields[i].name, cpp[i].name) << name;
    EXPECT_EQ(fields[i].offset, cpp[i].offset) << name << "." << cpp[i].name;
  }
  EXPECT_EQ(size, sizeof(T)) << name;
}

#define STRATA_FIELD(T, f) \
  Field { #f, offsetof(T, f) }

// W35's per-source share of a point-source entry (sim_clock.glsl; GpuClock's offsets are pinned
// by static_asserts in gl_layout.hpp).
TEST(GpuLayouts, ClockTermMatchesGlsl) {
  using strata::sim::GpuTerm;
  expectSimLayout<GpuTerm>(
      "Term",
      {STRATA_FIELD(GpuTerm, entry), STRATA_FIELD(GpuTerm, first), STRATA_FIELD(GpuTerm, count),
       STRATA_FIELD(GpuTerm, pad), STRATA_FIELD(GpuTerm, cellCount), STRATA_FIELD(GpuTerm, areaM2)},
      "sim_clock.glsl");
}

TEST(GpuLayouts, SimParamsMatchesGlsl) {
  using SimParams = strata::sim::GpuSimParams;
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
                                           STRATA_FIELD(SimParams, erosionLaw),
                                           STRATA_FIELD(SimParams, waterDensityKgM3),
                                           STRATA_FIELD(SimParams, bankFillShare),
                                           STRATA_FIELD(SimParams, slopeLimiter),
                                           STRATA_FIELD(SimParams, floodScheme),
                                           STRATA_FIELD(SimParams, pad1),
                                           STRATA_FIELD(SimParams, pad2),
                                           STRATA_FIELD(SimParams, pad3)});
}

TEST(GpuLayouts, SimMaterialSourceAndLevelEntryMatchGlsl) {
  using SimMaterial = strata::sim::GpuMaterial;
  using strata::sim::SourceEntry;
  expectSimLayout<SimMaterial>("SimMaterial",
                               {STRATA_FIELD(SimMaterial, erodibility), STRATA_FIELD(SimMaterial, dissolutionRate),
                                STRATA_FIELD(SimMaterial, tanTalus), STRATA_FIELD(SimMaterial, weatheringRatePerS),
                                STRATA_FIELD(SimMaterial, criticalShearPa), STRATA_FIELD(SimMaterial, shearErodibility),
                                STRATA_FIELD(SimMaterial, settlingVelocityMS), STRATA_FIELD(SimMaterial, tanFriction),
                                STRATA_FIELD(SimMaterial, sinFriction), STRATA_FIELD(SimMaterial, cosFriction),
                                STRATA_FIELD(SimMaterial, cohesionHeightM), STRATA_FIELD(SimMaterial, pad0)});
  // SourceEntry is 8 bytes: its std430 struct alignment is 4, not the 16 the generic parser
  // assumes for structs holding vec4s, so only the offsets are compared.
  size_t size = 0;
  const auto fields = glslLayout(std::string(STRATA_SOURCE_DIR) + "/sim/shaders/sim.glsl", "SourceEntry", size);
  ASSERT_EQ(fields.size(), 2u);
  EXPECT_EQ(fields[0].offset, offsetof(SourceEntry, cell));
  EXPECT_EQ(fields[1].offset, offsetof(SourceEntry, rateM3S));
  EXPECT_EQ(sizeof(SourceEntry), 8u);
  using strata::sim::LevelEntry;
  const auto level = glslLayout(std::string(STRATA_SOURCE_DIR) + "/sim/shaders/sim.glsl", "LevelEntry", size);
  ASSERT_EQ(level.size(), 2u);
  EXPECT_EQ(level[0].offset, offsetof(LevelEntry, cell));
  EXPECT_EQ(level[1].offset, offsetof(LevelEntry, stageM));
  EXPECT_EQ(sizeof(LevelEntry), 8u);
}

}  // namespace
}  // namespace strata::test
