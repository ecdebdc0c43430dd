#pragma once
// What the multi-rank tests share (CPU and GL): the flood scene, snapshots of every per-cell value
// gathered on rank 0, and bit-for-bit comparisons of them.
#include <gtest/gtest.h>
#include <mpi.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <string>
#include <tuple>
#include <vector>

#include <strata/sim/mpi/distributed_solver.hpp>

#include "mpi_support.hpp"
#include "sim_scenes.hpp"

namespace strata::sim::test_mpi {

using namespace strata::test;

using test::worldRank;
using test::worldSize;

// ---------------------------------------------------------------------------------------------
// Scenes

// A flood on 60 x 44 cells of 10 m: a reservoir in the north-east corner breaking towards the
// open west and south edges, rain on the western strip, a spring in the south, a fixed level on
// the west edge, friction and flood statistics. The front crosses block borders on any split.
struct FloodScene {
  SimInput input;
  SimParams params;
  Source spring;
  LevelBoundary level;
};
inline FloodScene floodScene() {
  FloodScene s;
  const int w = 60, h = 44;
  SimInput& in = s.input;
  in.baseM = gis::Grid<float>(w, h);
  in.waterDepthM = gis::Grid<float>(w, h);
  in.rainMmPerHour = gis::Grid<float>(w, h);
  in.rowDxM = {10.0};
  in.dyM = 10.0;
  in.datumM = 500.0;
  fourLayers(in, 0.5f, 0.3f, 0.2f, 0.0f);
  for (int y = 0; y < h; ++y) {
    for (int x = 0; x < w; ++x) {
      in.baseM.at(x, y) = float(503.0 + 0.1 * x + 0.04 * y + 0.5 * std::sin(0.3 * y) * std::cos(0.2 * x));
      in.waterDepthM.at(x, y) = x >= 48 && y < 14 ? 2.0f : 0.0f;
      in.rainMmPerHour.at(x, y) = x < 15 ? 40.0f : 0.0f;
    }
  }
  s.params = floodParams();
  s.params.openEdges = kEdgeWest | kEdgeSouth;
  s.params.manningN = 0.03f;
  s.spring.cells = {{30, 40}, {31, 40}};
  s.spring.dischargeM3S = TimeSeries({{0.0, 0.0}, {30.0, 5.0}, {1000.0, 5.0}});
  for (int y = 20; y < 24; ++y) s.level.cells.push_back({0, y});
  s.level.stageM = TimeSeries({{0.0, 504.5}, {1000.0, 504.5}});
  return s;
}

template <class S>
void feed(S& sim, const FloodScene& s) {
  ASSERT_TRUE(sim.addSource(s.spring));
  ASSERT_TRUE(sim.addLevel(s.level));
  sim.enableFloodStats(0.01f);
}

// The eroding valley of the erosion tests (40 x 40 cells of 4 m, pipes, erosion and thermal
// weathering, rain, a spring at its head, open to the south): material crosses block borders.
struct ErosionScene {
  SimInput input;
  SimParams params;
  Source spring;
};
inline ErosionScene erosionScene() {
  ErosionScene s{erodingValley(40), erosionParams(), valleySpring(40)};
  s.params.openEdges = kEdgeSouth;
  return s;
}

// ---------------------------------------------------------------------------------------------
// What is compared: every per-cell value of the interiors, the flood statistics, the face fluxes
// (flood mode) and the statistics; gathered on rank 0.

struct Snapshot {
  CellBlock cells;
  FloodStats flood;
  std::vector<float> faces;
  SimStats stats;
  gis::Grid<float> bed;
};

inline Snapshot snapshot(Solver& sim) {
  Snapshot s;
  s.cells = sim.readBlock(0, 0, sim.grid().width, sim.grid().height, kBlockAll);
  s.flood = sim.readFloodStats();
  if (sim.params().waterModel == WaterModel::kFiniteVolume) s.faces = sim.readFaceMassFlux();
  s.stats = sim.stats();
  s.bed = sim.readBed();
  return s;
}

inline bool sameBits(const std::vector<float>& a, const std::vector<float>& b) {
  // (empty vectors compare equal without memcmp: their data() may be null, which memcmp must not get)
  return a.size() == b.size() && (a.empty() || std::memcmp(a.data(), b.data(), a.size() * sizeof(float)) == 0);
}
inline size_t differing(const std::vector<float>& a, const std::vector<float>& b) {
  if (a.size() != b.size()) return std::max(a.size(), b.size());
  size_t n = 0;
  for (size_t i = 0; i < a.size(); ++i) n += std::memcmp(&a[i], &b[i], sizeof(float)) != 0 ? 1 : 0;
  return n;
}
inline bool sameBits(double a, double b) { return std::memcmp(&a, &b, sizeof a) == 0; }

// Every value bit for bit (rank 0).
inline void expectSame(const Snapshot& a, const Snapshot& b, const std::string& what, bool statsToo = true) {
  EXPECT_TRUE(sameBits(a.cells.state, b.cells.state))
      << what << ": state differs in " << differing(a.cells.state, b.cells.state) << " values";
  EXPECT_TRUE(sameBits(a.cells.flux, b.cells.flux)) << what << ": flux differs";
  EXPECT_TRUE(sameBits(a.cells.fluxDiag, b.cells.fluxDiag)) << what << ": diagonal flux differs";
  EXPECT_TRUE(sameBits(a.cells.layers, b.cells.layers))
      << what << ": layers differ in " << differing(a.cells.layers, b.cells.layers) << " values";
  EXPECT_TRUE(sameBits(a.cells.accum, b.cells.accum)) << what << ": accumulators differ";
  EXPECT_TRUE(sameBits(a.bed.data, b.bed.data)) << what << ": bed differs";
  EXPECT_TRUE(sameBits(a.flood.maxDepthM.data, b.flood.maxDepthM.data)) << what << ": max depth differs";
  EXPECT_TRUE(sameBits(a.flood.maxSpeedMS.data, b.flood.maxSpeedMS.data)) << what << ": max speed differs";
  EXPECT_TRUE(sameBits(a.flood.arrivalS.data, b.flood.arrivalS.data)) << what << ": arrival differs";
  EXPECT_TRUE(sameBits(a.flood.wetDurationS.data, b.flood.wetDurationS.data)) << what << ": wet duration differs";
  EXPECT_TRUE(sameBits(a.faces, b.faces)) << what << ": face fluxes differ in " << differing(a.faces, b.faces);
  if (!statsToo) return;
  const SimStats &s = a.stats, &t = b.stats;
  for (auto [x, y, name] : {std::tuple{s.timeS, t.timeS, "time"},
                            {s.storedWaterM3, t.storedWaterM3, "stored"},
                            {s.initialWaterM3, t.initialWaterM3, "initial water"},
                            {s.rainM3, t.rainM3, "rain"},
                            {s.inflowM3, t.inflowM3, "inflow"},
                            {s.outflowM3, t.outflowM3, "outflow"},
                            {s.evaporatedM3, t.evaporatedM3, "evaporated"},
                            {s.materialM3, t.materialM3, "material"},
                            {s.suspendedM3, t.suspendedM3, "suspended"},
                            {s.initialMaterialM3, t.initialMaterialM3, "initial material"},
                            {s.sedimentOutflowM3, t.sedimentOutflowM3, "sediment out"},
                            {s.maxDepthM, t.maxDepthM, "max depth"}}) {
    EXPECT_TRUE(sameBits(x, y)) << what << ": " << name << " " << x << " vs " << y;
  }
  EXPECT_EQ(s.steps, t.steps) << what;
}

// The scene run on this rank alone as one block: the reference every split must equal.
inline DistributedOptions oneBlock(const SimInput& in) {
  DistributedOptions o;
  o.comm = MPI_COMM_SELF;
  o.blockWidth = in.baseM.width;
  o.blockHeight = in.baseM.height;
  return o;
}

inline long long sumOver(long long v) {
  long long s = 0;
  MPI_Allreduce(&v, &s, 1, MPI_LONG_LONG, MPI_SUM, MPI_COMM_WORLD);
  return s;
}

}  // namespace strata::sim::test_mpi
