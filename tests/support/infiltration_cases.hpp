#pragma once
// Infiltration cases with known answers (W11b, issue 31): a flat closed basin over a Green-Ampt
// soil and the cumulative infiltration under ponding, shared by the CPU and GL tests.
#include <cmath>

#include <strata/sim/input.hpp>
#include <strata/sim/params.hpp>
#include <strata/terrain/material.hpp>

namespace strata::test {

// A sandy loam (Rawls, Brakensiek and Miller 1983, J. Hydraul. Eng. 109(1): Ks 10.9 mm/h, psi
// 110.1 mm) rounded, with a moisture deficit of 0.3: G = psi dtheta = 33 mm.
inline constexpr double kGaConductivityMmH = 10.0, kGaSuctionM = 0.110 * 0.3;
inline constexpr double kBasinCellM = 50.0;
inline constexpr int kBasinW = 10, kBasinH = 8;

inline double basinAreaM2() { return kBasinW * kBasinH * kBasinCellM * kBasinCellM; }

/// A flat basin of 10 x 8 cells of 50 m, closed on every side, `depthM` of still water on it, its
/// soil Green-Ampt's (kGaConductivityMmH, kGaSuctionM) everywhere.
inline sim::SimInput infiltrationBasin(double depthM) {
  sim::SimInput in;
  in.baseM = gis::Grid<float>(kBasinW, kBasinH, 500.0f);
  in.rowDxM = {kBasinCellM};
  in.dyM = kBasinCellM;
  in.datumM = 500.0;
  in.materials = {terrain::defaultMaterials()[0]};
  in.layersM = {gis::Grid<float>(kBasinW, kBasinH, 1.0f)};
  in.waterDepthM = gis::Grid<float>(kBasinW, kBasinH, float(depthM));
  in.infiltrationMmPerHour = gis::Grid<float>(kBasinW, kBasinH, float(kGaConductivityMmH));
  in.infiltrationSuctionM = gis::Grid<float>(kBasinW, kBasinH, float(kGaSuctionM));
  return in;
}

/// Flood mode, Manning 0.03, CFL 0.45, a step cap, uniform rain (mm/h), every edge closed.
inline sim::SimParams basinParams(float rainMmH, float maxStepS) {
  sim::SimParams p;
  p.waterModel = sim::WaterModel::kFiniteVolume;
  p.cflAlpha = 0.45f;
  p.maxDtS = maxStepS;
  p.manningN = 0.03f;
  p.rainMmPerHour = rainMmH;
  p.openEdges = 0;
  return p;
}

/// The basin without its soil, and two rain frames on it (mm/h): 10 on its west half, 30 on its
/// east half (the rain-frame tests).
struct RainFrames {
  sim::SimInput basin;
  gis::Grid<float> west, east;
};
inline RainFrames rainFrames() {
  RainFrames f{infiltrationBasin(0.0), gis::Grid<float>(kBasinW, kBasinH, 0.0f),
               gis::Grid<float>(kBasinW, kBasinH, 0.0f)};
  f.basin.infiltrationMmPerHour = {};
  f.basin.infiltrationSuctionM = {};
  for (int y = 0; y < kBasinH; ++y) {
    for (int x = 0; x < kBasinW; ++x) (x < kBasinW / 2 ? f.west : f.east).at(x, y) = x < kBasinW / 2 ? 10.0f : 30.0f;
  }
  return f;
}

/// Green and Ampt (1911) under ponding from a dry start: the cumulative infiltration F (m) at t
/// (s), F - G ln(1 + F / G) = Ks t, by bisection in double.
inline double greenAmptDepthM(double tS) {
  const double ks = kGaConductivityMmH / 3.6e6, g = kGaSuctionM;
  double lo = ks * tS, hi = ks * tS + std::sqrt(2.0 * g * ks * tS) + g;
  for (int i = 0; i < 200; ++i) {
    const double m = 0.5 * (lo + hi);
    (m - g * std::log1p(m / g) - ks * tS > 0 ? hi : lo) = m;
  }
  return 0.5 * (lo + hi);
}

}  // namespace strata::test
