// The CPU reference water solver against analytic solutions and exact budgets
// (docs/sim-water.md lists which test pins which equation).
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <utility>
#include <vector>

#include <strata/sim/bookkeeping.hpp>
#include <strata/sim/cpu_solver.hpp>

#include "sim_scenes.hpp"

namespace strata::sim {
namespace {

using test::fourLayers;

using test::floodParams;
using test::pipeParams;

void expectLakeAtRest(const SimParams& params, int steps) {
  const auto in = test::lakeAtRest(48, 2000.0);
  auto sim = CpuSolver::create(in, params);
  ASSERT_TRUE(sim) << sim.message();
  sim->step(steps);
  const auto h = sim->readWaterDepth();
  const auto bed = sim->readBed();
  const auto vel = sim->readVelocity();
  double maxDev = 0, maxSpeed = 0;
  int wet = 0, dry = 0;
  for (size_t i = 0; i < h.size(); ++i) {
    maxSpeed = std::max(maxSpeed, double(std::hypot(vel.uMS.data[i], vel.vMS.data[i])));
    if (h.data[i] <= 0.0f) {
      ++dry;
      continue;
    }
    ++wet;
    maxDev = std::max(maxDev, std::abs(double(bed.data[i]) + double(h.data[i]) - 3.0));
  }
  ::testing::Test::RecordProperty("max_surface_deviation_m", std::to_string(maxDev));
  ::testing::Test::RecordProperty("max_speed_ms", std::to_string(maxSpeed));
  std::printf("lake at rest (model %d, %d steps): max surface deviation %.3g m, max speed %.3g m/s, %d wet, %d dry\n",
              int(params.waterModel), steps, maxDev, maxSpeed, wet, dry);
  EXPECT_GT(dry, 20);  // the islands are there
  // Issue 5's bounds: float32 depths of a few metres carry ~2.4e-7 m of rounding, so 1e-5 m
  // leaves room for rounding only, not for a spurious current.
  EXPECT_LT(maxDev, 1e-5);
  EXPECT_LT(maxSpeed, 1e-5);
}

TEST(SimWaterCpu, PipeLakeAtRestStaysFlat) { expectLakeAtRest(pipeParams(), 1000); }
TEST(SimWaterCpu, DiagonalPipeLakeAtRestStaysFlat) {
  auto p = pipeParams();
  p.diagonalPipes = 1;
  expectLakeAtRest(p, 1000);
}
TEST(SimWaterCpu, FloodLakeAtRestStaysFlat) { expectLakeAtRest(floodParams(), 1000); }
TEST(SimWaterCpu, FloodLakeAtRestStaysFlatWithMcSlopes) {
  auto p = floodParams();
  p.slopeLimiter = SlopeLimiter::kMonotonizedCentral;
  expectLakeAtRest(p, 1000);
}

void expectClosedBoxConserves(const SimParams& params, int n, int steps) {
  auto sim = CpuSolver::create(test::sloshingBox(n), params);
  ASSERT_TRUE(sim) << sim.message();
  const double v0 = sim->stats().storedWaterM3;
  sim->step(steps);
  const auto st = sim->stats();
  const double rel = std::abs(st.storedWaterM3 - v0) / v0;
  std::printf("closed box (model %d, %dx%d): %lld steps, %.1f s, relative volume change %.3g\n", int(params.waterModel),
              n, n, st.steps, st.timeS, rel);
  // Every face flux is added to one cell and taken from the other with the same float value;
  // what is left is float32 rounding of the depth updates, unbiased and averaging over 4096
  // cells (measured 1e-8 for pipes, 1.4e-7 for flood mode); 1e-6 is issue 5's bound.
  EXPECT_LT(rel, 1e-6);
  EXPECT_GT(st.timeS, 0.0);
}

TEST(SimWaterCpu, PipeClosedBoxConservesVolume) { expectClosedBoxConserves(pipeParams(), 64, 10000); }
TEST(SimWaterCpu, FloodClosedBoxConservesVolume) { expectClosedBoxConserves(floodParams(), 32, 10000); }
TEST(SimWaterCpu, DiagonalPipeClosedBoxConservesVolume) {
  auto p = pipeParams();
  p.diagonalPipes = 1;
  expectClosedBoxConserves(p, 32, 10000);
}

// W1b: with only axis pipes a mound of water spreads further along the axes than along the
// diagonals; the diagonal pipes make the spread rounder.
TEST(SimWaterCpu, DiagonalPipesSpreadMoreEvenly) {
  const int n = 61, c = 30;
  SimInput in;
  in.baseM = gis::Grid<float>(n, n, 100.0f);
  in.waterDepthM = gis::Grid<float>(n, n);
  in.rowDxM = {1.0};
  in.dyM = 1.0;
  in.datumM = 100.0;
  fourLayers(in, 0, 0, 0, 0);
  for (int y = c - 2; y <= c + 2; ++y) {
    for (int x = c - 2; x <= c + 2; ++x) in.waterDepthM.at(x, y) = 2.0f;
  }
  auto reach = [&](uint32_t diagonal) {
    auto p = pipeParams();
    p.pipeAreaM2 = 1.0f;
    p.maxDtS = 0.05f;
    p.diagonalPipes = diagonal;
    auto sim = CpuSolver::create(in, p);
    EXPECT_TRUE(sim) << sim.message();
    sim->step(120);
    const auto h = sim->readWaterDepth();
    // Distance (m) from the centre to the last cell wetter than 1 mm, along +x and along x = y.
    double axis = 0, diag = 0;
    for (int k = 0; c + k < n; ++k) {
      if (h.at(c + k, c) > 1e-3f) axis = k;
      if (h.at(c + k, c + k) > 1e-3f) diag = k * std::sqrt(2.0);
    }
    return diag / axis;
  };
  const double four = reach(0), eight = reach(1);
  std::printf("spread: diagonal / axis reach %.3f with 4 pipes, %.3f with 8\n", four, eight);
  // A circle has ratio 1. The 4-pipe spread is already fairly round here (measured 0.962);
  // the 8 pipes with the isotropic weights halve the gap (measured 1.018). With equal areas on
  // all 8 pipes it overshoots to 1.23, which this bound would catch.
  EXPECT_LT(std::abs(eight - 1.0), std::abs(four - 1.0));
  EXPECT_LT(std::abs(eight - 1.0), 0.03);
}

TEST(SimWaterCpu, RainAddsItsVolume) {
  for (auto params : {pipeParams(), floodParams()}) {
    auto in = test::sloshingBox(32);
    in.waterDepthM = {};  // dry box: all water comes from the rain
    in.rainMmPerHour = gis::Grid<float>(32, 32);
    for (int y = 0; y < 32; ++y) {
      for (int x = 0; x < 32; ++x) in.rainMmPerHour.at(x, y) = float(x < 16 ? 200.0 : 50.0);
    }
    params.rainMmPerHour = 100.0f;
    params.maxDtS = 0.5f;
    auto sim = CpuSolver::create(in, params);
    ASSERT_TRUE(sim) << sim.message();
    sim->advance(1800.0);
    const auto st = sim->stats();
    // Expected: 200/50 mm/h on halves plus 100 mm/h uniform, for half an hour over 160 m x 160 m.
    const double expected = (0.5 * 300.0 + 0.5 * 150.0) / 1000.0 * 0.5 * 160.0 * 160.0;
    const double rel = std::abs(st.storedWaterM3 - st.rainM3) / st.rainM3;
    std::printf("rain (model %d): %lld steps, stored %.6f m3, rain %.6f m3 (expected %.6f), rel %.3g\n",
                int(params.waterModel), st.steps, st.storedWaterM3, st.rainM3, expected, rel);
    EXPECT_NEAR(st.timeS, 1800.0, 1e-6);
    EXPECT_NEAR(st.rainM3, expected, 1e-9 * expected);  // the bookkeeping is double
    // Each step adds ~1.4e-5 m of rain to depths up to 0.3 m, whose float32 spacing is up to
    // 3e-8 m: each addition is rounded by up to 1e-3 of itself, and as every cell adds the same
    // amount the roundings are correlated rather than averaging out. Measured 1.8e-5 (pipes)
    // and 2.3e-5 (flood) of the rain volume; the bound is 1e-4.
    EXPECT_LT(rel, 1e-4);
  }
}

TEST(SimWaterCpu, SourcesOutflowAndEvaporationBalance) {
  for (auto params : {pipeParams(), floodParams()}) {
    auto in = test::sloshingBox(40);
    params.openEdges = kEdgeEast;
    params.evaporationMmPerHour = 20.0f;
    auto sim = CpuSolver::create(in, params);
    ASSERT_TRUE(sim) << sim.message();
    Source spring;
    spring.cells = {{2, 10}, {2, 11}, {2, 12}};
    spring.dischargeM3S = TimeSeries({{0.0, 0.0}, {100.0, 6.0}, {300.0, 1.0}});
    ASSERT_TRUE(sim->addSource(spring));
    Source bad;
    bad.cells = {{40, 0}};
    const auto r = sim->addSource(bad);
    ASSERT_FALSE(r);
    EXPECT_NE(r.message().find("outside"), std::string::npos) << r.message();
    sim->advance(400.0);
    const auto st = sim->stats();
    // Hydrograph: 0 -> 6 m3/s over 100 s, 6 -> 1 over 200 s, then 1 m3/s held for 100 s (a time
    // series holds its last value).
    const double expectedInflow = 0.5 * 6.0 * 100.0 + 0.5 * 7.0 * 200.0 + 1.0 * 100.0;
    std::printf(
        "balance (model %d): inflow %.3f (expected %.3f) outflow %.3f evaporated %.3f stored %.3f -> %.3f, "
        "imbalance %.3g m3\n",
        int(params.waterModel), st.inflowM3, expectedInflow, st.outflowM3, st.evaporatedM3, st.initialWaterM3,
        st.storedWaterM3, st.waterBalanceM3());
    // Each step takes the hydrograph's exact integral over the step; the per-cell rates are
    // float32 (1e-7 relative).
    EXPECT_NEAR(st.inflowM3, expectedInflow, 1e-6 * expectedInflow);
    EXPECT_GT(st.outflowM3, 100.0);
    EXPECT_GT(st.evaporatedM3, 10.0);
    // The per-cell outflow and evaporation sums are compensated (W20), so what is left is the
    // float32 rounding of the depth updates in cells that drain every step for ~4000 steps:
    // measured 0.28 m3 (pipes) and 0.05 m3 (flood) of the ~5e4 m3 moved; bound 1e-5 of it.
    const double moved = st.initialWaterM3 + st.inflowM3 + st.outflowM3;
    EXPECT_LT(std::abs(st.waterBalanceM3()), 1e-5 * moved);
  }
}

// W34, issue 35: 150,000 float32 steps of rain on 1-1.5 m of water and a spring close the budget
// to 1e-5 of the water, with either scheme (before W34: 1.5e-3 and 2.6e-3).
TEST(SimWaterCpu, BalanceHoldsOver150kFloat32Steps) {
  for (auto scheme : {FloodScheme::kFiniteVolume, FloodScheme::kLocalInertial}) {
    auto sim = CpuSolver::create(test::longRainBox(), test::longRainParams(scheme));
    ASSERT_TRUE(sim) << sim.message();
    ASSERT_TRUE(sim->addSource(test::longRainSpring()));
    sim->step(int(test::kLongRainSteps));
    const auto st = sim->stats();
    const double water = st.initialWaterM3 + st.rainM3 + st.inflowM3;
    std::printf("scheme %d: %lld steps, %.1f s, rain %.2f inflow %.2f stored %.2f -> %.2f m3, balance %.2e\n",
                int(scheme), st.steps, st.timeS, st.rainM3, st.inflowM3, st.initialWaterM3, st.storedWaterM3,
                st.waterBalanceM3() / water);
    EXPECT_EQ(st.steps, test::kLongRainSteps);
    const double side = 5.0 * test::kLongRainCells;  // m
    EXPECT_NEAR(st.rainM3, 10.0 / 3.6e6 * 30000.0 * side * side, 1e-6 * st.rainM3);
    EXPECT_LT(std::abs(st.waterBalanceM3()), 1e-5 * water) << int(scheme);
  }
}

// W10 with sources, against its closed forms: a still, dry domain fed at r m/s takes
// dt = (alpha L / sqrt(g r))^(2/3); with wave speed S and no source, alpha L / S.
TEST(SimWaterCpu, StepCountsItsSources) {
  SimParams p = floodParams();
  p.cflAlpha = 0.5f;
  p.maxDtS = 1000.0f;
  const double g = p.gravityMS2, L = 20.0, r = 0.25;
  EXPECT_NEAR(stepDt(p, 0.0, L, r), std::pow(0.5 * L / std::sqrt(g * r), 2.0 / 3.0), 1e-9);
  EXPECT_NEAR(stepDt(p, 4.0, L), 0.5 * L / 4.0, 1e-12);
  const double both = stepDt(p, 4.0, L, r);  // dt (S + sqrt(g r dt)) = alpha L
  EXPECT_NEAR(both * (4.0 + std::sqrt(g * r * both)), 0.5 * L, 1e-9);
  EXPECT_EQ(stepDt(p, 0.0, L, 0.0), 1000.0);  // still and unfed: the cap
  // The local-inertial scheme (S = max sqrt(g h), W33): dt sqrt(S^2 + g r dt) = alpha L, longer
  // than the bound above and the same without a source or on a dry domain.
  SimParams in = p;
  in.floodScheme = FloodScheme::kLocalInertial;
  const double inertial = stepDt(in, 4.0, L, r);
  EXPECT_NEAR(inertial * std::sqrt(16.0 + g * r * inertial), 0.5 * L, 1e-9);
  EXPECT_GT(inertial, 1.2 * both);
  EXPECT_EQ(stepDt(in, 4.0, L), stepDt(p, 4.0, L));
  EXPECT_NEAR(stepDt(in, 0.0, L, r), stepDt(p, 0.0, L, r), 1e-12);
  // The rate bound: the hydrograph's peak inside the window, shared by the source's cells, over
  // the cell area; plus rain (uniform + the raster's maximum).
  Source s;
  s.cells = {{1, 1}, {2, 1}};
  s.dischargeM3S = TimeSeries({{0.0, 0.0}, {10.0, 80.0}, {20.0, 0.0}});
  p.rainMmPerHour = 36.0f;  // 1e-5 m/s
  SimInput grid;            // cells of 10 m x 4 m
  grid.baseM = gis::Grid<float>(4, 4);
  grid.rowDxM = {10.0};
  grid.dyM = 4.0;
  const auto cells = CellGrid::of(grid);
  EXPECT_NEAR(sourceDepthRate(p, 0.0, {s}, cells, 0.0, 5.0), 40.0 / 2.0 / 40.0 + 1e-5, 1e-9);    // Q(5) = 40
  EXPECT_NEAR(sourceDepthRate(p, 72.0, {s}, cells, 5.0, 30.0), 80.0 / 2.0 / 40.0 + 3e-5, 1e-9);  // peak 80
}

// Flood mode with a long step cap: a strong spring on a steep, dry hillside (the start of the
// Grand Canyon scenario in miniature). The CFL step of a dry domain is the cap, and the water a
// step pours in must not make that step too long for itself (W10): the balance holds to 1e-6 of
// the water moved whatever maxDtS is.
TEST(SimWaterCpu, FloodLongStepCapKeepsBalanceOnDrySlope) {
  for (float maxDt : {2.0f, 30.0f, 300.0f}) {
    auto p = floodParams();
    p.cflAlpha = 0.5f;
    p.maxDtS = maxDt;
    p.openEdges = kEdgeEast;
    p.manningN = 0.05f;
    auto sim = CpuSolver::create(test::steepDrySlope(), p);
    ASSERT_TRUE(sim) << sim.message();
    ASSERT_TRUE(sim->addSource(test::steepSlopeSpring()));
    sim->advance(600.0);
    const auto st = sim->stats();
    const double moved = st.initialWaterM3 + st.inflowM3 + st.outflowM3;
    std::printf(
        "dry slope, max step %.0f s: %lld steps, last dt %.3f s, inflow %.1f, outflow %.1f, stored %.1f, "
        "balance %.3g m3 (%.3g of the water moved)\n",
        double(maxDt), st.steps, st.lastDtS, st.inflowM3, st.outflowM3, st.storedWaterM3, st.waterBalanceM3(),
        st.waterBalanceM3() / moved);
    EXPECT_GT(st.outflowM3, 0.2 * st.inflowM3);  // the water reached the open edge
    EXPECT_LT(std::abs(st.waterBalanceM3()), 1e-6 * moved);
  }
}

// Ritter's dry dam break: h0 upstream of x0, dry downstream, frictionless, flat bed. For
// x0 - c0 t <= x <= x0 + 2 c0 t: h = (2 c0 - (x - x0)/t)^2 / (9 g), c0 = sqrt(g h0).
// Returns (relative L1 of depth, front travel error) at each time, with `perMetre` cells per metre.
std::vector<std::pair<double, double>> ritter(int perMetre, std::vector<double> times,
                                              SlopeLimiter slopes = SlopeLimiter::kMinmod, double lengthM = 400.0,
                                              double x0 = 200.0) {
  const int n = int(lengthM) * perMetre;
  const double h0 = 1.0, g = 9.81, dx = 1.0 / perMetre;
  SimInput in;
  in.baseM = gis::Grid<float>(n, 2, 500.0f);  // two rows: the smallest grid a simulation takes
  in.waterDepthM = gis::Grid<float>(n, 2);
  in.rowDxM = {dx};
  in.dyM = dx;
  in.datumM = 500.0;
  fourLayers(in, 0, 0, 0, 0);
  for (int y = 0; y < 2; ++y) {
    for (int x = 0; x < n; ++x) in.waterDepthM.at(x, y) = ((x + 0.5) * dx < x0) ? float(h0) : 0.0f;
  }
  auto p = floodParams();
  p.dryDepthM = 1e-6f;
  p.slopeLimiter = slopes;
  auto sim = CpuSolver::create(in, p);
  EXPECT_TRUE(sim) << sim.message();
  const double c0 = std::sqrt(g * h0);
  std::vector<std::pair<double, double>> out;
  for (double t : times) {
    sim->advance(t - sim->stats().timeS);
    const auto h = sim->readWaterDepth();
    double errSum = 0, refSum = 0, front = 0;
    for (int x = 0; x < n; ++x) {
      const double xc = (x + 0.5) * dx, num = h.at(x, 0);
      double exact = h0;
      if (xc - x0 > 2 * c0 * t)
        exact = 0;
      else if (xc - x0 > -c0 * t)
        exact = std::pow(2 * c0 - (xc - x0) / t, 2) / (9 * g);
      errSum += std::abs(num - exact) * dx;
      refSum += exact * dx;
      if (num > 1e-4 * h0) front = (x + 1.0) * dx;  // downstream edge of the last cell deeper than 0.1 mm
    }
    const double l1 = errSum / refSum, frontExact = x0 + 2 * c0 * t;
    const double frontErr = std::abs((front - x0) - (frontExact - x0)) / (frontExact - x0);
    std::printf("Ritter %s, dx=%.2f m, t=%.0f s: relative L1 %.4f, front %.2f m vs %.2f m (travel error %.3f)\n",
                slopes == SlopeLimiter::kMinmod ? "minmod" : "MC", dx, t, l1, front, frontExact, frontErr);
    out.emplace_back(l1, frontErr);
  }
  return out;
}

TEST(SimWaterCpu, FloodRitterDryDamBreak) {
  // L1: issue 5's bound (ANUGA's validation norm) on a 400 m channel, with either slope limiter
  // (W21); measured 0.0025 (minmod) and 0.0016 (MC) at 10 s and 20 s.
  for (const auto limiter : {SlopeLimiter::kMinmod, SlopeLimiter::kMonotonizedCentral}) {
    for (const auto& [l1, frontErr] : ritter(1, {10.0, 20.0}, limiter)) EXPECT_LT(l1, 0.10);
  }

  // Front: issue 5 asks for 5% of 2 c0 t. The depth near the front is tiny (below 1% of h0 over
  // its last 15%), and a finite-volume scheme resolves that thin tip only once the front has
  // crossed enough cells: the problem is self-similar, so the lag is a function of the cells
  // crossed (c0 t / dx), not of t or dx alone (docs/sim-water.md, "Known limits"). With MC
  // slopes and 1 m cells: 15.4% after 63 cells (10 s), 10.6% after 125, 5.0% after 500, 3.6% after
  // 1000 (160 s). So the 5% is checked on a 1560 m channel (dam at 520 m: the reflection from the
  // back wall never reaches the wave) after 750 and 1000 cells, and the lag must shrink throughout.
  const auto mc = ritter(1, {20.0, 80.0, 120.0, 160.0}, SlopeLimiter::kMonotonizedCentral, 1560.0, 520.0);
  for (size_t i = 0; i < mc.size(); ++i) {
    EXPECT_LT(mc[i].first, 0.10);
    if (i > 0) {
      EXPECT_LT(mc[i].second, mc[i - 1].second) << "the front lag must shrink as the front crosses cells";
    }
  }
  EXPECT_LT(mc[2].second, 0.05);  // t = 120 s: measured 0.041
  EXPECT_LT(mc[3].second, 0.05);  // t = 160 s: measured 0.036
  // The default minmod slopes, side by side: the lag falls more slowly (6.0% after 1000 cells
  // in the python replica), which is the price of their robustness on steep real terrain.
  const auto minmod = ritter(1, {160.0}, SlopeLimiter::kMinmod, 1560.0, 520.0);
  EXPECT_GT(minmod[0].second, mc[3].second);
  EXPECT_LT(minmod[0].second, 0.08);
}

// The front lag is numerical diffusion of velocity in the thin tip (docs/sim-water.md, "Known
// limits"), so it shrinks as the cells do: at t = 10 s, 1 m cells lag by 13.8% (minmod) and
// 15.4% (MC), 0.25 m cells by 9.8% and 7.4%.
TEST(SimWaterCpu, FloodRitterFrontConvergesWithRefinement) {
  for (const auto limiter : {SlopeLimiter::kMinmod, SlopeLimiter::kMonotonizedCentral}) {
    const double coarse = ritter(1, {10.0}, limiter)[0].second, fine = ritter(4, {10.0}, limiter)[0].second;
    // Measured ratios 0.71 (minmod, ~dx^0.25) and 0.48 (MC, ~dx^0.5); the bounds leave room for
    // float32 and fail if refining gains nothing.
    EXPECT_LT(fine, (limiter == SlopeLimiter::kMinmod ? 0.8 : 0.6) * coarse);
  }
}

// Thacker's planar-surface solution in a frictionless paraboloid z = -h0 (1 - r^2/a^2): the
// water moves as a tilted plane with angular frequency w = sqrt(2 g h0) / a.
TEST(SimWaterCpu, FloodThackerBowlPeriod) {
  const int n = 80;
  const double L = 4.0, a = 1.0, h0 = 0.1, eta = 0.5, g = 9.81, dx = L / n;
  SimInput in;
  in.baseM = gis::Grid<float>(n, n);
  in.waterDepthM = gis::Grid<float>(n, n);
  in.rowDxM = {dx};
  in.dyM = dx;
  in.datumM = -h0;
  fourLayers(in, 0, 0, 0, 0);
  for (int y = 0; y < n; ++y) {
    for (int x = 0; x < n; ++x) {
      const double px = (x + 0.5) * dx - L / 2, py = (y + 0.5) * dx - L / 2;
      const double z = -h0 * (1 - (px * px + py * py) / (a * a));
      in.baseM.at(x, y) = float(z);
      in.waterDepthM.at(x, y) = float(std::max(0.0, eta * h0 / (a * a) * (2 * px - eta) - z));
    }
  }
  auto p = floodParams();
  p.dryDepthM = 1e-5f;
  auto sim = CpuSolver::create(in, p);
  ASSERT_TRUE(sim) << sim.message();
  const double omega = std::sqrt(2 * g * h0) / a, period = 2 * std::numbers::pi / omega;
  std::vector<double> crossings;
  double prevT = 0, prevX = 0;
  while (sim->stats().timeS < 2.3 * period) {
    sim->step(1);
    const auto h = sim->readWaterDepth();
    double m = 0, mx = 0;
    for (int y = 0; y < n; ++y) {
      for (int x = 0; x < n; ++x) {
        m += h.at(x, y);
        mx += h.at(x, y) * ((x + 0.5) * dx - L / 2);
      }
    }
    const double t = sim->stats().timeS, xc = mx / m;
    if (prevT > 0 && (prevX > 0) != (xc > 0)) crossings.push_back(prevT + (t - prevT) * prevX / (prevX - xc));
    prevT = t;
    prevX = xc;
  }
  ASSERT_GE(crossings.size(), 4u);
  const double measured = 2.0 * (crossings.back() - crossings.front()) / double(crossings.size() - 1);
  std::printf("Thacker: %zu zero crossings, period %.4f s vs analytic %.4f s (error %.4f)\n", crossings.size(),
              measured, period, std::abs(measured - period) / period);
  // Issue 5's bound: 5% of the analytic period.
  EXPECT_NEAR(measured, period, 0.05 * period);
}

TEST(SimWaterCpu, BadInputIsAnError) {
  auto in = test::sloshingBox(8);
  in.rowDxM = {1.0, 2.0};
  auto r = CpuSolver::create(in, pipeParams());
  ASSERT_FALSE(r);
  EXPECT_NE(r.message().find("rowDxM"), std::string::npos) << r.message();
  in = test::sloshingBox(8);
  in.layersM[1].at(3, 4) = -1.0f;
  r = CpuSolver::create(in, pipeParams());
  ASSERT_FALSE(r);
  EXPECT_NE(r.message().find("layersM[1]"), std::string::npos) << r.message();
  auto p = floodParams();
  p.cflAlpha = 0.9f;
  r = CpuSolver::create(test::sloshingBox(8), p);
  ASSERT_FALSE(r);
  EXPECT_NE(r.message().find("cflAlpha"), std::string::npos) << r.message();
}

// W26: a closed, dry bowl filled only through a fixed level on its west edge whose stage rises
// to 3 m: it ends flat at the stage everywhere, the water in is exactly what the bowl holds
// below the stage, and the budget closes with the level's exchange counted as inflow.
TEST(SimWaterCpu, LevelBoundaryFillsABasinFlatAtTheStage) {
  auto params = floodParams();
  params.manningN = 0.05f;  // friction settles the seiche
  auto basin = test::levelBasin(24, 3.0);
  auto sim = CpuSolver::create(basin.input, params);
  ASSERT_TRUE(sim) << sim.message();
  ASSERT_TRUE(sim->addLevel(basin.level));
  sim->advance(3600.0);
  const auto h = sim->readWaterDepth();
  const auto bed = sim->readBed();
  double maxDev = 0, below = 0;
  for (size_t i = 0; i < h.size(); ++i) {
    maxDev = std::max(maxDev, std::abs(double(bed.data[i]) + h.data[i] - 3.0));
    below += std::max(0.0, 3.0 - double(bed.data[i])) * 100.0;
  }
  const auto st = sim->stats();
  std::printf(
      "level basin: surface within %.3g m of the stage, stored %.3f m3 (%.3f below the stage), in %.3f out %.3f, "
      "imbalance %.3g m3\n",
      maxDev, st.storedWaterM3, below, st.inflowM3, st.outflowM3, st.waterBalanceM3());
  // Settled after an hour: the surface is the stage to 1 mm (measured 3.4e-5 m).
  EXPECT_LT(maxDev, 1e-3);
  EXPECT_NEAR(st.storedWaterM3, below, 1e-3 * 100.0 * 24 * 24);  // 1 mm over the bowl
  EXPECT_NEAR(st.outflowM3, 0.0, 1e-6 * st.storedWaterM3);       // no cell lost water on balance
  // The exchange is summed per cell with compensation (W20): float32 rounding only (measured 9e-8).
  EXPECT_LT(std::abs(st.waterBalanceM3()), 1e-6 * st.inflowM3);

  // The virtual pipes have no friction: the bowl sloshes and overshoots the stage while the
  // level keeps pouring; the budget still closes.
  auto pipes = CpuSolver::create(basin.input, pipeParams());
  ASSERT_TRUE(pipes) << pipes.message();
  ASSERT_TRUE(pipes->addLevel(basin.level));
  pipes->advance(300.0);
  const auto sp = pipes->stats();
  std::printf("level basin (pipes): in %.3f out %.3f stored %.3f, imbalance %.3g m3\n", sp.inflowM3, sp.outflowM3,
              sp.storedWaterM3, sp.waterBalanceM3());
  EXPECT_GT(sp.storedWaterM3, 1000.0);
  EXPECT_LT(std::abs(sp.waterBalanceM3()), 1e-5 * (sp.inflowM3 + sp.outflowM3));

  // Bad levels are refused.
  LevelBoundary outside = basin.level;
  outside.cells.push_back({24, 3});
  EXPECT_EQ(sim->addLevel(outside).message(), "sim level: cell (24, 3) is outside the 24x24 grid");
  // A stage whose times go backwards is not a time series at all.
  EXPECT_EQ(TimeSeries::create({{10.0, 1.0}, {5.0, 2.0}}).message(), "sample 1: times must increase");
  LevelBoundary noStage = basin.level;
  noStage.stageM = TimeSeries();
  EXPECT_EQ(sim->addLevel(noStage).message(), "sim level: no stage samples");
}

}  // namespace
}  // namespace strata::sim
