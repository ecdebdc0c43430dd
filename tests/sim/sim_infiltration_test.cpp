// Infiltration (W11b, issue 31): a constant loss takes rate x wet area x time out of the water
// and the balance still closes; Green-Ampt's cumulative infiltration under ponding follows its
// analytic curve at any time step and goes on from where it was through a restart.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>

#include <strata/sim/cpu_solver.hpp>

#include "infiltration_cases.hpp"
#include "runoff_scenes.hpp"

namespace strata::sim {
namespace {

// The kinematic plane of sim_runoff_test.cpp (600 x 400 m, 5 %, n 0.05) under 40 mm/h of rain on
// a soil losing 15 mm/h: every cell is wet from the first step (rain lands before the loss), so the
// soil takes exactly 15 mm/h x the plane x the hour, and the runoff is that of 25 mm/h of rain:
// the kinematic wave's storage at i = 25 mm/h, the same at every step.
TEST(SimInfiltrationCpu, ConstantLossTakesRateTimesWetAreaTimesTimeAtEveryStep) {
  constexpr double kL = 600, kW = 400, kS = 0.05, kN = 0.05, kCell = 10, kLossMmH = 15;
  const double area = kL * kW;
  const double expectedLoss = kLossMmH / 3.6e6 * area * 3600.0;
  const double ref = kW * test::kinematicStoragePerWidth(kL, (40.0 - kLossMmH) / 3.6e6, kS, kN);
  for (const float maxStep : {30.0f, 2.0f}) {
    SimInput in = test::rainPlane(kL, kW, kS, kCell);
    in.infiltrationMmPerHour = gis::Grid<float>(in.baseM.width, in.baseM.height, float(kLossMmH));
    auto sim = CpuSolver::create(in, test::rainParams(float(kN), 40.0f, maxStep));
    ASSERT_TRUE(sim) << sim.message();
    sim->advance(3600.0);
    const auto st = sim->stats();
    std::printf("step cap %.1f s: infiltrated %.3f m3 (expected %.3f), stored %.1f m3 (kinematic %.1f), %lld steps\n",
                maxStep, st.infiltratedM3, expectedLoss, st.storedWaterM3, ref, st.steps);
    EXPECT_NEAR(st.infiltratedM3, expectedLoss, 1e-5 * expectedLoss) << "step cap " << maxStep;
    EXPECT_NEAR(st.waterBalanceM3(), 0.0, 1e-5 * st.rainM3) << "step cap " << maxStep;
    EXPECT_NEAR(st.storedWaterM3, ref, 0.05 * ref) << "step cap " << maxStep;
  }
}

// Rain lighter than the soil can take: all of it goes in, none is left on the ground.
TEST(SimInfiltrationCpu, RainBelowTheCapacityAllSoaksIn) {
  auto sim = CpuSolver::create(test::infiltrationBasin(0.0), test::basinParams(5.0f, 60.0f));
  ASSERT_TRUE(sim) << sim.message();
  sim->advance(3600.0);
  const auto st = sim->stats();
  EXPECT_GT(st.rainM3, 0.0);
  EXPECT_NEAR(st.infiltratedM3, st.rainM3, 1e-6 * st.rainM3);
  EXPECT_LT(st.storedWaterM3, 1e-6 * st.rainM3);
}

// 0.2 m of still water on a flat closed basin over a Green-Ampt soil (Ks 10 mm/h, psi dtheta
// 33 mm): ponded throughout, so each cell's cumulative infiltration at t is F with
// F - G ln(1 + F / G) = Ks t. Step caps of 15 s (CFL decides), 3 s and 0.5 s. The balance's
// bound is the other solver tests' for float32 depths (each step's ~1e-5 m loss off 0.2 m rounds
// by up to 1.5e-8 m; measured 1.1e-6 of the water after 1,200 steps).
TEST(SimInfiltrationCpu, GreenAmptUnderPondingFollowsItsCurveAtEveryStep) {
  const double area = test::basinAreaM2();
  const double expected = test::greenAmptDepthM(3600.0) * area;
  for (const float maxStep : {15.0f, 3.0f, 0.5f}) {
    auto sim = CpuSolver::create(test::infiltrationBasin(0.2), test::basinParams(0.0f, maxStep));
    ASSERT_TRUE(sim) << sim.message();
    sim->advance(3600.0);
    const auto st = sim->stats();
    std::printf("step cap %.1f s: F(1 h) %.6f m (Green-Ampt %.6f m), %lld steps\n", maxStep, st.infiltratedM3 / area,
                expected / area, st.steps);
    EXPECT_NEAR(st.infiltratedM3, expected, 2e-4 * expected) << "step cap " << maxStep;
    EXPECT_NEAR(st.waterBalanceM3(), 0.0, 1e-5 * st.initialWaterM3) << "step cap " << maxStep;
  }
}

// The soil keeps what it took in through a restart (a spin-up's end): the second half hour takes
// F(1 h) - F(30 min), not another F(30 min) from a dry soil.
TEST(SimInfiltrationCpu, RestartKeepsTheSoilsState) {
  const double area = test::basinAreaM2();
  auto sim = CpuSolver::create(test::infiltrationBasin(0.2), test::basinParams(0.0f, 15.0f));
  ASSERT_TRUE(sim) << sim.message();
  sim->advance(1800.0);
  sim->restartAt(0.0);
  EXPECT_EQ(sim->stats().infiltratedM3, 0.0);
  EXPECT_NEAR(sim->stats().waterBalanceM3(), 0.0, 1e-5 * sim->stats().initialWaterM3);
  sim->advance(1800.0);
  const auto st = sim->stats();
  const double expected = (test::greenAmptDepthM(3600.0) - test::greenAmptDepthM(1800.0)) * area;
  EXPECT_NEAR(st.infiltratedM3, expected, 2e-4 * expected);
  EXPECT_NEAR(st.waterBalanceM3(), 0.0, 1e-5 * st.initialWaterM3);
}

TEST(SimInfiltrationCpu, NegativeOrMismatchedSoilIsRefused) {
  SimInput in = test::infiltrationBasin(0.2);
  in.infiltrationMmPerHour.at(3, 2) = -1.0f;
  auto bad = CpuSolver::create(in, test::basinParams(0.0f, 15.0f));
  ASSERT_FALSE(bad);
  EXPECT_EQ(bad.message(), "sim input: infiltrationMmPerHour has a negative value at cell (3, 2)");
  in = test::infiltrationBasin(0.2);
  in.infiltrationMmPerHour = {};
  bad = CpuSolver::create(in, test::basinParams(0.0f, 15.0f));
  ASSERT_FALSE(bad);
  EXPECT_EQ(bad.message(), "sim input: infiltrationSuctionM without a rate");
}

}  // namespace
}  // namespace strata::sim
