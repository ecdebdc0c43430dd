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
  float thermalRate = 0.5f;
  float wetTalusScale = 0.5f;
  float maxErosionPerStepM = 0.01f;
  int32_t slopeLimiter = 0;
  float bankDepthM = 0.1f;
  float bankSlipRatePerS = 0.01f;
  float pad0 = 0.0f, pad1 = 0.0f;  ///< std430 rounds the block to 16 bytes
};
static_assert(sizeof(GpuSimParams) == 128);
static_assert(offsetof(GpuSimParams, dyM) == 32);
static_assert(offsetof(GpuSimParams, dtS) == 40);
static_assert(offsetof(GpuSimParams, manningN) == 60);
static_assert(offsetof(GpuSimParams, capacityK) == 72);
static_assert(offsetof(GpuSimParams, maxErosionPerStepM) == 104);

/// std430 mirror of `SimMaterial`.
struct GpuMaterial {
  float erodibility = 1.0f;
  float dissolutionRate = 0.0f;
  float tanTalus = 0.7f;
  float weatheringRatePerS = 0.1f;
};
static_assert(sizeof(GpuMaterial) == 16);
static_assert(offsetof(GpuMaterial, tanTalus) == 8);

/// The block the kernels read, from the parameters, the grid and the current step.
GpuSimParams gpuParams(const SimParams& params, const CellGrid& grid, float dtS);
GpuMaterial gpuMaterial(const MaterialConstants& m);

}  // namespace strata::sim
