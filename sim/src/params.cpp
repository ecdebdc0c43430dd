#include <strata/sim/params.hpp>

#include <cmath>
#include <string>

namespace strata::sim {
namespace {

// "sim params: <name> = <value>: must be <what>" unless `ok`, naming the field (Error::field).
Status require(bool ok, const char* name, float value, const char* what) {
  if (ok) return {};
  const std::string reason = std::string("must be ") + what;
  return failField(std::string("sim params: ") + name + " = " + std::to_string(value) + ": " + reason, name, reason);
}

}  // namespace

Status validateParams(const SimParams& p) {
  if (p.waterModel != WaterModel::kVirtualPipes && p.waterModel != WaterModel::kFiniteVolume) {
    return failField("sim params: waterModel " + std::to_string(int(p.waterModel)) + " is not 0 (pipes) or 1 (flood)",
                     "waterModel", "is not 0 (pipes) or 1 (flood)");
  }
  if (p.floodScheme != FloodScheme::kFiniteVolume && p.floodScheme != FloodScheme::kLocalInertial) {
    return failField("sim params: floodScheme " + std::to_string(int(p.floodScheme)) +
                         " is not 0 (finite volume) or 1 (local inertial)",
                     "floodScheme", "is not 0 (finite volume) or 1 (local inertial)");
  }
  const bool inertial = p.floodScheme == FloodScheme::kLocalInertial;
  if (inertial && p.waterModel != WaterModel::kFiniteVolume) {
    return failField("sim params: the local-inertial scheme is a flood-mode scheme (waterModel 1)", "floodScheme",
                     "is a flood-mode scheme");
  }
  if (inertial && (p.erosionEnabled || p.thermalEnabled)) {
    return failField(
        "sim params: the local-inertial scheme moves water only: erosion and thermal weathering need the "
        "finite-volume scheme",
        "floodScheme", "moves water only: erosion and thermal weathering need the finite-volume scheme");
  }
  if (p.localStepLevels < 0 || p.localStepLevels > kMaxLocalStepLevels) {
    return failField("sim params: localStepLevels " + std::to_string(p.localStepLevels) + " is not in [0, " +
                         std::to_string(kMaxLocalStepLevels) + "]",
                     "localStepLevels", "is not in [0, " + std::to_string(kMaxLocalStepLevels) + "]");
  }
  if (p.localStepLevels > 0 && (!inertial || p.cflAlpha <= 0)) {
    return failField("sim params: local time steps need the local-inertial scheme and an adaptive step (cflAlpha > 0)",
                     "localStepLevels", "needs the local-inertial scheme and an adaptive step (cflAlpha > 0)");
  }
  if (p.slopeLimiter != SlopeLimiter::kMinmod && p.slopeLimiter != SlopeLimiter::kMonotonizedCentral) {
    return failField("sim params: slopeLimiter " + std::to_string(int(p.slopeLimiter)) + " is not 0 (minmod) or 1 (MC)",
                     "slopeLimiter", "is not 0 (minmod) or 1 (MC)");
  }
  if (p.openEdges > 15u) {
    return failField("sim params: openEdges " + std::to_string(p.openEdges) + " is not a set of edges", "openEdges",
                     "is not a set of edges");
  }
  // Every constant must be a finite number (NaN fails every comparison below as well).
  const std::pair<const char*, float> all[] = {{"gravityMS2", p.gravityMS2},
                                               {"maxDtS", p.maxDtS},
                                               {"cflAlpha", p.cflAlpha},
                                               {"dryDepthM", p.dryDepthM},
                                               {"pipeAreaM2", p.pipeAreaM2},
                                               {"manningN", p.manningN},
                                               {"rainMmPerHour", p.rainMmPerHour},
                                               {"evaporationMmPerHour", p.evaporationMmPerHour},
                                               {"capacityK", p.capacityK},
                                               {"erosionRate", p.erosionRate},
                                               {"depositionRate", p.depositionRate},
                                               {"deepWaterM", p.deepWaterM},
                                               {"minSinTilt", p.minSinTilt},
                                               {"slowWaterMS", p.slowWaterMS},
                                               {"waterDensityKgM3", p.waterDensityKgM3},
                                               {"bankFillShare", p.bankFillShare}};
  for (const auto& [name, v] : all) STRATA_TRY_STATUS(require(std::isfinite(v), name, v, "a finite number"));
  STRATA_TRY_STATUS(require(p.maxDtS > 0, "maxDtS", p.maxDtS, "positive"));
  STRATA_TRY_STATUS(require(p.gravityMS2 > 0, "gravityMS2", p.gravityMS2, "positive"));
  STRATA_TRY_STATUS(require(p.cflAlpha >= 0, "cflAlpha", p.cflAlpha, ">= 0"));
  if (p.waterModel == WaterModel::kFiniteVolume && !inertial) {
    STRATA_TRY_STATUS(require(p.cflAlpha > 0 && p.cflAlpha <= 0.5f, "cflAlpha", p.cflAlpha,
                              "in (0, 0.5] in flood mode (positivity of the finite-volume scheme)"));
  }
  if (inertial) {  // W33: the gravity wave's Courant number (Bates et al. 2010 use 0.7)
    STRATA_TRY_STATUS(require(p.cflAlpha > 0 && p.cflAlpha <= 1.0f, "cflAlpha", p.cflAlpha,
                              "in (0, 1] with the local-inertial scheme (stability of its explicit step)"));
  }
  if (p.erosionLaw != ErosionLaw::kShearStress && p.erosionLaw != ErosionLaw::kForceBased) {
    return failField(
        "sim params: erosionLaw " + std::to_string(int(p.erosionLaw)) + " is not 0 (shear stress) or 1 (force-based)",
        "erosionLaw", "is not 0 (shear stress) or 1 (force-based)");
  }
  STRATA_TRY_STATUS(require(p.waterDensityKgM3 > 0, "waterDensityKgM3", p.waterDensityKgM3, "positive"));
  STRATA_TRY_STATUS(
      require(p.bankFillShare >= 0 && p.bankFillShare <= 1, "bankFillShare", p.bankFillShare, "in [0, 1]"));
  STRATA_TRY_STATUS(require(p.manningN >= 0, "manningN", p.manningN, ">= 0"));
  STRATA_TRY_STATUS(require(p.dryDepthM > 0, "dryDepthM", p.dryDepthM, "positive"));
  STRATA_TRY_STATUS(require(p.deepWaterM > 0, "deepWaterM", p.deepWaterM, "positive"));
  STRATA_TRY_STATUS(require(p.pipeAreaM2 > 0, "pipeAreaM2", p.pipeAreaM2, "positive"));
  for (const auto& [name, v] : {std::pair{"rainMmPerHour", p.rainMmPerHour},
                                {"evaporationMmPerHour", p.evaporationMmPerHour},
                                {"capacityK", p.capacityK},
                                {"erosionRate", p.erosionRate},
                                {"depositionRate", p.depositionRate},
                                {"minSinTilt", p.minSinTilt},
                                {"slowWaterMS", p.slowWaterMS}}) {
    STRATA_TRY_STATUS(require(v >= 0, name, v, ">= 0"));
  }
  return {};
}

SimParams runtimeParams(const SimParams& current, const SimParams& next) {
  SimParams p = next;
  p.waterModel = current.waterModel;
  p.floodScheme = current.floodScheme;
  p.localStepLevels = current.localStepLevels;
  p.diagonalPipes = current.diagonalPipes;
  return p;
}

}  // namespace strata::sim
