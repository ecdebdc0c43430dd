// Adaptive tiles (docs/sim-water.md, "Adaptive tiles", A1-A6): per-tile levels of the region's
// mip pyramid, halos by restriction/prolongation, refluxing at coarse/fine tile edges.
#include <strata/render/sim/adaptive_simulation.hpp>

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>
#include <utility>

#include <strata/terrain/sim/sim_host.hpp>
#include <strata/terrain/tile_store.hpp>

#include "tile_common.hpp"

namespace strata::render::sim {

namespace ts = strata::terrain::sim;

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

Result<AdaptiveSimulation> AdaptiveSimulation::create(const SimInput& input, const SimParams& params,
                                                      const AdaptiveOptions& options) {
  STRATA_TRY_STATUS(ts::validate(input, params));
  if (params.waterModel != int32_t(ts::WaterModel::kFiniteVolume) || params.erosionEnabled || params.thermalEnabled) {
    return fail("adaptive tiles: flood mode (waterModel = finite volume) without erosion or thermal weathering only");
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
  AdaptiveSimulation a;
  a.input_ = input;
  a.p_ = params;
  a.o_ = options;
  a.width_ = w;
  a.height_ = h;
  a.tilesX_ = w / T;
  a.tilesY_ = h / T;
  a.p_.width = w;
  a.p_.height = h;
  a.p_.layerCount = int(input.layersM.size());
  a.p_.dyM = float(input.dyM);
  const size_t n = size_t(w) * size_t(h);

  // A2: the mip pyramid: box means of base, layers and rain; row dx summed in pairs (a coarse
  // cell's area is the sum of its four children's); the bed as Simulation::create computes it.
  Pyramid l0;
  l0.width = w;
  l0.height = h;
  l0.baseM = input.baseM;
  l0.layersM = input.layersM;
  l0.rainMmH = input.rainMmPerHour.size() > 0 ? input.rainMmPerHour : gis::Grid<float>(w, h, 0.0f);
  for (int y = 0; y < h; ++y) l0.rowDxM.push_back(ts::rowDx(input, y));
  a.mips_.push_back(std::move(l0));
  for (int L = 1; L <= options.maxLevel; ++L) {
    const Pyramid& prev = a.mips_.back();
    Pyramid m;
    m.width = prev.width / 2;
    m.height = prev.height / 2;
    m.baseM = terrain::boxDownsample(prev.baseM, 2);
    m.rainMmH = terrain::boxDownsample(prev.rainMmH, 2);
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
      t.created.assign(size_t(options.maxLevel + 1), false);
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
  a.rainRateM3S_ = ts::rainVolumeRate(a.p_, a.mips_[0].rainMmH.data, a.mips_[0].rowDxM, w);
  a.prevDepth_ = input.waterDepthM.size() > 0 ? input.waterDepthM.data : std::vector<float>(n, 0.0f);
  a.initialWater_ = ts::integrate(a.prevDepth_, a.mips_[0].rowDxM, input.dyM, w);
  std::vector<float> layers;
  for (const auto& l : input.layersM) layers.insert(layers.end(), l.data.begin(), l.data.end());
  a.initialMaterial_ = ts::integrate(layers, a.mips_[0].rowDxM, input.dyM, w);
  return a;
}

int AdaptiveSimulation::ownerOf(int bx, int by) const { return (by / o_.tileSize) * tilesX_ + bx / o_.tileSize; }

Status AdaptiveSimulation::addSource(const Source& source) {
  if (started_) return fail("adaptive tiles: add sources before the first step");
  for (auto [x, y] : source.cells) {
    if (x < 0 || y < 0 || x >= width_ || y >= height_) {
      return fail("sim source: cell (" + std::to_string(x) + ", " + std::to_string(y) + ") is outside the " +
                  std::to_string(width_) + "x" + std::to_string(height_) + " grid");
    }
  }
  for (size_t i = 1; i < source.hydrographM3S.size(); ++i) {
    if (!(source.hydrographM3S[i].first > source.hydrographM3S[i - 1].first)) {
      return fail("sim source: hydrograph times must increase (sample " + std::to_string(i) + ")");
    }
  }
  for (auto [x, y] : source.cells) tiles_[size_t(ownerOf(x, y))].pinned = true;
  sources_.push_back(source);
  return {};
}

Status AdaptiveSimulation::ensureSim(Tile& t, int L) {
  if (t.created[size_t(L)]) return {};
  const auto& m = mips_[size_t(L)];
  const int ex0 = t.ex0[size_t(L)], ey0 = t.ey0[size_t(L)], ex1 = t.ex1[size_t(L)], ey1 = t.ey1[size_t(L)];
  SimInput sub;
  sub.baseM = crop(m.baseM, ex0, ey0, ex1, ey1);
  for (const auto& l : m.layersM) sub.layersM.push_back(crop(l, ex0, ey0, ex1, ey1));
  sub.materials = input_.materials;
  sub.rainMmPerHour = crop(m.rainMmH, ex0, ey0, ex1, ey1);
  sub.rowDxM.assign(m.rowDxM.begin() + ey0, m.rowDxM.begin() + ey1);
  sub.dyM = input_.dyM * double(1 << L);
  sub.datumM = input_.datumM;
  SimParams sp = p_;
  sp.openEdges = detail::tileOpenEdges(p_.openEdges, ex0, ey0, ex1, ey1, m.width, m.height);
  auto sim = Simulation::create(sub, sp);
  if (!sim)
    return fail("adaptive tile at (" + std::to_string(t.x0) + ", " + std::to_string(t.y0) + "): " + sim.message());
  // Each base cell of a source feeds its share into the level-L cell holding it.
  for (const auto& s : sources_) {
    for (auto one : detail::perCellSources(s)) {
      const int cx = one.cells[0].first >> L, cy = one.cells[0].second >> L;
      if (cx < ex0 || cx >= ex1 || cy < ey0 || cy >= ey1) continue;
      one.cells = {{cx - ex0, cy - ey0}};
      STRATA_TRY_STATUS(sim->addSource(one));
    }
  }
  t.sims[size_t(L)].emplace(std::move(sim).value());
  t.created[size_t(L)] = true;
  return {};
}

void AdaptiveSimulation::cellAt(const Tile& t, const std::vector<float>& st, int L, int cx, int cy,
                                float out[4]) const {
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

std::vector<std::vector<float>> AdaptiveSimulation::readStates() const {
  std::vector<std::vector<float>> states;
  states.reserve(tiles_.size());
  for (const auto& t : tiles_) states.push_back(t.sims[size_t(t.level)]->readStateRaw());
  return states;
}

void AdaptiveSimulation::fillHalos(const std::vector<std::vector<float>>& states) {
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
    t.sims[size_t(L)]->writeStateRaw(updated);
  }
}

void AdaptiveSimulation::reflux(std::vector<std::vector<float>>& states, double dtS) {
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

std::vector<float> AdaptiveSimulation::mergedState(const std::vector<std::vector<float>>& states) const {
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

void AdaptiveSimulation::regrid() {
  // A1: importance per tile from the base-resolution picture of the run.
  std::vector<float> merged;
  if (started_) {
    merged = mergedState(readStates());
  } else {
    merged.assign(4 * size_t(width_) * size_t(height_), 0.0f);
    for (size_t i = 0; i < prevDepth_.size(); ++i) merged[4 * i] = prevDepth_[i];
  }
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
            h > p_.dryDepthM ? std::hypot(double(merged[4 * i + 2]), double(merged[4 * i + 3])) / h : 0;
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
    t.sims[size_t(L)]->writeStateRaw(st);
  }
  for (size_t i = 0; i < prevDepth_.size(); ++i) prevDepth_[i] = merged[4 * i];
  started_ = true;
  fillHalos(readStates());
}

void AdaptiveSimulation::step(int n) {
  if (!started_) regrid();
  std::vector<double> minCell;
  for (size_t L = 0; L < mips_.size(); ++L)
    minCell.push_back(ts::minCellSize(mips_[L].rowDxM, input_.dyM * double(1 << L)));
  for (int s = 0; s < n; ++s) {
    // W10 over every tile at its own cell size, counting the depth rate the sources add (as
    // TiledSimulation does).
    std::vector<double> speed;
    double window = std::numeric_limits<double>::infinity(), rate = 0;
    for (auto& t : tiles_) {
      speed.push_back(t.sims[size_t(t.level)]->maxWaveSpeedMS());
      window = std::min(window, ts::stepDt(p_, speed.back(), minCell[size_t(t.level)]));
    }
    if (p_.cflAlpha > 0) {
      for (auto& t : tiles_) rate = std::max(rate, t.sims[size_t(t.level)]->sourceDepthRateMS(timeS_ + window));
    }
    double dt = std::numeric_limits<double>::infinity();
    for (size_t k = 0; k < tiles_.size(); ++k) {
      dt = std::min(dt, ts::stepDt(p_, speed[k], minCell[size_t(tiles_[k].level)], rate));
    }
    const double dtF = double(float(dt));
    for (const auto& e : ts::mergeSources(sources_, width_, timeS_, timeS_ + dtF)) inflowM3_ += double(e.rateM3S) * dtF;
    rainM3_ += rainRateM3S_ * dtF;
    for (auto& t : tiles_) {
      t.sims[size_t(t.level)]->stepWithDt(dt);
      cellUpdates_ += double(o_.tileSize >> t.level) * double(o_.tileSize >> t.level);
      const size_t L = size_t(t.level);
      computedUpdates_ += double(t.ex1[L] - t.ex0[L]) * double(t.ey1[L] - t.ey0[L]);
    }
    auto states = readStates();
    if (o_.reflux) reflux(states, dtF);
    timeS_ += dtF;
    lastDt_ = dtF;
    ++steps_;
    fillHalos(states);  // also writes the refluxed interiors back
    if (steps_ % o_.regridEvery == 0) regrid();
  }
}

gis::Grid<float> AdaptiveSimulation::readWaterDepth() const {
  gis::Grid<float> out(width_, height_, 0.0f);
  if (!started_) return input_.waterDepthM.size() > 0 ? input_.waterDepthM : out;
  const auto merged = mergedState(readStates());
  for (size_t i = 0; i < out.size(); ++i) out.data[i] = merged[4 * i];
  return out;
}

std::vector<gis::Grid<float>> AdaptiveSimulation::readLayers() const { return input_.layersM; }

std::vector<int> AdaptiveSimulation::levels() const {
  std::vector<int> out;
  for (const auto& t : tiles_) out.push_back(t.level);
  return out;
}

double AdaptiveSimulation::cellFraction() const {
  return steps_ > 0 ? cellUpdates_ / (double(steps_) * double(width_) * double(height_)) : 1.0;
}

double AdaptiveSimulation::computedCellFraction() const {
  return steps_ > 0 ? computedUpdates_ / (double(steps_) * double(width_) * double(height_)) : 1.0;
}

SimStats AdaptiveSimulation::stats() const {
  SimStats out;
  out.timeS = timeS_;
  out.steps = steps_;
  out.lastDtS = lastDt_;
  out.initialWaterM3 = initialWater_;
  out.rainM3 = rainM3_;
  out.inflowM3 = inflowM3_;
  out.materialM3 = initialMaterial_;  // no erosion: the layers do not change
  out.initialMaterialM3 = initialMaterial_;
  if (!started_) {
    out.storedWaterM3 = initialWater_;
    for (float h : prevDepth_) out.maxDepthM = std::max(out.maxDepthM, double(h));
    return out;
  }
  const int T = o_.tileSize;
  for (const auto& t : tiles_) {
    for (int L = 0; L <= o_.maxLevel; ++L) {
      if (!t.created[size_t(L)]) continue;
      const auto raw = t.sims[size_t(L)]->readRaw();
      const int ex0 = t.ex0[size_t(L)], ey0 = t.ey0[size_t(L)], w = t.ex1[size_t(L)] - ex0;
      const auto& dx = mips_[size_t(L)].rowDxM;
      const double dyL = input_.dyM * double(1 << L);
      for (int y = t.y0 >> L; y < (t.y0 + T) >> L; ++y) {
        for (int x = t.x0 >> L; x < (t.x0 + T) >> L; ++x) {
          const size_t i = size_t(y - ey0) * size_t(w) + size_t(x - ex0);
          out.outflowM3 += double(raw.accum[8 * i]);
          out.evaporatedM3 += double(raw.accum[8 * i + 2]);
          if (L == t.level) {
            out.storedWaterM3 += double(raw.state[4 * i]) * dx[size_t(y)] * dyL;
            out.suspendedM3 += double(raw.state[4 * i + 1]) * dx[size_t(y)] * dyL;
            out.maxDepthM = std::max(out.maxDepthM, double(raw.state[4 * i]));
          }
        }
      }
    }
  }
  return out;
}

}  // namespace strata::render::sim
