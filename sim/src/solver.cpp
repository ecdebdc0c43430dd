#include <strata/sim/solver.hpp>

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>

namespace strata::sim {

Solver::Solver(const SimInput& input, const SimParams& params) : params_(params), grid_(CellGrid::of(input)) {
  rainRaster_ = input.rainMmPerHour.data;
  maxRainRasterMmH_ = rainRaster_.empty() ? 0.0 : double(*std::max_element(rainRaster_.begin(), rainRaster_.end()));
  rainRateM3S_ = rainVolumeRate(params_, rainRaster_, grid_);
}

Solver::Solver(const CellGrid& grid, const SimParams& params) : params_(params), grid_(grid) {}

Solver::~Solver() = default;

Solver::RainTotals Solver::rainTotals() const {
  RainTotals r;
  for (float v : rainRaster_) r.maxRasterMmH = std::max(r.maxRasterMmH, double(v));
  r.volumeM3S = rainVolumeRate(params_, rainRaster_, grid_);
  return r;
}

void Solver::updateRainTotals() {
  const RainTotals r = rainTotals();
  maxRainRasterMmH_ = r.maxRasterMmH;
  rainRateM3S_ = r.volumeM3S;
}

void Solver::recordInitialTotals() {
  const SimStats s = stats();
  c_.initialWaterM3 = s.storedWaterM3;
  c_.initialMaterialM3 = s.materialM3;
}

Status Solver::addSource(const Source& source) {
  STRATA_TRY_STATUS(checkSource(source, grid_.width, grid_.height));
  STRATA_TRY_STATUS(onSourceAdded(source));
  sources_.push_back(source);
  return {};
}

Status Solver::addLevel(const LevelBoundary& level) {
  STRATA_TRY_STATUS(checkLevel(level, grid_.width, grid_.height));
  STRATA_TRY_STATUS(onLevelAdded(level));
  levels_.push_back(level);
  return {};
}

Status Solver::setParams(const SimParams& params) {
  const SimParams next = runtimeParams(params_, params);
  STRATA_TRY_STATUS(validateParams(next));
  params_ = next;
  updateRainTotals();
  onParamsChanged();
  return {};
}

Status Solver::setRainRaster(const gis::Grid<float>& mmPerHour) {
  if (mmPerHour.size() > 0) {
    if (mmPerHour.width != grid_.width || mmPerHour.height != grid_.height) {
      return fail("sim: a rain raster of " + std::to_string(mmPerHour.width) + "x" + std::to_string(mmPerHour.height) +
                  " cells for a grid of " + std::to_string(grid_.width) + "x" + std::to_string(grid_.height));
    }
    for (size_t i = 0; i < mmPerHour.size(); ++i) {
      const float v = mmPerHour.data[i];
      if (!(v >= 0.0f) || !std::isfinite(v)) {
        return fail("sim: rain raster value " + std::to_string(v) + " mm/h at cell (" +
                    std::to_string(i % size_t(grid_.width)) + ", " + std::to_string(i / size_t(grid_.width)) + ")");
      }
    }
  }
  STRATA_TRY_STATUS(onRainRasterChanged(mmPerHour));
  rainRaster_ = mmPerHour.data;
  updateRainTotals();
  return {};
}

Status Solver::onRainRasterChanged(const gis::Grid<float>& /*mmPerHour*/) {
  return fail("sim: the " + backendName() + " cannot change its rain raster during a run");
}

double Solver::nextDt() {
  if (params_.cflAlpha <= 0) return params_.maxDtS;  // no wave speed needed (a GPU read-back saved)
  const int levels = params_.localStepLevels;
  if (levels == 0) return stepDtWithSources(params_, maxWaveSpeedMS(), maxRainRasterMmH_, sources_, grid_, c_.timeS);
  // W37: the grid's step is 2^k of the finest, which W10 bounds for the fastest cell and the
  // sources' peak over the whole step: k the most levels whose step max_step allows, so that the
  // finest step is W10's own (a power of two of max_step would take up to twice the steps).
  const double speed = maxWaveSpeedMS();
  const double window = double(1 << levels) * stepDt(params_, speed, grid_.minCellM);
  const double rate = sourceDepthRate(params_, maxRainRasterMmH_, sources_, grid_, c_.timeS, c_.timeS + window);
  const double fine = stepDt(params_, speed, grid_.minCellM, rate);
  int k = levels;
  while (k > 0 && fine * double(1 << k) > double(params_.maxDtS)) --k;
  return fine * double(1 << k);
}

double Solver::sourceDepthRateMS(double t1S) const {
  return sourceDepthRate(params_, maxRainRasterMmH_, sources_, grid_, c_.timeS, t1S);
}

void Solver::step(int n) {
  for (int k = 0; k < n; ++k) stepWithDt(nextDt());
}

void Solver::advance(double seconds) {
  const double end = c_.timeS + seconds;
  while (!reached(c_.timeS, end)) {
    // A backend's own run that took no step (its clock's rule disagreeing with reached()) steps
    // from the host instead of looping.
    if (advanceBatch(end, std::numeric_limits<int64_t>::max()).steps == 0)
      stepWithDt(std::min(nextDt(), end - c_.timeS));
  }
}

Solver::Batch Solver::advanceBatch(double endS, int64_t maxSteps) {
  Batch b;
  if (maxSteps <= 0 || reached(c_.timeS, endS)) return b;
  // W10's bound on the rain's depth rate, as sourceDepthRate adds it.
  const double rainRateMS = (double(params_.rainMmPerHour) + maxRainRasterMmH_) / 3.6e6;
  if (const auto d = runOnDevice(DeviceRequest{c_.timeS, endS, maxSteps, rainRateMS})) {
    c_.rainM3 += rainRateM3S_ * (d->timeS - c_.timeS);
    c_.inflowM3 += d->inflowM3;
    c_.timeS = d->timeS;
    c_.steps += d->steps;
    if (d->steps > 0) c_.lastDtS = d->lastDtS;
    return {d->steps, d->minChosenDtS, d->lastChosenDtS};
  }
  b.minChosenDtS = std::numeric_limits<double>::infinity();
  while (b.steps < maxSteps && !reached(c_.timeS, endS)) {
    const double chosen = nextDt();
    b.minChosenDtS = std::min(b.minChosenDtS, chosen);
    b.lastChosenDtS = chosen;
    stepWithDt(std::min(chosen, endS - c_.timeS));
    ++b.steps;
  }
  if (b.steps == 0) b.minChosenDtS = 0;
  return b;
}

void Solver::stepWithDt(double dtS) { takeStep(dtS, true); }

void Solver::skipStep(double dtS) { takeStep(dtS, false); }

void Solver::takeStep(double dtS, bool run) {
  const float dt = float(dtS);
  const auto entries = mergeSources(sources_, grid_.width, c_.timeS, c_.timeS + double(dt));
  const auto levelCells = levels_.empty() ? std::vector<LevelEntry>{}
                                          : levelEntries(levels_, grid_.width, c_.timeS + double(dt), grid_.datumM);
  for (const auto& e : entries) c_.inflowM3 += double(e.rateM3S) * double(dt);
  c_.rainM3 += rainRateM3S_ * double(dt);
  if (run) runStep(StepInputs{dt, c_.timeS, entries, levelCells});
  c_.timeS += double(dt);
  c_.lastDtS = double(dt);
  ++c_.steps;
  if (run && wetThresholdM_ >= 0 && !keepsFloodStats()) updateHostFloodStats();
}

gis::Grid<float> Solver::readWaterDepth() const {
  const CellBlock b = readBlock(0, 0, grid_.width, grid_.height, kBlockState);
  gis::Grid<float> g(grid_.width, grid_.height);
  for (size_t i = 0; i < g.size(); ++i) g.data[i] = b.state[4 * i];
  return g;
}

gis::Grid<float> Solver::readSuspended() const {
  const CellBlock b = readBlock(0, 0, grid_.width, grid_.height, kBlockState);
  gis::Grid<float> g(grid_.width, grid_.height);
  for (size_t i = 0; i < g.size(); ++i) g.data[i] = b.state[4 * i + 1];
  return g;
}

VelocityField Solver::readVelocity() const {
  const CellBlock b = readBlock(0, 0, grid_.width, grid_.height, kBlockState);
  const float dry = params_.dryDepthM;
  VelocityField v{gis::Grid<float>(grid_.width, grid_.height), gis::Grid<float>(grid_.width, grid_.height)};
  for (size_t i = 0; i < v.uMS.size(); ++i) {
    const float h = b.state[4 * i];
    v.uMS.data[i] = h > dry ? b.state[4 * i + 2] / h : 0.0f;
    v.vMS.data[i] = h > dry ? b.state[4 * i + 3] / h : 0.0f;
  }
  return v;
}

std::vector<gis::Grid<float>> Solver::readLayers() const {
  const CellBlock b = readBlock(0, 0, grid_.width, grid_.height, kBlockLayers);
  const size_t n = grid_.cells();
  std::vector<gis::Grid<float>> out;
  for (int l = 0; l < grid_.layers; ++l) {
    gis::Grid<float> g(grid_.width, grid_.height);
    std::copy_n(b.layers.begin() + ptrdiff_t(size_t(l) * n), n, g.data.begin());
    out.push_back(std::move(g));
  }
  return out;
}

Solver::Totals Solver::totals() const {
  CellBlock b = readBlock(0, 0, grid_.width, grid_.height, kBlockState | kBlockLayers | kBlockAccum);
  const size_t n = grid_.cells();
  Totals t;
  t.depth.resize(n);
  t.suspended.resize(n);
  for (size_t i = 0; i < n; ++i) {
    t.depth[i] = b.state[4 * i];
    t.suspended[i] = b.state[4 * i + 1];
    const float* a = &b.accum[kAccumPerCell * i];
    t.outflowM3 += double(a[kAccumOutflow]);
    t.evaporatedM3 += double(a[kAccumEvaporated]);
    t.infiltratedM3 += double(a[kAccumInfiltrated]);
    t.sedimentOutflowM3 += double(a[kAccumSedimentOut]);
    (a[kAccumLevel] > 0 ? t.levelInM3 : t.levelOutM3) += double(a[kAccumLevel]);
  }
  t.layers = std::move(b.layers);
  return t;
}

// A checkpoint's per-cell arrays as the parts of a block of the whole grid: the same fields in
// the same order (CellBlock::forEachPart).
namespace {
template <class State, class F>
void forEachStatePart(State& s, F&& f) {
  f(s.state);
  f(s.flux);
  f(s.fluxDiag);
  f(s.layers);
  f(s.accum);
}
}  // namespace

void Solver::saveCells(SolverState& out) const {
  CellBlock b = readBlock(0, 0, grid_.width, grid_.height, kBlockAll);
  std::vector<std::vector<float>*> parts;
  CellBlock::forEachPart(b, grid_.layers, [&](unsigned bit, std::vector<float>& v, size_t, size_t) {
    if (bit != kBlockCarried) parts.push_back(&v);  // a part of the accumulators
  });
  size_t k = 0;
  forEachStatePart(out, [&](std::vector<float>& v) { v = std::move(*parts[k++]); });
}

Status Solver::restoreCells(const SolverState& in) {
  const size_t n = grid_.cells();
  const size_t diag = params_.diagonalPipes ? 4 * n : 0;
  if (in.state.size() != 4 * n || in.flux.size() != 4 * n || in.fluxDiag.size() != diag ||
      in.layers.size() != size_t(grid_.layers) * n || in.accum.size() != kAccumPerCell * n) {
    return fail("sim: the saved state is of a different grid or model (" + std::to_string(in.state.size() / 4) +
                " cells, this simulation has " + std::to_string(n) + ")");
  }
  CellBlock b{.rect = {0, 0, grid_.width, grid_.height}};
  std::vector<const std::vector<float>*> parts;
  forEachStatePart(in, [&](const std::vector<float>& v) { parts.push_back(&v); });
  size_t k = 0;
  CellBlock::forEachPart(b, grid_.layers, [&](unsigned bit, std::vector<float>& v, size_t, size_t) {
    if (bit != kBlockCarried) v = *parts[k++];
  });
  writeBlock(b);
  return {};
}

SimStats Solver::counterStats() const {
  SimStats s;
  s.timeS = c_.timeS;
  s.steps = c_.steps;
  s.lastDtS = c_.lastDtS;
  s.initialWaterM3 = c_.initialWaterM3;
  s.rainM3 = c_.rainM3;
  s.inflowM3 = c_.inflowM3;
  s.initialMaterialM3 = c_.initialMaterialM3;
  s.infiltratedM3 = -c_.infiltratedBeforeM3;  // stats() adds the cells' sums
  return s;
}

SimStats Solver::stats() const {
  const Totals t = totals();
  SimStats s = counterStats();
  s.storedWaterM3 = integrate(t.depth, grid_);
  s.inflowM3 = c_.inflowM3 + t.levelInM3;    // W26: level cells that gained water on balance
  s.outflowM3 = t.outflowM3 - t.levelOutM3;  // and those that lost (levelOut <= 0)
  s.evaporatedM3 = t.evaporatedM3;
  s.infiltratedM3 += t.infiltratedM3;
  s.sedimentOutflowM3 = t.sedimentOutflowM3;
  s.suspendedM3 = integrate(t.suspended, grid_);
  s.materialM3 = s.suspendedM3 + integrate(t.layers, grid_);
  float hmax = 0.0f;
  for (float h : t.depth) hmax = std::max(hmax, h);
  s.maxDepthM = hmax;
  return s;
}

unsigned haloParts(const SimParams& p) {
  unsigned parts = kBlockState | kBlockCarried;
  if (p.waterModel == WaterModel::kVirtualPipes || p.floodScheme == FloodScheme::kLocalInertial) parts |= kBlockFlux;
  if (p.erosionEnabled || p.thermalEnabled) parts |= kBlockLayers;
  return parts;
}

bool blockFits(const CellBlock& b, int width, int height, int layers) {
  const size_t n = b.cells();
  const gis::CellRect& r = b.rect;
  bool fits =
      r.x >= 0 && r.y >= 0 && r.width >= 0 && r.height >= 0 && r.x + r.width <= width && r.y + r.height <= height;
  CellBlock::forEachPart(b, layers, [&](unsigned, const std::vector<float>& v, size_t per, size_t planes) {
    fits = fits && (v.empty() || v.size() == per * planes * n);
  });
  return fits;
}

void copyOverlap(const CellBlock& src, CellBlock& dst, int layers) {
  const gis::CellRect r = src.rect.intersected(dst.rect);
  if (r.empty()) return;
  const size_t srcCells = src.cells(), dstCells = dst.cells();
  // The parts of `src`, by position in the one list, into the same parts of `dst`.
  std::vector<const std::vector<float>*> from;
  CellBlock::forEachPart(src, layers,
                         [&](unsigned, const std::vector<float>& v, size_t, size_t) { from.push_back(&v); });
  size_t k = 0;
  CellBlock::forEachPart(dst, layers, [&](unsigned, std::vector<float>& d, size_t per, size_t planes) {
    const std::vector<float>& s = *from[k++];
    if (s.empty()) return;
    d.resize(per * planes * dstCells);
    for (size_t p = 0; p < planes; ++p) {
      for (int y = 0; y < r.height; ++y) {
        const size_t si =
            p * srcCells + size_t(r.y - src.rect.y + y) * size_t(src.rect.width) + size_t(r.x - src.rect.x);
        const size_t di =
            p * dstCells + size_t(r.y - dst.rect.y + y) * size_t(dst.rect.width) + size_t(r.x - dst.rect.x);
        std::copy_n(&s[per * si], per * size_t(r.width), &d[per * di]);
      }
    }
  });
}

std::vector<float> initialFloodStatsCells(size_t cells) {
  std::vector<float> v(4 * cells, 0.0f);
  for (size_t i = 0; i < cells; ++i) v[4 * i + 2] = -1.0f;
  return v;
}

FloodStats floodStatsFromCells(const std::vector<float>& v, int width, int height) {
  FloodStats f;
  gis::Grid<float>* grids[4] = {&f.maxDepthM, &f.maxSpeedMS, &f.arrivalS, &f.wetDurationS};
  const size_t n = size_t(width) * size_t(height);
  for (int k = 0; k < 4; ++k) {
    *grids[k] = gis::Grid<float>(width, height);
    for (size_t i = 0; i < n; ++i) grids[k]->data[i] = v[4 * i + size_t(k)];
  }
  return f;
}

void Solver::startClockAt(double timeS) {
  STRATA_CHECK(c_.steps == 0 && std::isfinite(timeS)) << "the clock is set before the first step";
  setClock(timeS);
}

void Solver::setClock(double timeS) {
  c_.timeS = timeS;
  forEachPart([timeS](Solver& part) { part.setClock(timeS); });
}

void Solver::restartAt(double timeS) {
  STRATA_CHECK(std::isfinite(timeS)) << "restart at " << timeS;
  setClock(timeS);
  c_.infiltratedBeforeM3 += stats().infiltratedM3;
  clearAccumulators();
  c_.inflowM3 = 0;
  c_.rainM3 = 0;
  recordInitialTotals();
}

void Solver::clearAccumulators() {
  // The infiltration pair (the soil's state) and the depth error (the water's) are kept.
  static_assert(kAccumInfiltrated + 2 == kAccumDepthError && kAccumDepthError + 1 == kAccumPerCell,
                "the infiltration pair and the depth error are a cell's last");
  CellBlock b = readBlock(0, 0, grid_.width, grid_.height, kBlockAccum);
  for (size_t i = 0; i < b.accum.size(); i += kAccumPerCell) {
    std::fill_n(&b.accum[i], kAccumInfiltrated, 0.0f);  // the sums before the infiltration pair
  }
  writeBlock(b);
}

void Solver::enableFloodStats(float wetThresholdM) {
  STRATA_CHECK(wetThresholdM >= 0 && std::isfinite(wetThresholdM)) << "wet threshold " << wetThresholdM;
  wetThresholdM_ = wetThresholdM;
  if (keepsFloodStats()) {
    resetFloodStats();
  } else {
    hostFlood_ = initialFloodStatsCells(grid_.cells());
  }
}

FloodStats Solver::readFloodStats() const {
  if (wetThresholdM_ < 0) return floodStatsFromCells(initialFloodStatsCells(grid_.cells()), grid_.width, grid_.height);
  return floodStatsFromCells(keepsFloodStats() ? floodStatsCells() : hostFlood_, grid_.width, grid_.height);
}

std::vector<gis::CellRect> Solver::localRects() const { return {{0, 0, grid_.width, grid_.height}}; }

std::vector<float> Solver::readFaceMassFluxAt(const std::vector<size_t>& faces) const {
  const std::vector<float> all = readFaceMassFlux();
  std::vector<float> out;
  out.reserve(faces.size());
  for (size_t i : faces) {
    STRATA_CHECK(i < all.size()) << "face " << i << " outside the grid's " << all.size();
    out.push_back(all[i]);
  }
  return out;
}

CellBlock Solver::readLocal(const gis::CellRect& rect, unsigned parts) const {
  return readBlock(rect.x, rect.y, rect.width, rect.height, parts);
}

FloodStats Solver::readLocalFloodStats(const gis::CellRect& rect) const {
  const FloodStats all = readFloodStats();
  if (rect.x == 0 && rect.y == 0 && rect.width == grid_.width && rect.height == grid_.height) return all;
  return cropFloodStats(all, rect);
}

gis::Grid<float> Solver::readLocalBed(const gis::CellRect& rect) const {
  const gis::Grid<float> all = readBed();
  if (rect.x == 0 && rect.y == 0 && rect.width == grid_.width && rect.height == grid_.height) return all;
  return cropGrid(all, rect);
}

gis::Grid<float> cropGrid(const gis::Grid<float>& g, const gis::CellRect& r) {
  gis::Grid<float> out(r.width, r.height);
  for (int y = 0; y < r.height; ++y) std::copy_n(&g.at(r.x, r.y + y), size_t(r.width), &out.at(0, y));
  return out;
}

FloodStats cropFloodStats(const FloodStats& f, const gis::CellRect& r) {
  return {cropGrid(f.maxDepthM, r), cropGrid(f.maxSpeedMS, r), cropGrid(f.arrivalS, r), cropGrid(f.wetDurationS, r)};
}

// The same per-cell update as the backends' own (e.g. sim/shaders/flood_stats.comp), on the host.
void Solver::updateHostFloodStats() {
  const auto h = readWaterDepth();
  const auto v = readVelocity();
  const float t = float(c_.timeS), dt = float(c_.lastDtS);
  for (size_t i = 0; i < h.size(); ++i) {
    float* f = &hostFlood_[4 * i];
    f[0] = std::max(f[0], h.data[i]);
    f[1] = std::max(f[1], std::sqrt(v.uMS.data[i] * v.uMS.data[i] + v.vMS.data[i] * v.vMS.data[i]));
    if (h.data[i] > wetThresholdM_) {
      if (f[2] < 0.0f) f[2] = t;
      f[3] += dt;
    }
  }
}

SolverState Solver::saveState() const {
  SolverState s;
  s.counters = c_;
  s.wetThresholdM = wetThresholdM_;
  saveCells(s);
  if (wetThresholdM_ >= 0 && !floodStatsInParts()) s.flood = keepsFloodStats() ? floodStatsCells() : hostFlood_;
  return s;
}

Status Solver::restoreState(const SolverState& s) {
  if (s.wetThresholdM >= 0 && !floodStatsInParts() && s.flood.size() != 4 * grid_.cells()) {
    return fail("sim: the saved flood statistics are of " + std::to_string(s.flood.size() / 4) +
                " cells, this simulation has " + std::to_string(grid_.cells()));
  }
  STRATA_TRY_STATUS(restoreCells(s));
  c_ = s.counters;
  wetThresholdM_ = s.wetThresholdM;
  if (wetThresholdM_ >= 0 && !floodStatsInParts()) {
    if (keepsFloodStats()) {
      setFloodStatsCells(s.flood);
    } else {
      hostFlood_ = s.flood;
    }
  }
  return {};
}

}  // namespace strata::sim
