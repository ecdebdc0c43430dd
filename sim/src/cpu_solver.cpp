// The CPU backend: storage, the order of the passes in a step, the choice of the cells they run
// on, and the conversions between its planes and the Solver interface's per-cell arrays.
#include <strata/sim/cpu_solver.hpp>

#include <algorithm>
#include <bit>
#include <chrono>
#include <cmath>
#include <cstring>
#include <string>

#include "cpu_impl.hpp"

namespace strata::sim {
namespace cpu {
namespace {

uint32_t bitsOf(float v) {
  uint32_t b;
  std::memcpy(&b, &v, 4);
  return b;
}

}  // namespace

// Whether a value in [x0, x1) of a row has a bit set (-0 counts).
STRATA_ROW_KERNEL bool anyBitsRow(const float* row, int x0, int x1) {
  uint32_t any = 0;
#pragma omp simd reduction(| : any)
  for (int x = x0; x < x1; ++x) any |= bitsOf(row[x]);
  return any != 0;
}

namespace {

// Whether a value in [x0, x1) x [y0, y1) of `plane` has a bit set, row by row.
bool anyBits(const Plane& plane, int x0, int x1, int y0, int y1) {
  for (int y = y0; y < y1; ++y) {
    if (anyBitsRow(plane.row(y), x0, x1)) return true;
  }
  return false;
}

}  // namespace

Impl::Impl(const SimInput& input, const SimParams& params, int threadCount, bool skipQuiet)
    : p(params), skip(skipQuiet) {
  const CellGrid grid = CellGrid::of(input);
  // OpenMP's default count is the most a grid of this size can use: no more threads than it has
  // kMinParallelCells (a 5,000-cell grid runs on one), and the tuner's choice between one and those.
  threads = threadCount > 0 ? threadCount
                            : std::clamp(int(grid.cells() / kMinParallelCells), 1, std::max(1, omp_get_max_threads()));
  tune = threadCount <= 0 && threads > 1;
  passThreads = threads;
  tuner = ThreadTuner(threads);
  w = grid.width;
  h = grid.height;
  L = grid.layers;
  dy = float(input.dyM);
  bw = (w + kBlock - 1) / kBlock;
  bh = (h + kBlock - 1) / kBlock;
  for (const auto& m : input.materials) {
    const MaterialConstants c = materialConstants(m);
    erodibility.push_back(c.erodibility);
    dissolutionRate.push_back(c.dissolutionRate);
    tanTalus.push_back(c.tanTalus);
    weatheringRate.push_back(c.weatheringRatePerS);
    criticalShear.push_back(c.criticalShearPa);
    shearErodibility.push_back(c.shearErodibility);
    tanFriction.push_back(c.tanFriction);
    sinFriction.push_back(c.sinFriction);
    cosFriction.push_back(c.cosFriction);
    cohesionHeight.push_back(c.cohesionHeightM);
    settling = c.settlingVelocityMS;  // the last layer's: deposits land there
  }
  for (int y = 0; y < h; ++y) {
    rowDx.push_back(float(grid.rowDxM[size_t(y)]));
    rowArea.push_back(rowDx.back() * dy);
  }
  for (int y = 0; y <= h; ++y) {
    faceWidthY.push_back(y <= 0   ? rowDx[0]
                         : y >= h ? rowDx[size_t(h) - 1]
                                  : 0.5f * (rowDx[size_t(y) - 1] + rowDx[size_t(y)]));
  }
  base = Plane(w, h);
  bed = Plane(w, h);
  layers = Plane(w, L * h);
  layerStride = layers.stride() * size_t(h);
  for (int y = 0; y < h; ++y) {
    for (int x = 0; x < w; ++x) {
      base.at(x, y) = float(double(input.baseM.at(x, y)) - input.datumM);
      for (int l = 0; l < L; ++l) layers.at(x, l * h + y) = input.layersM[size_t(l)].at(x, y);
      recomputeBed(x, y);
    }
  }
  const bool floodMode = p.waterModel == WaterModel::kFiniteVolume;
  for (auto& s : state) s = Water{Plane(w, h), Plane(w, h), Plane(w, h), Plane(w, h)};
  if (input.waterDepthM.size() > 0) {
    for (int y = 0; y < h; ++y) {
      for (int x = 0; x < w; ++x) state[0].h.at(x, y) = input.waterDepthM.at(x, y);
    }
  }
  if (input.manningN.size() > 0) {
    manningN2 = Plane(w, h);
    for (int y = 0; y < h; ++y) {
      for (int x = 0; x < w; ++x) manningN2.at(x, y) = input.manningN.at(x, y) * input.manningN.at(x, y);
    }
  }
  if (input.infiltrationMmPerHour.size() > 0) {
    infilKs = Plane(w, h);
    infilG = Plane(w, h);
    for (int y = 0; y < h; ++y) {
      for (int x = 0; x < w; ++x) {
        infilKs.at(x, y) = input.infiltrationMmPerHour.at(x, y) * kMmPerHourToMS;
        if (input.infiltrationSuctionM.size() > 0) infilG.at(x, y) = input.infiltrationSuctionM.at(x, y);
      }
    }
  }
  for (auto& a : accum) a = Plane(w, h);
  if (floodMode && p.floodScheme == FloodScheme::kLocalInertial) {
    faceX = Faces{Plane(w + 1, h), Plane(), Plane(), Plane()};
    faceY = Faces{Plane(w, h + 1), Plane(), Plane(), Plane()};
    limit = Plane(w, h);
    for (auto& f : flux) f = Plane(w, h);
  } else if (floodMode) {
    stage = Water{Plane(w, h), Plane(w, h), Plane(w, h), Plane(w, h)};
    faceX = Faces{Plane(w + 1, h), Plane(w + 1, h), Plane(w + 1, h), Plane(w + 1, h)};
    faceY = Faces{Plane(w, h + 1), Plane(w, h + 1), Plane(w, h + 1), Plane(w, h + 1)};
    srcX = Plane(w, h);
    srcY = Plane(w, h);
    limit = Plane(w, h);
    for (int t = 0; t < threads; ++t) scratch.emplace_back(w + 2 * 16, 40);
  } else {
    for (auto& f : flux) f = Plane(w, h);
    if (p.diagonalPipes) {
      for (auto& f : fluxDiag) f = Plane(w, h);
    }
  }
  const size_t blocks = size_t(bw) * size_t(bh);
  needCell.assign(cells(), 0);
  needPrevCell.assign(cells(), 0);
  columns.assign(size_t(w), 0);
  for (auto* v : {&spanRun, &spanPrev, &spanNeed}) v->assign(size_t(h), {w, 0});
  extent.assign(size_t(bw) * size_t(bh), Run{});
  for (auto* v : {&forced, &evapResidual, &rainBlock, &thermalMoving, &thermalForced, &work}) {
    v->assign(blocks, 0);
  }
  for (auto* set : {&water, &sources, &thermalEval, &thermalApply, &lastThermalApply}) {
    set->on.assign(blocks, 0);
    set->runs.reserve(blocks);
  }
  setRain(input.rainMmPerHour);
  allocateFor(p);
  markAll();
}

// The rain raster (mm/h; empty or all 0: none) and which blocks it falls on.
void Impl::setRain(const gis::Grid<float>& mmPerHour) {
  const bool any = std::any_of(mmPerHour.data.begin(), mmPerHour.data.end(), [](float r) { return r != 0.0f; });
  rain = any ? Plane(w, h) : Plane();
  for (int y = 0; y < h && any; ++y) {
    for (int x = 0; x < w; ++x) rain.at(x, y) = mmPerHour.at(x, y);
  }
  for (int by = 0; by < bh; ++by) {
    for (int bx = 0; bx < bw; ++bx) {
      bool wet = false;
      for (int y = by * kBlock; y < std::min(h, (by + 1) * kBlock) && any; ++y) {
        for (int x = bx * kBlock; x < std::min(w, (bx + 1) * kBlock); ++x) wet = wet || rain.at(x, y) != 0.0f;
      }
      rainBlock[size_t(by * bw + bx)] = wet;
    }
  }
}

// Planes that depend on the run-time parameters (erosion and thermal weathering may be switched
// on mid-run): allocated once, never in a step.
void Impl::allocateFor(const SimParams& params) {
  anySuspended = anySuspended || params.erosionEnabled;
  if (params.erosionEnabled && tilt.empty()) tilt = Plane(w, h);
  if (params.thermalEnabled && thermal[0].empty()) {
    for (auto& t : thermal) t = Plane(w, h);
  }
  if ((params.thermalEnabled || params.erosionEnabled) && scour.empty()) scour = Plane(w, h);
  if (params.erosionEnabled && erosionScratch.empty()) {
    for (int t = 0; t < threads; ++t) erosionScratch.emplace_back(w, 2);
  }
  if (params.waterModel == WaterModel::kFiniteVolume && anySuspended && den.empty()) den = Plane(w, h);
}

float Impl::bedOf(int x, int y) const {
  float b = base.at(x, y);
  const float* lay = layers.row(y) + x;
  for (int l = 0; l < L; ++l) b += lay[size_t(l) * layerStride];
  return b;
}

void Impl::recomputeBed(int x, int y) { bed.at(x, y) = bedOf(x, y); }

// The state was replaced (creation, restore): every flag is recomputed and every block runs in
// the next two steps, which brings the ping-pong buffers and the intermediates of every block
// back in line with the state.
void Impl::markAll() {
  dirty = true;
  thermalDirty = true;
  for (int by = 0; by < bh; ++by) {
    for (int bx = 0; bx < bw; ++bx) {
      extent[size_t(by * bw + bx)] = busyExtent(bx, by);
      evapResidual[size_t(by * bw + bx)] = blockEvapResidual(bx, by);
    }
  }
  for (int y = 0; y < h && !anySuspended; ++y) {
    for (int x = 0; x < w; ++x) anySuspended = anySuspended || bitsOf(now().s.at(x, y)) != 0;
  }
  allocateFor(p);
}

// A cell is quiet when its water state (and pipe outflows) are +0: with quiet neighbours, no
// rain, source or level, a step maps it to itself, bit for bit (docs/sim-water.md, "The CPU
// backend"). The smallest rectangle of block (bx, by)'s cells that are not (x1 <= x0: none).
Run Impl::busyExtent(int bx, int by) const {
  const int x0 = bx * kBlock, x1 = std::min(w, x0 + kBlock), y0 = by * kBlock, y1 = std::min(h, y0 + kBlock);
  const Water& u = now();
  const Plane* planes[12] = {&u.h, &u.hu, &u.hv, &u.s};
  int n = 4;
  for (int d = 0; d < 4; ++d) {
    if (!flux[d].empty()) planes[n++] = &flux[d];
    if (!fluxDiag[d].empty()) planes[n++] = &fluxDiag[d];
  }
  // A row's kBlock columns are read whole (a plane's rows are padded to 16 floats, and x0 is a
  // multiple of kBlock, so they are inside the row); those past the grid's edge are masked.
  static_assert(kBlock <= 16 && 16 % kBlock == 0);
  const uint32_t inside = x1 - x0 == kBlock ? ~0u : (1u << (x1 - x0)) - 1u;
  uint32_t columnsSet = 0;
  Run box{y1, y0, x1, x0};
  for (int y = y0; y < y1; ++y) {
    uint32_t bits[kBlock] = {};
    for (int k = 0; k < n; ++k) {
      const float* row = planes[k]->row(y) + x0;
#pragma omp simd
      for (int i = 0; i < kBlock; ++i) bits[i] |= bitsOf(row[i]);
    }
    uint32_t set = 0;
    for (int i = 0; i < kBlock; ++i) set |= uint32_t(bits[i] != 0) << i;
    set &= inside;
    if (set == 0) continue;
    columnsSet |= set;
    box.y0 = std::min(box.y0, y);
    box.y1 = y + 1;
  }
  if (columnsSet == 0) return box;
  box.x0 = x0 + std::countr_zero(columnsSet);
  box.x1 = x0 + 32 - std::countl_zero(columnsSet);
  return box;
}

// Adding 0 to a compensated sum with a nonzero error term may change it (W20), so the sources
// pass keeps running where a cell's evaporation sum has one.
bool Impl::blockEvapResidual(int bx, int by) const {
  const int x0 = bx * kBlock, y0 = by * kBlock;
  return anyBits(accum[kAccumEvaporated + 1], x0, std::min(w, x0 + kBlock), y0, std::min(h, y0 + kBlock));
}

void Impl::dilate(std::vector<uint8_t>& on) {
  std::fill(work.begin(), work.end(), 0);
  for (int by = 0; by < bh; ++by) {
    for (int bx = 0; bx < bw; ++bx) {
      if (!on[size_t(by * bw + bx)]) continue;
      for (int j = std::max(by - 1, 0); j <= std::min(by + 1, bh - 1); ++j) {
        for (int i = std::max(bx - 1, 0); i <= std::min(bx + 1, bw - 1); ++i) work[size_t(j * bw + i)] = 1;
      }
    }
  }
  on.swap(work);
}

void Impl::fillRuns(BlockSet& set) const {
  set.runs.clear();
  set.cells = 0;
  for (int by = 0; by < bh; ++by) {
    const int y0 = by * kBlock, y1 = std::min(h, y0 + kBlock);
    for (int bx = 0; bx < bw;) {
      if (!set.on[size_t(by * bw + bx)]) {
        ++bx;
        continue;
      }
      const int first = bx;
      while (bx < bw && set.on[size_t(by * bw + bx)]) ++bx;
      const Run r{y0, y1, first * kBlock, std::min(w, bx * kBlock)};
      set.runs.push_back(r);
      set.cells += size_t(r.y1 - r.y0) * size_t(r.x1 - r.x0);
    }
  }
}

// How far one step reaches (cells): a cell further than this from every cell that is not quiet,
// gets rain, a source or a level keeps its state and intermediates bit for bit. Flood mode's
// finite volumes: W21's limited slope of a dry cell beside a dry cell is 0 (minmod and MC are 0
// when either difference is), and a face whose two reconstructed depths are 0 carries nothing
// (W13-W16: no flux, no hydrostatic term), so the predictor wets at most the cells beside water
// and the corrector the cells beside those: 2. A cell further away keeps its predictor (its
// state), faces (0), limit (1) and bed source at a dry neighbourhood's values. The local-inertial
// scheme: a face between two dry cells has hf = 0 (W31) and carries nothing whatever the faces
// across it carried, and an open edge's ghost never lets water in (W32): 1.
// (SimCpu.SkippingQuietBlocksChangesNoBit fails with 1 and 0.) Pipes, erosion's bank failure and
// the thermal passes after the water keep the 8 cells the blocks gave them (not analysed).
int Impl::reachCells() const {
  if (p.localStepLevels > 0) return 1 << p.localStepLevels;  // W37: a step of up to 2^levels of the finest
  if (p.waterModel != WaterModel::kFiniteVolume || p.erosionEnabled || p.thermalEnabled) return kBlock;
  return inertial() ? 1 : 2;
}

// Marks the cells [x0 - margin, x1 + margin) x [y0 - margin, y1 + margin) (clipped) to run.
void Impl::needCells(int x0, int x1, int y0, int y1, int margin) {
  x0 = std::max(x0 - margin, 0), x1 = std::min(x1 + margin, w);
  y0 = std::max(y0 - margin, 0), y1 = std::min(y1 + margin, h);
  if (x1 <= x0) return;
  for (int y = y0; y < y1; ++y) {
    std::fill_n(needCell.begin() + ptrdiff_t(size_t(y) * size_t(w) + size_t(x0)), x1 - x0, uint8_t(1));
    auto& s = spanNeed[size_t(y)];
    s = {std::min(s.first, x0), std::max(s.second, x1)};
  }
}

// The water passes' runs from `needCell` (within `spanRun`): per group of kRunRows rows, each span
// of columns with a cell to run in the group, its rows trimmed to those that have one.
void Impl::fillWaterRuns() {
  water.runs.clear();
  water.cells = 0;
  std::fill(water.on.begin(), water.on.end(), 0);
  const uint8_t* need = needCell.data();
  uint8_t* col = columns.data();
  for (int g0 = 0; g0 < h; g0 += kRunRows) {
    const int g1 = std::min(h, g0 + kRunRows);
    int a = w, b = 0;  // the group's columns with a mark
    for (int y = g0; y < g1; ++y) a = std::min(a, spanRun[size_t(y)].first), b = std::max(b, spanRun[size_t(y)].second);
    if (b <= a) continue;
    std::fill(col + a, col + b, uint8_t(0));
    for (int y = g0; y < g1; ++y) {
      const uint8_t* row = need + size_t(y) * size_t(w);
#pragma omp simd
      for (int x = a; x < b; ++x) col[x] |= row[x];
    }
    for (int x = a; x < b;) {
      const auto* hit = static_cast<const uint8_t*>(std::memchr(col + x, 1, size_t(b - x)));
      if (!hit) break;
      const int x0 = int(hit - col);
      const auto* end = static_cast<const uint8_t*>(std::memchr(col + x0, 0, size_t(b - x0)));
      const int x1 = end ? int(end - col) : b;
      x = x1;
      auto rowHas = [&](int y) {
        return std::memchr(need + size_t(y) * size_t(w) + size_t(x0), 1, size_t(x1 - x0)) != nullptr;
      };
      int y0 = g0, y1 = g1;
      while (!rowHas(y0)) ++y0;
      while (!rowHas(y1 - 1)) --y1;
      water.runs.push_back(Run{y0, y1, x0, x1});
      water.cells += size_t(y1 - y0) * size_t(x1 - x0);
      for (int by = y0 / kBlock; by <= (y1 - 1) / kBlock; ++by) {
        for (int bx = x0 / kBlock; bx <= (x1 - 1) / kBlock; ++bx) water.on[size_t(by * bw + bx)] = 1;
      }
    }
  }
}

// The cells and blocks this step's passes run on. A block is busy when a cell of it is not quiet
// or it gets rain, a source or a level this step; the water passes run on the cells within a
// step's reach (reachCells) of such cells (of the whole block for rain), on blocks written from
// outside, and on the cells last step ran for these reasons, so a cell that falls idle runs once
// more with quiet surroundings, which leaves both state buffers and its faces, limits and
// predictor at the values every later step would give them. The sources pass runs on the busy
// blocks and where an evaporation sum carries an error term.
void Impl::planStep(const std::vector<SourceEntry>& entries, const std::vector<LevelEntry>& levels) {
  const size_t blocks = extent.size();
  auto all = [&](BlockSet& set) {
    std::fill(set.on.begin(), set.on.end(), 1);
    fillRuns(set);
  };
  if (!skip) {
    all(water);
    all(sources);
    if (p.thermalEnabled) all(thermalEval);
    return;
  }
  std::vector<uint8_t>& busy = sources.on;
  const bool rainEverywhere = p.rainMmPerHour != 0.0f;
  for (size_t b = 0; b < blocks; ++b) busy[b] = !quiet(b) || rainBlock[b] || rainEverywhere;
  for (const auto& e : entries) busy[blockOf(e.cell)] = 1;
  for (const auto& e : levels) busy[blockOf(e.cell)] = 1;
  // Last step's marks are cleared where they were (row spans), this step's made.
  for (int y = 0; y < h; ++y) {
    const auto [a, b] = spanRun[size_t(y)];
    if (b > a) std::fill_n(needCell.begin() + ptrdiff_t(size_t(y) * size_t(w) + size_t(a)), b - a, uint8_t(0));
  }
  std::fill(spanNeed.begin(), spanNeed.end(), std::pair{w, 0});
  if (dirty || rainEverywhere) {
    needCells(0, w, 0, h, 0);
  } else {
    const int reach = reachCells();
    for (int by = 0; by < bh; ++by) {
      for (int bx = 0; bx < bw; ++bx) {
        const size_t b = size_t(by * bw + bx);
        const int x0 = bx * kBlock, y0 = by * kBlock, x1 = std::min(w, x0 + kBlock), y1 = std::min(h, y0 + kBlock);
        if (rainBlock[b]) {
          needCells(x0, x1, y0, y1, reach);
        } else if (!quiet(b)) {
          const Run& e = extent[b];
          if (e.x1 > e.x0) needCells(e.x0, e.x1, e.y0, e.y1, reach);
        }
        if (forced[b]) needCells(x0, x1, y0, y1, 0);
      }
    }
    auto cellAt = [&](uint32_t cell) {
      const int x = int(cell % uint32_t(w)), y = int(cell / uint32_t(w));
      needCells(x, x + 1, y, y + 1, reach);
    };
    for (const auto& e : entries) cellAt(e.cell);
    for (const auto& e : levels) cellAt(e.cell);
  }
  // The cells to run: this step's and last step's marks; this step's are kept for the next.
  for (int y = 0; y < h; ++y) {
    const auto now = spanNeed[size_t(y)], prev = spanPrev[size_t(y)];
    const int a = std::min(now.first, prev.first), b = std::max(now.second, prev.second);
    uint8_t* cell = needCell.data() + size_t(y) * size_t(w);
    uint8_t* last = needPrevCell.data() + size_t(y) * size_t(w);
#pragma omp simd
    for (int x = a; x < b; ++x) {
      const uint8_t need = cell[x];
      cell[x] = need | last[x];
      last[x] = need;
    }
    spanRun[size_t(y)] = {a, b};
    spanPrev[size_t(y)] = now;
  }
  for (size_t b = 0; b < blocks; ++b) busy[b] = busy[b] || evapResidual[b] || forced[b] || dirty;
  fillWaterRuns();
  fillRuns(sources);
  if (p.thermalEnabled) {
    // The thermal flux of a block changes only when the bed, layers or water of it or its
    // neighbours changed: where the water passes or last step's thermal transfers ran.
    thermalEval.on = water.on;
    for (size_t b = 0; b < blocks; ++b) {
      thermalEval.on[b] = thermalEval.on[b] || lastThermalApply.on[b] || thermalForced[b];
    }
    dilate(thermalEval.on);
    if (thermalDirty) std::fill(thermalEval.on.begin(), thermalEval.on.end(), 1);
    fillRuns(thermalEval);
  }
}

// After a step that updated `updates` cells: the quiet and evaporation flags of the blocks that ran
// (the others did not change).
void Impl::finishStep(long long updates) {
  cellUpdates += updates;
  dirty = false;
  thermalDirty = false;
  if (!skip) return;
  const int blocks = bw * bh;
  const bool parallel = passThreads > 1 && water.cells >= kMinParallelCells;
  // While rain falls everywhere every block is busy anyway: the blocks that ran count as not
  // quiet, their whole block as their extent (which is always safe), without a look at their cells.
  const bool rainEverywhere = p.rainMmPerHour != 0.0f;
#pragma omp parallel for schedule(dynamic, 8) num_threads(passThreads) if (parallel)
  for (int b = 0; b < blocks; ++b) {
    if (water.on[size_t(b)]) {
      const int x0 = (b % bw) * kBlock, y0 = (b / bw) * kBlock;
      extent[size_t(b)] =
          rainEverywhere ? Run{y0, std::min(h, y0 + kBlock), x0, std::min(w, x0 + kBlock)} : busyExtent(b % bw, b / bw);
    }
    if (sources.on[size_t(b)]) evapResidual[size_t(b)] = blockEvapResidual(b % bw, b / bw);
  }
  std::fill(forced.begin(), forced.end(), 0);
  std::fill(thermalForced.begin(), thermalForced.end(), 0);
  lastThermalApply.on.swap(thermalApply.on);
}

// One step: docs/sim-water.md, "Step".
void Impl::step(const std::vector<SourceEntry>& entries, const std::vector<LevelEntry>& levels, float dtS,
                double endS) {
  dt = dtS;
  planStep(entries, levels);
  if (p.waterModel == WaterModel::kVirtualPipes) {
    sourcesPass(entries);
    pipeFluxPass();
    pipeUpdatePass();
  } else if (inertial()) {
    inertialFacePass();
    sourcesPass(entries);  // W38: after the faces, before the limits
    fvLimitPass();
    inertialUpdatePass();
  } else {
    sourcesPass(entries, 0.5f);  // W12b: half of the point sources before the faces
    fvFacePass(now(), false);
    fvUpdatePass(false);
    fvFacePass(stage, true);
    fvLimitPass();
    if (anySuspended) fvDenPass();
    fvUpdatePass(true);
  }
  cur = 1 - cur;
  if (p.waterModel == WaterModel::kFiniteVolume && !inertial()) pointSources(entries, 0.5f);  // W12b: the other half
  if (!levels.empty()) levelPass(levels);
  if (p.erosionEnabled) erosionPass();
  if (p.thermalEnabled) {
    thermalFluxPass();
    // What is shed lands on the neighbours: the blocks with a cell that sheds and theirs.
    if (skip) {
      thermalApply.on = thermalMoving;
      dilate(thermalApply.on);
    } else {
      std::fill(thermalApply.on.begin(), thermalApply.on.end(), 1);
    }
    fillRuns(thermalApply);
    thermalApplyPass();
  } else {
    std::fill(thermalApply.on.begin(), thermalApply.on.end(), 0);
  }
  if (floodStats) floodStatsPass(float(endS));
  finishStep((long long)water.cells);
}

}  // namespace cpu

struct CpuSolver::Impl : cpu::Impl {
  using cpu::Impl::Impl;
};

using cpu::kMmPerHourToMS;
using cpu::velocityOf;

CpuSolver::CpuSolver(const SimInput& input, const SimParams& params, const CpuOptions& options)
    : Solver(input, params), impl_(std::make_unique<Impl>(input, params, options.threads, options.skipQuietBlocks)) {}
CpuSolver::CpuSolver(CpuSolver&&) noexcept = default;
CpuSolver& CpuSolver::operator=(CpuSolver&&) noexcept = default;
CpuSolver::~CpuSolver() = default;

Result<CpuSolver> CpuSolver::create(const SimInput& input, const SimParams& params, const CpuOptions& options) {
  STRATA_TRY_STATUS(validate(input, params));
  CpuSolver s(input, params, options);
  s.recordInitialTotals();
  return s;
}

std::string CpuSolver::backendName() const {
  const int n = impl_->threads;
  if (impl_->tune) {  // how the steps so far were shared
    const auto& t = impl_->tuner;
    const long long one = t.stepsOn(true), all = one + t.stepsOn(false);
    const std::string counts = "CPU, 1 or " + std::to_string(n) + " OpenMP threads, whichever ";
    if (all == 0) return counts + "runs faster";
    return counts + "ran faster (" + std::to_string(int(std::lround(100.0 * double(one) / double(all)))) +
           "% of the steps on 1)";
  }
  return "CPU, " + std::to_string(n) + (n == 1 ? " OpenMP thread" : " OpenMP threads");
}

int CpuSolver::threads() const { return impl_->threads; }
long long CpuSolver::cellUpdates() const { return impl_->cellUpdates; }

void CpuSolver::integrateFaces(const std::vector<size_t>& faces) {
  Impl& m = *impl_;
  if (m.p.localStepLevels == 0) return;  // one step applies one flux
  const size_t xFaces = size_t(m.w + 1) * size_t(m.h);
  m.integrated.clear();
  m.integratedSlot.clear();
  for (size_t k = 0; k < faces.size(); ++k) {
    const size_t i = faces[k];
    const bool alongX = i < xFaces;
    const size_t j = alongX ? i : i - xFaces, across = size_t(alongX ? m.w + 1 : m.w);
    const int x = int(j % across), y = int(j / across);  // cell b's, and the face's, position
    const int xa = alongX ? x - 1 : x, ya = alongX ? y : y - 1;
    m.integrated.push_back({xa, ya, x, y, alongX, xa >= 0 && ya >= 0, x < m.w && y < m.h});
    m.integratedSlot.emplace(i, k);
  }
  m.integratedQdt.assign(faces.size(), 0.0);
  m.integratedStepS = 0;
}

SolverFactory cpuSolverFactory(const CpuOptions& options) {
  return [options](const SimInput& input, const SimParams& params) -> Result<std::unique_ptr<Solver>> {
    STRATA_TRY(auto s, CpuSolver::create(input, params, options));
    return std::unique_ptr<Solver>(std::make_unique<CpuSolver>(std::move(s)));
  };
}

double cpu::ThreadTuner::median(int k) const {
  static_assert(kRounds == 3);
  const double* r = rates_[k];
  switch (std::min(measured_[k], kRounds)) {
    case 0: return 0.0;
    case 1: return r[0];
    case 2: return 0.5 * (r[0] + r[1]);
    default: return std::max(std::min(r[0], r[1]), std::min(std::max(r[0], r[1]), r[2]));
  }
}

void cpu::ThreadTuner::record(double seconds, long long updates) {
  const int k = now_ == 1 ? 0 : 1;
  ++steps_[k];
  seconds_ += seconds;
  updates_ += double(updates);
  if (++inWindow_ < kWindow) return;
  if (updates_ > 0) rates_[k][measured_[k]++ % kRounds] = seconds_ / updates_;
  inWindow_ = 0;
  seconds_ = updates_ = 0;
  ++windows_;
  if (windows_ < 2 * kRounds) {  // the first windows alternate the counts
    now_ = now_ == 1 ? most_ : 1;
    return;
  }
  if ((runLeft_ -= kWindow) > 0) return;
  if (runLeft_ > -kWindow) {  // a run ended: the other count for one window
    now_ = now_ == 1 ? most_ : 1;
    runLeft_ = -kWindow;
    return;
  }
  const bool both = measured_[0] > 0 && measured_[1] > 0;
  now_ = both && median(1) < kGain * median(0) ? most_ : 1;
  runLeft_ = kRun;
}

void CpuSolver::runStep(const StepInputs& step) {
  Impl& m = *impl_;
  m.floodStats = floodThresholdM() >= 0;
  m.wetThresholdM = floodThresholdM();
  auto run = [&] {
    const double end = step.startS + double(step.dtS);
    if (m.p.localStepLevels == 0) return m.step(step.sources, step.levels, step.dtS, end);
    // W10's bound on the rain's depth rate, as sourceDepthRate adds it.
    m.localStep(step.sources, step.levels, step.dtS, end, (double(m.p.rainMmPerHour) + maxRainRasterMmH()) / 3.6e6);
  };
  if (!m.tune) return run();
  m.passThreads = m.tuner.threads();
  const long long before = m.cellUpdates;
  const auto t0 = std::chrono::steady_clock::now();
  run();
  m.tuner.record(std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count(), m.cellUpdates - before);
}

Status CpuSolver::onRainRasterChanged(const gis::Grid<float>& mmPerHour) {
  impl_->setRain(mmPerHour);
  return {};
}

void CpuSolver::onParamsChanged() {
  Impl& m = *impl_;
  const SimParams& next = params();
  // The thermal flux depends on these besides the cells: evaluate it everywhere once.
  if (next.thermalEnabled != m.p.thermalEnabled || next.bankFillShare != m.p.bankFillShare ||
      next.erosionEnabled != m.p.erosionEnabled) {
    m.thermalDirty = true;
  }
  const int reach = m.reachCells();
  m.p = next;
  // Cells the old reach left out may hold intermediates the new model reads: all run twice.
  if (m.reachCells() != reach) m.dirty = true;
  m.allocateFor(next);
  // No erosion, no toe scour (E8): what the last erosion pass left must not bring banks down.
  if (!next.erosionEnabled && !m.scour.empty()) m.scour = cpu::Plane(m.w, m.h);
}

double CpuSolver::maxWaveSpeedMS() const { return double(impl_->maxWaveSpeed()); }

namespace {
template <class F>
gis::Grid<float> gridOf(int w, int h, F&& value) {
  gis::Grid<float> g(w, h);
  for (int y = 0; y < h; ++y) {
    for (int x = 0; x < w; ++x) g.at(x, y) = value(x, y);
  }
  return g;
}
}  // namespace

gis::Grid<float> CpuSolver::readWaterDepth() const {
  const auto& u = impl_->now();
  return gridOf(impl_->w, impl_->h, [&](int x, int y) { return u.h.at(x, y); });
}

VelocityField CpuSolver::readVelocity() const {
  const auto& u = impl_->now();
  const float dry = params().dryDepthM;
  return {gridOf(impl_->w, impl_->h, [&](int x, int y) { return velocityOf(u.h.at(x, y), u.hu.at(x, y), dry); }),
          gridOf(impl_->w, impl_->h, [&](int x, int y) { return velocityOf(u.h.at(x, y), u.hv.at(x, y), dry); })};
}

std::vector<gis::Grid<float>> CpuSolver::readLayers() const {
  const Impl& m = *impl_;
  std::vector<gis::Grid<float>> out;
  for (int l = 0; l < m.L; ++l)
    out.push_back(gridOf(m.w, m.h, [&](int x, int y) { return m.layers.at(x, l * m.h + y); }));
  return out;
}

gis::Grid<float> CpuSolver::readSuspended() const {
  const auto& u = impl_->now();
  return gridOf(impl_->w, impl_->h, [&](int x, int y) { return u.s.at(x, y); });
}

gis::Grid<float> CpuSolver::readBed() const {
  return gridOf(impl_->w, impl_->h, [&](int x, int y) { return impl_->bed.at(x, y); });
}

Solver::Totals CpuSolver::totals() const {
  const Impl& m = *impl_;
  const auto& u = m.now();
  Totals t;
  t.depth.resize(m.cells());
  t.suspended.resize(m.cells());
  t.layers.resize(m.cells() * size_t(m.L));
  for (int y = 0; y < m.h; ++y) {
    for (int x = 0; x < m.w; ++x) {
      const size_t i = size_t(y) * size_t(m.w) + size_t(x);
      t.depth[i] = u.h.at(x, y);
      t.suspended[i] = u.s.at(x, y);
      for (int l = 0; l < m.L; ++l) t.layers[size_t(l) * m.cells() + i] = m.layers.at(x, l * m.h + y);
      t.outflowM3 += double(m.accum[kAccumOutflow].at(x, y));
      t.evaporatedM3 += double(m.accum[kAccumEvaporated].at(x, y));
      t.infiltratedM3 += double(m.accum[kAccumInfiltrated].at(x, y));
      t.sedimentOutflowM3 += double(m.accum[kAccumSedimentOut].at(x, y));
      const float level = m.accum[kAccumLevel].at(x, y);
      (level > 0 ? t.levelInM3 : t.levelOutM3) += double(level);
    }
  }
  return t;
}

void CpuSolver::resetFloodStats() {
  Impl& m = *impl_;
  for (auto& f : m.flood) f = cpu::Plane(m.w, m.h);
  for (int y = 0; y < m.h; ++y) {
    float* arrival = m.flood[2].row(y);
    std::fill(arrival, arrival + m.w, -1.0f);
  }
}

std::vector<float> CpuSolver::floodStatsCells() const {
  const Impl& m = *impl_;
  std::vector<float> out(4 * m.cells());
  for (int y = 0; y < m.h; ++y) {
    for (int x = 0; x < m.w; ++x) {
      const size_t i = size_t(y) * size_t(m.w) + size_t(x);
      for (int k = 0; k < 4; ++k) out[4 * i + size_t(k)] = m.flood[k].at(x, y);
    }
  }
  return out;
}

void CpuSolver::setFloodStatsCells(const std::vector<float>& cells) {
  Impl& m = *impl_;
  STRATA_CHECK(cells.size() == 4 * m.cells()) << "flood statistics of " << cells.size() / 4 << " cells";
  if (m.flood[0].empty()) resetFloodStats();
  for (int y = 0; y < m.h; ++y) {
    for (int x = 0; x < m.w; ++x) {
      const size_t i = size_t(y) * size_t(m.w) + size_t(x);
      for (int k = 0; k < 4; ++k) m.flood[k].at(x, y) = cells[4 * i + size_t(k)];
    }
  }
}

namespace {
// Copies N planes at cells [x0, x0 + width) x [y0, y0 + height) to / from per-cell groups.
template <size_t N>
void planesToCells(const std::array<const cpu::Plane*, N>& planes, int x0, int y0, int width, int height, float* out) {
  for (int y = 0; y < height; ++y) {
    for (int x = 0; x < width; ++x) {
      for (size_t k = 0; k < N; ++k) *out++ = planes[k]->empty() ? 0.0f : planes[k]->at(x0 + x, y0 + y);
    }
  }
}
template <size_t N>
void cellsToPlanes(const float* in, int x0, int y0, int width, int height, const std::array<cpu::Plane*, N>& planes) {
  for (int y = 0; y < height; ++y) {
    for (int x = 0; x < width; ++x) {
      for (size_t k = 0; k < N; ++k, ++in) {
        if (!planes[k]->empty()) planes[k]->at(x0 + x, y0 + y) = *in;
      }
    }
  }
}
// A group's planes: the water state, the pipes, the diagonal pipes, the accumulators (AccumOffset order).
template <class P, size_t N>
std::array<P*, N> planesOf(P (&planes)[N]) {
  std::array<P*, N> out;
  for (size_t k = 0; k < N; ++k) out[k] = &planes[k];
  return out;
}
// The accumulators a halo carries (kBlockCarried): the last kAccumCarried of them.
template <class P, size_t N>
std::array<P*, kAccumCarried> carriedPlanesOf(P (&accum)[N]) {
  static_assert(N == kAccumPerCell);
  std::array<P*, kAccumCarried> out;
  for (size_t k = 0; k < out.size(); ++k) out[k] = &accum[kAccumCarriedFrom + k];
  return out;
}
template <class W>
auto statePlanesOf(W& u) {
  using P = std::remove_reference_t<decltype((u.h))>;
  return std::array<P*, 4>{&u.h, &u.s, &u.hu, &u.hv};
}
}  // namespace

void CpuSolver::saveCells(SolverState& out) const {
  const Impl& m = *impl_;
  const auto& u = m.now();
  const size_t n = m.cells();
  const auto statePlanes = statePlanesOf(u);
  const auto fluxPlanes = planesOf(m.flux);
  const auto diagPlanes = planesOf(m.fluxDiag);
  const auto accumPlanes = planesOf(m.accum);
  out.state.resize(4 * n);
  out.flux.resize(4 * n);
  out.fluxDiag.resize(4 * n);
  out.accum.resize(kAccumPerCell * n);
  planesToCells(statePlanes, 0, 0, m.w, m.h, out.state.data());
  planesToCells(fluxPlanes, 0, 0, m.w, m.h, out.flux.data());
  planesToCells(diagPlanes, 0, 0, m.w, m.h, out.fluxDiag.data());
  planesToCells(accumPlanes, 0, 0, m.w, m.h, out.accum.data());
  out.layers = totals().layers;
}

Status CpuSolver::restoreCells(const SolverState& in) {
  Impl& m = *impl_;
  const size_t n = m.cells();
  if (in.state.size() != 4 * n || in.flux.size() != 4 * n || in.fluxDiag.size() != 4 * n ||
      in.layers.size() != size_t(m.L) * n || in.accum.size() != kAccumPerCell * n) {
    return fail("sim: the saved state is of a different grid (" + std::to_string(in.state.size() / 4) +
                " cells, this simulation has " + std::to_string(n) + ")");
  }
  CellBlock b{.rect = {0, 0, m.w, m.h},
              .state = in.state,
              .flux = in.flux,
              .fluxDiag = in.fluxDiag,
              .layers = in.layers,
              .accum = in.accum};
  writeBlock(b);
  m.markAll();
  return {};
}

CellBlock CpuSolver::readBlock(int x0, int y0, int width, int height, unsigned parts) const {
  const Impl& m = *impl_;
  CellBlock b{.rect = {x0, y0, width, height}};
  STRATA_CHECK(blockFits(b, m.w, m.h, m.L)) << "readBlock (" << x0 << ", " << y0 << ") " << width << "x" << height
                                            << " outside the " << m.w << "x" << m.h << " grid";
  const auto& u = m.now();
  const size_t cells = b.cells();
  const auto statePlanes = statePlanesOf(u);
  const auto fluxPlanes = planesOf(m.flux);
  const auto diagPlanes = planesOf(m.fluxDiag);
  const auto accumPlanes = planesOf(m.accum);
  if (parts & kBlockState) {
    b.state.resize(4 * cells);
    planesToCells(statePlanes, x0, y0, width, height, b.state.data());
  }
  if (parts & kBlockFlux) {
    b.flux.resize(4 * cells);
    planesToCells(fluxPlanes, x0, y0, width, height, b.flux.data());
    if (params().diagonalPipes) {
      b.fluxDiag.resize(4 * cells);
      planesToCells(diagPlanes, x0, y0, width, height, b.fluxDiag.data());
    }
  }
  if (parts & kBlockLayers) {
    b.layers.resize(size_t(m.L) * cells);
    for (int l = 0; l < m.L; ++l) {
      for (int y = 0; y < height; ++y) {
        for (int x = 0; x < width; ++x) {
          b.layers[size_t(l) * cells + size_t(y) * size_t(width) + size_t(x)] = m.layers.at(x0 + x, l * m.h + y0 + y);
        }
      }
    }
  }
  if (parts & kBlockAccum) {
    b.accum.resize(kAccumPerCell * cells);
    planesToCells(accumPlanes, x0, y0, width, height, b.accum.data());
  }
  if (parts & kBlockCarried) {
    b.carried.resize(kAccumCarried * cells);
    planesToCells(carriedPlanesOf(m.accum), x0, y0, width, height, b.carried.data());
  }
  return b;
}

void CpuSolver::writeBlock(const CellBlock& b) {
  Impl& m = *impl_;
  STRATA_CHECK(blockFits(b, m.w, m.h, m.L)) << "writeBlock: sizes do not match the block or the grid";
  auto& u = m.now();
  const size_t cells = b.cells();
  const auto statePlanes = statePlanesOf(u);
  const auto fluxPlanes = planesOf(m.flux);
  const auto diagPlanes = planesOf(m.fluxDiag);
  const auto accumPlanes = planesOf(m.accum);
  if (!b.state.empty()) cellsToPlanes(b.state.data(), b.rect.x, b.rect.y, b.rect.width, b.rect.height, statePlanes);
  if (!b.flux.empty()) cellsToPlanes(b.flux.data(), b.rect.x, b.rect.y, b.rect.width, b.rect.height, fluxPlanes);
  if (!b.fluxDiag.empty())
    cellsToPlanes(b.fluxDiag.data(), b.rect.x, b.rect.y, b.rect.width, b.rect.height, diagPlanes);
  if (!b.accum.empty()) cellsToPlanes(b.accum.data(), b.rect.x, b.rect.y, b.rect.width, b.rect.height, accumPlanes);
  if (!b.carried.empty()) {
    cellsToPlanes(b.carried.data(), b.rect.x, b.rect.y, b.rect.width, b.rect.height, carriedPlanesOf(m.accum));
  }
  if (!b.layers.empty()) {
    for (int l = 0; l < m.L; ++l) {
      for (int y = 0; y < b.rect.height; ++y) {
        for (int x = 0; x < b.rect.width; ++x) {
          m.layers.at(b.rect.x + x, l * m.h + b.rect.y + y) =
              b.layers[size_t(l) * cells + size_t(y) * size_t(b.rect.width) + size_t(x)];
        }
      }
    }
    for (int y = 0; y < b.rect.height; ++y) {
      for (int x = 0; x < b.rect.width; ++x) m.recomputeBed(b.rect.x + x, b.rect.y + y);
    }
  }
  // The blocks written run in the next two steps (their other state buffer and intermediates
  // are stale), and their flags follow the new cells.
  if (b.rect.width == 0 || b.rect.height == 0) return;
  for (int by = b.rect.y / cpu::kBlock; by <= (b.rect.y + b.rect.height - 1) / cpu::kBlock; ++by) {
    for (int bx = b.rect.x / cpu::kBlock; bx <= (b.rect.x + b.rect.width - 1) / cpu::kBlock; ++bx) {
      const size_t k = size_t(by * m.bw + bx);
      m.forced[k] = 1;
      m.thermalForced[k] = 1;
      m.extent[k] = m.busyExtent(bx, by);
      m.evapResidual[k] = m.blockEvapResidual(bx, by);
    }
  }
  for (int y = b.rect.y; y < b.rect.y + b.rect.height && !m.anySuspended && !b.state.empty(); ++y) {
    for (int x = b.rect.x; x < b.rect.x + b.rect.width; ++x)
      m.anySuspended = m.anySuspended || u.s.at(x, y) != 0.0f || std::signbit(u.s.at(x, y));
  }
  m.allocateFor(m.p);
}

namespace {

// Flood mode's flux through x face (x, y) or y face (x, y) as the last corrector applied it:
// scaled by its upwind cell's W25 limit (fvUpdatePass). The local-inertial scheme's cells keep the
// discharges they applied (the same product), which local steps (W37) leave on every face as the
// last step of its finer cell applied it.
template <class Impl>
float appliedFaceFlux(const Impl& m, bool xFace, int x, int y) {
  if (m.inertial()) {
    if (xFace) return x < m.w ? m.flux[0].at(x, y) : m.flux[1].at(m.w - 1, y);
    return y < m.h ? m.flux[2].at(x, y) : m.flux[3].at(x, m.h - 1);
  }
  const float f = xFace ? m.faceX.mass.at(x, y) : m.faceY.mass.at(x, y);
  const int ux = f > 0.0f ? (xFace ? x - 1 : x) : x, uy = f > 0.0f ? (xFace ? y : y - 1) : y;
  return ux < 0 || uy < 0 || ux >= m.w || uy >= m.h ? f : f * m.limit.at(ux, uy);
}

}  // namespace

std::vector<float> CpuSolver::readFaceMassFlux() const {
  const Impl& m = *impl_;
  STRATA_CHECK(params().waterModel == WaterModel::kFiniteVolume) << "face fluxes exist in flood mode only";
  std::vector<float> out;
  out.reserve(size_t(m.w + 1) * size_t(m.h) + size_t(m.w) * size_t(m.h + 1));
  for (int y = 0; y < m.h; ++y) {
    for (int x = 0; x <= m.w; ++x) out.push_back(appliedFaceFlux(m, true, x, y));
  }
  for (int y = 0; y <= m.h; ++y) {
    for (int x = 0; x < m.w; ++x) out.push_back(appliedFaceFlux(m, false, x, y));
  }
  return out;
}

std::vector<float> CpuSolver::readFaceMassFluxAt(const std::vector<size_t>& faces) const {
  const Impl& m = *impl_;
  STRATA_CHECK(params().waterModel == WaterModel::kFiniteVolume) << "face fluxes exist in flood mode only";
  const size_t xFaces = size_t(m.w + 1) * size_t(m.h), all = xFaces + size_t(m.w) * size_t(m.h + 1);
  std::vector<float> out;
  out.reserve(faces.size());
  for (size_t i : faces) {
    STRATA_CHECK(i < all) << "face " << i << " outside the grid's " << all;
    // W37: an integrated face's mean over the last step of local steps.
    if (const auto slot = m.integratedSlot.find(i); slot != m.integratedSlot.end() && m.integratedStepS > 0) {
      out.push_back(float(m.integratedQdt[slot->second] / m.integratedStepS));
    } else if (i < xFaces) {
      out.push_back(appliedFaceFlux(m, true, int(i % size_t(m.w + 1)), int(i / size_t(m.w + 1))));
    } else {
      out.push_back(appliedFaceFlux(m, false, int((i - xFaces) % size_t(m.w)), int((i - xFaces) / size_t(m.w))));
    }
  }
  return out;
}

}  // namespace strata::sim
