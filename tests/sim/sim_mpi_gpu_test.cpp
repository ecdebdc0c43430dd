// The distributed run with GL blocks (label gpu; llvmpipe here): each rank makes its own headless
// context on the device rankEglDevice() names (its own GPU on a GPU node: one per local rank;
// Mesa surfaceless here), and the split run must equal one GlSolver bit for bit, idle blocks
// skipping included.
#include <gtest/gtest.h>
#include <mpi.h>

#include <cstdio>
#include <optional>
#include <string>

#include <strata/gl/context.hpp>
#include <strata/sim/gl/gl_solver.hpp>

#include "mpi_compare.hpp"

namespace strata::sim {
namespace {

using namespace test_mpi;

TEST(SimDistributedGl, FloodOnGlBlocksEqualsOneGlSolver) {
  gl::HeadlessOptions opt;
  opt.device = rankEglDevice(MPI_COMM_WORLD);
  opt.debugOutput = false;
  auto ctx = gl::HeadlessContext::create(opt);
  int ok = ctx ? 1 : 0, all = 0;
  MPI_Allreduce(&ok, &all, 1, MPI_INT, MPI_MIN, MPI_COMM_WORLD);
  ASSERT_TRUE(all) << (ctx ? "another rank has no GL context" : ctx.message());
  // The flood scene without its rain and level, so the western blocks start dry and idle.
  auto scene = floodScene();
  scene.input.rainMmPerHour = {};
  const int steps = 40;
  Snapshot reference;
  if (worldRank() == 0) {
    auto one = GlSolver::create(scene.input, scene.params);
    ASSERT_TRUE(one) << one.message();
    ASSERT_TRUE(one->addSource(scene.spring));
    one->enableFloodStats(0.01f);
    one->step(steps);
    reference = snapshot(*one);
  }
  DistributedOptions o;
  o.blockWidth = 20;
  o.blockHeight = 22;
  auto sim = DistributedSolver::create(scene.input, scene.params, o, glSolverFactory());
  ASSERT_TRUE(sim) << sim.message();
  ASSERT_TRUE(sim->addSource(scene.spring));
  sim->enableFloodStats(0.01f);
  sim->step(steps);
  const Snapshot snap = snapshot(*sim);
  const long long idle = sumOver(sim->counters().idleBlockSteps);
  if (worldRank() != 0) return;
  std::printf("GL blocks on %d ranks (%s, device %s): %lld block steps idle\n", worldSize(),
              ctx->info().renderer.c_str(), opt.device.c_str(), idle);
  expectSame(reference, snap, "GL blocks vs one GlSolver", false);
  EXPECT_NEAR(snap.stats.storedWaterM3, reference.stats.storedWaterM3, 1e-9 * reference.stats.storedWaterM3);
  EXPECT_GT(idle, 0);
}

}  // namespace
}  // namespace strata::sim
