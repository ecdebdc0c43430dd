#pragma once
// Small simulation scenes shared by the CPU reference tests (tests/terrain) and the GPU tests
// (tests/render): the same inputs go to both solvers.
#include <algorithm>
#include <cmath>
#include <numbers>

#include <strata/sim/input.hpp>
#include <strata/terrain/material.hpp>

namespace strata::test {

/// Four layers (rock, soil, sand, sediment) of the given thicknesses everywhere.
inline void fourLayers(sim::SimInput& in, float rock, float soil, float sand, float sediment) {
  const int w = in.baseM.width, h = in.baseM.height;
  in.materials = terrain::defaultMaterials();
  in.layersM = {gis::Grid<float>(w, h, rock), gis::Grid<float>(w, h, soil), gis::Grid<float>(w, h, sand),
                gis::Grid<float>(w, h, sediment)};
}

/// A lake at rest at `datumM + 3 m` over a bumpy bed (datum + 0..5 m) with islands above the
/// surface; 10 m cells. Depth is surface - bed where positive.
inline sim::SimInput lakeAtRest(int n, double datumM) {
  sim::SimInput in;
  in.baseM = gis::Grid<float>(n, n);
  in.waterDepthM = gis::Grid<float>(n, n);
  in.rowDxM = {10.0};
  in.dyM = 10.0;
  in.datumM = datumM;
  const double surface = 3.0;
  fourLayers(in, 0.5f, 0.5f, 0.5f, 0.0f);
  for (int y = 0; y < n; ++y) {
    for (int x = 0; x < n; ++x) {
      const double fx = double(x) / n, fy = double(y) / n;
      double b = 1.5 + 1.2 * std::sin(7.0 * fx) * std::cos(5.0 * fy) + 0.6 * std::sin(19.0 * fx + 3.0 * fy);
      // Two islands rising to 5 m above the datum.
      for (auto [cx, cy] : {std::pair{0.3, 0.35}, std::pair{0.7, 0.6}}) {
        const double r2 = (fx - cx) * (fx - cx) + (fy - cy) * (fy - cy);
        b = std::max(b, 5.0 - 40.0 * r2 * 10.0);
      }
      const double base = b - 1.5;  // the layers add 1.5 m
      in.baseM.at(x, y) = float(datumM + base);
      // The depth as the solver will see it: the input holds absolute float32 elevations (0.12 mm
      // steps at 2000 m); the solver subtracts the datum and adds the layers in float.
      const float baseRel = float(double(in.baseM.at(x, y)) - datumM);
      const float bedF = baseRel + 0.5f + 0.5f + 0.5f + 0.0f;
      in.waterDepthM.at(x, y) = float(std::max(0.0, surface - double(bedF)));
    }
  }
  return in;
}

/// A steep, dry hillside: 48 x 16 cells of 20 m falling east at 30% (6 m a cell) with a
/// cross-slope ripple (gullies), datum 1500 m, no water; open to the east. Feed it with
/// `steepSlopeSpring()`: a strong spring on the dry crest, the case where a long step used to
/// break the water balance.
inline sim::SimInput steepDrySlope() {
  sim::SimInput in;
  const int w = 48, h = 16;
  in.baseM = gis::Grid<float>(w, h);
  in.rowDxM = {20.0};
  in.dyM = 20.0;
  in.datumM = 1500.0;
  fourLayers(in, 1.0f, 0.5f, 0.0f, 0.0f);
  for (int y = 0; y < h; ++y) {
    for (int x = 0; x < w; ++x) in.baseM.at(x, y) = float(1800.0 - 6.0 * x + 3.0 * std::sin(0.9 * y + 0.3 * x));
  }
  return in;
}

/// 200 m^3/s over two crest cells of `steepDrySlope()`, rising from 0 in 60 s, for 20 minutes.
inline sim::Source steepSlopeSpring() {
  sim::Source s;
  s.cells = {{1, 7}, {1, 8}};
  s.dischargeM3S = TimeSeries({{0.0, 0.0}, {60.0, 200.0}, {1200.0, 200.0}});
  return s;
}

/// A dry bowl (bed datum + 0.5 m at the centre, + 1.5 m at the edges' midpoints, + 2.5 m at the
/// corners; 10 m cells) and a fixed level on five cells in the middle of its west edge whose stage
/// rises from 1 m to `stageM` above the datum over the first 600 s, then holds.
struct LevelBasin {
  sim::SimInput input;
  sim::LevelBoundary level;
};
inline LevelBasin levelBasin(int n, double stageM) {
  LevelBasin b;
  auto& in = b.input;
  in.baseM = gis::Grid<float>(n, n);
  in.rowDxM = {10.0};
  in.dyM = 10.0;
  in.datumM = 500.0;
  fourLayers(in, 0.0f, 0.0f, 0.0f, 0.0f);
  for (int y = 0; y < n; ++y) {
    for (int x = 0; x < n; ++x) {
      const double fx = (x + 0.5) / n - 0.5, fy = (y + 0.5) / n - 0.5;
      in.baseM.at(x, y) = float(in.datumM + 0.5 + 4.0 * (fx * fx + fy * fy));
    }
  }
  for (int y = n / 2 - 2; y <= n / 2 + 2; ++y) b.level.cells.push_back({0, y});
  b.level.stageM = TimeSeries({{0.0, in.datumM + 1.0}, {600.0, in.datumM + stageM}});
  return b;
}

/// A flat-bottomed closed box with a bumpy surface of water (a sloshing basin), 5 m cells.
inline sim::SimInput sloshingBox(int n) {
  sim::SimInput in;
  in.baseM = gis::Grid<float>(n, n);
  in.waterDepthM = gis::Grid<float>(n, n);
  in.rowDxM = {5.0};
  in.dyM = 5.0;
  in.datumM = 1000.0;
  fourLayers(in, 1.0f, 0.5f, 0.5f, 0.1f);
  for (int y = 0; y < n; ++y) {
    for (int x = 0; x < n; ++x) {
      const double fx = double(x) / n, fy = double(y) / n;
      in.baseM.at(x, y) = float(1000.0 + 0.5 * fx + 0.3 * std::sin(6.0 * fy));
      in.waterDepthM.at(x, y) =
          float(1.0 + 0.5 * std::exp(-30.0 * ((fx - 0.3) * (fx - 0.3) + (fy - 0.4) * (fy - 0.4))));
    }
  }
  return in;
}

/// Issue 35's float32 budget case (W34): sloshingBox(8) (64 cells: the drift it checks is each
/// cell's own rounding, so the size of the box does not change it; a GL step on llvmpipe costs
/// 2.1x more at 16^2), closed, under 10 mm/h of rain with a 0.02 m^3/s spring at (3, 3), in
/// flood mode with 0.2 s steps (the cap: the CFL step is longer). Each step's rain, 5.6e-7 m, is
/// 4.7 ulp of a depth in [1, 2) m: float32 depths without compensation round it alike in every
/// cell (measured after 150,000 steps: at 16^2 before W34, +1.5e-3 of the water with the
/// finite-volume scheme, +2.6e-3 with the local-inertial one; here, GL with the depths' rounding
/// errors dropped, 3.0e-3 and 2.75e-3).
inline constexpr int kLongRainCells = 8;
inline sim::SimInput longRainBox() { return sloshingBox(kLongRainCells); }
inline sim::SimParams longRainParams(sim::FloodScheme scheme) {
  sim::SimParams p;
  p.waterModel = sim::WaterModel::kFiniteVolume;
  p.floodScheme = scheme;
  p.maxDtS = 0.2f;
  p.cflAlpha = scheme == sim::FloodScheme::kLocalInertial ? 0.7f : 0.45f;
  p.rainMmPerHour = 10.0f;
  return p;
}
inline sim::Source longRainSpring() {
  sim::Source s;
  s.cells = {{3, 3}};
  s.dischargeM3S = TimeSeries({{0.0, 0.02}, {1e6, 0.02}});
  return s;
}
inline constexpr long long kLongRainSteps = 150000;

}  // namespace strata::test

