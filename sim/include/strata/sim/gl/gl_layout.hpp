#pragma once
// The GL backend's std430 blocks (sim/shaders/sim.glsl), derived from the user's SimParams and
// the grid in one place (gpuParams). The static_asserts pin the offsets; tests/gl's layout test
// lays the GLSL structs out by the std430 rules and compares.

#include <cstddef>
#include <cstdint>

#include <strata/sim/input.hpp>
#include <strata/sim/params.hpp>

namespace strata::sim {

/// std430 mirror of `SimParams` in sim/shaders/sim.glsl: only 4-byte scalars, in that order.
struct GpuSimParams {
  int32_t width = 0;
  int32_t height = 0;
  int32_t layerCount = 0;
  int32_t waterModel = 0;
  uint32_t openEdges = 0;
  uint32_t erosionEnabled = 0;
  uint32_t thermalEnabled = 0;
  uint32_t diagonalPipes = 0;
  float dyM = 1.0f;
  float gravityMS2 = 9.81f;
  float dtS = 0.0f;  ///< the current step, written before each step
  float maxDtS = 0.05f;
  float cflAlpha = 0.0f;
  float dryDepthM = 1e-6f;
  float pipeAreaM2 = 1.0f;
  float manningN = 0.0f;
  float rainMmPerHour = 0.0f;
  float evaporationMmPerHour = 0.0f;
  float capacityK = 0.0f;
  float erosionRate = 0.0f;
  float depositionRate = 0.0f;
  float deepWaterM = 1.0f;
  float minSinTilt = 0.05f;
  float slowWaterMS = 0.1f;
  int32_t erosionLaw = 0;
  float waterDensityKgM3 = 1000.0f;
  float bankFillShare = 0.5f;
  int32_t slopeLimiter = 0;
  int32_t floodScheme = 0;                      ///< FloodScheme: 0 finite volume, 1 local inertial
  float pad1 = 0.0f, pad2 = 0.0f, pad3 = 0.0f;  ///< std430 rounds the block to 16 bytes
};
static_assert(sizeof(GpuSimParams) == 128);
static_assert(offsetof(GpuSimParams, dyM) == 32);
static_assert(offsetof(GpuSimParams, dtS) == 40);
static_assert(offsetof(GpuSimParams, manningN) == 60);
static_assert(offsetof(GpuSimParams, capacityK) == 72);
static_assert(offsetof(GpuSimParams, bankFillShare) == 104);

/// std430 mirror of `SimMaterial` (MaterialConstants).
struct GpuMaterial {
  float erodibility = 1.0f;
  float dissolutionRate = 0.0f;
  float tanTalus = 0.7f;
  float weatheringRatePerS = 0.1f;
  float criticalShearPa = 1.0f;
  float shearErodibility = 2e-7f;
  float settlingVelocityMS = 0.02f;
  float tanFriction = 0.58f;
  float sinFriction = 0.5f;
  float cosFriction = 0.87f;
  float cohesionHeightM = 0.0f;
  float pad0 = 0.0f;
};
static_assert(sizeof(GpuMaterial) == 48);
static_assert(offsetof(GpuMaterial, tanTalus) == 8);
static_assert(offsetof(GpuMaterial, cohesionHeightM) == 40);

/// W35: the shapes of the passes a device step dispatches indirectly (sim_clock.glsl's
/// CLOCK_SHAPE_*): 16 x 16 groups over the grid, 256 cells a group, 64 source entries a group.
enum ClockShape : int { kShapeGrid = 0, kShapeCells = 1, kShapeEntries = 2, kClockShapes = 3 };

/// std430 mirror of sim_clock.glsl's ClockBlock: the GPU's clock of a run of device steps.
struct GpuClock {
  double timeS = 0, endS = 0, inflowM3 = 0, minChosenDtS = 0, lastChosenDtS = 0;
  double maxDtS = 0, reachM = 0, gravityMS2 = 0, rainRateMS = 0, pad0 = 0;
  float lastDtS = 0;
  uint32_t steps = 0, done = 0, adaptive = 0, termCount = 0, inertial = 0, pointSources = 0, pad3 = 0;
  uint32_t dispatchNow[3 * kClockShapes] = {};
  uint32_t dispatchFull[3 * kClockShapes] = {};
};
static_assert(offsetof(GpuClock, lastDtS) == 80);
static_assert(offsetof(GpuClock, steps) == 84);
static_assert(offsetof(GpuClock, dispatchNow) == 112);
static_assert(offsetof(GpuClock, dispatchFull) == 148);
static_assert(sizeof(GpuClock) == 184);

/// std430 mirror of sim_clock.glsl's Term: one source's share of one point-source entry.
struct GpuTerm {
  uint32_t entry = 0, first = 0, count = 0, pad = 0;
  double cellCount = 1, areaM2 = 1;
};
static_assert(sizeof(GpuTerm) == 32);

/// The block the kernels read, from the parameters, the grid and the current step.
GpuSimParams gpuParams(const SimParams& params, const CellGrid& grid, float dtS);
GpuMaterial gpuMaterial(const MaterialConstants& m);

}  // namespace strata::sim
