#include <strata/sim/bookkeeping.hpp>

#include <algorithm>
#include <cmath>
#include <map>
#include <string>

namespace strata::sim {
namespace {

Status checkCells(const std::vector<std::pair<int, int>>& cells, int width, int height, const char* what) {
  for (auto [x, y] : cells) {
    if (x < 0 || y < 0 || x >= width || y >= height) {
      return fail(std::string("sim ") + what + ": cell (" + std::to_string(x) + ", " + std::to_string(y) +
                  ") is outside the " + std::to_string(width) + "x" + std::to_string(height) + " grid");
    }
  }
  return {};
}

}  // namespace

Status checkSource(const Source& source, int width, int height) {
  STRATA_TRY_STATUS(checkCells(source.cells, width, height, "source"));
  if (source.dischargeM3S.empty()) return fail("sim source: no hydrograph");
  return {};
}

Status checkLevel(const LevelBoundary& level, int width, int height) {
  STRATA_TRY_STATUS(checkCells(level.cells, width, height, "level"));
  if (level.stageM.empty()) return fail("sim level: no stage samples");
  return {};
}

std::vector<LevelEntry> levelEntries(const std::vector<LevelBoundary>& levels, int width, double tS, double datumM) {
  std::map<uint32_t, double> perCell;  // a cell held by several levels takes the highest
  for (const auto& l : levels) {
    const double z = l.stageM.at(tS) - datumM;
    for (auto [x, y] : l.cells) {
      auto [it, fresh] = perCell.emplace(uint32_t(y) * uint32_t(width) + uint32_t(x), z);
      if (!fresh) it->second = std::max(it->second, z);
    }
  }
  std::vector<LevelEntry> out;
  out.reserve(perCell.size());
  for (auto [cell, z] : perCell) out.push_back({cell, float(z)});
  return out;
}

std::vector<SourceEntry> mergeSources(const std::vector<Source>& sources, int width, double t0S, double t1S) {
  std::map<uint32_t, double> perCell;
  for (const auto& s : sources) {
    if (s.cells.empty() || !(t1S > t0S)) continue;
    const double q = s.dischargeM3S.integral(t0S, t1S) / (t1S - t0S) / double(s.cells.size());
    for (auto [x, y] : s.cells) perCell[uint32_t(y) * uint32_t(width) + uint32_t(x)] += q;
  }
  std::vector<SourceEntry> out;
  out.reserve(perCell.size());
  for (auto [cell, q] : perCell) out.push_back({cell, float(q)});
  return out;
}

double stepDt(const SimParams& params, double maxWaveSpeedMS, double minCellM, double sourceDepthRateMS) {
  const double cap = params.maxDtS, reach = double(params.cflAlpha) * minCellM;
  if (params.cflAlpha <= 0 || (maxWaveSpeedMS <= 0 && sourceDepthRateMS <= 0)) return cap;
  // W10's travel grows with dt: bisect for where it reaches alpha * min cell.
  auto travel = [&](double dt) { return stepTravelM(params, maxWaveSpeedMS, sourceDepthRateMS, dt); };
  if (travel(cap) <= reach) return cap;
  double lo = 0.0, hi = cap;
  for (int i = 0; i < 60; ++i) {
    const double mid = 0.5 * (lo + hi);
    (travel(mid) <= reach ? lo : hi) = mid;
  }
  return lo;
}

double stepTravelM(const SimParams& params, double maxWaveSpeedMS, double sourceDepthRateMS, double dtS) {
  const double k = std::sqrt(double(params.gravityMS2) * std::max(sourceDepthRateMS, 0.0));
  // W10: dt (S + k sqrt(dt)), or dt sqrt(S^2 + k^2 dt) for the local-inertial scheme (W33).
  if (params.floodScheme == FloodScheme::kLocalInertial) {
    return dtS * std::sqrt(maxWaveSpeedMS * maxWaveSpeedMS + k * k * dtS);
  }
  return dtS * (maxWaveSpeedMS + k * std::sqrt(dtS));
}

double sourceDepthRate(const SimParams& params, double maxRainRasterMmH, const std::vector<Source>& sources,
                       const CellGrid& grid, double t0S, double t1S) {
  std::map<std::pair<int, int>, double> perCell;  // m^3/s
  for (const auto& s : sources) {
    if (s.cells.empty()) continue;
    // Peak of the piecewise-linear hydrograph over the window: its ends and the samples inside.
    const double peak = s.dischargeM3S.maxOver(t0S, t1S);
    for (const auto& c : s.cells) perCell[c] += peak / double(s.cells.size());
  }
  double cellRate = 0;
  for (const auto& [c, q] : perCell) cellRate = std::max(cellRate, q / grid.area(c.second));
  return cellRate + (double(params.rainMmPerHour) + maxRainRasterMmH) / 3.6e6;
}

double stepDtWithSources(const SimParams& params, double maxWaveSpeedMS, double maxRainRasterMmH,
                         const std::vector<Source>& sources, const CellGrid& grid, double timeS) {
  if (params.cflAlpha <= 0) return params.maxDtS;
  const double window = stepDt(params, maxWaveSpeedMS, grid.minCellM);
  const double r = sourceDepthRate(params, maxRainRasterMmH, sources, grid, timeS, timeS + window);
  return stepDt(params, maxWaveSpeedMS, grid.minCellM, r);
}

double rainVolumeRate(const SimParams& params, const std::vector<float>& rainRasterMmH, const CellGrid& grid) {
  double sum = 0;
  for (int y = 0; y < grid.height; ++y) {
    const double area = grid.area(y);
    for (int x = 0; x < grid.width; ++x) {
      // The same float sum the kernels add (raster + uniform), then m/h -> m/s.
      const float raster = rainRasterMmH.empty() ? 0.0f : rainRasterMmH[size_t(y) * size_t(grid.width) + size_t(x)];
      sum += double(raster + params.rainMmPerHour) * area;
    }
  }
  return sum / 3.6e6;
}

double integrate(const std::vector<float>& values, const CellGrid& grid) {
  double sum = 0;
  const int rows = int(values.size() / size_t(grid.width));
  for (int y = 0; y < rows; ++y) {
    double row = 0;
    for (int x = 0; x < grid.width; ++x) row += double(values[size_t(y) * size_t(grid.width) + size_t(x)]);
    // Layer stacks are several grids one after the other: row y of the stack is row y % height.
    sum += row * grid.area(y % grid.height);
  }
  return sum;
}

}  // namespace strata::sim
