#pragma once
// A flood front over a flat floodplain, after the UK Environment Agency's benchmark test 4
// (Néelz and Pender 2013, report SC120002, "speed of flood propagation over an extended
// floodplain"): a horizontal plain 2000 m east-west by 1000 m north-south at elevation 0, Manning
// 0.05, walled, fed from a 20 m breach in the middle of its west side with a peak of 20 m^3/s.
// The hydrograph's shape is ours (the report gives it as a figure): up to the peak over the first
// hour, held to 4 h, back to 0 at its 6 h time base; the run lasts 5 h. Gauges on the centre line
// 50, 100, 200, 300, 400 and 500 m from the breach. Shared by the CPU and GL tests and the
// benchmarks: the same input goes to every solver and scheme.
#include <cmath>
#include <utility>
#include <vector>

#include <strata/sim/input.hpp>
#include <strata/sim/params.hpp>
#include <strata/terrain/material.hpp>

namespace strata::test {

struct FlatPlain {
  sim::SimInput input;
  sim::Source breach;
  std::vector<std::pair<int, int>> gauges;  ///< cells, in the order of gaugeDistancesM
};

inline constexpr double kPlainGaugeDistancesM[6] = {50, 100, 200, 300, 400, 500};
inline constexpr double kPlainDurationS = 5 * 3600.0;

/// The plain at `cellM` (a divisor of 20 m and of 1000 m: 20, 10, 5, 4, 2, 1 m).
inline FlatPlain flatPlain(double cellM) {
  FlatPlain p;
  const int w = int(std::lround(2000.0 / cellM)), h = int(std::lround(1000.0 / cellM));
  sim::SimInput& in = p.input;
  in.baseM = gis::Grid<float>(w, h, 0.0f);
  in.rowDxM = {cellM};
  in.dyM = cellM;
  in.datumM = 0.0;
  in.materials = {terrain::defaultMaterials()[0]};
  in.layersM = {gis::Grid<float>(w, h, 0.0f)};
  // The breach: the 20 m of the west edge centred on y = 500 m.
  const int breachCells = std::max(1, int(std::lround(20.0 / cellM)));
  const int y0 = h / 2 - breachCells / 2;
  for (int k = 0; k < breachCells; ++k) p.breach.cells.push_back({0, y0 + k});
  p.breach.dischargeM3S = TimeSeries({{0.0, 0.0}, {3600.0, 20.0}, {4 * 3600.0, 20.0}, {6 * 3600.0, 0.0}});
  for (double d : kPlainGaugeDistancesM) p.gauges.push_back({int(d / cellM), h / 2});
  return p;
}

/// Flood mode on the plain: Manning 0.05, closed edges, the step from the CFL rule (0.45 for
/// finite volumes, 0.7 for the local-inertial scheme) capped at 30 s.
inline sim::SimParams flatPlainParams(sim::FloodScheme scheme) {
  sim::SimParams p;
  p.waterModel = sim::WaterModel::kFiniteVolume;
  p.floodScheme = scheme;
  p.cflAlpha = scheme == sim::FloodScheme::kLocalInertial ? 0.7f : 0.45f;
  p.maxDtS = 30.0f;
  p.manningN = 0.05f;
  p.openEdges = 0;
  return p;
}

}  // namespace strata::test
