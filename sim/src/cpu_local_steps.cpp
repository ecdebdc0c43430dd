// Local time steps (W37, issue 35 item 3; docs/sim-water.md, "Local time steps"): the
// local-inertial scheme's blocks step at dt, 2 dt, ..., 2^M dt as their own CFL bound allows, the
// grid's step being the longest, so the few deep cells of an inflow no longer set every cell's
// step. A conservative multirate scheme after Sanders (2008, J. Hydraulic Research 46) and Dazzi
// et al. (2018, Advances in Water Resources 111): a face steps with the finer of its two cells,
// and what it carries reaches the coarser cell each time; W25's limit holds over a cell's whole
// step.
#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <utility>

#include "cpu_impl.hpp"

namespace strata::sim::cpu {

namespace {
// Face directions of a cell: the bits of LevelCell::finer.
constexpr uint8_t kW = 1, kE = 2, kN = 4, kS = 8;
}  // namespace

// Each block's value the largest of its own and its eight neighbours'.
void Impl::spread(std::vector<float>& perBlock) const {
  std::vector<float> rows(perBlock.size());
  for (int by = 0; by < bh; ++by) {
    for (int bx = 0; bx < bw; ++bx) {
      float m = perBlock[size_t(by * bw + bx)];
      if (bx > 0) m = std::max(m, perBlock[size_t(by * bw + bx - 1)]);
      if (bx + 1 < bw) m = std::max(m, perBlock[size_t(by * bw + bx + 1)]);
      rows[size_t(by * bw + bx)] = m;
    }
  }
  for (int by = 0; by < bh; ++by) {
    for (int bx = 0; bx < bw; ++bx) {
      float m = rows[size_t(by * bw + bx)];
      if (by > 0) m = std::max(m, rows[size_t((by - 1) * bw + bx)]);
      if (by + 1 < bh) m = std::max(m, rows[size_t((by + 1) * bw + bx)]);
      perBlock[size_t(by * bw + bx)] = m;
    }
  }
}

// Each block's level: the longest of dt, 2 dt, ..., 2^M dt (dt = dtS / 2^M) within W33's bound
// for its own deepest water and the depth rate the rain and its faces' inflows (the discharges its
// cells last applied) bring (W33's sources term: over a longer step a cell can fill up and speed
// its wave; without it the 1 m plain's shallow cells went into a checkerboard mode, 0.43 m next to
// 0 where one step for the grid has 0.18 m); the finest for a block with a point source (whose
// rate bounds the finest step, W33); then at most one level above each of its four neighbours'
// (two passes of a city-block distance). M, the fewest levels whose finest step fits every block
// as W33 bounds one step for the grid (the sources, not the inflows), is returned.
int Impl::planLevels(const std::vector<SourceEntry>& entries, float dtS, double rainRateMS) {
  const int blocks = bw * bh;
  blockLevel.assign(size_t(blocks), 0);
  blockSpeed.assign(size_t(blocks), 0.0f);
  blockRate.assign(size_t(blocks), float(rainRateMS));
  blockInflow.assign(size_t(blocks), 0.0f);
  const bool parallel = passThreads > 1 && water.cells >= kMinParallelCells;
#pragma omp parallel for schedule(dynamic, 8) num_threads(passThreads) if (parallel)
  for (int b = 0; b < blocks; ++b) {
    if (!water.on[size_t(b)]) continue;
    const int x0 = (b % bw) * kBlock, x1 = std::min(x0 + kBlock, w);
    const int y0 = (b / bw) * kBlock, y1 = std::min(y0 + kBlock, h);
    float deepest = 0.0f, inflow = 0.0f;
    for (int y = y0; y < y1; ++y) {
      const float* d = now().h.row(y);
      const float *qW = flux[0].row(y), *qE = flux[1].row(y), *qN = flux[2].row(y), *qS = flux[3].row(y);
      const float dx = rowDx[size_t(y)];
      for (int x = x0; x < x1; ++x) {
        deepest = maxOf(deepest, d[x]);
        inflow = maxOf(
            inflow, (maxOf(qW[x], 0.0f) + maxOf(-qE[x], 0.0f)) / dx + (maxOf(qN[x], 0.0f) + maxOf(-qS[x], 0.0f)) / dy);
      }
    }
    blockSpeed[size_t(b)] = std::sqrt(p.gravityMS2 * deepest);
    blockInflow[size_t(b)] = inflow;
  }
  for (const auto& e : entries) {
    float& r = blockRate[blockOf(e.cell)];
    r = std::max(r, float(rainRateMS + double(e.rateM3S) / double(rowArea[size_t(e.cell / uint32_t(w))])));
  }
  // A block takes the fastest speed and rate of the blocks around it as well: water from a
  // neighbour can cross a whole block (kBlock cells) in the grid's step at most (one cell a finest
  // step, 2^3 = kBlock of them), so a wetting front never enters a block stepping slower than the
  // one it leaves. (Without this a dam break on the Grand Canyon at 600 m piled 112 m of water
  // into the first dry cell below the dam, which one step for the grid fills to 63-73 m.)
  static_assert((1 << kMaxLocalStepLevels) <= kBlock);
  spread(blockSpeed);
  spread(blockRate);
  spread(blockInflow);
  float minCell = dy;
  for (float dx : rowDx) minCell = std::min(minCell, dx);
  const double reach = double(p.cflAlpha) * double(minCell);
  auto fits = [&](int b, double dtLevel, bool coarse) {
    const double rate = double(blockRate[size_t(b)]) + (coarse ? double(blockInflow[size_t(b)]) : 0.0);
    return stepTravelM(p, double(blockSpeed[size_t(b)]), rate, dtLevel) <= reach;
  };
  const int most = p.localStepLevels;
  int levels = most;  // W10's rounding may leave the finest step a hair long: the most levels then
  for (int m = 0; m < most; ++m) {
    const double fine = double(dtS) / double(1 << m);
    bool all = true;
    for (int b = 0; b < blocks && all; ++b) all = fits(b, fine, false);
    if (all) {
      levels = m;
      break;
    }
  }
  for (int b = 0; b < blocks; ++b) {
    int m = levels;
    while (m > 0 && !fits(b, double(dtS) / double(1 << (levels - m)), true)) --m;
    blockLevel[size_t(b)] = uint8_t(m);
  }
  for (const auto& e : entries) blockLevel[blockOf(e.cell)] = 0;
  auto lower = [&](int b, int n) {
    blockLevel[size_t(b)] = uint8_t(std::min(int(blockLevel[size_t(b)]), int(blockLevel[size_t(n)]) + 1));
  };
  for (int by = 0; by < bh; ++by) {
    for (int bx = 0; bx < bw; ++bx) {
      if (bx > 0) lower(by * bw + bx, by * bw + bx - 1);
      if (by > 0) lower(by * bw + bx, (by - 1) * bw + bx);
    }
  }
  for (int by = bh - 1; by >= 0; --by) {
    for (int bx = bw - 1; bx >= 0; --bx) {
      if (bx + 1 < bw) lower(by * bw + bx, by * bw + bx + 1);
      if (by + 1 < bh) lower(by * bw + bx, (by + 1) * bw + bx);
    }
  }
  return levels;
}

// The runs of `in` cut where the blocks' level changes, into out[level] (each run lies in one row
// of blocks: the water set's groups of kRunRows rows and fillRuns' block rows do).
void Impl::splitByLevel(const BlockSet& in, std::vector<BlockSet>& out, int levels) const {
  out.resize(size_t(levels) + 1);
  for (auto& s : out) {
    s.runs.clear();
    s.cells = 0;
  }
  for (const Run& r : in.runs) {
    const int by = r.y0 / kBlock;
    for (int x0 = r.x0; x0 < r.x1;) {
      const int m = blockLevel[size_t(by * bw + x0 / kBlock)];
      int x1 = std::min(r.x1, (x0 / kBlock + 1) * kBlock);
      while (x1 < r.x1 && blockLevel[size_t(by * bw + x1 / kBlock)] == m) x1 = std::min(r.x1, x1 + kBlock);
      BlockSet& s = out[size_t(m)];
      s.runs.push_back(Run{r.y0, r.y1, x0, x1});
      s.cells += size_t(r.y1 - r.y0) * size_t(x1 - x0);
      x0 = x1;
    }
  }
}

// The faces between cells of two levels that both run this step, and the coarser cells beside
// them. A face beside a cell that does not run carries nothing this step (reachCells), whatever
// its level.
void Impl::findLevelFaces() {
  levelFaces.clear();
  levelCells.clear();
  auto runs = [&](int x, int y) { return !skip || needCell[size_t(y) * size_t(w) + size_t(x)] != 0; };
  std::vector<std::pair<size_t, uint8_t>> coarse;  // (cell, bit of its face to the finer cell)
  auto add = [&](int x, int y, bool alongX) {
    const int xb = alongX ? x + 1 : x, yb = alongX ? y : y + 1;
    const int la = levelOf(x, y), lb = levelOf(xb, yb);
    if (la == lb || !runs(x, y) || !runs(xb, yb)) return;
    const bool fineIsA = la < lb;
    levelFaces.push_back(LevelFace{x, y, alongX, fineIsA, std::min(la, lb), 0});
    if (fineIsA) {
      coarse.emplace_back(size_t(yb) * size_t(w) + size_t(xb), alongX ? kW : kN);
    } else {
      coarse.emplace_back(size_t(y) * size_t(w) + size_t(x), alongX ? kE : kS);
    }
  };
  for (int by = 0; by < bh; ++by) {
    for (int bx = 0; bx < bw; ++bx) {
      const int m = blockLevel[size_t(by * bw + bx)];
      const int x0 = bx * kBlock, y0 = by * kBlock, x1 = std::min(w, x0 + kBlock), y1 = std::min(h, y0 + kBlock);
      if (bx + 1 < bw && blockLevel[size_t(by * bw + bx + 1)] != m) {
        for (int y = y0; y < y1; ++y) add(x1 - 1, y, true);
      }
      if (by + 1 < bh && blockLevel[size_t((by + 1) * bw + bx)] != m) {
        for (int x = x0; x < x1; ++x) add(x, y1 - 1, false);
      }
    }
  }
  std::sort(coarse.begin(), coarse.end());
  for (size_t i = 0; i < coarse.size();) {
    const size_t cell = coarse[i].first;
    uint8_t bits = 0;
    for (; i < coarse.size() && coarse[i].first == cell; ++i) bits = uint8_t(bits | coarse[i].second);
    const int x = int(cell % size_t(w)), y = int(cell / size_t(w));
    levelCells.push_back(LevelCell{x, y, levelOf(x, y), 1.0f, 0.0f, bits, 0.0f});
  }
  for (auto& f : levelFaces) {  // levelCells are in the order of their cells
    const auto cell = f.fineIsA ? std::pair{f.yb(), f.xb()} : std::pair{f.y, f.x};
    f.coarse = size_t(std::lower_bound(levelCells.begin(), levelCells.end(), cell,
                                       [](const LevelCell& c, std::pair<int, int> at) {
                                         return std::pair{c.y, c.x} < at;
                                       }) -
                      levelCells.begin());
  }
}

// Adds to each integrated face the flux its cells applied at the end of level m's step, times the
// step, if the face steps with level m (the finer of its cells'; the finer cell's discharge is the
// face's, W37).
void Impl::integrateLevel(int m, float dtLevel) {
  for (size_t k = 0; k < integrated.size(); ++k) {
    const IntegratedFace& f = integrated[k];
    const int la = f.hasA ? levelOf(f.xa, f.ya) : 255, lb = f.hasB ? levelOf(f.xb, f.yb) : 255;
    if (std::min(la, lb) != m) continue;
    const float q = la <= lb ? flux[f.alongX ? 1 : 3].at(f.xa, f.ya) : flux[f.alongX ? 0 : 2].at(f.xb, f.yb);
    integratedQdt[k] += double(q) * double(dtLevel);
  }
}

// One step of dtS in local steps (docs/sim-water.md, "Local time steps"). Substep i of the finest
// step dt runs, for each level m whose step starts at i (i a multiple of 2^m): the faces of its
// cells over 2^m dt; the faces between levels with the finer cell's step and its q0; the sources
// and limits of its cells (W38); the limits of the coarser cells beside them (what they may still
// give); then, for each level whose step ends at i, finest first, the update of its cells, its
// fixed levels (W26) and flood statistics. The update writes the state in place (no ping-pong: a
// cell whose step has not ended is read where it is).
void Impl::localStep(const std::vector<SourceEntry>& entries, const std::vector<LevelEntry>& levels, float dtS,
                     double endS, double rainRateMS) {
  planStep(entries, levels);
  const int M = planLevels(entries, dtS, rainRateMS);
  splitByLevel(water, levelWater, M);
  const bool rains = rainOrLosses();
  if (rains) splitByLevel(sources, levelRain, M);
  findLevelFaces();
  auto dtOf = [&](int m) { return dtS / float(1 << (M - m)); };  // exact: a power of two
  const double startS = endS - double(dtS);
  Water& u = now();
  inPlace = true;

  // A face's value, width, and the discharges its two cells last applied through it.
  auto faceOf = [&](const LevelFace& f) -> float& {
    return f.alongX ? faceX.mass.at(f.x + 1, f.y) : faceY.mass.at(f.x, f.y + 1);
  };
  auto widthOf = [&](const LevelFace& f) { return f.alongX ? dy : faceWidthY[size_t(f.y) + 1]; };
  auto appliedA = [&](const LevelFace& f) -> float& { return f.alongX ? flux[1].at(f.x, f.y) : flux[3].at(f.x, f.y); };
  auto appliedB = [&](const LevelFace& f) -> float& {
    return f.alongX ? flux[0].at(f.x + 1, f.y) : flux[2].at(f.x, f.y + 1);
  };
  // The volume rate (m^3/s) leaving cell c through its faces in `dirs`.
  auto outflow = [&](const LevelCell& c, uint8_t dirs) {
    const int x = c.x, y = c.y;
    float out = 0.0f;
    if (dirs & kW) out += maxOf(-faceX.mass.at(x, y), 0.0f) * dy;
    if (dirs & kE) out += maxOf(faceX.mass.at(x + 1, y), 0.0f) * dy;
    if (dirs & kN) out += maxOf(-faceY.mass.at(x, y), 0.0f) * faceWidthY[size_t(y)];
    if (dirs & kS) out += maxOf(faceY.mass.at(x, y + 1), 0.0f) * faceWidthY[size_t(y) + 1];
    return out;
  };

  long long updates = 0;
  integratedQdt.assign(integrated.size(), 0.0);
  const int substeps = 1 << M;
  for (int i = 0; i < substeps; ++i) {
    auto starts = [&](int m) { return i % (1 << m) == 0; };
    auto ends = [&](int m) { return (i + 1) % (1 << m) == 0; };
    // Faces, then sources (W38: after the faces, before the limits), then limits of the levels
    // starting a step.
    for (int m = 0; m <= M; ++m) {
      if (!starts(m)) continue;
      dt = dtOf(m);
      inertialFacePass(levelWater[size_t(m)]);
    }
    // Halfway through the coarser cell's step, its face to the finer cell sees it as it stands
    // then (Berger and Oliger's time interpolation): its depth less what it holds ahead of that
    // time (LevelCell::ahead).
    for (const auto& f : levelFaces) {
      if (!starts(f.level)) continue;
      dt = dtOf(f.level);
      float ha = u.h.at(f.x, f.y), hb = u.h.at(f.xb(), f.yb());
      float& coarse = f.fineIsA ? hb : ha;
      if (!starts(f.level + 1)) coarse = maxOf(coarse - levelCells[f.coarse].ahead, 0.0f);
      faceOf(f) = inertialFaceAt(f.x, f.y, f.alongX, f.fineIsA ? appliedA(f) : appliedB(f), ha, hb);
    }
    for (int m = 0; m <= M; ++m) {
      if (!starts(m)) continue;
      dt = dtOf(m);
      for (auto& c : levelCells) {
        if (c.level == m) c.ahead = u.h.at(c.x, c.y);
      }
      if (rains) rainPass(levelRain[size_t(m)]);
      // What a coarser cell holds at the midpoint of its step beyond the depth it has then: half
      // of what W11 and W11b poured in at its start (W38), less half of what its faces to cells
      // of its own level bring over the step (their flow is applied at its end).
      for (auto& c : levelCells) {
        if (c.level != m) continue;
        const int x = c.x, y = c.y;
        float in = 0.0f;  // m^3/s
        if (!(c.finer & kW)) in += faceX.mass.at(x, y) * dy;
        if (!(c.finer & kE)) in -= faceX.mass.at(x + 1, y) * dy;
        if (!(c.finer & kN)) in += faceY.mass.at(x, y) * faceWidthY[size_t(y)];
        if (!(c.finer & kS)) in -= faceY.mass.at(x, y + 1) * faceWidthY[size_t(y) + 1];
        c.ahead = 0.5f * ((u.h.at(x, y) - c.ahead) - in * dt / rowArea[size_t(y)]);
      }
      if (m == 0) pointSources(entries);  // a point source's block is level 0 (planLevels)
      fvLimitPass(levelWater[size_t(m)]);
    }
    // W25 over a coarser cell's whole step: at its start its limit K from all its faces (those to
    // finer cells as they are now) and the volume K leaves for them after its own faces' share;
    // at each start of the finer cells' step, the share of what those faces would take that the
    // volume left can give (<= K).
    for (auto& c : levelCells) {
      float& k = limit.at(c.x, c.y);
      if (starts(c.level)) {
        c.limit = k;
        const float own = outflow(c, uint8_t(~c.finer & 15)) * dtOf(c.level);
        c.budget = u.h.at(c.x, c.y) * rowArea[size_t(c.y)] - c.limit * own;
      }
      if (starts(c.level - 1)) {
        const float out = outflow(c, c.finer) * dtOf(c.level - 1);
        const float left = maxOf(c.budget, 0.0f);
        k = out > left ? minOf(c.limit, left / out) : c.limit;
        c.budget -= k * out;
      }
    }
    // Updates of the levels ending a step, finest first: a finer cell reads its coarser
    // neighbour's share above; a coarser cell's own update takes its limit over its step and leaves
    // its faces to finer cells to them (each of their updates has brought it what they carried).
    for (int m = 0; m <= M; ++m) {
      if (!ends(m)) continue;
      dt = dtOf(m);
      for (const auto& c : levelCells) {
        if (c.level != m) continue;
        limit.at(c.x, c.y) = c.limit;
        if (c.finer & kW) faceX.mass.at(c.x, c.y) = 0.0f;
        if (c.finer & kE) faceX.mass.at(c.x + 1, c.y) = 0.0f;
        if (c.finer & kN) faceY.mass.at(c.x, c.y) = 0.0f;
        if (c.finer & kS) faceY.mass.at(c.x, c.y + 1) = 0.0f;
      }
      inertialUpdatePass(levelWater[size_t(m)]);
      updates += (long long)levelWater[size_t(m)].cells;
      for (const auto& e : levels) {
        if (levelOf(e.cell) == m) levelPass({&e, 1});
      }
      // What the finer cells just applied through faces to coarser cells reaches those: the
      // same float term W34 added to the finer cell's depth (on rows of equal area).
      for (const auto& f : levelFaces) {
        if (f.level != m) continue;
        const int xc = levelCells[f.coarse].x, yc = levelCells[f.coarse].y;
        const float term = dt / rowArea[size_t(yc)] * ((f.fineIsA ? appliedA(f) : appliedB(f)) * widthOf(f));
        addDepth(u.h.at(xc, yc), accum[kAccumDepthError].at(xc, yc), f.fineIsA ? term : -term);
      }
      // A coarser cell keeps the discharges its finer neighbours applied last as its own (the
      // next step's q0 if the levels change), and its hu, hv from them.
      for (const auto& c : levelCells) {
        if (c.level != m) continue;
        const int x = c.x, y = c.y;
        if (c.finer & kW) flux[0].at(x, y) = flux[1].at(x - 1, y);
        if (c.finer & kE) flux[1].at(x, y) = flux[0].at(x + 1, y);
        if (c.finer & kN) flux[2].at(x, y) = flux[3].at(x, y - 1);
        if (c.finer & kS) flux[3].at(x, y) = flux[2].at(x, y + 1);
        u.hu.at(x, y) = 0.5f * (flux[0].at(x, y) + flux[1].at(x, y));
        u.hv.at(x, y) = 0.5f * (flux[2].at(x, y) + flux[3].at(x, y));
      }
      integrateLevel(m, dt);
      // Each cell's flood statistics at the end of each of its own steps.
      if (floodStats) floodStatsPass(levelWater[size_t(m)], float(startS + double(i + 1) * double(dtOf(0))));
    }
  }
  inPlace = false;
  dt = dtS;
  integratedStepS = double(dtS);
  finishStep(updates);
}

}  // namespace strata::sim::cpu