namespace strata::test {

/// A valley draining north to south with four layers (rock, soil, sand, sediment), rain and
/// a spring at its head: water keeps flowing, so erosion, transport and deposition stay busy.
inline sim::SimInput erodingValley(int n) {
  sim::SimInput in;
  in.baseM = gis::Grid<float>(n, n);
  in.rowDxM = {4.0};
  in.dyM = 4.0;
  in.datumM = 2600.0;
  in.materials = terrain::defaultMaterials();
  in.layersM = {gis::Grid<float>(n, n), gis::Grid<float>(n, n), gis::Grid<float>(n, n), gis::Grid<float>(n, n)};
  in.waterDepthM = gis::Grid<float>(n, n);
  for (int y = 0; y < n; ++y) {
    for (int x = 0; x < n; ++x) {
      const double fx = double(x) / n - 0.5, fy = double(y) / n;
      in.baseM.at(x, y) = float(2600.0 + 20.0 * (1.0 - fy) + 30.0 * fx * fx + 0.3 * std::sin(13.0 * fx + 7.0 * fy));
      in.layersM[0].at(x, y) = 2.0f;
      in.layersM[1].at(x, y) = float(0.5 + 0.4 * std::sin(5.0 * fy));
      in.layersM[2].at(x, y) = float(0.3 + 0.3 * std::cos(9.0 * fx));
      in.layersM[3].at(x, y) = (x + y) % 3 == 0 ? 0.1f : 0.0f;
      in.waterDepthM.at(x, y) = fy > 0.8 ? 0.5f : 0.0f;
    }
  }
  return in;
}

/// Erosion parameters for erodingValley (pipes, erosion and thermal weathering on).
/// Virtual pipes with a fixed 0.1 s step and 25 m^2 pipes (the water tests' default).
inline sim::SimParams pipeParams() {
  sim::SimParams p;
  p.waterModel = sim::WaterModel::kVirtualPipes;
  p.maxDtS = 0.1f;
  p.pipeAreaM2 = 25.0f;
  return p;
}

/// Flood mode with the CFL step (alpha 0.45) capped at 10 s.
inline sim::SimParams floodParams() {
  sim::SimParams p;
  p.waterModel = sim::WaterModel::kFiniteVolume;
  p.maxDtS = 10.0f;
  p.cflAlpha = 0.45f;
  return p;
}

inline sim::SimParams erosionParams() {
  sim::SimParams p;
  p.waterModel = sim::WaterModel::kVirtualPipes;
  p.erosionLaw = sim::ErosionLaw::kForceBased;  // pipes have no Manning n to give a shear stress
  p.maxDtS = 0.05f;
  p.pipeAreaM2 = 16.0f;
  p.rainMmPerHour = 50.0f;
  p.erosionEnabled = 1;
  p.thermalEnabled = 1;
  p.capacityK = 0.05f;
  p.erosionRate = 0.5f;
  p.depositionRate = 0.3f;
  p.deepWaterM = 2.0f;
  p.slowWaterMS = 0.05f;
  p.dryDepthM = 1e-3f;  // no velocities (and so no erosion) from films of rain
  return p;
}

/// A spring at the valley head feeding erodingValley.
inline sim::Source valleySpring(int n) {
  sim::Source s;
  for (int x = n / 2 - 2; x <= n / 2 + 2; ++x) s.cells.push_back({x, 1});
  s.dischargeM3S = TimeSeries({{0.0, 2.0}, {200.0, 5.0}, {1000.0, 5.0}});
  return s;
}

}  // namespace strata::test

