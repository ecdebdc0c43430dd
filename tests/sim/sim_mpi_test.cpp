// The distributed run (DistributedSolver) under mpirun on 1, 2 and 4 ranks (tests/sim/CMakeLists.txt
// registers each): every run is compared with the same scene run on one rank as one block
// (MPI_COMM_SELF) and with the plain CPU solver, cell for cell and bit for bit, statistics
// included. Rank 0 compares; the others take part in the collective calls.
#include <gtest/gtest.h>
#include <mpi.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <numeric>
#include <random>
#include <sstream>
#include <string>
#include <vector>

#include <strata/sim/cpu_solver.hpp>
#include <strata/sim/mpi/distributed_solver.hpp>
#include <strata/sim/state_codec.hpp>

#include <strata/sim/exact_sum.hpp>
#include <strata/sim/mpi/ranks.hpp>
#include "../../sim/src/mpi/decomposition.hpp"
#include "mpi_compare.hpp"

namespace strata::sim {
namespace {

using namespace test_mpi;

// ---------------------------------------------------------------------------------------------

constexpr int kFloodSteps = 80;

// The flood scene after kFloodSteps on this rank alone as one block (computed once).
const Snapshot& floodReference() {
  static const Snapshot reference = [] {
    const auto scene = floodScene();
    auto ref = DistributedSolver::create(scene.input, scene.params, oneBlock(scene.input), cpuSolverFactory());
    EXPECT_TRUE(ref) << ref.message();
    feed(*ref, scene);
    ref->step(kFloodSteps);
    return snapshot(*ref);
  }();
  return reference;
}

TEST(SimDistributed, FloodEqualsOneRankBitForBit) {
  const auto scene = floodScene();
  Snapshot reference, plain;
  if (worldRank() == 0) {
    reference = floodReference();
    // The plain CPU solver: the same cells bit for bit (sources split per cell round the same
    // here); its statistics are summed in another order (double row sums), so close, not equal.
    auto cpu = CpuSolver::create(scene.input, scene.params);
    ASSERT_TRUE(cpu) << cpu.message();
    feed(*cpu, scene);
    cpu->step(kFloodSteps);
    plain = snapshot(*cpu);
    expectSame(reference, plain, "one block vs CpuSolver", false);
    std::printf("one block vs CpuSolver: stored %.17g / %.17g m3 (relative %.2g), outflow %.17g / %.17g m3\n",
                reference.stats.storedWaterM3, plain.stats.storedWaterM3,
                std::abs(reference.stats.storedWaterM3 / plain.stats.storedWaterM3 - 1), reference.stats.outflowM3,
                plain.stats.outflowM3);
    EXPECT_NEAR(reference.stats.storedWaterM3, plain.stats.storedWaterM3, 1e-9 * plain.stats.storedWaterM3);
    EXPECT_NEAR(reference.stats.outflowM3, plain.stats.outflowM3, 1e-9 * plain.stats.storedWaterM3);
    EXPECT_NEAR(reference.stats.rainM3, plain.stats.rainM3, 1e-12 * plain.stats.rainM3);
    EXPECT_TRUE(sameBits(reference.stats.inflowM3, plain.stats.inflowM3));
    EXPECT_GT(reference.stats.outflowM3, 0.0);  // the open edges and the level took water out
    EXPECT_GT(reference.stats.rainM3, 0.0);
  }
  struct Variant {
    const char* name;
    DistributedOptions options;
  };
  std::vector<Variant> variants;
  variants.push_back({"default (4 blocks per rank, balanced by work)", {}});
  {
    DistributedOptions o;
    o.blockWidth = 12;
    o.blockHeight = 11;
    o.rebalanceEvery = 10;
    o.idleWeight = 0.01;
    variants.push_back({"12x11 blocks, re-balanced every 10 steps", o});
  }
  {
    DistributedOptions o;
    o.blocksPerRank = 1;
    o.skipIdle = false;
    o.balanceAtStart = false;
    variants.push_back({"1 block per rank, no idle skipping", o});
  }
  for (const auto& v : variants) {
    auto sim = DistributedSolver::create(scene.input, scene.params, v.options, cpuSolverFactory());
    ASSERT_TRUE(sim) << sim.message();
    feed(*sim, scene);
    sim->step(kFloodSteps);
    const Snapshot snap = snapshot(*sim);
    const long long idle = sumOver(sim->counters().idleBlockSteps);
    const long long active = sumOver(sim->counters().activeBlockSteps);
    if (worldRank() != 0) continue;
    const std::string what = std::string(v.name) + " on " + std::to_string(worldSize()) + " ranks";
    std::printf("%s: %d blocks, %lld block steps active, %lld idle, %zu re-balances\n", what.c_str(), sim->blockCount(),
                active, idle, sim->counters().rebalances.size());
    expectSame(reference, snap, what);
    if (v.options.blockWidth == 12) {
      EXPECT_GT(idle, 0) << what << ": dry blocks far from the water should have skipped steps";
      EXPECT_FALSE(sim->counters().rebalances.empty());
    }
    if (!v.options.skipIdle) {
      EXPECT_EQ(idle, 0);
    }
  }
  if (worldRank() == 0) {
    // The front crossed block borders: water now stands in cells far from where it started.
    const auto& st = reference.cells.state;
    int wetWest = 0, wetSouth = 0;
    for (int y = 0; y < 44; ++y) {
      for (int x = 0; x < 60; ++x) {
        const float h = st[4 * (size_t(y) * 60 + size_t(x))];
        if (h > 0.05f && x < 40 && y < 14) ++wetWest;
        if (h > 0.05f && x >= 48 && y >= 20) ++wetSouth;
      }
    }
    EXPECT_GT(wetWest, 10);
    EXPECT_GT(wetSouth, 10);
  }
}

// The local-inertial scheme (W30-W33) over ranks: its face discharges are the blocks' flux part,
// which the halos carry, so any split equals one process bit for bit.
TEST(SimDistributed, InertialFloodEqualsOneRankBitForBit) {
  auto scene = floodScene();
  scene.params.floodScheme = FloodScheme::kLocalInertial;
  scene.params.cflAlpha = 0.7f;
  Snapshot plain;
  if (worldRank() == 0) {
    auto cpu = CpuSolver::create(scene.input, scene.params);
    ASSERT_TRUE(cpu) << cpu.message();
    feed(*cpu, scene);
    cpu->step(kFloodSteps);
    plain = snapshot(*cpu);
    EXPECT_GT(plain.stats.outflowM3, 0.0);
  }
  DistributedOptions small;
  small.blockWidth = 12;
  small.blockHeight = 11;
  small.rebalanceEvery = 10;
  for (const auto& options : {DistributedOptions{}, small}) {
    auto sim = DistributedSolver::create(scene.input, scene.params, options, cpuSolverFactory());
    ASSERT_TRUE(sim) << sim.message();
    feed(*sim, scene);
    sim->step(kFloodSteps);
    const Snapshot snap = snapshot(*sim);
    if (worldRank() != 0) continue;
    const std::string what = "inertial, " + std::to_string(sim->blockCount()) + " blocks on " +
                             std::to_string(worldSize()) + " ranks vs CpuSolver";
    expectSame(plain, snap, what, false);
    EXPECT_NEAR(snap.stats.storedWaterM3, plain.stats.storedWaterM3, 1e-9 * plain.stats.storedWaterM3) << what;
  }
}

// Halos carry what the next steps read (haloParts): a flood in rain over a Green-Ampt soil
// carries the state and the infiltrated sum and depth error of each halo cell, 28 B; once
// erosion and thermal weathering are turned on (setParams) the four layers as well, 44 B. The
// other sums are summed by their owner alone. Any split equals one process bit for bit, before
// and after the change.
TEST(SimDistributed, HalosCarryOnlyWhatTheStepsRead) {
  auto scene = floodScene();
  const int w = scene.input.baseM.width, h = scene.input.baseM.height;
  scene.input.infiltrationMmPerHour = gis::Grid<float>(w, h, 10.0f);
  scene.input.infiltrationSuctionM = gis::Grid<float>(w, h, 0.033f);
  SimParams eroding = scene.params;
  eroding.erosionEnabled = true;
  eroding.thermalEnabled = true;
  EXPECT_EQ(haloParts(scene.params), kBlockState | kBlockCarried);
  EXPECT_EQ(haloParts(eroding), kBlockState | kBlockCarried | kBlockLayers);
  auto run = [&](Solver& sim, std::vector<double>* bytesPerHaloCell) {
    feed(sim, scene);
    auto* d = dynamic_cast<DistributedSolver*>(&sim);
    double bytes = 0, haloCells = 0;
    auto tally = [&] {  // this phase's halo bytes over the halo cells the blocks received
      const DistributedCounters& c = d->counters();
      double b = c.haloBytesSent + c.haloBytesLocal, cells = c.computedCells - c.interiorCells;
      MPI_Allreduce(MPI_IN_PLACE, &b, 1, MPI_DOUBLE, MPI_SUM, MPI_COMM_WORLD);
      MPI_Allreduce(MPI_IN_PLACE, &cells, 1, MPI_DOUBLE, MPI_SUM, MPI_COMM_WORLD);
      bytesPerHaloCell->push_back((b - bytes) / (cells - haloCells));
      bytes = b, haloCells = cells;
    };
    sim.step(kFloodSteps / 2);
    if (d && bytesPerHaloCell) tally();
    ASSERT_TRUE(sim.setParams(eroding));
    sim.step(kFloodSteps / 2);
    if (d && bytesPerHaloCell) tally();
  };
  Snapshot plain;
  if (worldRank() == 0) {
    auto cpu = CpuSolver::create(scene.input, scene.params);
    ASSERT_TRUE(cpu) << cpu.message();
    run(*cpu, nullptr);
    plain = snapshot(*cpu);
    EXPECT_GT(plain.stats.infiltratedM3, 0.0);
  }
  DistributedOptions options;
  options.blocksPerRank = 2;
  options.skipIdle = false;  // every block steps, so its halo is received every step
  auto sim = DistributedSolver::create(scene.input, scene.params, options, cpuSolverFactory());
  ASSERT_TRUE(sim) << sim.message();
  std::vector<double> bytesPerHaloCell;
  run(*sim, &bytesPerHaloCell);
  const Snapshot snap = snapshot(*sim);
  if (worldRank() != 0) return;
  const std::string what = std::to_string(sim->blockCount()) + " blocks on " + std::to_string(worldSize()) + " ranks";
  std::printf("%s: %.1f B a halo cell in water only, %.1f B eroding; infiltrated %.3f m3\n", what.c_str(),
              bytesPerHaloCell[0], bytesPerHaloCell[1], snap.stats.infiltratedM3);
  expectSame(plain, snap, what, false);
  EXPECT_NEAR(snap.stats.infiltratedM3, plain.stats.infiltratedM3, 1e-9 * plain.stats.infiltratedM3) << what;
  ASSERT_EQ(bytesPerHaloCell.size(), 2u);
  EXPECT_EQ(bytesPerHaloCell[0], 4.0 * (4 + kAccumCarried));
  EXPECT_EQ(bytesPerHaloCell[1], 4.0 * (4 + kAccumCarried + 4));
}

// A spin-up starts the clock before 0: the blocks' springs and levels must follow the run's clock
// (they once followed their own, from 0, and a scenario's spin-up fed the flood peak); so must a
// clock moved on by Solver::restartAt (a spin-up steady early).
TEST(SimDistributed, AClockStartedBeforeZeroReachesTheBlocks) {
  const auto scene = floodScene();
  auto sim = DistributedSolver::create(scene.input, scene.params, DistributedOptions{}, cpuSolverFactory());
  ASSERT_TRUE(sim) << sim.message();
  auto run = [&](Solver& s) {
    s.startClockAt(-20.0);
    feed(s, scene);
    s.step(kFloodSteps / 2);
    s.restartAt(-10.0);
    s.step(kFloodSteps - kFloodSteps / 2);
  };
  run(*sim);
  const Snapshot snap = snapshot(*sim);
  if (worldRank() != 0) return;
  auto cpu = CpuSolver::create(scene.input, scene.params);
  ASSERT_TRUE(cpu) << cpu.message();
  run(*cpu);
  expectSame(snapshot(*cpu), snap, "clock started at -20 s on " + std::to_string(worldSize()) + " ranks", false);
  // Counted from the restart, the ramp later than in the run from 0: less came in.
  EXPECT_LT(snap.stats.inflowM3, floodReference().stats.inflowM3);
}

TEST(SimDistributed, TooNarrowHaloDiffers) {
  // A 1-cell halo is narrower than what one step reads: the split must then differ from the
  // reference, which shows the comparisons above can fail.
  const auto scene = floodScene();
  DistributedOptions o;
  o.blockWidth = 20;
  o.blockHeight = 15;
  o.halo = 1;
  auto sim = DistributedSolver::create(scene.input, scene.params, o, cpuSolverFactory());
  ASSERT_TRUE(sim) << sim.message();
  feed(*sim, scene);
  sim->step(kFloodSteps);
  const Snapshot snap = snapshot(*sim);
  if (worldRank() != 0) return;
  const Snapshot reference = floodReference();
  EXPECT_GT(differing(reference.cells.state, snap.cells.state), 100u);
}

TEST(SimDistributed, ErosionEqualsOneRankBitForBit) {
  auto scene = erosionScene();
  for (bool diagonal : {false, true}) {
    scene.params.diagonalPipes = diagonal;
    Snapshot reference;
    if (worldRank() == 0) {
      auto ref = DistributedSolver::create(scene.input, scene.params, oneBlock(scene.input), cpuSolverFactory());
      ASSERT_TRUE(ref) << ref.message();
      ASSERT_TRUE(ref->addSource(scene.spring));
      ref->step(100);
      reference = snapshot(*ref);
      auto cpu = CpuSolver::create(scene.input, scene.params);
      ASSERT_TRUE(cpu) << cpu.message();
      ASSERT_TRUE(cpu->addSource(scene.spring));
      cpu->step(100);
      expectSame(reference, snapshot(*cpu), "erosion: one block vs CpuSolver", false);
    }
    DistributedOptions o;
    o.blocksPerRank = 3;
    auto sim = DistributedSolver::create(scene.input, scene.params, o, cpuSolverFactory());
    ASSERT_TRUE(sim) << sim.message();
    ASSERT_TRUE(sim->addSource(scene.spring));
    sim->step(100);
    const Snapshot snap = snapshot(*sim);
    if (worldRank() != 0) continue;
    const std::string what = std::string("erosion") + (diagonal ? " (diagonal pipes)" : "") + " on " +
                             std::to_string(worldSize()) + " ranks";
    expectSame(reference, snap, what);
    // Material moved (eroded, carried, left through the south edge) and is all accounted for.
    const SimStats& s = snap.stats;
    const double moved = s.suspendedM3 + s.sedimentOutflowM3;
    const double balance = s.materialM3 + s.sedimentOutflowM3 - s.initialMaterialM3;
    std::printf("%s: suspended %.4f m3, carried out %.4f m3, material balance %.3g m3 of %.1f m3\n", what.c_str(),
                s.suspendedM3, s.sedimentOutflowM3, balance, s.initialMaterialM3);
    EXPECT_GT(moved, 0.5);
    EXPECT_LT(std::abs(balance), 1e-5 * s.initialMaterialM3);
  }
}

// A shared folder for this run's files.
std::filesystem::path sharedTempDir(const std::string& name) { return test::sharedTempDir("strata-mpi-" + name); }

void writeFile(const std::filesystem::path& p, const std::string& bytes) {
  std::ofstream(p, std::ios::binary).write(bytes.data(), std::streamsize(bytes.size()));
}
std::string readFile(const std::filesystem::path& p) {
  std::ifstream f(p, std::ios::binary);
  std::stringstream ss;
  ss << f.rdbuf();
  return ss.str();
}

DistributedOptions checkpointOptions() {
  DistributedOptions o;
  o.blockWidth = 12;
  o.blockHeight = 11;
  o.rebalanceEvery = 15;  // the blocks have moved by the checkpoint
  o.idleWeight = 0.01;
  return o;
}

TEST(SimDistributed, CheckpointResumesBitForBit) {
  // Stop after 40 steps, each rank writing its part to its own file; a new run of the scene
  // (fresh solver, its blocks dealt afresh) restores from the files and takes the other 40.
  const auto scene = floodScene();
  const auto dir = sharedTempDir("checkpoint");
  const auto file = dir / ("rank" + std::to_string(worldRank()) + ".state");
  std::vector<int> ownersAtCheckpoint;
  {
    auto first = DistributedSolver::create(scene.input, scene.params, checkpointOptions(), cpuSolverFactory());
    ASSERT_TRUE(first) << first.message();
    feed(*first, scene);
    first->step(40);
    writeFile(file, encodeState(first->saveState()));
    ownersAtCheckpoint = first->owners();
  }
  auto resumed = DistributedSolver::create(scene.input, scene.params, checkpointOptions(), cpuSolverFactory());
  ASSERT_TRUE(resumed) << resumed.message();
  feed(*resumed, scene);
  auto state = decodeState(readFile(file));
  ASSERT_TRUE(state) << state.message();
  const auto restored = resumed->restoreState(*state);
  ASSERT_TRUE(restored) << restored.message();
  EXPECT_EQ(resumed->owners(), ownersAtCheckpoint);
  EXPECT_EQ(resumed->counterStats().steps, 40);
  resumed->step(kFloodSteps - 40);
  const Snapshot snap = snapshot(*resumed);
  if (worldRank() == 0) {
    // The uninterrupted run: every split equals it (FloodEqualsOneRankBitForBit).
    expectSame(floodReference(), snap, "resumed vs uninterrupted on " + std::to_string(worldSize()) + " ranks");
    std::filesystem::remove_all(dir);
  }
  // A checkpoint of another block grid is refused on every rank, naming the mismatch.
  DistributedOptions other = checkpointOptions();
  other.blockWidth = 15;
  auto wrong = DistributedSolver::create(scene.input, scene.params, other, cpuSolverFactory());
  ASSERT_TRUE(wrong) << wrong.message();
  const auto refused = wrong->restoreState(*state);
  ASSERT_FALSE(refused);
  EXPECT_NE(refused.message().find("block grid"), std::string::npos) << refused.message();
}

TEST(SimDistributed, CheckpointAcrossJobs) {
  // Run by ctest as two mpirun jobs on the same number of ranks (STRATA_MPI_PHASE = write, then
  // resume): the first stops after 40 steps leaving one file per rank; the second, in fresh
  // processes, resumes from them and must equal an uninterrupted run.
  const char* phase = std::getenv("STRATA_MPI_PHASE");
  const char* dirEnv = std::getenv("STRATA_MPI_CHECKPOINT_DIR");
  if (!phase || !dirEnv) GTEST_SKIP() << "only as the ctest jobs sim_mpi_checkpoint_write / _resume";
  const std::filesystem::path dir(dirEnv);
  const auto file = dir / ("rank" + std::to_string(worldRank()) + "-of-" + std::to_string(worldSize()) + ".state");
  const auto scene = floodScene();
  auto sim = DistributedSolver::create(scene.input, scene.params, checkpointOptions(), cpuSolverFactory());
  ASSERT_TRUE(sim) << sim.message();
  feed(*sim, scene);
  if (std::string(phase) == "write") {
    std::filesystem::create_directories(dir);
    sim->step(40);
    writeFile(file, encodeState(sim->saveState()));
    return;
  }
  ASSERT_EQ(std::string(phase), "resume");
  ASSERT_TRUE(std::filesystem::exists(file)) << file << ": run the write job first";
  auto state = decodeState(readFile(file));
  ASSERT_TRUE(state) << state.message();
  ASSERT_TRUE(sim->restoreState(*state));
  sim->step(kFloodSteps - 40);
  const Snapshot snap = snapshot(*sim);
  if (worldRank() == 0) {
    expectSame(floodReference(), snap, "resumed in a new job vs uninterrupted");
  }
  MPI_Barrier(MPI_COMM_WORLD);
  std::filesystem::remove(file);
}

TEST(SimDistributed, ReadersAndWriteBlockAreCollective) {
  const auto scene = floodScene();
  auto sim = DistributedSolver::create(scene.input, scene.params, {}, cpuSolverFactory());
  ASSERT_TRUE(sim) << sim.message();
  auto ref = CpuSolver::create(scene.input, scene.params);
  ASSERT_TRUE(ref) << ref.message();
  // Rank 0 pours 1 m of water on a rectangle across block borders (the other ranks pass
  // nothing); both runs take it and 20 steps.
  const CellBlock before = ref->readBlock(20, 10, 25, 20, kBlockState);
  CellBlock pour = before;
  for (size_t i = 0; i < pour.cells(); ++i) pour.state[4 * i] += 1.0f;
  ref->writeBlock(pour);
  sim->writeBlock(worldRank() == 0 ? pour : CellBlock{});
  ref->step(20);
  sim->step(20);
  const auto depth = sim->readWaterDepth();
  const auto vel = sim->readVelocity();
  const auto layers = sim->readLayers();
  const auto susp = sim->readSuspended();
  const CellBlock part = sim->readBlock(7, 3, 33, 29, kBlockState | kBlockLayers);
  if (worldRank() != 0) {
    EXPECT_EQ(depth.size(), 0u);  // only rank 0 gets the grids
    EXPECT_TRUE(part.state.empty());
    return;
  }
  EXPECT_TRUE(sameBits(depth.data, ref->readWaterDepth().data));
  EXPECT_TRUE(sameBits(vel.uMS.data, ref->readVelocity().uMS.data));
  EXPECT_TRUE(sameBits(vel.vMS.data, ref->readVelocity().vMS.data));
  EXPECT_TRUE(sameBits(susp.data, ref->readSuspended().data));
  ASSERT_EQ(layers.size(), 4u);
  for (size_t l = 0; l < 4; ++l) EXPECT_TRUE(sameBits(layers[l].data, ref->readLayers()[l].data));
  const CellBlock refPart = ref->readBlock(7, 3, 33, 29, kBlockState | kBlockLayers);
  EXPECT_TRUE(sameBits(part.state, refPart.state));
  EXPECT_TRUE(sameBits(part.layers, refPart.layers));
}

// What each rank holds, read without a gather (what a scenario's maps are written from): the
// ranks' local rectangles cover every cell once, and their state, flood statistics and bed are
// the one-process solver's, bit for bit.
TEST(SimDistributed, LocalReadsCoverTheGridOnceAndEqualOneProcess) {
  const auto scene = floodScene();
  auto sim = DistributedSolver::create(scene.input, scene.params, {}, cpuSolverFactory());
  ASSERT_TRUE(sim) << sim.message();
  auto ref = CpuSolver::create(scene.input, scene.params);
  ASSERT_TRUE(ref) << ref.message();
  feed(*sim, scene);
  feed(*ref, scene);
  sim->enableFloodStats(0.01f);
  ref->enableFloodStats(0.01f);
  sim->step(30);
  ref->step(30);
  const int w = sim->grid().width, h = sim->grid().height;
  std::vector<int> covered(size_t(w) * size_t(h), 0);
  const FloodStats refFlood = ref->readFloodStats();
  for (const auto& r : sim->localRects()) {
    for (int y = r.y; y < r.y + r.height; ++y) {
      for (int x = r.x; x < r.x + r.width; ++x) covered[size_t(y) * size_t(w) + size_t(x)] += 1;
    }
    const CellBlock mine = sim->readLocal(r, kBlockState | kBlockLayers);
    const CellBlock theirs = ref->readBlock(r.x, r.y, r.width, r.height, kBlockState | kBlockLayers);
    EXPECT_EQ(mine.rect.x, r.x);
    EXPECT_TRUE(sameBits(mine.state, theirs.state));
    EXPECT_TRUE(sameBits(mine.layers, theirs.layers));
    const FloodStats f = sim->readLocalFloodStats(r), g = cropFloodStats(refFlood, r);
    ASSERT_EQ(f.maxDepthM.width, r.width);
    EXPECT_TRUE(sameBits(f.maxDepthM.data, g.maxDepthM.data));
    EXPECT_TRUE(sameBits(f.maxSpeedMS.data, g.maxSpeedMS.data));
    EXPECT_TRUE(sameBits(f.arrivalS.data, g.arrivalS.data));
    EXPECT_TRUE(sameBits(f.wetDurationS.data, g.wetDurationS.data));
    EXPECT_TRUE(sameBits(sim->readLocalBed(r).data, cropGrid(ref->readBed(), r).data));
  }
  MPI_Allreduce(MPI_IN_PLACE, covered.data(), int(covered.size()), MPI_INT, MPI_SUM, MPI_COMM_WORLD);
  EXPECT_TRUE(std::all_of(covered.begin(), covered.end(), [](int c) { return c == 1; }));
  float wettest = 0;
  for (float v : refFlood.maxDepthM.data) wettest = std::max(wettest, v);
  EXPECT_GT(wettest, 0.1f);  // the statistics compared hold a flood, not only zeros
}

TEST(SimDistributed, BadRankInputFailsOnEveryRank) {
  // Rank 1's (or, alone, rank 0's) windows cannot be read: every rank gets the failure, named
  // (a failure of rank 0, the lead, carries no rank).
  const auto scene = floodScene();
  RegionSource region = regionSourceOf(scene.input);
  const int bad = worldSize() > 1 ? 1 : 0;
  auto inner = region.read;
  region.read = [inner, bad](const CellRect& w) -> Result<SimInput> {
    if (worldRank() == bad)
      return fail("dem.tif: cannot read window at (" + std::to_string(w.x) + ", " + std::to_string(w.y) + ")");
    return inner(w);
  };
  DistributedOptions o;
  o.balanceAtStart = false;
  auto sim = DistributedSolver::create(region, scene.params, o, cpuSolverFactory());
  ASSERT_FALSE(sim);
  const std::string where = bad > 0 ? "rank " + std::to_string(bad) + ": block" : "block";
  EXPECT_EQ(sim.message().rfind(where, 0), 0u) << sim.message();
  EXPECT_NE(sim.message().find("dem.tif: cannot read window"), std::string::npos) << sim.message();
}

TEST(SimDistributed, EachLocalRankGetsItsOwnGpu) {
  // All ranks of a ctest run share one node: local rank = world rank.
  EXPECT_EQ(localRank(MPI_COMM_WORLD), worldRank());
  EXPECT_EQ(rankEglDevice(MPI_COMM_WORLD), "gpu:" + std::to_string(worldRank()));
}

// ---------------------------------------------------------------------------------------------
// The pieces (no MPI needed beyond the reduction).

TEST(SimDistributedParts, ExactSumIsOrderIndependent) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> mag(-30, 10);
  std::vector<double> terms;
  for (int i = 0; i < 20000; ++i) terms.push_back((i % 2 ? -1 : 1) * std::pow(2.0, mag(rng)) * 1.2345);
  ExactSum a, b;
  for (double t : terms) a.add(t);
  std::shuffle(terms.begin(), terms.end(), rng);
  for (double t : terms) b.add(t);
  EXPECT_TRUE(a.fixed == b.fixed);
  // Against a long double sum: rounding of each term to 2^-64 only.
  long double ref = 0;
  for (double t : terms) ref += t;
  EXPECT_NEAR(double(ref), a.value(), 1e-9);
  ExactSum c;
  c.add(std::nan(""));
  EXPECT_TRUE(std::isnan(c.value()));
  // Over ranks: each rank adds its share; the total equals the one-process sum on every rank.
  ExactSum mine;
  for (size_t i = size_t(worldRank()); i < terms.size(); i += size_t(worldSize())) mine.add(terms[i]);
  allreduceExact(&mine, 1, MPI_COMM_WORLD);
  EXPECT_TRUE(mine.fixed == a.fixed);
}

TEST(SimDistributedParts, BlocksHalosAndPartition) {
  const auto g = detail::BlockGrid::make(60, 44, 4, 4, 0, 0, 8);
  EXPECT_EQ(g.count(), 16);  // deals evenly to 4 ranks
  const auto square = detail::BlockGrid::make(512, 512, 2, 4, 0, 0, 8);
  EXPECT_EQ(square.count(), 8);
  EXPECT_EQ(detail::BlockGrid::make(512, 512, 4, 1, 0, 0, 8).blockWidth, 256);
  // Every halo cell of every block comes from exactly one piece, from the block that owns it.
  const auto pieces = detail::haloPieces(g);
  for (int d = 0; d < g.count(); ++d) {
    const CellRect e = g.extent(d), in = g.interior(d);
    std::vector<int> hits(size_t(e.width) * size_t(e.height), 0);
    for (const auto& p : pieces) {
      if (p.dst != d) continue;
      for (int y = p.rect.y; y < p.rect.y + p.rect.height; ++y) {
        for (int x = p.rect.x; x < p.rect.x + p.rect.width; ++x) {
          EXPECT_EQ(g.blockAt(x, y), p.src);
          ++hits[size_t(y - e.y) * size_t(e.width) + size_t(x - e.x)];
        }
      }
    }
    for (int y = e.y; y < e.y + e.height; ++y) {
      for (int x = e.x; x < e.x + e.width; ++x) {
        const bool interior = x >= in.x && y >= in.y && x < in.x + in.width && y < in.y + in.height;
        EXPECT_EQ(hits[size_t(y - e.y) * size_t(e.width) + size_t(x - e.x)], interior ? 0 : 1);
      }
    }
  }
  // The Hilbert order visits every block once, each step to a grid neighbour (power-of-two grid).
  const auto order = detail::hilbertOrder(8, 8);
  std::vector<int> sorted = order;
  std::sort(sorted.begin(), sorted.end());
  for (int i = 0; i < 64; ++i) EXPECT_EQ(sorted[size_t(i)], i);
  for (size_t k = 1; k < order.size(); ++k) {
    EXPECT_EQ(std::abs(order[k] % 8 - order[k - 1] % 8) + std::abs(order[k] / 8 - order[k - 1] / 8), 1);
  }
  // Work-weighted cut: 4 heavy blocks among 60 idle ones end up on different ranks.
  std::vector<double> w(64, 0.01);
  for (int b : {0, 9, 18, 27}) w[size_t(b)] = 1.0;
  const auto owner = detail::partition(order, w, 4);
  std::vector<int> heavyRanks;
  for (int b : {0, 9, 18, 27}) heavyRanks.push_back(owner[size_t(b)]);
  std::sort(heavyRanks.begin(), heavyRanks.end());
  EXPECT_EQ(heavyRanks, (std::vector<int>{0, 1, 2, 3}));
  EXPECT_LT(detail::imbalance(owner, w, 4), 1.4);
  std::vector<int> even(64);
  for (int b = 0; b < 64; ++b) even[size_t(b)] = b / 16;
  EXPECT_GT(detail::imbalance(even, w, 4), 1.8);
}

}  // namespace
}  // namespace strata::sim
