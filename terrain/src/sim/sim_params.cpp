#include <algorithm>
#include <cmath>
#include <map>
#include <numbers>
#include <string>

#include <strata/terrain/sim/sim_host.hpp>
#include <strata/terrain/sim/sim_params.hpp>

namespace strata::terrain::sim {

SimMaterial toSimMaterial(const Material& m) {
  SimMaterial s;
  s.erodibility = m.erodibility;
  s.dissolutionRate = m.dissolutionRate;
  s.tanTalus = float(std::tan(double(m.talusAngleDeg) * std::numbers::pi / 180.0));
  return s;
}

double Source::rateAt(double tS) const {
  if (hydrographM3S.empty() || tS < hydrographM3S.front().first || tS > hydrographM3S.back().first) return 0.0;
  if (hydrographM3S.size() == 1 || tS == hydrographM3S.back().first) return hydrographM3S.back().second;
  auto it = std::upper_bound(hydrographM3S.begin(), hydrographM3S.end(), tS,
                             [](double t, const std::pair<double, double>& p) { return t < p.first; });
  const auto& [t1, q1] = *it;
  const auto& [t0, q0] = *(it - 1);
  return q0 + (q1 - q0) * (tS - t0) / (t1 - t0);
}

double Source::volume(double t0S, double t1S) const {
  double v = 0;
  for (size_t i = 1; i < hydrographM3S.size(); ++i) {
    const auto [ta, qa] = hydrographM3S[i - 1];
    const auto [tb, qb] = hydrographM3S[i];
    const double a = std::max(t0S, ta), b = std::min(t1S, tb);
    if (b <= a) continue;
    auto q = [&](double t) { return qa + (qb - qa) * (t - ta) / (tb - ta); };
    v += 0.5 * (q(a) + q(b)) * (b - a);  // trapezoid: exact for a linear piece
  }
  return v;
}

double LevelBoundary::stageAt(double tS) const {
  if (stageM.empty()) return 0.0;
  if (tS <= stageM.front().first) return stageM.front().second;
  if (tS >= stageM.back().first) return stageM.back().second;
  auto it = std::upper_bound(stageM.begin(), stageM.end(), tS,
                             [](double t, const std::pair<double, double>& p) { return t < p.first; });
  const auto& [t1, z1] = *it;
  const auto& [t0, z0] = *(it - 1);
  return z0 + (z1 - z0) * (tS - t0) / (t1 - t0);
}

Status checkLevel(const LevelBoundary& level, int width, int height) {
  if (level.stageM.empty()) return fail("sim level: no stage samples");
  for (size_t i = 1; i < level.stageM.size(); ++i) {
    if (!(level.stageM[i].first > level.stageM[i - 1].first)) {
      return fail("sim level: stage times must increase (sample " + std::to_string(i) + ")");
    }
  }
  for (auto [x, y] : level.cells) {
    if (x < 0 || y < 0 || x >= width || y >= height) {
      return fail("sim level: cell (" + std::to_string(x) + ", " + std::to_string(y) + ") is outside the " +
                  std::to_string(width) + "x" + std::to_string(height) + " grid");
    }
  }
  return {};
}

std::vector<LevelEntry> levelEntries(const std::vector<LevelBoundary>& levels, int width, double tS, double datumM) {
  std::map<uint32_t, double> perCell;  // a cell held by several levels takes the highest
  for (const auto& l : levels) {
    const double z = l.stageAt(tS) - datumM;
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

namespace {

Status checkGrid(const gis::Grid<float>& g, int w, int h, const std::string& field, bool nonNegative) {
  if (g.width != w || g.height != h) {
    return fail("sim input: " + field + " is " + std::to_string(g.width) + "x" + std::to_string(g.height) +
                ", expected " + std::to_string(w) + "x" + std::to_string(h));
  }
  for (size_t i = 0; i < g.size(); ++i) {
    const float v = g.data[i];
    if (!std::isfinite(v) || (nonNegative && v < 0.0f)) {
      return fail("sim input: " + field + " has " + (std::isfinite(v) ? "a negative" : "a non-finite") +
                  " value at cell (" + std::to_string(i % size_t(w)) + ", " + std::to_string(i / size_t(w)) + ")");
    }
  }
  return {};
}

}  // namespace

Status validate(const SimInput& input, const SimParams& params) {
  const int w = input.baseM.width, h = input.baseM.height;
  if (w < 2 || h < 2) return fail("sim input: baseM must be at least 2x2 cells");
  STRATA_TRY_STATUS(checkGrid(input.baseM, w, h, "baseM", false));
  if (input.layersM.empty()) return fail("sim input: layersM is empty (need at least one material layer)");
  if (input.materials.size() != input.layersM.size()) {
    return fail("sim input: " + std::to_string(input.materials.size()) + " materials for " +
                std::to_string(input.layersM.size()) + " layers");
  }
  for (size_t l = 0; l < input.layersM.size(); ++l) {
    STRATA_TRY_STATUS(checkGrid(input.layersM[l], w, h, "layersM[" + std::to_string(l) + "]", true));
  }
  if (input.waterDepthM.size() > 0) STRATA_TRY_STATUS(checkGrid(input.waterDepthM, w, h, "waterDepthM", true));
  if (input.rainMmPerHour.size() > 0) STRATA_TRY_STATUS(checkGrid(input.rainMmPerHour, w, h, "rainMmPerHour", true));
  if (input.rowDxM.size() != 1 && input.rowDxM.size() != size_t(h)) {
    return fail("sim input: rowDxM has " + std::to_string(input.rowDxM.size()) + " values, expected 1 or " +
                std::to_string(h) + " (one per row)");
  }
  for (double dx : input.rowDxM) {
    if (!(dx > 0)) return fail("sim input: rowDxM has a non-positive cell size " + std::to_string(dx));
  }
  if (!(input.dyM > 0)) return fail("sim input: dyM must be positive, got " + std::to_string(input.dyM));
  return validateParams(params);
}

Status validateParams(const SimParams& params) {
  if (!(params.maxDtS > 0)) return fail("sim params: maxDtS must be positive");
  if (!(params.gravityMS2 > 0)) return fail("sim params: gravityMS2 must be positive");
  if (params.waterModel != int32_t(WaterModel::kVirtualPipes) &&
      params.waterModel != int32_t(WaterModel::kFiniteVolume)) {
    return fail("sim params: waterModel " + std::to_string(params.waterModel) + " is not 0 (pipes) or 1 (flood)");
  }
  if (params.slopeLimiter != int32_t(SlopeLimiter::kMinmod) &&
      params.slopeLimiter != int32_t(SlopeLimiter::kMonotonizedCentral)) {
    return fail("sim params: slopeLimiter " + std::to_string(params.slopeLimiter) + " is not 0 (minmod) or 1 (MC)");
  }
  if (params.waterModel == int32_t(WaterModel::kFiniteVolume) && !(params.cflAlpha > 0 && params.cflAlpha <= 0.5f)) {
    return fail("sim params: flood mode needs cflAlpha in (0, 0.5] (positivity of the finite-volume scheme)");
  }
  if (params.thermalRate <= 0 || params.thermalRate > 1) return fail("sim params: thermalRate must be in (0, 1]");
  if (params.manningN < 0 || params.dryDepthM <= 0 || params.deepWaterM <= 0) {
    return fail("sim params: manningN must be >= 0, dryDepthM and deepWaterM > 0");
  }
  return {};
}

SimParams runtimeParams(const SimParams& current, const SimParams& next) {
  SimParams p = next;
  p.width = current.width;
  p.height = current.height;
  p.layerCount = current.layerCount;
  p.waterModel = current.waterModel;
  p.dyM = current.dyM;
  p.dtS = current.dtS;
  return p;
}

double rowDx(const SimInput& input, int row) {
  return input.rowDxM.size() == 1 ? input.rowDxM[0] : input.rowDxM[size_t(row)];
}

std::vector<SourceEntry> mergeSources(const std::vector<Source>& sources, int width, double t0S, double t1S) {
  std::map<uint32_t, double> perCell;
  for (const auto& s : sources) {
    if (s.cells.empty() || !(t1S > t0S)) continue;
    const double q = s.volume(t0S, t1S) / (t1S - t0S) / double(s.cells.size());
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
  const double k = std::sqrt(double(params.gravityMS2) * std::max(sourceDepthRateMS, 0.0));
  // W10: dt (S + k sqrt(dt)) grows with dt; bisect for where it reaches alpha * min cell.
  auto travel = [&](double dt) { return dt * (maxWaveSpeedMS + k * std::sqrt(dt)); };
  if (travel(cap) <= reach) return cap;
  double lo = 0.0, hi = cap;
  for (int i = 0; i < 60; ++i) {
    const double mid = 0.5 * (lo + hi);
    (travel(mid) <= reach ? lo : hi) = mid;
  }
  return lo;
}

double sourceDepthRate(const SimParams& params, double maxRainRasterMmH, const std::vector<Source>& sources,
                       const std::vector<double>& rowDxM, double dyM, double t0S, double t1S) {
  std::map<std::pair<int, int>, double> perCell;  // m^3/s
  for (const auto& s : sources) {
    if (s.cells.empty()) continue;
    // Peak of the piecewise-linear hydrograph over the window: its ends and the samples inside.
    double peak = std::max(s.rateAt(t0S), s.rateAt(t1S));
    for (const auto& [t, q] : s.hydrographM3S) {
      if (t > t0S && t < t1S) peak = std::max(peak, q);
    }
    for (const auto& c : s.cells) perCell[c] += peak / double(s.cells.size());
  }
  double cellRate = 0;
  for (const auto& [c, q] : perCell) {
    const double dx = rowDxM.size() == 1 ? rowDxM[0] : rowDxM[size_t(c.second)];
    cellRate = std::max(cellRate, q / (dx * dyM));
  }
  return cellRate + (double(params.rainMmPerHour) + maxRainRasterMmH) / 3.6e6;
}

double stepDtWithSources(const SimParams& params, double maxWaveSpeedMS, double minCellM, double maxRainRasterMmH,
                         const std::vector<Source>& sources, const std::vector<double>& rowDxM, double dyM,
                         double timeS) {
  if (params.cflAlpha <= 0) return params.maxDtS;
  const double window = stepDt(params, maxWaveSpeedMS, minCellM);
  const double r = sourceDepthRate(params, maxRainRasterMmH, sources, rowDxM, dyM, timeS, timeS + window);
  return stepDt(params, maxWaveSpeedMS, minCellM, r);
}

double minCellSize(const std::vector<double>& rowDxM, double dyM) {
  double m = dyM;
  for (double dx : rowDxM) m = std::min(m, dx);
  return m;
}

double rainVolumeRate(const SimParams& params, const std::vector<float>& rainRasterMmH,
                      const std::vector<double>& rowDxM, int width) {
  const int height = int(rainRasterMmH.size() / size_t(width));
  double sum = 0;
  for (int y = 0; y < height; ++y) {
    const double area = (rowDxM.size() == 1 ? rowDxM[0] : rowDxM[size_t(y)]) * double(params.dyM);
    for (int x = 0; x < width; ++x) {
      // The same float sum the kernels add (raster + uniform), then m/h -> m/s.
      const float mmH = rainRasterMmH[size_t(y) * size_t(width) + size_t(x)] + params.rainMmPerHour;
      sum += double(mmH) * area;
    }
  }
  return sum / 3.6e6;
}

double integrate(const std::vector<float>& values, const std::vector<double>& rowDxM, double dyM, int width,
                 size_t offset) {
  double sum = 0;
  const size_t count = values.size() - offset;
  const int height = int(count / size_t(width));
  for (int y = 0; y < height; ++y) {
    double row = 0;
    for (int x = 0; x < width; ++x) row += double(values[offset + size_t(y) * size_t(width) + size_t(x)]);
    // Layer stacks are several grids one after the other: row y of the stack is row y % rows.
    sum += row * (rowDxM.size() == 1 ? rowDxM[0] : rowDxM[size_t(y) % rowDxM.size()]) * dyM;
  }
  return sum;
}

}  // namespace strata::terrain::sim
