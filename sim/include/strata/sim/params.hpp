#pragma once
// What a user chooses about a water / erosion run: the model and its constants (docs/sim-water.md,
// docs/sim-erosion.md; equation numbers W1.., E1.. refer to them). Plain values: the grid is in
// SimInput, the solver's state in the solver, and the GL backend derives its std430 block from
// these in one place (sim/gl/gl_layout.hpp).

#include <cstdint>

#include <strata/core/result.hpp>

namespace strata::sim {

/// Which shallow-water model moves the water.
enum class WaterModel : int32_t {
  kVirtualPipes = 0,  ///< Mei et al. 2007 / Stava et al. 2008 outflow pipes (W1-W4)
  kFiniteVolume = 1,  ///< flood mode: Godunov finite volumes, HLL + hydrostatic reconstruction (W13-W24)
};

/// Flood mode's scheme (docs/sim-water.md): both keep the depth on the cells and budget every
/// volume the same way; they differ in how the discharge is carried.
enum class FloodScheme : int32_t {
  /// Godunov finite volumes (HLL with hydrostatic reconstruction, Heun in time, W13-W25): the
  /// full shallow-water equations, shocks, supercritical and steep flow (the default).
  kFiniteVolume = 0,
  /// Local inertial (Bates, Horritt and Fewtrell 2010, J. Hydrology 387; the semi-implicit
  /// friction of de Almeida et al. 2012, Water Resources Research 48; W30-W33): the discharge on
  /// each face from the water-surface slope and Manning friction, no advection. One face pass and
  /// one update a step, and a step set by sqrt(g h) alone: the fast choice for gently varying
  /// floodplain flow (LISFLOOD-FP's ACC solver); not for supercritical flow or steep slopes.
  kLocalInertial = 1,
};

/// Flood mode's slope limiter (W21).
enum class SlopeLimiter : int32_t {
  kMinmod = 0,  ///< the smaller one-sided slope: the most diffusive, robust on steep real terrain (the default)
  kMonotonizedCentral = 1,  ///< van Leer's MC: sharper fronts and smooth flow (Ritter front lag as dx^0.5, not dx^0.3)
};

/// What moves material between the bed and the water (docs/sim-erosion.md, E1-E3).
enum class ErosionLaw : int32_t {
  /// Entrainment from the excess bed shear stress of each material, E = k_d (tau - tau_c) with
  /// Manning's tau = rho g n^2 |u|^2 / h^(1/3) (Partheniades 1965; Hanson and Simon 2001), and
  /// deposition at the settling velocity, D = w_s c (Hairsine and Rose 1992): physical units,
  /// the materials' constants (terrain::Material), needs flood mode's Manning n.
  kShearStress = 0,
  /// The seed systems' force-based capacity (Stava et al. 2008): C = Kc sin(tilt) |v| (1 - h /
  /// deepWaterM), picked up at Ks, dropped at Kd. Model constants, for authoring terrain.
  kForceBased = 1,
};

/// Bits of SimParams::openEdges: an open edge lets water flow out freely (and counts it);
/// a closed one is a wall.
enum EdgeBits : uint32_t { kEdgeWest = 1u, kEdgeEast = 2u, kEdgeNorth = 4u, kEdgeSouth = 8u };

/// The most levels of local time steps (W37): blocks step at up to 2^3 = 8 times the finest step
/// (more levels saved nothing on the Environment Agency's test 4, docs/sim-water.md).
constexpr int kMaxLocalStepLevels = 3;

/// What a backend other than the CPU's says to localStepLevels > 0: its steps are the grid's.
inline constexpr const char* kLocalStepsOnTheCpuOnly =
    "sim params: local time steps (localStepLevels) run on the CPU backend only; this backend takes one step for the "
    "whole grid";

/// The model and its constants. setParams() may change any of them mid-run but the water model,
/// the flood scheme, local steps and diagonal pipes, which decide what the solver allocates.
struct SimParams {
  WaterModel waterModel = WaterModel::kVirtualPipes;
  FloodScheme floodScheme = FloodScheme::kFiniteVolume;  ///< flood mode's scheme (fixed at creation)
  /// Local time steps (W37; the local-inertial scheme on the CPU backend, fixed at creation): each
  /// block of cells steps at dt, 2 dt, ... 2^localStepLevels dt as its own CFL bound allows, the
  /// grid's step being the longest. 0: one step for the whole grid (the default); at most
  /// kMaxLocalStepLevels.
  int localStepLevels = 0;
  SlopeLimiter slopeLimiter = SlopeLimiter::kMinmod;  ///< flood mode's W21 slopes
  uint32_t openEdges = 0;                             ///< EdgeBits; 0 = closed box
  bool erosionEnabled = false;                        ///< erosion, deposition, dissolution and transport (E1-E6)
  bool thermalEnabled = false;                        ///< weathering of slopes and bank failure (E7-E8)
  bool diagonalPipes = false;         ///< pipes model with 8 pipes (diagonals too), no axis-aligned gullies (W1b)
  float gravityMS2 = 9.81f;           ///< g (m/s^2)
  float maxDtS = 0.05f;               ///< fixed step, or the upper bound of the adaptive one (s)
  float cflAlpha = 0.0f;              ///< > 0: dt = min(maxDtS, alpha * min(dx,dy) / max(|u| + sqrt(g h))) (W10)
  float dryDepthM = 1e-6f;            ///< below this depth a cell or face counts as dry (m)
  float pipeAreaM2 = 1.0f;            ///< cross-section of a virtual pipe (m^2) (W1)
  float manningN = 0.0f;              ///< Manning's n (s m^-1/3), flood mode; 0 = frictionless (W19)
  float rainMmPerHour = 0.0f;         ///< uniform rain (mm/h), added to the rain raster
  float evaporationMmPerHour = 0.0f;  ///< evaporation from wet cells (mm/h) (W11)
  ErosionLaw erosionLaw =
      ErosionLaw::kShearStress;      ///< E1-E3 (the materials' constants, or the force-based ones below)
  float waterDensityKgM3 = 1000.0f;  ///< rho of the bed shear stress (E1)
  float capacityK = 0.0f;            ///< force-based law: sediment capacity constant Kc (s) (E1)
  float erosionRate = 0.0f;          ///< force-based law: Ks, the capacity deficit's pick-up rate (1/s) (E2)
  float depositionRate = 0.0f;       ///< force-based law: Kd, the excess's settling rate (1/s) (E3)
  float deepWaterM = 1.0f;           ///< force-based law: capacity falls linearly to 0 at this depth (m) (E1)
  float minSinTilt = 0.05f;          ///< force-based law: floor of sin(tilt) so flat beds still carry sediment (E1)
  float slowWaterMS = 0.1f;          ///< dissolution acts where |v| is below this (m/s) (E4)
  /// E8: the share of what the flow took off a cell in a step (its toe scour) that each bank
  /// failing into it may bring down in that step (the slumped volume is bounded by the undercut).
  float bankFillShare = 0.5f;
};

/// Checks the parameters (finite, ranges, the model's own constraints); the message names the
/// parameter and the problem.
Status validateParams(const SimParams& params);

/// `next` with what is fixed at creation (water model, flood scheme, local steps, diagonal pipes)
/// taken from `current`: what setParams() applies mid-run.
SimParams runtimeParams(const SimParams& current, const SimParams& next);

}  // namespace strata::sim
