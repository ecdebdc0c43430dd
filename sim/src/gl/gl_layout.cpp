#include <strata/sim/gl/gl_layout.hpp>

namespace strata::sim {

GpuSimParams gpuParams(const SimParams& p, const CellGrid& grid, float dtS) {
  GpuSimParams g;
  g.width = grid.width;
  g.height = grid.height;
  g.layerCount = grid.layers;
  g.waterModel = int32_t(p.waterModel);
  g.openEdges = p.openEdges;
  g.erosionEnabled = p.erosionEnabled ? 1u : 0u;
  g.thermalEnabled = p.thermalEnabled ? 1u : 0u;
  g.diagonalPipes = p.diagonalPipes ? 1u : 0u;
  g.dyM = float(grid.dyM);
  g.gravityMS2 = p.gravityMS2;
  g.dtS = dtS;
  g.maxDtS = p.maxDtS;
  g.cflAlpha = p.cflAlpha;
  g.dryDepthM = p.dryDepthM;
  g.pipeAreaM2 = p.pipeAreaM2;
  g.manningN = p.manningN;
  g.rainMmPerHour = p.rainMmPerHour;
  g.evaporationMmPerHour = p.evaporationMmPerHour;
  g.capacityK = p.capacityK;
  g.erosionRate = p.erosionRate;
  g.depositionRate = p.depositionRate;
  g.deepWaterM = p.deepWaterM;
  g.minSinTilt = p.minSinTilt;
  g.slowWaterMS = p.slowWaterMS;
  g.floodScheme = int32_t(p.floodScheme);
  g.erosionLaw = int32_t(p.erosionLaw);
  g.waterDensityKgM3 = p.waterDensityKgM3;
  g.bankFillShare = p.bankFillShare;
  g.slopeLimiter = int32_t(p.slopeLimiter);
  return g;
}

GpuMaterial gpuMaterial(const MaterialConstants& m) {
  GpuMaterial g;
  g.erodibility = m.erodibility;
  g.dissolutionRate = m.dissolutionRate;
  g.tanTalus = m.tanTalus;
  g.weatheringRatePerS = m.weatheringRatePerS;
  g.criticalShearPa = m.criticalShearPa;
  g.shearErodibility = m.shearErodibility;
  g.settlingVelocityMS = m.settlingVelocityMS;
  g.tanFriction = m.tanFriction;
  g.sinFriction = m.sinFriction;
  g.cosFriction = m.cosFriction;
  g.cohesionHeightM = m.cohesionHeightM;
  return g;
}

}  // namespace strata::sim
