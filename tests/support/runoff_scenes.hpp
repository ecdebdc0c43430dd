#pragma once
// Rain-on-grid and morphodynamic cases with known answers or bounds (issue 30;
// shared/VALIDATION.md), shared by the CPU tests, the GL tests and the benchmarks: the
// kinematic-wave plane, the V-catchment (Di Giammarco, Todini and Lamberti 1996) and their
// reference solutions, a channel, a gorge and a valley for erosion and bank failure.
#include <algorithm>
#include <cmath>
#include <random>
#include <vector>

#include <strata/sim/input.hpp>
#include <strata/sim/params.hpp>
#include <strata/terrain/material.hpp>

namespace strata::test {

/// A plane `lengthM` long (falling east at `slope`) and `widthM` wide, cells of `cellM`; closed
/// on three sides, open to the east (the foot). Rock 2 m thick under `sandM` of sand (the layers
/// rock, sand, sediment), datum 500 m. Dry.
inline sim::SimInput rainPlane(double lengthM, double widthM, double slope, double cellM, float sandM = 0.0f) {
  sim::SimInput in;
  const int w = int(std::lround(lengthM / cellM)), h = int(std::lround(widthM / cellM));
  in.baseM = gis::Grid<float>(w, h);
  in.rowDxM = {cellM};
  in.dyM = cellM;
  in.datumM = 500.0;
  const auto all = terrain::defaultMaterials();
  in.materials = {all[0], all[2], all[3]};
  in.layersM = {gis::Grid<float>(w, h, 2.0f), gis::Grid<float>(w, h, sandM), gis::Grid<float>(w, h, 0.0f)};
  for (int y = 0; y < h; ++y) {
    for (int x = 0; x < w; ++x) in.baseM.at(x, y) = float(in.datumM + slope * (lengthM - (x + 0.5) * cellM));
  }
  return in;
}

/// Flood mode for rain on a grid: CFL 0.45, Manning n, a step cap, the foot (east) open.
inline sim::SimParams rainParams(float manningN, float rainMmH, float maxStepS) {
  sim::SimParams p;
  p.waterModel = sim::WaterModel::kFiniteVolume;
  p.cflAlpha = 0.45f;
  p.maxDtS = maxStepS;
  p.manningN = manningN;
  p.rainMmPerHour = rainMmH;
  p.openEdges = sim::kEdgeEast;
  return p;
}

/// Kinematic-wave steady state of a plane of length L (m) under rain i (m/s), slope S, Manning n:
/// unit discharge q = i x, depth h = (i x n / sqrt S)^(3/5), water held per unit width
/// (i n / sqrt S)^(3/5) L^(8/5) / (8/5) (e.g. Singh 1996, Kinematic Wave Modeling in Water
/// Resources; shared/VALIDATION.md).
inline double kinematicDepth(double x, double i, double S, double n) { return std::pow(i * x * n / std::sqrt(S), 0.6); }
inline double kinematicStoragePerWidth(double L, double i, double S, double n) {
  return std::pow(i * n / std::sqrt(S), 0.6) * std::pow(L, 1.6) / 1.6;
}
/// Its time to equilibrium: (n L / sqrt S)^(3/5) / i^(2/5).
inline double kinematicEquilibriumS(double L, double i, double S, double n) {
  return std::pow(n * L / std::sqrt(S), 0.6) / std::pow(i, 0.4);
}

/// The V-catchment (Di Giammarco, Todini and Lamberti 1996, J. Hydrology 175; the rainfall-runoff
/// check of SERGHEI, TRITON, ParFlow and others): two planes `planeM` (800 m) wide falling at
/// `sx` (0.05) towards a channel `channelM` (20 m) wide, everything falling at `sy` (0.02) along
/// its `lengthM` (1000 m) to the south, where the channel's end is open. The channel bed lies
/// `incisionM` below the planes' feet. Cells of `cellM`. Datum 100 m.
struct VCatchment {
  sim::SimInput input;
  int channelX0 = 0, channelX1 = 0;  ///< channel columns [x0, x1)
};
inline VCatchment vCatchment(double cellM, double planeM = 800.0, double channelM = 20.0, double lengthM = 1000.0,
                             double sx = 0.05, double sy = 0.02, double incisionM = 1.0) {
  VCatchment v;
  auto& in = v.input;
  const int np = int(std::lround(planeM / cellM)), nc = std::max(1, int(std::lround(channelM / cellM)));
  const int w = 2 * np + nc, h = int(std::lround(lengthM / cellM));
  v.channelX0 = np;
  v.channelX1 = np + nc;
  in.baseM = gis::Grid<float>(w, h);
  in.rowDxM = {cellM};
  in.dyM = cellM;
  in.datumM = 100.0;
  const auto all = terrain::defaultMaterials();
  in.materials = {all[0]};
  in.layersM = {gis::Grid<float>(w, h, 0.0f)};
  for (int y = 0; y < h; ++y) {
    const double along = sy * (lengthM - (y + 0.5) * cellM);
    for (int x = 0; x < w; ++x) {
      double across = 0;  // height above the plane's foot
      if (x < np) across = sx * (np - x - 0.5) * cellM;
      if (x >= np + nc) across = sx * (x - (np + nc) + 0.5) * cellM;
      const bool channel = x >= np && x < np + nc;
      in.baseM.at(x, y) = float(in.datumM + 10.0 + along + across - (channel ? incisionM : 0.0));
    }
  }
  return v;
}

/// Reference outlet hydrograph of the V-catchment by the kinematic wave: each plane a 1-D
/// kinematic wave of Manning `nPlane` on slope sx under rain i (m/s) from t = 0 to tRainS, feeding
/// a channel of width b, Manning `nChannel` and slope sy (a wide rectangular channel: q = sqrt(S)
/// / n A (A / b)^(2/3)) with both planes' outflow and its own rain. Solved with an implicit upwind
/// finite-difference scheme (Chow, Maidment and Mays 1988, 9.6, Newton on the nonlinear cell
/// equation) on `nodes` nodes per plane and channel and steps of dtS: fine enough that it no longer
/// changes (the test checks that against a coarser solve). Returns the outlet discharge (m^3/s)
/// at every multiple of dtS up to tEndS.
inline std::vector<double> vCatchmentKinematic(double i, double tRainS, double tEndS, double dtS, double planeM,
                                               double channelM, double lengthM, double sx, double sy, double nPlane,
                                               double nChannel, int nodes) {
  // One kinematic-wave reach: A_t + Q_x = lateral (m^2/s per m), Q = alpha A^m (per unit width for
  // planes: A = h, Q = q). Implicit upwind in space, backward Euler in time: for node k,
  // (A_k^{n+1} - A_k^n) / dt + (Q_k^{n+1} - Q_{k-1}^{n+1}) / dx = lateral_k^{n+1}, solved node by
  // node downstream with Newton on A_k^{n+1}.
  struct Reach {
    double alpha, m, dx;
    std::vector<double> A;
    double step(double dt, double lateral) {
      double qUp = 0;
      for (size_t k = 0; k < A.size(); ++k) {
        const double rhs = A[k] + dt * (lateral + qUp / dx);
        double a = std::max(A[k], 1e-12);
        for (int it = 0; it < 60; ++it) {
          const double f = a + dt / dx * alpha * std::pow(a, m) - rhs;
          const double df = 1.0 + dt / dx * alpha * m * std::pow(a, m - 1.0);
          const double next = std::max(a - f / df, 1e-300);
          if (std::abs(next - a) <= 1e-14 * std::max(a, 1e-12)) {
            a = next;
            break;
          }
          a = next;
        }
        A[k] = a;
        qUp = alpha * std::pow(a, m);
      }
      return qUp;
    }
  };
  Reach plane{std::sqrt(sx) / nPlane, 5.0 / 3.0, planeM / nodes, std::vector<double>(size_t(nodes), 0.0)};
  // A wide rectangular channel: hydraulic radius = depth = A / b.
  Reach channel{std::sqrt(sy) / nChannel / std::pow(channelM, 2.0 / 3.0), 5.0 / 3.0, lengthM / nodes,
                std::vector<double>(size_t(nodes), 0.0)};
  std::vector<double> out{0.0};
  const int steps = int(std::lround(tEndS / dtS));
  for (int s = 1; s <= steps; ++s) {
    const double t = s * dtS;
    const double rain = t <= tRainS + 1e-9 ? i : 0.0;
    const double qPlane = plane.step(dtS, rain);  // m^2/s per metre of channel, from each plane
    out.push_back(channel.step(dtS, 2.0 * qPlane + rain * channelM));
  }
  return out;
}

/// A straight channel 20 m wide (columns 4-7 of 5 m cells) falling 2 % southwards over `lengthM`,
/// between banks rising 1 m a cell, cut in 2 m of `bedMaterial` (a default material's index) over
/// 5 m of rock, with `depositMaterial`'s grains as the load and the deposits; the channel bed
/// carries uniform noise of +-`noiseM` (a fixed seed). Datum 100 m; the south edge is open. Feed
/// it with channelInflow().
inline sim::SimInput noisyChannel(double lengthM, double noiseM, int bedMaterial, int depositMaterial) {
  const double cell = 5.0;
  const int w = 12, h = int(std::lround(lengthM / cell));
  sim::SimInput in;
  in.baseM = gis::Grid<float>(w, h);
  in.rowDxM = {cell};
  in.dyM = cell;
  in.datumM = 100.0;
  const auto all = terrain::defaultMaterials();
  auto deposit = all[size_t(depositMaterial)];
  deposit.name = "sediment";
  in.materials = {all[0], all[size_t(bedMaterial)], deposit};
  in.layersM = {gis::Grid<float>(w, h, 5.0f), gis::Grid<float>(w, h, 2.0f), gis::Grid<float>(w, h, 0.0f)};
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> noise(-noiseM, noiseM);
  for (int y = 0; y < h; ++y) {
    for (int x = 0; x < w; ++x) {
      const int away = std::max({0, 4 - x, x - 7});
      const double bump = away == 0 ? noise(rng) : 0.0;
      in.baseM.at(x, y) = float(in.datumM + 0.02 * (h - y - 0.5) * cell + 1.0 * away + bump);
    }
  }
  return in;
}
/// `m3s` over the channel's first row.
inline sim::Source channelInflow(double m3s) {
  sim::Source s;
  for (int x = 4; x <= 7; ++x) s.cells.push_back({x, 0});
  s.dischargeM3S = TimeSeries::constant(m3s);
  return s;
}

/// A valley 1 km long falling 2 % southwards on cells of `cellM`: a floor two cells wide between
/// walls of six cells a side rising at `wallDeg`. `sandValley`: everything is sand 10 m thick on
/// 10 m of rock; else the walls are rock 20 m thick and the floor carries 1 m of sand on it (a
/// gorge). Layers rock, sand, sediment; datum 100 m; the south edge is open. Feed it with
/// valleyStream().
inline sim::SimInput valley(double cellM, double wallDeg, bool sandValley) {
  const int wall = 6, w = 2 * wall + 2, h = int(std::lround(1000.0 / cellM));
  const double rise = cellM * std::tan(wallDeg * 3.14159265358979 / 180.0);
  sim::SimInput in;
  in.baseM = gis::Grid<float>(w, h);
  in.rowDxM = {cellM};
  in.dyM = cellM;
  in.datumM = 100.0;
  const auto all = terrain::defaultMaterials();
  in.materials = {all[0], all[2], all[3]};
  in.layersM = {gis::Grid<float>(w, h, 0.0f), gis::Grid<float>(w, h, 0.0f), gis::Grid<float>(w, h, 0.0f)};
  for (int y = 0; y < h; ++y) {
    for (int x = 0; x < w; ++x) {
      const int away = std::max({0, wall - x, x - (wall + 1)});
      const double surface = in.datumM + 0.02 * (h - y - 0.5) * cellM + rise * away;
      const bool floor = away == 0;
      if (sandValley) {
        in.baseM.at(x, y) = float(surface - 20.0);
        in.layersM[0].at(x, y) = 10.0f;
        in.layersM[1].at(x, y) = 10.0f;
      } else {
        in.baseM.at(x, y) = float(surface - 20.0 - (floor ? 1.0 : 0.0));
        in.layersM[0].at(x, y) = 20.0f;
        in.layersM[1].at(x, y) = floor ? 1.0f : 0.0f;
      }
    }
  }
  return in;
}
inline bool valleyFloor(int x) { return x == 6 || x == 7; }
/// `m3s` into the valley floor's first row.
inline sim::Source valleyStream(double m3s) {
  sim::Source s;
  s.cells = {{6, 0}, {7, 0}};
  s.dischargeM3S = TimeSeries::constant(m3s);
  return s;
}

/// Flood mode with erosion (the shear-stress law) and thermal weathering / bank failure, Manning
/// n, CFL 0.45, a step cap, the south edge open.
inline sim::SimParams erosionFloodParams(float manningN, float maxStepS, bool thermal) {
  sim::SimParams p;
  p.waterModel = sim::WaterModel::kFiniteVolume;
  p.cflAlpha = 0.45f;
  p.maxDtS = maxStepS;
  p.manningN = manningN;
  p.openEdges = sim::kEdgeSouth;
  p.erosionEnabled = true;
  p.thermalEnabled = thermal;
  return p;
}

}  // namespace strata::test
