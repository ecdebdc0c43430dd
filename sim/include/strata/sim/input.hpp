#pragma once
// What a simulation starts from and is fed with: the terrain and water on its grid (SimInput),
// inflows (Source) and fixed water levels (LevelBoundary). Cells are (x, y) = (column, row),
// row 0 north.

#include <utility>
#include <vector>

#include <strata/core/result.hpp>
#include <strata/core/time_series.hpp>
#include <strata/gis/raster.hpp>
#include <strata/sim/params.hpp>
#include <strata/terrain/material.hpp>

namespace strata::sim {

/// The terrain and water a simulation starts from. Elevations are absolute metres; solvers store
/// them relative to `datumM` so float32 keeps millimetres at 2800 m.
struct SimInput {
  gis::Grid<float> baseM;                 ///< non-erodible base elevation (m above sea level)
  std::vector<gis::Grid<float>> layersM;  ///< layer thicknesses, bottom to top (m, >= 0); the top one receives sediment
  std::vector<terrain::Material> materials;  ///< one per layer
  gis::Grid<float> waterDepthM;    ///< initial water depth (m, >= 0); empty = dry (a dam-break volume goes here)
  gis::Grid<float> rainMmPerHour;  ///< rain raster (mm/h); empty = none (uniform rain is in SimParams)
  /// Manning's n per cell (s m^-1/3, >= 0; W19, E1): a roughness map; empty = SimParams::manningN
  /// everywhere (and then a setParams changes it).
  gis::Grid<float> manningN;
  /// Infiltration per cell (W11b): the loss rate, or with a suction Green-Ampt's saturated
  /// hydraulic conductivity Ks (mm/h, >= 0); empty = no infiltration.
  gis::Grid<float> infiltrationMmPerHour;
  /// Green-Ampt's wetting-front suction head times the soil's moisture deficit, psi * dtheta (m,
  /// >= 0) per cell; 0 or empty (with a rate) = a constant loss at the rate.
  gis::Grid<float> infiltrationSuctionM;
  std::vector<double> rowDxM;  ///< cell size east-west per row (m): one value, or one per row (geographic grids)
  double dyM = 1.0;            ///< cell size north-south (m)
  double datumM = 0.0;         ///< elevations are stored relative to this (m)
};

/// A point or line of inflow: its discharge over time (m^3/s) split equally over `cells` (W12).
struct Source {
  std::vector<std::pair<int, int>> cells;  ///< (x, y) cells it feeds
  TimeSeries dischargeM3S;                 ///< (time s, discharge m^3/s)
};

/// A fixed water level (W26): each step the listed cells are set to depth max(0, stage(t) - bed),
/// a Dirichlet condition. The water this puts in or takes out is summed per cell since the start:
/// a cell that gained on balance counts as inflow, one that lost as outflow.
struct LevelBoundary {
  std::vector<std::pair<int, int>> cells;  ///< (x, y) cells held at the level
  TimeSeries stageM;                       ///< (time s, water surface elevation m, the reference of SimInput::baseM)
};

/// A material's constants as the erosion passes use them (E1-E8): both backends take them from
/// here, so they agree to the bit.
struct MaterialConstants {
  float erodibility = 1.0f;          ///< terrain::Material::erodibility (dimensionless, force-based law)
  float dissolutionRate = 0.0f;      ///< m of material per m of water per s
  float tanTalus = 0.7f;             ///< tan(terrain::Material::talusAngleDeg)
  float weatheringRatePerS = 0.1f;   ///< terrain::Material::weatheringRatePerS (1/s)
  float criticalShearPa = 1.0f;      ///< tau_c (Pa)
  float shearErodibility = 2e-7f;    ///< k_d (m/(s Pa))
  float settlingVelocityMS = 0.02f;  ///< w_s (m/s)
  float tanFriction = 0.58f, sinFriction = 0.5f, cosFriction = 0.87f;  ///< of the wet bank's friction angle phi'
  float cohesionHeightM = 0.0f;  ///< 4 c' / gamma (m): Culmann's critical bank height scale (E8)
};
MaterialConstants materialConstants(const terrain::Material& m);

/// Checks `input` against `params` (sizes, per-row dx, materials, finite non-negative
/// thicknesses); the message names the field and the problem.
Status validate(const SimInput& input, const SimParams& params);

/// The cell grid a solver runs on, taken from its input: what every backend and the shared
/// bookkeeping need to know about cells.
struct CellGrid {
  int width = 0, height = 0, layers = 0;
  std::vector<double> rowDxM;  ///< per row (m), always height values
  double dyM = 1.0;            ///< north-south (m), rounded to float32 as the kernels use it
  double datumM = 0.0;         ///< elevations are stored relative to this (m)
  double minCellM = 1.0;       ///< smallest cell side (m)
  size_t cells() const { return size_t(width) * size_t(height); }
  double area(int row) const { return rowDxM[size_t(row)] * dyM; }
  static CellGrid of(const SimInput& input);
  /// The same from the shape alone (a region read by windows); rowDxM: one value or one per row.
  static CellGrid of(int width, int height, int layers, const std::vector<double>& rowDxM, double dyM, double datumM);
};

}  // namespace strata::sim
