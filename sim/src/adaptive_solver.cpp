// Adaptive tiles (docs/sim-water.md, "Adaptive tiles", A1-A6): per-tile levels of the region's
// mip pyramid, halos by restriction/prolongation, refluxing at coarse/fine tile edges.
#include <strata/sim/adaptive_solver.hpp>

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>
#include <utility>

#include <strata/terrain/tile_store.hpp>

#include "tile_common.hpp"

namespace strata::sim {

using detail::crop;

namespace {
// A3: the water level eta at which cells of beds b_i and areas a_i hold `volume`
// (sum a_i max(0, eta - b_i) = volume); `cells` holds (b_i, a_i) and is sorted here.
double fillLevel(std::vector<std::pair<double, double>>& cells, double volume) {
  std::sort(cells.begin(), cells.end());
  double area = 0, moment = 0;  // sum a_j, sum a_j b_j over the cells below eta
  for (size_t i = 0; i < cells.size(); ++i) {
    area += cells[i].second;
    moment += cells[i].first * cells[i].second;
    const double eta = (volume + moment) / area;
    if (i + 1 == cells.size() || eta <= cells[i + 1].first) return eta;
  }
  return cells.empty() ? 0.0 : cells.back().first;
}
}  // namespace

AdaptiveSolver::AdaptiveSolver(const SimInput& input, const SimParams& params, const AdaptiveOptions& options,
                               const SolverFactory& makeTile)
    : Solver(input, params), input_(input), o_(options), makeTile_(makeTile) {}

Result<AdaptiveSolver> AdaptiveSolver::create(const SimInput& input, const SimParams& params,
                                              const AdaptiveOptions& options, const SolverFactory& makeTile) {
  STRATA_TRY_STATUS(validate(input, params));
  if (params.waterModel != WaterModel::kFiniteVolume || params.floodScheme != FloodScheme::kFiniteVolume ||
      params.erosionEnabled || params.thermalEnabled) {
    return fail(
        "adaptive tiles: flood mode's finite-volume scheme (waterModel = finite volume) without erosion or thermal "
        "weathering only");
  }
  if (input.infiltrationMmPerHour.size() > 0) {
    // A level's cells would start with a dry soil where a finer or coarser one had taken water in.
    return fail("adaptive tiles: no infiltration (the soil's state does not pass between levels)");
  }
  const int T = options.tileSize, f = 1 << std::max(0, options.maxLevel);
  if (options.maxLevel < 0 || options.maxLevel > 6 || T < 2 || T % f != 0 || options.halo < 1 ||
      options.regridEvery < 1 || !(options.coarsenBelow <= options.refineAbove)) {
    return fail(
        "adaptive tiles: need 0 <= maxLevel <= 6, tileSize a multiple of 2^maxLevel, halo >= 1, "
        "regridEvery >= 1 and coarsenBelow <= refineAbove");
  }
  const int w = input.baseM.width, h = input.baseM.height;
  if (w % T != 0 || h % T != 0) {
    return fail("adaptive tiles: the grid (" + std::to_string(w) + "x" + std::to_string(h) +
                ") must be a multiple of tileSize (" + std::to_string(T) + ") in both directions");
  }
  AdaptiveSolver a(input, params, options, makeTile);
  a.width_ = w;
  a.height_ = h;
  a.tilesX_ = w / T;
  a.tilesY_ = h / T;
  const size_t n = size_t(w) * size_t(h);

  // A2: the mip pyramid: box means of base, layers and rain; row dx summed in pairs (a coarse
  // cell's area is the sum of its four children's); the bed as the solvers compute it.
  Pyramid l0;
  l0.width = w;
  l0.height = h;
  l0.baseM = input.baseM;
  l0.layersM = input.layersM;
  l0.rainMmH = input.rainMmPerHour.size() > 0 ? input.rainMmPerHour : gis::Grid<float>(w, h, 0.0f);
  l0.manningN = input.manningN;
  l0.rowDxM = a.grid().rowDxM;
  a.mips_.push_back(std::move(l0));
  for (int L = 1; L <= options.maxLevel; ++L) {
    const Pyramid& prev = a.mips_.back();
    Pyramid m;
    m.width = prev.width / 2;
    m.height = prev.height / 2;
    m.baseM = terrain::boxDownsample(prev.baseM, 2);
    m.rainMmH = terrain::boxDownsample(prev.rainMmH, 2);
    if (prev.manningN.size() > 0) m.manningN = terrain::boxDownsample(prev.manningN, 2);
    for (const auto& l : prev.layersM) m.layersM.push_back(terrain::boxDownsample(l, 2));
    for (int y = 0; y < m.height; ++y) m.rowDxM.push_back(prev.rowDxM[size_t(2 * y)] + prev.rowDxM[size_t(2 * y + 1)]);
    a.mips_.push_back(std::move(m));
  }
  for (auto& m : a.mips_) {
    m.bed.resize(size_t(m.width) * size_t(m.height));
    for (size_t i = 0; i < m.bed.size(); ++i) {
      float b = float(double(m.baseM.data[i]) - input.datumM);
      for (const auto& l : m.layersM) b += l.data[i];
      m.bed[i] = b;
    }
  }

  for (int ty = 0; ty < a.tilesY_; ++ty) {
    for (int tx = 0; tx < a.tilesX_; ++tx) {
      Tile t;
      t.x0 = tx * T;
      t.y0 = ty * T;
      t.level = options.maxLevel;
      t.sims.resize(size_t(options.maxLevel + 1));
      for (int L = 0; L <= options.maxLevel; ++L) {
        const auto& m = a.mips_[size_t(L)];
        t.ex0.push_back(std::max(0, (t.x0 >> L) - options.halo));
        t.ey0.push_back(std::max(0, (t.y0 >> L) - options.halo));
        t.ex1.push_back(std::min(m.width, ((t.x0 + T) >> L) + options.halo));
        t.ey1.push_back(std::min(m.height, ((t.y0 + T) >> L) + options.halo));
      }
      a.tiles_.push_back(std::move(t));
    }
  }
  for (size_t L = 0; L < a.mips_.size(); ++L) {
    double m = input.dyM * double(1 << L);
    for (double dx : a.mips_[L].rowDxM) m = std::min(m, dx);
    a.minCell_.push_back(m);
  }
  a.prevDepth_ = input.waterDepthM.size() > 0 ? input.waterDepthM.data : std::vector<float>(n, 0.0f);
  a.recordInitialTotals();
  return a;
}

std::string AdaptiveSolver::backendName() const {
  for (const auto& t : tiles_) {
    for (const auto& s : t.sims) {
      if (s) return "adaptive tiles on " + s->backendName();
    }
  }
  return "adaptive tiles";
}

int AdaptiveSolver::ownerOf(int bx, int by) const { return (by / o_.tileSize) * tilesX_ + bx / o_.tileSize; }

void AdaptiveSolver::forEachPart(const std::function<void(Solver&)>& f) {
  for (auto& t : tiles_) {
    for (auto& sim : t.sims) {
      if (sim) f(*sim);
    }
  }
}

// Its solvers hold the accumulators (each tile's levels made so far; one made later starts at 0).
void AdaptiveSolver::clearAccumulators() {
  forEachPart([](Solver& sim) { sim.restartAt(sim.timeS()); });
}

Status AdaptiveSolver::onSourceAdded(const Source& source) {
  if (started_) return fail("adaptive tiles: add sources before the first step");
  for (auto [x, y] : source.cells) tiles_[size_t(ownerOf(x, y))].pinned = true;
  return {};
}

Status AdaptiveSolver::onLevelAdded(const LevelBoundary& /*level*/) {
  return fail("adaptive tiles: fixed water levels are not supported (use a full-resolution or tiled run)");
}

Status AdaptiveSolver::ensureSim(Tile& t, int L) {
  if (t.sims[size_t(L)]) return {};
  const auto& m = mips_[size_t(L)];
  const int ex0 = t.ex0[size_t(L)], ey0 = t.ey0[size_t(L)], ex1 = t.ex1[size_t(L)], ey1 = t.ey1[size_t(L)];
  SimInput sub;
  sub.baseM = crop(m.baseM, ex0, ey0, ex1, ey1);
  for (const auto& l : m.layersM) sub.layersM.push_back(crop(l, ex0, ey0, ex1, ey1));
  sub.materials = input_.materials;
  sub.rainMmPerHour = crop(m.rainMmH, ex0, ey0, ex1, ey1);
  if (m.manningN.size() > 0) sub.manningN = crop(m.manningN, ex0, ey0, ex1, ey1);
  sub.rowDxM.assign(m.rowDxM.begin() + ey0, m.rowDxM.begin() + ey1);
  sub.dyM = input_.dyM * double(1 << L);
  sub.datumM = input_.datumM;
  SimParams sp = params();
  sp.openEdges = detail::tileOpenEdges(params().openEdges, ex0, ey0, ex1, ey1, m.width, m.height);
  auto sim = makeTile_(sub, sp);
  if (!sim)
    return fail("adaptive tile at (" + std::to_string(t.x0) + ", " + std::to_string(t.y0) + "): " + sim.message());
  // Each base cell of a source feeds its share into the level-L cell holding it.
  for (const auto& s : sources()) {
    for (auto one : detail::perCellSources(s)) {
      const int cx = one.cells[0].first >> L, cy = one.cells[0].second >> L;
      if (cx < ex0 || cx >= ex1 || cy < ey0 || cy >= ey1) continue;
      one.cells = {{cx - ex0, cy - ey0}};
      STRATA_TRY_STATUS((*sim)->addSource(one));
    }
  }
  // Its clock is the run's (a sim made mid-run or during a spin-up feeds its sources at that time).
  (*sim)->startClockAt(timeS());
  t.sims[size_t(L)] = std::move(sim).value();
  return {};
}

void AdaptiveSolver::cellAt(const Tile& t, const std::vector<float>& st, int L, int cx, int cy, float out[4]) const {
  const int Lt = t.level;
  const int ex0 = t.ex0[size_t(Lt)], ey0 = t.ey0[size_t(Lt)], wt = t.ex1[size_t(Lt)] - ex0;
  auto at = [&](int x, int y) { return &st[4 * (size_t(y - ey0) * size_t(wt) + size_t(x - ex0))]; };
  if (L == Lt) {
    std::copy_n(at(cx, cy), 4, out);
  } else if (L > Lt) {
    // A4, restriction: the area-weighted mean of the tile's cells in the block.
    const int f = 1 << (L - Lt);
    const auto& dx = mips_[size_t(Lt)].rowDxM;
    double sum[4] = {0, 0, 0, 0}, area = 0;
    for (int y = cy * f; y < (cy + 1) * f; ++y) {
      for (int x = cx * f; x < (cx + 1) * f; ++x) {
        const float* v = at(x, y);
        for (int c = 0; c < 4; ++c) sum[c] += double(v[c]) * dx[size_t(y)];
      }
      area += dx[size_t(y)] * f;
    }
    for (int c = 0; c < 4; ++c) out[c] = float(sum[c] / area);
  } else {
    // A3, prolongation: the coarse cell's volume spread over its children at one water level;
    // sediment and momentum follow the depth (same concentration and velocity).
    const int f = 1 << (Lt - L);
    const float* v = at(cx / f, cy / f);
    if (!(v[0] > 0.0f)) {
      std::fill_n(out, 4, 0.0f);
      return;
    }
    const auto& m = mips_[size_t(L)];
    const double dyL = input_.dyM * double(1 << L);
    std::vector<std::pair<double, double>> cells;
    cells.reserve(size_t(f) * size_t(f));
    double area = 0;
    for (int y = (cy / f) * f; y < (cy / f + 1) * f; ++y) {
      for (int x = (cx / f) * f; x < (cx / f + 1) * f; ++x) {
        cells.emplace_back(double(m.bed[size_t(y) * size_t(m.width) + size_t(x)]), m.rowDxM[size_t(y)] * dyL);
        area += m.rowDxM[size_t(y)] * dyL;
      }
    }
    const double eta = fillLevel(cells, double(v[0]) * area);
    const double h = std::max(0.0, eta - double(m.bed[size_t(cy) * size_t(m.width) + size_t(cx)]));
    const double r = h / double(v[0]);
    out[0] = float(h);
    out[1] = float(double(v[1]) * r);
    out[2] = float(double(v[2]) * r);
    out[3] = float(double(v[3]) * r);
  }
}

std::vector<float> AdaptiveSolver::stateOf(const Tile& t) const {
  const size_t L = size_t(t.level);
  return t.sims[L]->readBlock(0, 0, t.ex1[L] - t.ex0[L], t.ey1[L] - t.ey0[L], kBlockState).state;
}

void AdaptiveSolver::writeState(Tile& t, const std::vector<float>& state) {
  const size_t L = size_t(t.level);
  CellBlock b{.rect = {0, 0, t.ex1[L] - t.ex0[L], t.ey1[L] - t.ey0[L]}, .state = state};
  t.sims[L]->writeBlock(b);
}

std::vector<std::vector<float>> AdaptiveSolver::readStates() const {
  std::vector<std::vector<float>> states;
  states.reserve(tiles_.size());
  for (const auto& t : tiles_) states.push_back(stateOf(t));
  return states;
}

void AdaptiveSolver::fillHalos(const std::vector<std::vector<float>>& states) {
  for (size_t k = 0; k < tiles_.size(); ++k) {
    Tile& t = tiles_[k];
    const int L = t.level, T = o_.tileSize;
    const int ex0 = t.ex0[size_t(L)], ey0 = t.ey0[size_t(L)], ex1 = t.ex1[size_t(L)], ey1 = t.ey1[size_t(L)];
    const int ix0 = t.x0 >> L, iy0 = t.y0 >> L, ix1 = (t.x0 + T) >> L, iy1 = (t.y0 + T) >> L;
    std::vector<float> updated = states[k];
    for (int y = ey0; y < ey1; ++y) {
      for (int x = ex0; x < ex1; ++x) {
        if (x >= ix0 && x < ix1 && y >= iy0 && y < iy1) continue;
        const size_t o = size_t(ownerOf(x << L, y << L));
        cellAt(tiles_[o], states[o], L, x, y, &updated[4 * (size_t(y - ey0) * size_t(ex1 - ex0) + size_t(x - ex0))]);
      }
    }
    writeState(t, updated);
  }
}

void AdaptiveSolver::reflux(std::vector<std::vector<float>>& states, double dtS) {
  // A5: across a tile edge whose two sides run at different levels, the coarse side's face
  // fluxes are replaced by the sum of the fine side's over the same stretch of edge (the fine
  // side is the better estimate); the difference goes into the coarse cells along the edge.
  std::vector<std::vector<float>> faces(tiles_.size());
  auto facesOf = [&](size_t k) -> const std::vector<float>& {
    if (faces[k].empty()) faces[k] = tiles_[k].sims[size_t(tiles_[k].level)]->readFaceMassFlux();
    return faces[k];
  };
  const int T = o_.tileSize;
  for (int ty = 0; ty < tilesY_; ++ty) {
    for (int tx = 0; tx < tilesX_; ++tx) {
      const size_t k = size_t(ty * tilesX_ + tx);
      const Tile& c = tiles_[k];
      const int Lc = c.level;
      const int cex0 = c.ex0[size_t(Lc)], cey0 = c.ey0[size_t(Lc)], cw = c.ex1[size_t(Lc)] - cex0,
                ch = c.ey1[size_t(Lc)] - cey0;
      const auto& dxC = mips_[size_t(Lc)].rowDxM;
      const double dyC = input_.dyM * double(1 << Lc);
      // (neighbour dx, dy, whether the edge is at the tile's high side)
      const int dirs[4][3] = {{-1, 0, 0}, {1, 0, 1}, {0, -1, 0}, {0, 1, 1}};
      for (const auto& d : dirs) {
        const int nx = tx + d[0], ny = ty + d[1];
        if (nx < 0 || ny < 0 || nx >= tilesX_ || ny >= tilesY_) continue;
        const size_t mk = size_t(ny * tilesX_ + nx);
        const Tile& fT = tiles_[mk];
        const int Lf = fT.level;
        if (Lf >= Lc) continue;
        const int r = 1 << (Lc - Lf);
        const auto& fc = facesOf(k);
        const auto& ff = facesOf(mk);
        const int fex0 = fT.ex0[size_t(Lf)], fey0 = fT.ey0[size_t(Lf)], fw = fT.ex1[size_t(Lf)] - fex0,
                  fh = fT.ey1[size_t(Lf)] - fey0;
        const auto& dxF = mips_[size_t(Lf)].rowDxM;
        const double dyF = input_.dyM * double(1 << Lf);
        const bool high = d[2] != 0;
        auto& st = states[k];
        auto apply = [&](int cx, int cy, double dV) {
          float& hc = st[4 * (size_t(cy - cey0) * size_t(cw) + size_t(cx - cex0))];
          const double hNew = double(hc) + dV / (dxC[size_t(cy)] * dyC);
          if (hNew < 0) {
            clampedM3_ += -hNew * dxC[size_t(cy)] * dyC;
            hc = 0.0f;
            st[4 * (size_t(cy - cey0) * size_t(cw) + size_t(cx - cex0)) + 2] = 0.0f;
            st[4 * (size_t(cy - cey0) * size_t(cw) + size_t(cx - cex0)) + 3] = 0.0f;
          } else {
            hc = float(hNew);
          }
        };
        if (d[0] != 0) {
          const int X = high ? c.x0 + T : c.x0;  // base x of the edge
          const int fxC = (X >> Lc) - cex0, fxF = (X >> Lf) - fex0;
          const int cellX = high ? (X >> Lc) - 1 : (X >> Lc);
          for (int cy = c.y0 >> Lc; cy < (c.y0 + T) >> Lc; ++cy) {
            const double mC = double(fc[size_t(cy - cey0) * size_t(cw + 1) + size_t(fxC)]) * dyC;
            double mF = 0;
            for (int y = cy * r; y < (cy + 1) * r; ++y)
              mF += double(ff[size_t(y - fey0) * size_t(fw + 1) + size_t(fxF)]) * dyF;
            apply(cellX, cy, (high ? mC - mF : mF - mC) * dtS);
          }
        } else {
          const int Y = high ? c.y0 + T : c.y0;  // base y of the edge
          const int fyC = (Y >> Lc) - cey0, fyF = (Y >> Lf) - fey0;
          const size_t offC = size_t(cw + 1) * size_t(ch), offF = size_t(fw + 1) * size_t(fh);
          const int cellY = high ? (Y >> Lc) - 1 : (Y >> Lc);
          const double wC = 0.5 * (dxC[size_t((Y >> Lc) - 1)] + dxC[size_t(Y >> Lc)]);
          const double wF = 0.5 * (dxF[size_t((Y >> Lf) - 1)] + dxF[size_t(Y >> Lf)]);
          for (int cx = c.x0 >> Lc; cx < (c.x0 + T) >> Lc; ++cx) {
            const double mC = double(fc[offC + size_t(fyC) * size_t(cw) + size_t(cx - cex0)]) * wC;
            double mF = 0;
            for (int x = cx * r; x < (cx + 1) * r; ++x)
              mF += double(ff[offF + size_t(fyF) * size_t(fw) + size_t(x - fex0)]) * wF;
            apply(cx, cellY, (high ? mC - mF : mF - mC) * dtS);
          }
        }
      }
    }
  }
}

std::vector<float> AdaptiveSolver::mergedState(const std::vector<std::vector<float>>& states) const {
  std::vector<float> out(4 * size_t(width_) * size_t(height_));
  for (size_t k = 0; k < tiles_.size(); ++k) {
    const Tile& t = tiles_[k];
    for (int y = t.y0; y < t.y0 + o_.tileSize; ++y) {
      for (int x = t.x0; x < t.x0 + o_.tileSize; ++x) {
        cellAt(t, states[k], 0, x, y, &out[4 * (size_t(y) * size_t(width_) + size_t(x))]);
      }
    }
  }
  return out;
}

void AdaptiveSolver::regrid() {
  // A1: importance per tile from the base-resolution picture of the run.
  const std::vector<float> merged = mergedNow();
  const int T = o_.tileSize, look = o_.lookaheadCells;
  std::vector<int> target(tiles_.size());
  for (size_t k = 0; k < tiles_.size(); ++k) {
    Tile& t = tiles_[k];
    double importance = t.pinned ? std::numeric_limits<double>::infinity() : 0.0;
    for (int y = std::max(0, t.y0 - look); y < std::min(height_, t.y0 + T + look) && std::isfinite(importance); ++y) {
      for (int x = std::max(0, t.x0 - look); x < std::min(width_, t.x0 + T + look); ++x) {
        const size_t i = size_t(y) * size_t(width_) + size_t(x);
        const double h = merged[4 * i], hp = prevDepth_[i];
        if (h <= o_.wetDepthM && hp <= o_.wetDepthM) continue;
        const double speed =
            h > params().dryDepthM ? std::hypot(double(merged[4 * i + 2]), double(merged[4 * i + 3])) / h : 0;
        importance = std::max({importance, speed / o_.speedRefMS, std::abs(h - hp) / o_.depthChangeRefM});
      }
    }
    int level = t.level;
    if (importance >= o_.refineAbove) {
      level = 0;
      t.quietEvaluations = 0;
    } else if (!started_) {
      level = o_.maxLevel;
    } else if (importance < o_.coarsenBelow) {
      if (++t.quietEvaluations >= o_.coarsenAfter) {
        level = std::min(o_.maxLevel, level + 1);
        t.quietEvaluations = 0;
      }
    } else {
      t.quietEvaluations = 0;
    }
    target[k] = level;
  }
  // A6: neighbouring tiles (8-neighbourhood) differ by at most one level; balancing only refines.
  for (bool changed = true; changed;) {
    changed = false;
    for (int ty = 0; ty < tilesY_; ++ty) {
      for (int tx = 0; tx < tilesX_; ++tx) {
        int& l = target[size_t(ty * tilesX_ + tx)];
        for (int dy = -1; dy <= 1; ++dy) {
          for (int dx = -1; dx <= 1; ++dx) {
            const int nx = tx + dx, ny = ty + dy;
            if (nx < 0 || ny < 0 || nx >= tilesX_ || ny >= tilesY_) continue;
            const int nl = target[size_t(ny * tilesX_ + nx)];
            if (l > nl + 1) {
              l = nl + 1;
              changed = true;
            }
          }
        }
      }
    }
  }
  // Tiles that change level (all of them at the start) take their state from the merged picture,
  // restricted to the new level over interior and halo (the halo is refilled below anyway).
  for (size_t k = 0; k < tiles_.size(); ++k) {
    Tile& t = tiles_[k];
    if (started_ && target[k] == t.level) continue;
    const int L = target[k];
    const auto status = ensureSim(t, L);
    STRATA_CHECK(status.ok()) << status.message();
    const int ex0 = t.ex0[size_t(L)], ey0 = t.ey0[size_t(L)], ex1 = t.ex1[size_t(L)], ey1 = t.ey1[size_t(L)];
    const int f = 1 << L;
    const auto& dx = mips_[0].rowDxM;
    std::vector<float> st(4 * size_t(ex1 - ex0) * size_t(ey1 - ey0));
    for (int cy = ey0; cy < ey1; ++cy) {
      for (int cx = ex0; cx < ex1; ++cx) {
        double sum[4] = {0, 0, 0, 0}, area = 0;
        for (int y = cy * f; y < (cy + 1) * f; ++y) {
          for (int x = cx * f; x < (cx + 1) * f; ++x) {
            const size_t i = size_t(y) * size_t(width_) + size_t(x);
            for (int c = 0; c < 4; ++c) sum[c] += double(merged[4 * i + size_t(c)]) * dx[size_t(y)];
          }
          area += dx[size_t(y)] * f;
        }
        for (int c = 0; c < 4; ++c)
          st[4 * (size_t(cy - ey0) * size_t(ex1 - ex0) + size_t(cx - ex0)) + size_t(c)] = float(sum[c] / area);
      }
    }
    t.level = L;
    writeState(t, st);
  }
  for (size_t i = 0; i < prevDepth_.size(); ++i) prevDepth_[i] = merged[4 * i];
  started_ = true;
  fillHalos(readStates());
}

double AdaptiveSolver::nextDt() {
  if (!started_) regrid();
  // W10 over every tile at its own cell size, counting the depth rate the sources add (as the
  // tiled runner does).
  std::vector<double> speed;
  double window = std::numeric_limits<double>::infinity(), rate = 0;
  for (auto& t : tiles_) {
    speed.push_back(t.sims[size_t(t.level)]->maxWaveSpeedMS());
    window = std::min(window, stepDt(params(), speed.back(), minCell_[size_t(t.level)]));
  }
  if (params().cflAlpha > 0) {
    for (auto& t : tiles_) rate = std::max(rate, t.sims[size_t(t.level)]->sourceDepthRateMS(timeS() + window));
  }
  double dt = std::numeric_limits<double>::infinity();
  for (size_t k = 0; k < tiles_.size(); ++k) {
    dt = std::min(dt, stepDt(params(), speed[k], minCell_[size_t(tiles_[k].level)], rate));
  }
  return dt;
}

double AdaptiveSolver::maxWaveSpeedMS() const {
  double speed = 0;
  for (const auto& t : tiles_) {
    if (t.sims[size_t(t.level)]) speed = std::max(speed, t.sims[size_t(t.level)]->maxWaveSpeedMS());
  }
  return speed;
}

void AdaptiveSolver::runStep(const StepInputs& step) {
  if (!started_) regrid();
  const double dtF = double(step.dtS);
  for (auto& t : tiles_) {
    t.sims[size_t(t.level)]->stepWithDt(dtF);
    cellUpdates_ += double(o_.tileSize >> t.level) * double(o_.tileSize >> t.level);
    const size_t L = size_t(t.level);
    computedUpdates_ += double(t.ex1[L] - t.ex0[L]) * double(t.ey1[L] - t.ey0[L]);
  }
  auto states = readStates();
  if (o_.reflux) reflux(states, dtF);
  fillHalos(states);  // also writes the refluxed interiors back
  // Solver counts this step once runStep returns: regrid after every regridEvery-th step.
  if ((counterStats().steps + 1) % o_.regridEvery == 0) regrid();
}

std::vector<float> AdaptiveSolver::mergedNow() const {
  if (started_) return mergedState(readStates());
  std::vector<float> merged(4 * size_t(width_) * size_t(height_), 0.0f);
  for (size_t i = 0; i < prevDepth_.size(); ++i) merged[4 * i] = prevDepth_[i];
  return merged;
}

gis::Grid<float> AdaptiveSolver::readBed() const {
  gis::Grid<float> out(width_, height_);
  out.data = mips_[0].bed;
  return out;
}

CellBlock AdaptiveSolver::readBlock(int x0, int y0, int width, int height, unsigned parts) const {
  CellBlock b{.rect = {x0, y0, width, height}};
  STRATA_CHECK(blockFits(b, width_, height_, grid().layers)) << "readBlock outside the grid";
  STRATA_CHECK((parts & (kBlockFlux | kBlockAccum | kBlockCarried)) == 0)
      << "adaptive tiles: only state and layers read as blocks";
  const size_t cells = b.cells(), row = size_t(width);
  if (parts & kBlockState) {
    const auto merged = mergedNow();
    b.state.resize(4 * cells);
    for (int y = 0; y < height; ++y) {
      std::copy_n(&merged[4 * (size_t(y0 + y) * size_t(width_) + size_t(x0))], 4 * row, &b.state[4 * size_t(y) * row]);
    }
  }
  if (parts & kBlockLayers) {
    b.layers.resize(size_t(grid().layers) * cells);
    for (int l = 0; l < grid().layers; ++l) {
      for (int y = 0; y < height; ++y) {
        std::copy_n(&input_.layersM[size_t(l)].data[size_t(y0 + y) * size_t(width_) + size_t(x0)], row,
                    &b.layers[size_t(l) * cells + size_t(y) * row]);
      }
    }
  }
  return b;
}

void AdaptiveSolver::writeBlock(const CellBlock& /*block*/) {
  STRATA_CHECK(false) << "adaptive tiles are a whole region: they are not nested in another runner";
}

std::vector<float> AdaptiveSolver::readFaceMassFlux() const {
  STRATA_CHECK(false) << "adaptive tiles are a whole region: they are not nested in another runner";
  return {};
}

std::vector<int> AdaptiveSolver::levels() const {
  std::vector<int> out;
  for (const auto& t : tiles_) out.push_back(t.level);
  return out;
}

double AdaptiveSolver::cellFraction() const {
  const double steps = double(counterStats().steps);
  return steps > 0 ? cellUpdates_ / (steps * double(width_) * double(height_)) : 1.0;
}

double AdaptiveSolver::computedCellFraction() const {
  const double steps = double(counterStats().steps);
  return steps > 0 ? computedUpdates_ / (steps * double(width_) * double(height_)) : 1.0;
}

SimStats AdaptiveSolver::stats() const {
  SimStats out = counterStats();
  std::vector<float> layers;
  for (const auto& l : input_.layersM) layers.insert(layers.end(), l.data.begin(), l.data.end());
  out.materialM3 = integrate(layers, grid());  // no erosion: the layers do not change
  if (!started_) {
    out.storedWaterM3 = integrate(prevDepth_, grid());
    for (float h : prevDepth_) out.maxDepthM = std::max(out.maxDepthM, double(h));
    return out;
  }
  const int T = o_.tileSize;
  for (const auto& t : tiles_) {
    for (int L = 0; L <= o_.maxLevel; ++L) {
      if (!t.sims[size_t(L)]) continue;
      const int ex0 = t.ex0[size_t(L)], ey0 = t.ey0[size_t(L)];
      const int ix0 = t.x0 >> L, iy0 = t.y0 >> L, iw = T >> L;
      const CellBlock b = t.sims[size_t(L)]->readBlock(ix0 - ex0, iy0 - ey0, iw, iw, kBlockState | kBlockAccum);
      const auto& dx = mips_[size_t(L)].rowDxM;
      const double dyL = input_.dyM * double(1 << L);
      for (int y = 0; y < iw; ++y) {
        for (int x = 0; x < iw; ++x) {
          const size_t i = size_t(y) * size_t(iw) + size_t(x);
          out.outflowM3 += double(b.accum[kAccumPerCell * i + kAccumOutflow]);
          out.evaporatedM3 += double(b.accum[kAccumPerCell * i + kAccumEvaporated]);
          if (L == t.level) {
            out.storedWaterM3 += double(b.state[4 * i]) * dx[size_t(iy0 + y)] * dyL;
            out.suspendedM3 += double(b.state[4 * i + 1]) * dx[size_t(iy0 + y)] * dyL;
            out.maxDepthM = std::max(out.maxDepthM, double(b.state[4 * i]));
          }
        }
      }
    }
  }
  return out;
}

void AdaptiveSolver::saveCells(SolverState& out) const {
  // Every solver made so far (they keep their outflow totals), tile by tile, level by level;
  // per tile: level, quiet evaluations, pinned, and a mask of the levels made.
  for (const auto& t : tiles_) {
    int32_t made = 0;
    for (size_t L = 0; L < t.sims.size(); ++L) {
      if (!t.sims[L]) continue;
      made |= int32_t(1) << L;
      out.parts.push_back(t.sims[L]->saveState());
    }
    out.tags.insert(out.tags.end(), {int32_t(t.level), int32_t(t.quietEvaluations), int32_t(t.pinned), made});
  }
  out.tags.push_back(started_ ? 1 : 0);
  out.extra = prevDepth_;
  out.numbers = {clampedM3_, cellUpdates_, computedUpdates_};
}

Status AdaptiveSolver::restoreCells(const SolverState& in) {
  if (in.tags.size() != 4 * tiles_.size() + 1 || in.extra.size() != prevDepth_.size() || in.numbers.size() != 3) {
    return fail("adaptive tiles: the saved state is of a different run");
  }
  size_t part = 0;
  for (size_t k = 0; k < tiles_.size(); ++k) {
    Tile& t = tiles_[k];
    const int32_t* tag = &in.tags[4 * k];
    for (int L = 0; L <= o_.maxLevel; ++L) {
      if (!(tag[3] & (int32_t(1) << L))) continue;
      if (part >= in.parts.size()) return fail("adaptive tiles: the saved state lacks a tile's solver");
      STRATA_TRY_STATUS(ensureSim(t, L));
      STRATA_TRY_STATUS(t.sims[size_t(L)]->restoreState(in.parts[part++]));
    }
    if (tag[0] < 0 || tag[0] > o_.maxLevel || !t.sims[size_t(tag[0])]) {
      return fail("adaptive tiles: the saved state has a tile at a level it never ran");
    }
    t.level = tag[0];
    t.quietEvaluations = tag[1];
    t.pinned = tag[2] != 0;
  }
  started_ = in.tags.back() != 0;
  prevDepth_ = in.extra;
  clampedM3_ = in.numbers[0];
  cellUpdates_ = in.numbers[1];
  computedUpdates_ = in.numbers[2];
  return {};
}

}  // namespace strata::sim