namespace strata::test {

/// A straight channel running south between two banks, 2 m cells: the channel (columns
/// w/2 - 2 .. w/2 + 1) falls 0.04 m a cell; the banks rise 0.9 m a cell away from it (a slope of
/// 0.45, 24 degrees: below the dry talus of sand, 0.62, above its undercut-bank angle, 0.31).
/// Rock `rockM` thick under `sandM` of sand everywhere; no water. Datum 1200 m.
inline sim::SimInput bankedChannel(int w, int h, float rockM, float sandM) {
  sim::SimInput in;
  in.baseM = gis::Grid<float>(w, h);
  in.rowDxM = {2.0};
  in.dyM = 2.0;
  in.datumM = 1200.0;
  fourLayers(in, rockM, 0.0f, sandM, 0.0f);
  const int c0 = w / 2 - 2, c1 = w / 2 + 1;
  for (int y = 0; y < h; ++y) {
    for (int x = 0; x < w; ++x) {
      const int away = std::max({0, c0 - x, x - c1});
      in.baseM.at(x, y) = float(1200.0 + 0.04 * (h - y) + 0.9 * away);
    }
  }
  return in;
}

/// 4 m^3/s over the channel cells of bankedChannel's second row, from the start.
inline sim::Source channelSpring(int w) {
  sim::Source s;
  for (int x = w / 2 - 2; x <= w / 2 + 1; ++x) s.cells.push_back({x, 1});
  s.dischargeM3S = TimeSeries({{0.0, 4.0}, {1e6, 4.0}});
  return s;
}

/// Flood mode with friction (Manning 0.035; the frictionless pipes run a spring's sheet down a
/// slope at tens of m/s), CFL 0.45, steps of at most 0.5 s; thermal weathering and bank failure
/// on, erosion off (so no toe is scoured and no bank falls); closed edges, no rain.
inline sim::SimParams bankParams() {
  sim::SimParams p;
  p.waterModel = sim::WaterModel::kFiniteVolume;
  p.cflAlpha = 0.45f;
  p.maxDtS = 0.5f;
  p.manningN = 0.035f;
  p.dryDepthM = 1e-3f;
  p.thermalEnabled = true;
  p.slowWaterMS = 0.05f;
  return p;
}

/// bankParams with everything on: rain (50 mm/h), erosion (the shear-stress law), deposition and
/// dissolution, thermal weathering and bank failure, an open south edge, and the scenarios' dry
/// depth (1e-6 m: rain films carry tiny loads everywhere). Feed bankedChannel with channelSpring.
inline sim::SimParams everythingOnParams() {
  sim::SimParams p = bankParams();
  p.erosionEnabled = true;
  p.rainMmPerHour = 50.0f;
  p.dryDepthM = 1e-6f;
  p.openEdges = sim::kEdgeSouth;
  return p;
}

}  // namespace strata::test
