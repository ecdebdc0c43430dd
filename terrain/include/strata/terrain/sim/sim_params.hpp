#pragma once
// Parameters, inputs and statistics of the water / erosion simulation, shared by the CPU
// reference solver (terrain/sim/cpu_simulation.hpp) and the GPU one (render/sim/simulation.hpp).
// The maths is in docs/sim-water.md and docs/sim-erosion.md; equation numbers (W1.., E1..) refer
// to those pages.
//
// SimParams and SimMaterial are also the std430 blocks the compute shaders read
// (shaders/common/sim.glsl): only 4-byte scalars, in the same order; the static_asserts pin the
// offsets and tests/render/gpu_layouts_test.cpp checks the GLSL side.

#include <cstddef>
#include <cstdint>
#include <utility>
#include <vector>

#include <strata/core/result.hpp>
#include <strata/gis/raster.hpp>
#include <strata/terrain/material.hpp>

namespace strata::terrain::sim {

/// Which shallow-water model moves the water.
enum class WaterModel : int32_t {
  kVirtualPipes = 0,  ///< Mei et al. 2007 / Stava et al. 2008 outflow pipes (W1-W4)
  kFiniteVolume = 1,  ///< flood mode: Godunov finite volumes, HLL + hydrostatic reconstruction (W13-W24)
};

/// Flood mode's slope limiter (W21), SimParams::slopeLimiter.
enum class SlopeLimiter : int32_t {
  kMinmod = 0,  ///< the smaller one-sided slope: the most diffusive, robust on steep real terrain (the default)
  kMonotonizedCentral = 1,  ///< van Leer's MC: sharper fronts and smooth flow (Ritter front lag as dx^0.5, not dx^0.3)
};

/// Bits of SimParams::openEdges: an open edge lets water flow out freely (and counts it);
/// a closed one is a wall.
enum EdgeBits : uint32_t { kEdgeWest = 1u, kEdgeEast = 2u, kEdgeNorth = 4u, kEdgeSouth = 8u };

/// Run parameters (std430 mirror of `SimParams` in shaders/common/sim.glsl).
struct SimParams {
  int32_t width = 0;       ///< cells in x (set by create from the input grids)
  int32_t height = 0;      ///< cells in y (rows, row 0 north)
  int32_t layerCount = 0;  ///< material layers (set by create)
  int32_t waterModel = int32_t(WaterModel::kVirtualPipes);
  uint32_t openEdges = 0;             ///< EdgeBits; 0 = closed box
  uint32_t erosionEnabled = 0;        ///< 1: erosion, deposition, dissolution and transport (E1-E6)
  uint32_t thermalEnabled = 0;        ///< 1: thermal weathering and bank slippage (E7-E8)
  uint32_t diagonalPipes = 0;         ///< 1: pipes model with 8 pipes (diagonals too), no axis-aligned gullies (W1b)
  float dyM = 1.0f;                   ///< cell size north-south (m); per-row dx is in SimInput::rowDxM
  float gravityMS2 = 9.81f;           ///< g (m/s^2)
  float dtS = 0.0f;                   ///< the current step (s); written by the solver each step
  float maxDtS = 0.05f;               ///< fixed step, or the upper bound of the adaptive one (s)
  float cflAlpha = 0.0f;              ///< > 0: dt = min(maxDtS, alpha * min(dx,dy) / max(|u| + sqrt(g h))) (W10)
  float dryDepthM = 1e-6f;            ///< below this depth a cell or face counts as dry (m)
  float pipeAreaM2 = 1.0f;            ///< cross-section of a virtual pipe (m^2) (W1)
  float manningN = 0.0f;              ///< Manning's n (s m^-1/3), flood mode; 0 = frictionless (W19)
  float rainMmPerHour = 0.0f;         ///< uniform rain (mm/h), added to the rain raster
  float evaporationMmPerHour = 0.0f;  ///< evaporation from wet cells (mm/h) (W11)
  float capacityK = 0.0f;             ///< sediment capacity constant Kc (s) (E1)
  float erosionRate = 0.0f;           ///< Ks: fraction of the capacity deficit picked up per second (1/s) (E2)
  float depositionRate = 0.0f;        ///< Kd: fraction of the excess dropped per second (1/s) (E3)
  float deepWaterM = 1.0f;            ///< capacity falls linearly to 0 at this depth (m) (E1)
  float minSinTilt = 0.05f;           ///< floor of sin(tilt) so flat beds still carry sediment (E1)
  float slowWaterMS = 0.1f;           ///< dissolution acts where |v| is below this (m/s) (E4)
  float thermalRate = 0.5f;           ///< fraction of the talus excess moved per step, in (0,1] (E7)
  float wetTalusScale = 0.5f;         ///< talus tangent multiplier for banks touching water (E8)
  float maxErosionPerStepM = 0.01f;   ///< cap on material moved by E2/E4 in one step (m)
  int32_t slopeLimiter = int32_t(SlopeLimiter::kMinmod);  ///< flood mode's W21 slopes (SlopeLimiter)
};
static_assert(sizeof(SimParams) == 112);
static_assert(offsetof(SimParams, dyM) == 32);
static_assert(offsetof(SimParams, dtS) == 40);
static_assert(offsetof(SimParams, manningN) == 60);
static_assert(offsetof(SimParams, capacityK) == 72);
static_assert(offsetof(SimParams, maxErosionPerStepM) == 104);

/// Per-layer material constants as the shaders read them (std430 mirror of `SimMaterial`).
struct SimMaterial {
  float erodibility = 1.0f;      ///< Material::erodibility (dimensionless)
  float dissolutionRate = 0.0f;  ///< Material::dissolutionRate (m of material per m of water per s)
  float tanTalus = 0.7f;         ///< tan(Material::talusAngleDeg)
  float pad = 0.0f;
};
static_assert(sizeof(SimMaterial) == 16);
static_assert(offsetof(SimMaterial, tanTalus) == 8);

/// SimMaterial from a terrain Material.
SimMaterial toSimMaterial(const Material& m);

/// The terrain and water a simulation starts from. Elevations are absolute metres; the solver
/// stores them relative to `datumM` so float32 keeps millimetres at 2800 m.
struct SimInput {
  gis::Grid<float> baseM;                 ///< non-erodible base elevation (m above sea level)
  std::vector<gis::Grid<float>> layersM;  ///< layer thicknesses, bottom to top (m, >= 0); the top one receives sediment
  std::vector<Material> materials;        ///< one per layer
  gis::Grid<float> waterDepthM;           ///< initial water depth (m, >= 0); empty = dry (a dam-break volume goes here)
  gis::Grid<float> rainMmPerHour;         ///< rain raster (mm/h); empty = none (uniform rain is in SimParams)
  std::vector<double> rowDxM;  ///< cell size east-west per row (m): one value, or one per row (geographic grids)
  double dyM = 1.0;            ///< cell size north-south (m)
  double datumM = 0.0;         ///< elevations are stored relative to this (m)
};

/// A point or line of inflow: discharge over time, linearly interpolated between samples and
/// zero outside their span (as terrain::Hydrograph in scenario files), split equally over
/// `cells` (W12).
struct Source {
  std::vector<std::pair<int, int>> cells;                ///< (x, y) cells it feeds
  std::vector<std::pair<double, double>> hydrographM3S;  ///< (time s, discharge m^3/s), time increasing
  /// Discharge at time `tS` (m^3/s).
  double rateAt(double tS) const;
  /// Volume delivered between t0S and t1S (m^3): the exact integral of the piecewise-linear curve.
  double volume(double t0S, double t1S) const;
};

/// A fixed water level (W26): each step the listed cells are set to depth max(0, stage(t) - bed),
/// a Dirichlet condition. The water this puts in or takes out is summed per cell since the start:
/// a cell that gained on balance counts as inflow, one that lost as outflow. The stage is linearly
/// interpolated between samples and holds its end values outside their span.
struct LevelBoundary {
  std::vector<std::pair<int, int>> cells;         ///< (x, y) cells held at the level
  std::vector<std::pair<double, double>> stageM;  ///< (time s, water surface elevation m), time increasing
  /// Water surface elevation at time `tS` (m, the same reference as SimInput::baseM).
  double stageAt(double tS) const;
};

/// Water and material bookkeeping since the start (volumes in m^3, summed in double).
struct SimStats {
  double timeS = 0;              ///< simulated time
  long long steps = 0;           ///< steps taken
  double lastDtS = 0;            ///< the most recent step
  double storedWaterM3 = 0;      ///< water in the domain now
  double initialWaterM3 = 0;     ///< water at the start
  double rainM3 = 0;             ///< rain added
  double inflowM3 = 0;           ///< added by sources
  double outflowM3 = 0;          ///< left through open edges
  double evaporatedM3 = 0;       ///< evaporated
  double materialM3 = 0;         ///< all layers + suspended sediment now
  double suspendedM3 = 0;        ///< suspended sediment now
  double initialMaterialM3 = 0;  ///< all layers + suspended at the start
  double sedimentOutflowM3 = 0;  ///< suspended sediment carried out through open edges
  double maxDepthM = 0;          ///< deepest water now
  /// stored - (initial + rain + inflow - outflow - evaporated): 0 up to rounding.
  double waterBalanceM3() const {
    return storedWaterM3 - (initialWaterM3 + rainM3 + inflowM3 - outflowM3 - evaporatedM3);
  }
};

/// Checks `input` against `params` (sizes, per-row dx, materials, non-negative thicknesses);
/// the message names the field and the problem.
Status validate(const SimInput& input, const SimParams& params);

/// Checks the parameters alone (ranges, model); validate() calls it.
Status validateParams(const SimParams& params);

/// `next` with the fields fixed at creation (grid size, layer count, water model, dyM) and the
/// current step taken from `current`: what setParams() applies mid-run.
SimParams runtimeParams(const SimParams& current, const SimParams& next);

/// Cell-size helpers shared by both solvers: dx of `row`, and the minimum over rows.
double rowDx(const SimInput& input, int row);

}  // namespace strata::terrain::sim
