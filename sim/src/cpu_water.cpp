// The CPU backend's water passes: sources (W11, W12), virtual pipes (W1-W4), flood mode
// (W13-W25), fixed levels (W26), flood statistics and the wave speed (W10). Each pass is the
// compute shader it names in C++, over the active blocks' runs of cells: the pass walks the runs
// (in parallel), and a row kernel (STRATA_ROW_KERNEL, built for two instruction sets) walks a
// row's cells.
#include <algorithm>
#include <cmath>

#include "cpu_impl.hpp"
#include "cpu_kernels.hpp"
#include "cpu_rows.hpp"

namespace strata::sim::cpu {
namespace {

constexpr int kDiagDx[4] = {-1, 1, -1, 1};  // NW, NE, SW, SE; the opposite of k is 3 - k
constexpr int kDiagDy[4] = {-1, -1, 1, 1};

}  // namespace

// ---------------------------------------------------------------------------------------------
// Sources

// sim/shaders/sources.comp for a row: rain (raster, may be null, plus uniform) and evaporation,
// into the depth with compensation (W34, error in `herr`), the evaporated volume summed with
// compensation.
STRATA_ROW_KERNEL void sourcesRow(float* h, float* herr, float* sum, float* err, const float* rain, float area, int x0,
                                  int x1, float uniform, float dtS, float evapMax) {
  auto cells = [=](auto kRaster) {
    const float uniformDepth = (0.0f + uniform) * kMmPerHourToMS * dtS;  // a raster of 0 mm/h
#pragma omp simd
    for (int x = x0; x < x1; ++x) {
      float hx = h[x], ex = herr[x];
      if constexpr (decltype(kRaster)::value) {
        addDepth(hx, ex, (rain[x] + uniform) * kMmPerHourToMS * dtS);
      } else {
        addDepth(hx, ex, uniformDepth);
      }
      const float e = minOf(hx, evapMax);
      addDepth(hx, ex, -e);
      kahanAdd(sum[x], err[x], e * area);
      h[x] = hx;
      herr[x] = ex;
    }
  };
  rain ? cells(std::true_type{}) : cells(std::false_type{});
}

// sim/shaders/sources.comp for a row, after rain and evaporation: each cell loses to the soil
// what its infiltration capacity over the step allows of its water (W11b), the infiltrated
// volume summed with compensation; that sum over the cell's area is the capacity's F.
STRATA_ROW_KERNEL void infiltrationRow(float* h, float* herr, float* sum, float* err, const float* ks, const float* g,
                                       float area, int x0, int x1, float dtS) {
  for (int x = x0; x < x1; ++x) {
    const float hx = h[x];
    if (!(hx > 0.0f)) continue;  // dry: nothing to lose
    // The capacity is at least Ks dt: water up to that soaks in whole, with nothing to solve.
    const float ksDt = ks[x] * dtS;
    const float f = hx <= ksDt ? hx : minOf(hx, infiltrationCapacity(ksDt, g[x], sum[x] / area));
    if (f > 0.0f) {
      addDepth(h[x], herr[x], -f);
      kahanAdd(sum[x], err[x], f * area);
    }
  }
}

// sim/shaders/sources.comp: rain (W11), evaporation (W11), infiltration (W11b), then
// point_sources.comp (W12). Without rain, evaporation or infiltration W11 and W11b change nothing
// (adding 0 leaves a settled depth as it is) and are skipped, as the GL backend skips the pass.
// `share` of each point source's step (W12b: the finite-volume scheme pours it in two halves).
void Impl::sourcesPass(const std::vector<SourceEntry>& entries, float share) {
  if (rainOrLosses()) rainPass(sources);
  pointSources(entries, share);
}

void Impl::rainPass(const BlockSet& set) {
  forRuns(set, [&](const Run& r, int) {
    const float evapMax = p.evaporationMmPerHour * kMmPerHourToMS * dt;
    for (int y = r.y0; y < r.y1; ++y) {
      float* herr = accum[kAccumDepthError].row(y);
      sourcesRow(now().h.row(y), herr, accum[kAccumEvaporated].row(y), accum[kAccumEvaporated + 1].row(y),
                 rain.empty() ? nullptr : rain.row(y), rowArea[size_t(y)], r.x0, r.x1, p.rainMmPerHour, dt, evapMax);
      if (!infilKs.empty()) {
        infiltrationRow(now().h.row(y), herr, accum[kAccumInfiltrated].row(y), accum[kAccumInfiltrated + 1].row(y),
                        infilKs.row(y), infilG.row(y), rowArea[size_t(y)], r.x0, r.x1, dt);
      }
    }
  });
}

void Impl::pointSources(std::span<const SourceEntry> entries, float share) {
  for (const auto& e : entries) {
    const int y = int(e.cell / uint32_t(w)), x = int(e.cell % uint32_t(w));
    addDepth(now().h.at(x, y), accum[kAccumDepthError].at(x, y), share * (e.rateM3S * dt / rowArea[size_t(y)]));
  }
}

// ---------------------------------------------------------------------------------------------
// Virtual pipes

struct PipeConst {
  int w, h;
  float dt, g, dy, dry, A, Ad;  // A, Ad: axis and diagonal pipe areas (W1b)
  uint32_t open;
};

// One row of pipe_flux.comp / pipe_update.comp's inputs: row y and its neighbours above (N) and
// below (S), which are row y itself at an edge.
struct PipeRow {
  int y;
  float dx, lenD, A, AN, AS;  // dx, diagonal pipe length, cell areas of rows y, y - 1, y + 1
  const float *h, *hN, *hS, *b, *bN, *bS, *s, *sN, *sS;
  float* f[4];                 // outflows of row y (W, E, N, S)
  const float *fN[4], *fS[4];  // of the rows above and below
  float* fd[4];                // diagonal outflows of row y (NW, NE, SW, SE)
  const float *fdN[4], *fdS[4];
};

// pipe_update.comp's outputs for a row, and the row's accumulators (slots 0, 1, 4, 5).
struct PipeOut {
  float *h, *s, *hu, *hv;
  float *outSum, *outErr, *sedSum, *sedErr;
};

namespace {

// sim/shaders/pipe_flux.comp: W1 (flux from head difference), W1a, W1b, W2 (scaling K).
template <bool kEdge, bool kDiag>
inline void pipeFluxCell(const PipeConst& c, const PipeRow& r, int x) {
  const bool in[4] = {!kEdge || x > 0, !kEdge || x < c.w - 1, !kEdge || r.y > 0, !kEdge || r.y < c.h - 1};
  const int xw = in[0] ? x - 1 : x, xe = in[1] ? x + 1 : x;
  const float hi = r.h[x], bi = r.b[x];
  const float hj[4] = {r.h[xw], r.h[xe], r.hN[x], r.hS[x]};
  const float bj[4] = {r.b[xw], r.b[xe], r.bN[x], r.bS[x]};
  const float len[4] = {r.dx, r.dx, c.dy, c.dy};
  float f[4];
  float sum = 0.0f;
  for (int d = 0; d < 4; ++d) {
    float dH = (bi - bj[d]) + (hi - hj[d]);
    // W1a: heads equal to float32 resolution are equal (a lake at rest stays at rest).
    const float noise = kHeadNoise * maxOf(maxOf(std::abs(bi), std::abs(bj[d])), maxOf(hi, hj[d]));
    dH = std::abs(dH) <= noise ? 0.0f : dH;
    if (kEdge && !in[d]) dH = hi;  // an open edge: a dry ghost cell at the same bed level
    const float v = maxOf(0.0f, r.f[d][x] + c.dt * c.A * c.g * dH / len[d]);
    f[d] = kEdge && !in[d] && !(c.open & (1u << d)) ? 0.0f : v;  // a closed edge: no pipe
    sum += f[d];
  }
  float fd[4] = {0.0f, 0.0f, 0.0f, 0.0f};
  if constexpr (kDiag) {  // W1b: diagonal pipes to the four corner neighbours, closed at the edges
    const bool inD[4] = {in[2] && in[0], in[2] && in[1], in[3] && in[0], in[3] && in[1]};
    const float hd[4] = {r.hN[xw], r.hN[xe], r.hS[xw], r.hS[xe]};
    const float bd[4] = {r.bN[xw], r.bN[xe], r.bS[xw], r.bS[xe]};
    for (int k = 0; k < 4; ++k) {
      float dH = (bi - bd[k]) + (hi - hd[k]);
      const float noise = kHeadNoise * maxOf(maxOf(std::abs(bi), std::abs(bd[k])), maxOf(hi, hd[k]));
      dH = std::abs(dH) <= noise ? 0.0f : dH;
      const float v = maxOf(0.0f, r.fd[k][x] + c.dt * c.Ad * c.g * dH / r.lenD);
      fd[k] = inD[k] ? v : 0.0f;
      sum += fd[k];
    }
  }
  const float K = sum > 0.0f ? minOf(1.0f, hi * r.A / (sum * c.dt)) : 0.0f;
  for (int d = 0; d < 4; ++d) r.f[d][x] = f[d] * K;
  if constexpr (kDiag) {
    for (int k = 0; k < 4; ++k) r.fd[k][x] = fd[k] * K;
  }
}

// Share of a cell's water (and so of its suspended sediment) leaving through a pipe of outflow
// f this step, given its depth h, area A and total outflow `out`.
inline float pipeFraction(float f, float h, float A, float out, float dt) {
  const float den = maxOf(h * A, out * dt);
  return den > 0.0f ? f * dt / den : 0.0f;
}

// sim/shaders/pipe_update.comp: W3 (depth), W4 (velocity), E5 (sediment transport, when kSed;
// without any suspended sediment it is s = 0 -> 0 and is skipped in the interior). The edge
// cells (kEdge) count what leaves through an open edge.
template <bool kEdge, bool kDiag, bool kSed>
inline void pipeUpdateCell(const PipeConst& c, const PipeRow& r, const PipeOut& o, int x) {
  const bool inside[4] = {!kEdge || x > 0, !kEdge || x < c.w - 1, !kEdge || r.y > 0, !kEdge || r.y < c.h - 1};
  const int xw = inside[0] ? x - 1 : x, xe = inside[1] ? x + 1 : x;
  const float A = r.A, dt = c.dt;
  const float h = r.h[x], s = r.s[x];
  const float fI[4] = {r.f[0][x], r.f[1][x], r.f[2][x], r.f[3][x]};
  const float fdI[4] = {r.fd[0][x], r.fd[1][x], r.fd[2][x], r.fd[3][x]};
  auto total = [&](const float* const* f, const float* const* fd, int i) {
    float out = f[0][i] + f[1][i] + f[2][i] + f[3][i];
    if constexpr (kDiag) out += fd[0][i] + fd[1][i] + fd[2][i] + fd[3][i];
    return out;
  };
  const float outI = total(r.f, r.fd, x);
  // What the neighbours W, E, N, S send this cell.
  const float fj[4] = {r.f[1][xw], r.f[0][xe], r.fN[3][x], r.fS[2][x]};
  float in = 0.0f, sIn = 0.0f, sOut = 0.0f;
  float inD[4] = {0.0f, 0.0f, 0.0f, 0.0f};
  for (int d = 0; d < 4; ++d) {
    if (kEdge && !inside[d]) continue;
    inD[d] = fj[d];
    in += fj[d];
  }
  if constexpr (kSed) {
    const float nh[4] = {r.h[xw], r.h[xe], r.hN[x], r.hS[x]};
    const float ns[4] = {r.s[xw], r.s[xe], r.sN[x], r.sS[x]};
    const float nA[4] = {A, A, r.AN, r.AS};
    const float outJ[4] = {total(r.f, r.fd, xw), total(r.f, r.fd, xe), total(r.fN, r.fdN, x), total(r.fS, r.fdS, x)};
    for (int d = 0; d < 4; ++d) {
      const float fr = pipeFraction(fI[d], h, A, outI, dt);
      if (!kEdge || inside[d]) {
        sIn += ns[d] * nA[d] * pipeFraction(fj[d], nh[d], nA[d], outJ[d], dt);
      } else if (fI[d] > 0.0f) {  // out through an open edge
        kahanAdd(o.outSum[x], o.outErr[x], fI[d] * dt);
        kahanAdd(o.sedSum[x], o.sedErr[x], s * A * fr);
      }
      sOut += fr;
    }
  }
  float qxDiag = 0.0f, qyDiag = 0.0f;
  if constexpr (kDiag) {
    const bool inK[4] = {inside[2] && inside[0], inside[2] && inside[1], inside[3] && inside[0],
                         inside[3] && inside[1]};
    const int kx[4] = {xw, xe, xw, xe};
    const float fk[4] = {r.fdN[3][xw], r.fdN[2][xe], r.fdS[1][xw], r.fdS[0][xe]};  // what each sends back
    for (int k = 0; k < 4; ++k) {
      if (kEdge && !inK[k]) continue;
      in += fk[k];
      if constexpr (kSed) {
        const bool north = k < 2;
        const float* const* kf = north ? r.fN : r.fS;
        const float* const* kfd = north ? r.fdN : r.fdS;
        const float kh = (north ? r.hN : r.hS)[kx[k]], ks = (north ? r.sN : r.sS)[kx[k]];
        const float kA = north ? r.AN : r.AS;
        sIn += ks * kA * pipeFraction(fk[k], kh, kA, total(kf, kfd, kx[k]), dt);
        sOut += pipeFraction(fdI[k], h, A, outI, dt);
      }
      // Net flow along the pipe's direction, projected on x and y.
      const float net = fdI[k] - fk[k];
      qxDiag += 0.5f * net * float(kDiagDx[k]) * r.dx / r.lenD;
      qyDiag += 0.5f * net * float(kDiagDy[k]) * c.dy / r.lenD;
    }
  }
  const float hNew = maxOf(0.0f, h + dt * (in - outI) / A);
  const float sNew = kSed ? s - s * sOut + sIn / A : s;
  // W4: mean discharge through the cell over its cross-section.
  const float hMean = 0.5f * (h + hNew);
  const float qx = 0.5f * (inD[0] - fI[0] + fI[1] - inD[1]) + qxDiag;
  const float qy = 0.5f * (inD[2] - fI[2] + fI[3] - inD[3]) + qyDiag;
  const bool moving = hMean > c.dry;
  const float u = moving ? qx / (c.dy * hMean) : 0.0f, v = moving ? qy / (r.dx * hMean) : 0.0f;
  o.h[x] = hNew;
  o.s[x] = sNew;
  o.hu[x] = u * hNew;
  o.hv[x] = v * hNew;
}

PipeConst pipeConst(const Impl& m) {
  const SimParams& p = m.p;
  // W1b: with diagonal pipes the areas follow the isotropic 9-point Laplacian (axis 2/3,
  // diagonal sqrt(2)/6 of pipeAreaM2), which keeps the total conductance of the 4 pipes.
  const float A = p.diagonalPipes ? p.pipeAreaM2 * (2.0f / 3.0f) : p.pipeAreaM2;
  return {m.w, m.h, m.dt, p.gravityMS2, m.dy, p.dryDepthM, A, p.pipeAreaM2 * (1.41421356f / 6.0f), p.openEdges};
}

PipeRow pipeRow(Impl& m, int y) {
  const Water& u = m.now();
  const int yn = y > 0 ? y - 1 : y, ys = y + 1 < m.h ? y + 1 : y;
  PipeRow r{};
  r.y = y;
  r.dx = m.rowDx[size_t(y)];
  r.lenD = std::sqrt(r.dx * r.dx + m.dy * m.dy);
  r.A = m.rowArea[size_t(y)];
  r.AN = m.rowArea[size_t(yn)];
  r.AS = m.rowArea[size_t(ys)];
  r.h = u.h.row(y), r.hN = u.h.row(yn), r.hS = u.h.row(ys);
  r.b = m.bed.row(y), r.bN = m.bed.row(yn), r.bS = m.bed.row(ys);
  r.s = u.s.row(y), r.sN = u.s.row(yn), r.sS = u.s.row(ys);
  for (int d = 0; d < 4; ++d) {
    r.f[d] = m.flux[d].row(y), r.fN[d] = m.flux[d].row(yn), r.fS[d] = m.flux[d].row(ys);
    Plane& diag = m.fluxDiag[d].empty() ? m.flux[d] : m.fluxDiag[d];
    r.fd[d] = diag.row(y), r.fdN[d] = diag.row(yn), r.fdS[d] = diag.row(ys);
  }
  return r;
}

}  // namespace

STRATA_ROW_KERNEL void pipeFluxRow(const PipeConst& c, const PipeRow& r, int x0, int x1, bool diag) {
  const bool edgeRow = r.y == 0 || r.y == c.h - 1;
  if (diag) {
    forRowCells(x0, x1, c.w, edgeRow, [&](auto e, int x) { pipeFluxCell<decltype(e)::value, true>(c, r, x); });
  } else {
    forRowCells(x0, x1, c.w, edgeRow, [&](auto e, int x) { pipeFluxCell<decltype(e)::value, false>(c, r, x); });
  }
}

STRATA_ROW_KERNEL void pipeUpdateRow(const PipeConst& c, const PipeRow& r, const PipeOut& o, int x0, int x1, bool diag,
                                     bool sed) {
  const bool edgeRow = r.y == 0 || r.y == c.h - 1;
  auto cells = [&](auto kDiag, auto kSed) {
    forRowCells(x0, x1, c.w, edgeRow, [&](auto e, int x) {
      // Edge cells always take the full path: their sediment outflow is counted.
      constexpr bool kEdge = decltype(e)::value;
      pipeUpdateCell<kEdge, decltype(kDiag)::value, kEdge || decltype(kSed)::value>(c, r, o, x);
    });
  };
  if (diag) {
    sed ? cells(std::true_type{}, std::true_type{}) : cells(std::true_type{}, std::false_type{});
  } else {
    sed ? cells(std::false_type{}, std::true_type{}) : cells(std::false_type{}, std::false_type{});
  }
}

// E0: sin of the bed tilt from central differences (one-sided at the edges) for a row whose
// neighbours above and below are bu, bd (the row itself at an edge) `dyRows` metres apart.
STRATA_ROW_KERNEL void tiltRow(const float* b, const float* bu, const float* bd, float* t, float dx, float dyRows,
                               int x0, int x1, int w) {
  forRowCells(x0, x1, w, false, [=](auto e, int x) {
    constexpr bool kEdge = decltype(e)::value;
    const int xl = kEdge ? std::max(x - 1, 0) : x - 1, xr = kEdge ? std::min(x + 1, w - 1) : x + 1;
    const float gx = (b[xr] - b[xl]) / (float(xr - xl) * dx);
    const float gy = (bd[x] - bu[x]) / dyRows;
    const float g2 = gx * gx + gy * gy;
    t[x] = std::sqrt(g2 / (1.0f + g2));
  });
}

void Impl::tiltRows(int y, int x0, int x1) {
  const int yu = std::max(y - 1, 0), yd = std::min(y + 1, h - 1);
  tiltRow(bed.row(y), bed.row(yu), bed.row(yd), tilt.row(y), rowDx[size_t(y)], float(yd - yu) * dy, x0, x1, w);
}

// sim/shaders/pipe_flux.comp, in place: each cell reads its own outflows and its neighbours'
// depth and bed, and writes only its own outflows.
void Impl::pipeFluxPass() {
  forRuns(water, [&](const Run& run, int) {
    const PipeConst c = pipeConst(*this);
    for (int y = run.y0; y < run.y1; ++y) pipeFluxRow(c, pipeRow(*this, y), run.x0, run.x1, p.diagonalPipes);
  });
}

// sim/shaders/pipe_update.comp: the state into next(), and E0's tilt when erosion is on.
void Impl::pipeUpdatePass() {
  forRuns(water, [&](const Run& run, int) {
    const PipeConst c = pipeConst(*this);
    for (int y = run.y0; y < run.y1; ++y) {
      Water& nx = next();
      const PipeOut o{nx.h.row(y),
                      nx.s.row(y),
                      nx.hu.row(y),
                      nx.hv.row(y),
                      accum[kAccumOutflow].row(y),
                      accum[kAccumOutflow + 1].row(y),
                      accum[kAccumSedimentOut].row(y),
                      accum[kAccumSedimentOut + 1].row(y)};
      pipeUpdateRow(c, pipeRow(*this, y), o, run.x0, run.x1, p.diagonalPipes, anySuspended);
      if (p.erosionEnabled) tiltRows(y, run.x0, run.x1);
    }
  });
}

// ---------------------------------------------------------------------------------------------
// Flood mode

namespace {

// The face pass's per-thread rows (Impl::scratch), 16 floats of margin on either side: the
// primitives h, eta, u, v of four rows (a ring indexed by row & 3), the x sides of one row (east
// side h, eta, un, ut, then the west side) and the y sides of two rows (ring by row & 1: south
// side, then north side).
constexpr int kScratchMargin = 16;
inline float* primRow(Plane& s, int y, int comp) { return s.row((y & 3) * 4 + comp) + kScratchMargin; }
inline float* xSideRow(Plane& s, int comp) { return s.row(16 + comp) + kScratchMargin; }
inline float* ySideRow(Plane& s, int y, int comp) { return s.row(24 + (y & 1) * 8 + comp) + kScratchMargin; }

}  // namespace

// Four rows of one value each (h, eta, un, ut of a side; mass, nL, nR, t of a face).
struct Rows4 {
  float *a, *b, *c, *d;
};

namespace {

inline Side sideAt(const Rows4& r, int x) { return {r.a[x], r.b[x], r.c[x], r.d[x]}; }
inline void store(float& o, float v, bool average) { o = average ? 0.5f * (o + v) : v; }
template <bool kAvg>
inline void storeFace(const Rows4& o, int x, FaceFlux f) {
  store(o.a[x], f.mass, kAvg);
  store(o.b[x], f.nL, kAvg);
  store(o.c[x], f.nR, kAvg);
  store(o.d[x], f.t, kAvg);
}
Rows4 faceRows(Faces& f, int y) { return {f.mass.row(y), f.nL.row(y), f.nR.row(y), f.t.row(y)}; }

}  // namespace

// The primitives of one row: depth, surface (bed + h), velocities.
STRATA_ROW_KERNEL void primitivesRow(const float* h, const float* hu, const float* hv, const float* b, float* ph,
                                     float* pe, float* pu, float* pv, int x0, int x1, float dry) {
#pragma omp simd
  for (int x = x0; x < x1; ++x) {
    const float hx = h[x];
    ph[x] = hx;
    pe[x] = b[x] + hx;
    pu[x] = velocityOf(hx, hu[x], dry);
    pv[x] = velocityOf(hx, hv[x], dry);
  }
}

// W21 for a row of one primitive: from the cell's value c and its neighbours' m (before) and p
// (after) along the face normal, the value at the far face (+ half a limited slope) and at the
// near face (- half). A cell on the grid's edge along the normal (an edge row, `lowRow` /
// `highRow`, or columns 0 and w - 1 when `columns`) has one neighbour: W27, at an open edge its
// depth and surface continue the slope from that neighbour (`extrapolate`; the depth's slope
// bounded so that neither face goes below zero), anything else is first order (the cell's own
// value at both faces).
enum class EdgeSlope { kNone, kSurface, kDepth };
STRATA_ROW_KERNEL void reconstructRow(const float* c, const float* m, const float* pv, float* plus, float* minus,
                                      int x0, int x1, bool lowRow, bool highRow, bool columns, bool openLow,
                                      bool openHigh, EdgeSlope extrapolate, int w, bool mc) {
  auto cells = [=](auto kMC) {
#pragma omp simd
    for (int x = x0; x < x1; ++x) {
      const float cx = c[x];
      const float back = cx - m[x], fwd = pv[x] - cx;
      const float sl = limitedSlope<decltype(kMC)::value>(back, fwd);
      const bool lo = lowRow | (columns & (x == 0)), hi = highRow | (columns & (x == w - 1));
      const float one = lo ? fwd : back;  // the one-sided slope towards the inside
      const float bounded = minOf(maxOf(one, -2.0f * cx), 2.0f * cx);
      const float ex = extrapolate == EdgeSlope::kDepth ? bounded : one;
      const bool open = (lo != hi) & (lo ? openLow : openHigh) & (extrapolate != EdgeSlope::kNone);
      const float slope = (lo | hi) ? (open ? ex : 0.0f) : sl;
      plus[x] = cx + 0.5f * slope;
      minus[x] = cx + -0.5f * slope;
    }
  };
  mc ? cells(std::true_type{}) : cells(std::false_type{});
}

// W13-W16 between the sides L (cell x) and R (cell x + shift) of a row, into faces o[x + shift].
STRATA_ROW_KERNEL void faceRow(Rows4 L, Rows4 R, Rows4 o, int x0, int x1, int shift, float g, float dry, bool average) {
  auto cells = [=](auto kAvg) {
#pragma omp simd
    for (int x = x0; x < x1; ++x) {
      storeFace<decltype(kAvg)::value>(o, x + shift, hllFace(sideAt(L, x), sideAt(R, x + shift), g, dry));
    }
  };
  average ? cells(std::true_type{}) : cells(std::false_type{});
}

// W23: the centred bed-slope source and the pressure on the slanted sides of a cell whose north
// and south widths differ, as momentum rates (m^4/s^2), from the cell's four sides.
STRATA_ROW_KERNEL void bedSourceRow(Rows4 W, Rows4 E, Rows4 N, Rows4 S, float* sx, float* sy, int x0, int x1, float g,
                                    float dy, float wN, float wS, bool average) {
  auto cells = [=](auto kAvg) {
#pragma omp simd
    for (int x = x0; x < x1; ++x) {
      const float wh = W.a[x], we = W.b[x], eh = E.a[x], ee = E.b[x];
      const float nh = N.a[x], ne = N.b[x], sh = S.a[x], se = S.b[x];
      const float bx = -g * 0.5f * (wh + eh) * ((ee - we) - (eh - wh)) * dy;
      const float by = -g * 0.5f * (nh + sh) * ((se - ne) - (sh - nh)) * (0.5f * (wN + wS)) +
                       0.5f * g * (0.5f * (nh * nh + sh * sh)) * (wS - wN);
      store(sx[x], bx, decltype(kAvg)::value);
      store(sy[x], by, decltype(kAvg)::value);
    }
  };
  average ? cells(std::true_type{}) : cells(std::false_type{});
}

// sim/shaders/fv_face.comp: W13-W16 on every face of the active runs from the reconstructed
// sides (W21), ghost cells at the edges (W17), and W23's bed source of each cell (fv_update.comp's
// bedSource, from the same sides). `average`: the Heun corrector, face = (F(U0) + F(U1)) / 2 and
// source = (S(U0) + S(U1)) / 2 (W22). Each cell owns its east and south faces, and the west face
// in column 0 and the north face in row 0; a face owned by an inactive cell is zero and stays so.
// A run's rows are swept top to bottom, each row's primitives and sides computed once into the
// thread's scratch rows.
void Impl::fvFacePass(const Water& u, bool average) {
  const bool mc = p.slopeLimiter == SlopeLimiter::kMonotonizedCentral;
  forRuns(water, [&](const Run& r, int thread) {
    const float g = p.gravityMS2, dry = p.dryDepthM;
    const uint32_t open = p.openEdges;
    Plane& sc = scratch[size_t(thread)];
    const int pa = std::max(r.x0 - 1, 0), pb = std::min(r.x1 + 2, w);  // primitives' columns
    auto prims = [&](int y) {
      primitivesRow(u.h.row(y), u.hu.row(y), u.hv.row(y), bed.row(y), primRow(sc, y, 0), primRow(sc, y, 1),
                    primRow(sc, y, 2), primRow(sc, y, 3), pa, pb, dry);
    };
    // Primitives h, eta, v, u (y sides) or h, eta, u, v (x sides): W27 extrapolates h and eta.
    const EdgeSlope kinds[4] = {EdgeSlope::kDepth, EdgeSlope::kSurface, EdgeSlope::kNone, EdgeSlope::kNone};
    auto ySides = [&](int y) {  // south and north sides of row y's cells (un = v, ut = u)
      const int ym = y > 0 ? y - 1 : y, yp = y + 1 < h ? y + 1 : y;
      const int comp[4] = {0, 1, 3, 2};  // h, eta, v, u
      for (int k = 0; k < 4; ++k) {
        reconstructRow(primRow(sc, y, comp[k]), primRow(sc, ym, comp[k]), primRow(sc, yp, comp[k]), ySideRow(sc, y, k),
                       ySideRow(sc, y, 4 + k), r.x0, r.x1, y == 0, y == h - 1, false, open & kEdgeNorth,
                       open & kEdgeSouth, kinds[k], w, mc);
      }
    };
    auto xSides = [&](int y) {  // east and west sides of row y's cells (un = u, ut = v)
      const int xb = std::min(r.x1 + 1, w);
      for (int k = 0; k < 4; ++k) {
        const float* c = primRow(sc, y, k);
        reconstructRow(c, c - 1, c + 1, xSideRow(sc, k), xSideRow(sc, 4 + k), r.x0, xb, false, false, true,
                       open & kEdgeWest, open & kEdgeEast, kinds[k], w, mc);
      }
    };
    if (r.y0 > 0) prims(r.y0 - 1);
    prims(r.y0);
    if (r.y0 + 1 < h) prims(r.y0 + 1);
    ySides(r.y0);
    for (int y = r.y0; y < r.y1; ++y) {
      if (y + 2 < h) prims(y + 2);
      if (y + 1 < h) ySides(y + 1);
      xSides(y);
      const Rows4 east{xSideRow(sc, 0), xSideRow(sc, 1), xSideRow(sc, 2), xSideRow(sc, 3)};
      const Rows4 west{xSideRow(sc, 4), xSideRow(sc, 5), xSideRow(sc, 6), xSideRow(sc, 7)};
      const Rows4 south{ySideRow(sc, y, 0), ySideRow(sc, y, 1), ySideRow(sc, y, 2), ySideRow(sc, y, 3)};
      const Rows4 north{ySideRow(sc, y, 4), ySideRow(sc, y, 5), ySideRow(sc, y, 6), ySideRow(sc, y, 7)};
      const Rows4 below{ySideRow(sc, y + 1, 4), ySideRow(sc, y + 1, 5), ySideRow(sc, y + 1, 6), ySideRow(sc, y + 1, 7)};
      const Rows4 fx = faceRows(faceX, y), fs = faceRows(faceY, y + 1);
      auto put = [&](const Rows4& o, int x, const FaceFlux& f) {
        average ? storeFace<true>(o, x, f) : storeFace<false>(o, x, f);
      };
      faceRow(east, west, fx, r.x0, std::min(r.x1, w - 1), 1, g, dry, average);
      if (r.x1 == w) put(fx, w, edgeFlux(sideAt(east, w - 1), true, open & kEdgeEast, g, dry));
      if (r.x0 == 0) put(fx, 0, edgeFlux(sideAt(west, 0), false, open & kEdgeWest, g, dry));
      if (y + 1 < h) {
        faceRow(south, below, fs, r.x0, r.x1, 0, g, dry, average);
      } else {
        for (int x = r.x0; x < r.x1; ++x) put(fs, x, edgeFlux(sideAt(south, x), true, open & kEdgeSouth, g, dry));
      }
      if (y == 0) {
        const Rows4 fn = faceRows(faceY, 0);
        for (int x = r.x0; x < r.x1; ++x) put(fn, x, edgeFlux(sideAt(north, x), false, open & kEdgeNorth, g, dry));
      }
      bedSourceRow(west, east, north, south, srcX.row(y), srcY.row(y), r.x0, r.x1, g, dy, faceWidthY[size_t(y)],
                   faceWidthY[size_t(y) + 1], average);
    }
  });
}

// fv_limit.comp for a row: the faces' mass fluxes (x faces of the row, y faces above and below),
// the depths, the limits out.
STRATA_ROW_KERNEL void limitRow(const float* fx, const float* fn, const float* fs, const float* h, float* k, int x0,
                                int x1, float dy, float wN, float wS, float area, float dtS) {
#pragma omp simd
  for (int x = x0; x < x1; ++x) {
    const float fW = fx[x], fE = fx[x + 1], fN = fn[x], fS = fs[x];
    const float out = ((maxOf(-fW, 0.0f) + maxOf(fE, 0.0f)) * dy + maxOf(-fN, 0.0f) * wN + maxOf(fS, 0.0f) * wS) * dtS;
    const float have = h[x] * area;
    k[x] = out > have ? have / out : 1.0f;
  }
}

// sim/shaders/fv_limit.comp, W25: after the corrector's faces, the share K = min(1, h A /
// (outflow dt)) of its outgoing mass fluxes each cell can give without going below zero (as the
// pipe model's W2), so the corrector never has to clip a depth, which would create water.
void Impl::fvLimitPass(const BlockSet& set) {
  forRuns(set, [&](const Run& r, int) {
    for (int y = r.y0; y < r.y1; ++y) {
      limitRow(faceX.mass.row(y), faceY.mass.row(y), faceY.mass.row(y + 1), now().h.row(y), limit.row(y), r.x0, r.x1,
               dy, faceWidthY[size_t(y)], faceWidthY[size_t(y) + 1], rowArea[size_t(y)], dt);
    }
  });
}

// W25: the volume rate leaving cell (x, y) through its four faces (m^3/s), each face's mass flux
// scaled by its upwind cell's limit (an upwind cell outside the grid does not limit).
float Impl::outflowLimited(int x, int y) const {
  auto limitOf = [&](float massFlux, int xl, int yl, int xr, int yr) {
    const int ux = massFlux > 0.0f ? xl : xr, uy = massFlux > 0.0f ? yl : yr;
    return ux < 0 || uy < 0 || ux >= w || uy >= h ? 1.0f : limit.at(ux, uy);
  };
  float fW = faceX.mass.at(x, y), fE = faceX.mass.at(x + 1, y), fN = faceY.mass.at(x, y), fS = faceY.mass.at(x, y + 1);
  fW *= limitOf(fW, x - 1, y, x, y);
  fE *= limitOf(fE, x, y, x + 1, y);
  fN *= limitOf(fN, x, y - 1, x, y);
  fS *= limitOf(fS, x, y, x, y + 1);
  return (maxOf(-fW, 0.0f) + maxOf(fE, 0.0f)) * dy + maxOf(-fN, 0.0f) * faceWidthY[size_t(y)] +
         maxOf(fS, 0.0f) * faceWidthY[size_t(y) + 1];
}

// E5's denominators for the interior cells [x0, x1) of a row: max(h A, limited outflow dt).
STRATA_ROW_KERNEL void denRow(const float* fx, const float* fn, const float* fs, const float* k, const float* kN,
                              const float* kS, const float* h, float* out, int x0, int x1, float dy, float wN, float wS,
                              float area, float dtS) {
#pragma omp simd
  for (int x = x0; x < x1; ++x) {
    float fW = fx[x], fE = fx[x + 1], fN = fn[x], fS = fs[x];
    const float kw = k[x - 1], kc = k[x], ke = k[x + 1], kn = kN[x], ks = kS[x];
    fW *= fW > 0.0f ? kw : kc;
    fE *= fE > 0.0f ? kc : ke;
    fN *= fN > 0.0f ? kn : kc;
    fS *= fS > 0.0f ? kc : ks;
    const float o = (maxOf(-fW, 0.0f) + maxOf(fE, 0.0f)) * dy + maxOf(-fN, 0.0f) * wN + maxOf(fS, 0.0f) * wS;
    out[x] = maxOf(h[x] * area, o * dtS);
  }
}

// E5's denominators of fv_update.comp, once per cell: max(h A, limited outflow dt), the volume
// whose share of the cell's load each outgoing face carries.
void Impl::fvDenPass() {
  forRuns(water, [&](const Run& r, int) {
    for (int y = r.y0; y < r.y1; ++y) {
      const float* hh = now().h.row(y);
      float* out = den.row(y);
      const float A = rowArea[size_t(y)];
      auto edgeCell = [&](int x) { out[x] = maxOf(hh[x] * A, outflowLimited(x, y) * dt); };
      forEdgesAndInterior(r.x0, r.x1, w, y == 0 || y == h - 1, edgeCell, [&](int xa, int xb) {
        denRow(faceX.mass.row(y), faceY.mass.row(y), faceY.mass.row(y + 1), limit.row(y), limit.row(y - 1),
               limit.row(y + 1), hh, out, xa, xb, dy, faceWidthY[size_t(y)], faceWidthY[size_t(y) + 1], A, dt);
      });
    }
  });
}

struct FvConst {
  int w, h;
  float dt, g, dy, dry;
};

// One row of fv_update.comp's inputs and outputs.
struct FvRow {
  int y;
  float A, AN, AS, wN, wS;
  const float *fxm, *fxnL, *fxnR, *fxt;  // x faces of row y
  const float *fnm, *fnnL, *fnnR, *fnt;  // y faces above (row y) and below (row y + 1)
  const float *fsm, *fsnL, *fsnR, *fst;
  const float *lim, *limN, *limS;  // W25 limits of rows y, y - 1, y + 1 (row y at an edge)
  const float *den, *denN, *denS;  // E5 denominators (interior, with sediment)
  const float *h, *s, *hu, *hv, *sN, *sS;
  const float *srcX, *srcY;
  float *oh, *os, *ohu, *ohv;
  float* herr;  // the depth's error (W34), read and written by the corrector
};

namespace {

// W25's limit of a face with mass flux f between a left / top cell l and a right / bottom cell
// r: the upwind cell's (1 outside the grid).
inline float upwindLimit(float f, float kl, bool lInside, float kr, bool rInside) {
  return f > 0.0f ? (lInside ? kl : 1.0f) : (rInside ? kr : 1.0f);
}

// sim/shaders/fv_update.comp without E5 at the edges (Impl::fvSedimentEdge) and W19 (frictionRow):
// W18, W24, W25 (final), the sediment exchange in the interior (kSed). The limited faces go to
// `limited` at the edges.
template <bool kEdge, bool kFinal, bool kSed>
inline void fvUpdateCell(const FvConst& c, const FvRow& r, int x, FaceFlux* limited) {
  const bool inW = !kEdge || x > 0, inE = !kEdge || x < c.w - 1, inN = !kEdge || r.y > 0, inS = !kEdge || r.y < c.h - 1;
  const int xw = inW ? x - 1 : x, xe = inE ? x + 1 : x;
  FaceFlux W{r.fxm[x], r.fxnL[x], r.fxnR[x], r.fxt[x]}, E{r.fxm[x + 1], r.fxnL[x + 1], r.fxnR[x + 1], r.fxt[x + 1]};
  FaceFlux N{r.fnm[x], r.fnnL[x], r.fnnR[x], r.fnt[x]}, S{r.fsm[x], r.fsnL[x], r.fsnR[x], r.fst[x]};
  if constexpr (kFinal) {  // W25: the mass (and, with it, the tangential momentum) each upwind cell can give
    const float kW = upwindLimit(W.mass, r.lim[xw], inW, r.lim[x], true);
    const float kE = upwindLimit(E.mass, r.lim[x], true, r.lim[xe], inE);
    const float kN = upwindLimit(N.mass, r.limN[x], inN, r.lim[x], true);
    const float kS = upwindLimit(S.mass, r.lim[x], true, r.limS[x], inS);
    W.mass *= kW, W.t *= kW, E.mass *= kE, E.t *= kE, N.mass *= kN, N.t *= kN, S.mass *= kS, S.t *= kS;
  }
  const float dy = c.dy, wN = r.wN, wS = r.wS;
  const float h = r.h[x], s = r.s[x], hu = r.hu[x], hv = r.hv[x];
  const float sx = r.srcX[x], sy = r.srcY[x];
  const float k = c.dt / r.A;
  float hNew = h;
  if constexpr (kFinal) {  // W34: the step's depth with compensation, face by face
    float e = r.herr[x];
    addDepthFaces(hNew, e, k, W.mass * dy, E.mass * dy, N.mass * wN, S.mass * wS);
    r.herr[x] = e;
  } else {  // the predictor's stage: read by the corrector's faces only
    hNew -= k * ((E.mass - W.mass) * dy + S.mass * wS - N.mass * wN);
  }
  // W24: a net force below float32 resolution of the forces it sums is rounding, not a
  // pressure gradient (the momentum analogue of W1a): a lake at rest stays at rest.
  float fx = sx - ((E.nL - W.nR) * dy + S.t * wS - N.t * wN);
  float fy = sy - (S.nL * wS - N.nR * wN + (E.t - W.t) * dy);
  const float magX = std::abs(E.nL * dy) + std::abs(W.nR * dy) + std::abs(S.t * wS) + std::abs(N.t * wN) + std::abs(sx);
  const float magY = std::abs(S.nL * wS) + std::abs(N.nR * wN) + std::abs(E.t * dy) + std::abs(W.t * dy) + std::abs(sy);
  fx = std::abs(fx) <= kForceNoise * magX ? 0.0f : fx;
  fy = std::abs(fy) <= kForceNoise * magY ? 0.0f : fy;
  float huNew = hu + k * fx;
  float hvNew = hv + k * fy;
  hNew = maxOf(hNew, 0.0f);
  const bool dryNew = hNew <= c.dry;
  huNew = dryNew ? 0.0f : huNew;
  hvNew = dryNew ? 0.0f : hvNew;
  float sNew = s;
  if constexpr (kFinal && kSed && !kEdge) {
    // E5: suspended sediment moves with the water volume crossing each face, upwind.
    const float A = r.A, dt = c.dt, denI = r.den[x];
    const float vols[4] = {-W.mass * dy * dt, E.mass * dy * dt, -N.mass * wN * dt, S.mass * wS * dt};
    const float sj[4] = {r.s[x - 1], r.s[x + 1], r.sN[x], r.sS[x]};
    const float Aj[4] = {A, A, r.AN, r.AS};
    const float dj[4] = {r.den[x - 1], r.den[x + 1], r.denN[x], r.denS[x]};
    for (int d = 0; d < 4; ++d) {
      const float volOut = vols[d];
      const float moved = denI > 0.0f ? s * A * volOut / denI : 0.0f;
      const float gained = sj[d] * Aj[d] * (-volOut) / dj[d] / A;
      sNew = volOut > 0.0f ? sNew - moved / A : (volOut < 0.0f && dj[d] > 0.0f ? sNew + gained : sNew);
    }
  }
  if constexpr (kEdge) {
    limited[0] = W, limited[1] = E, limited[2] = N, limited[3] = S;
  }
  r.oh[x] = hNew;
  r.os[x] = sNew;
  r.ohu[x] = huNew;
  r.ohv[x] = hvNew;
}

}  // namespace

// fv_update.comp's interior cells [x0, x1) of a row (all four neighbours in the grid).
STRATA_ROW_KERNEL void fvUpdateRow(const FvConst& c, const FvRow& r, int x0, int x1, bool final, bool sed) {
  auto cells = [&](auto kFinal, auto kSed) {
#pragma omp simd
    for (int x = x0; x < x1; ++x) fvUpdateCell<false, decltype(kFinal)::value, decltype(kSed)::value>(c, r, x, nullptr);
  };
  if (!final) {
    cells(std::false_type{}, std::false_type{});
  } else {
    sed ? cells(std::true_type{}, std::true_type{}) : cells(std::true_type{}, std::false_type{});
  }
}

// W19, implicit Manning friction on a row's new state: the discharge divided by
// (1 + sqrt(1 + 4 dt g n^2 |u| / h^(4/3))) / 2 where the cell is wet (h^(4/3) = h cbrt(h) with
// cubeRoot, which vectorises; fv_update.comp uses pow).
// `n2row`: n^2 per cell (a roughness map), or null for `n2` everywhere.
STRATA_ROW_KERNEL void frictionRow(const float* h, float* hu, float* hv, int x0, int x1, float dtg, float n2,
                                   const float* n2row, float dry) {
  auto cells = [=](auto kMap) {
#pragma omp simd
    for (int x = x0; x < x1; ++x) {
      const float hx = h[x];
      const bool wet = hx > dry;
      const float hw = wet ? hx : 1.0f;
      float n2x = n2;
      if constexpr (decltype(kMap)::value) n2x = n2row[x];
      const float dtgnSpeed = dtg * n2x * (std::sqrt(hu[x] * hu[x] + hv[x] * hv[x]) / hx);
      const float cf = 0.5f + 0.5f * std::sqrt(1.0f + 4.0f * (dtgnSpeed / (hw * cubeRoot(hw))));
      hu[x] = wet ? hu[x] / cf : hu[x];
      hv[x] = wet ? hv[x] / cf : hv[x];
    }
  };
  n2row ? cells(std::true_type{}) : cells(std::false_type{});
}

// sim/shaders/fv_update.comp: W18 (conservative update with the face fluxes). The predictor
// (final = false) writes U1 = U0 - dt L(U0) into `stage`; the corrector (final = true) writes
// U0 - dt (L(U0) + L(U1)) / 2 into next() (W22), then W19 (Manning friction), E5, E0.
void Impl::fvUpdatePass(bool final) {
  const bool sed = anySuspended;
  forRuns(water, [&](const Run& run, int) {
    const FvConst c{w, h, dt, p.gravityMS2, dy, p.dryDepthM};
    const float n2 = p.manningN * p.manningN;
    for (int y = run.y0; y < run.y1; ++y) {
      const int yn = std::max(y - 1, 0), ys = std::min(y + 1, h - 1);
      const Water& u = now();
      Water& o = final ? next() : stage;
      const Plane& dn = den.empty() ? limit : den;
      const FvRow r{y,
                    rowArea[size_t(y)],
                    rowArea[size_t(yn)],
                    rowArea[size_t(ys)],
                    faceWidthY[size_t(y)],
                    faceWidthY[size_t(y) + 1],
                    faceX.mass.row(y),
                    faceX.nL.row(y),
                    faceX.nR.row(y),
                    faceX.t.row(y),
                    faceY.mass.row(y),
                    faceY.nL.row(y),
                    faceY.nR.row(y),
                    faceY.t.row(y),
                    faceY.mass.row(y + 1),
                    faceY.nL.row(y + 1),
                    faceY.nR.row(y + 1),
                    faceY.t.row(y + 1),
                    limit.row(y),
                    limit.row(yn),
                    limit.row(ys),
                    dn.row(y),
                    dn.row(yn),
                    dn.row(ys),
                    u.h.row(y),
                    u.s.row(y),
                    u.hu.row(y),
                    u.hv.row(y),
                    u.s.row(yn),
                    u.s.row(ys),
                    srcX.row(y),
                    srcY.row(y),
                    o.h.row(y),
                    o.s.row(y),
                    o.hu.row(y),
                    o.hv.row(y),
                    accum[kAccumDepthError].row(y)};
      auto edgeCell = [&](int x) {
        FaceFlux limited[4];
        if (final) {
          fvUpdateCell<true, true, true>(c, r, x, limited);
          r.os[x] = fvSedimentEdge(x, y, limited);
        } else {
          fvUpdateCell<true, false, false>(c, r, x, limited);
        }
      };
      forEdgesAndInterior(run.x0, run.x1, w, y == 0 || y == h - 1, edgeCell,
                          [&](int xa, int xb) { fvUpdateRow(c, r, xa, xb, final, sed); });
      if (n2 > 0.0f || !manningN2.empty()) {
        frictionRow(r.oh, r.ohu, r.ohv, run.x0, run.x1, dt * p.gravityMS2, n2,
                    manningN2.empty() ? nullptr : manningN2.row(y), p.dryDepthM);
      }
      if (!final) continue;
      if (p.erosionEnabled) tiltRows(y, run.x0, run.x1);
    }
  });
}

// E5 at an edge cell of fv_update.comp: the sediment exchange through its four faces (limited
// mass fluxes W, E, N, S), counting what leaves through the grid's edge with the water (W20).
float Impl::fvSedimentEdge(int x, int y, const FaceFlux limited[4]) {
  const Water& u = now();
  const float A = rowArea[size_t(y)], dtS = dt, s = u.s.at(x, y);
  const float wN = faceWidthY[size_t(y)], wS = faceWidthY[size_t(y) + 1];
  const float denI = maxOf(u.h.at(x, y) * A, outflowLimited(x, y) * dtS);
  float sNew = s;
  auto exchange = [&](float volOut, int nx, int ny, bool boundary) {
    // volOut > 0: leaves this cell; < 0: enters from the neighbour.
    if (volOut > 0.0f) {
      const float moved = denI > 0.0f ? s * A * volOut / denI : 0.0f;
      sNew -= moved / A;
      if (boundary) {
        kahanAdd(accum[kAccumOutflow].at(x, y), accum[kAccumOutflow + 1].at(x, y), volOut);
        kahanAdd(accum[kAccumSedimentOut].at(x, y), accum[kAccumSedimentOut + 1].at(x, y), moved);
      }
    } else if (volOut < 0.0f && !boundary) {
      const float Aj = rowArea[size_t(ny)];
      const float denJ = maxOf(u.h.at(nx, ny) * Aj, outflowLimited(nx, ny) * dtS);
      if (denJ > 0.0f) sNew += u.s.at(nx, ny) * Aj * (-volOut) / denJ / A;
    }
  };
  exchange(-limited[0].mass * dy * dtS, x - 1, y, x == 0);
  exchange(limited[1].mass * dy * dtS, x + 1, y, x == w - 1);
  exchange(-limited[2].mass * wN * dtS, x, y - 1, y == 0);
  exchange(limited[3].mass * wS * dtS, x, y + 1, y == h - 1);
  return sNew;
}

// ---------------------------------------------------------------------------------------------
// Flood mode, local-inertial scheme (W30-W33)

namespace {

// W30-W31: the discharge per unit width (m^2/s, + towards b) on the face between cells a (west /
// north) and b, `dist` apart, which carried q0 last step while qt crossed it (the mean of the four
// nearest faces across): the local-inertial momentum equation (Bates et al. 2010) with Manning
// friction implicit as the finite-volume scheme's W19,
//   q* = q0 - g hf dt deta / dist,   q = q* / c,   c = (1 + sqrt(1 + 4 a |(q*, qt)|)) / 2,
// a = dt g n^2 / hf^(7/3): backward Euler's q (1 + a |q|) = q*. Bates et al.'s semi-implicit
// 1 + a |q0| iterates towards the same Manning balance but oscillates about it once the friction
// time is below the step (thin sheets: a rain-fed plane held a third of its water at the CFL
// step); on the magnitude, because the normal component alone under-counts the friction of flow at
// an angle to the grid (1 / sqrt 2 of it at 45 degrees: a point-fed flood 1.2 cm low 50 m out).
// hf = max(eta_a, eta_b) - max(b_a, b_b) is the depth of water above the higher bed (W31), 0 when
// that is dry. A surface difference below float32 resolution of the surfaces is 0 (W1a).
inline float inertialFace(float q0, float qt, float ba, float ha, float bb, float hb, float dist, float dtg, float n2,
                          float dry) {
  const float ea = ba + ha, eb = bb + hb;
  const float hf = maxOf(ea, eb) - maxOf(ba, bb);
  float dEta = eb - ea;
  dEta = std::abs(dEta) <= kHeadNoise * maxOf(std::abs(ea), std::abs(eb)) ? 0.0f : dEta;
  const bool wet = hf > dry;
  const float hw = wet ? hf : 1.0f;
  const float qStar = q0 - dtg * hw * dEta / dist;
  const float a = dtg * n2 / (hw * hw * cubeRoot(hw));
  const float c = 0.5f + 0.5f * std::sqrt(1.0f + 4.0f * a * std::sqrt(qStar * qStar + qt * qt));
  return wet ? qStar / c : 0.0f;
}

// W32: the discharge out through an open edge (m^2/s, >= 0, away from the grid) of edge cell e
// whose inner neighbour's surface is etaIn (etaIn = the cell's own without one): a ghost cell
// beyond the edge continues the water surface's slope (free outflow; water does not come in).
inline float inertialEdgeFace(float q0Out, float qt, float be, float he, float etaIn, float dist, float dtg, float n2,
                              float dry) {
  const float eta = be + he;
  const float q = inertialFace(q0Out, qt, be, he, be, he - (etaIn - eta), dist, dtg, n2, dry);
  return maxOf(q, 0.0f);
}

}  // namespace

// A row of faces' inputs: cells a and b on either side (bed, depth, n^2 of a roughness map or
// null), last step's discharge through each face and the two faces across of each of its cells.
struct InertialFaces {
  const float *q0, *ba, *ha, *bb, *hb, *n2a, *n2b;
  const float *ta0, *ta1, *tb0, *tb1;
};

// W30 for a row of faces: out[x] from r's values at x; n^2 of a face the mean of its two cells'
// (a roughness map) or `n2`.
STRATA_ROW_KERNEL void inertialFaceRow(const InertialFaces& r, float* out, int x0, int x1, float dist, float dtg,
                                       float n2, float dry) {
  auto faces = [=](auto kMap) {
#pragma omp simd
    for (int x = x0; x < x1; ++x) {
      float n2f = n2;
      if constexpr (decltype(kMap)::value) n2f = 0.5f * (r.n2a[x] + r.n2b[x]);
      const float qt = 0.25f * ((r.ta0[x] + r.ta1[x]) + (r.tb0[x] + r.tb1[x]));
      out[x] = inertialFace(r.q0[x], qt, r.ba[x], r.ha[x], r.bb[x], r.hb[x], dist, dtg, n2f, dry);
    }
  };
  r.n2a ? faces(std::true_type{}) : faces(std::false_type{});
}

// W30 and W32 on every face of the active runs, into faceX.mass / faceY.mass (unlimited; W25's
// limits follow in fvLimitPass). Each cell owns its east and south faces, and the west face in
// column 0 and the north face in row 0, as in fvFacePass; a face owned by an inactive cell is
// zero and stays so. Reads last step's applied discharges from flux[0..3].
void Impl::inertialFacePass(const BlockSet& set) {
  forRuns(set, [&](const Run& r, int) {
    const float dtg = dt * p.gravityMS2, dry = p.dryDepthM, n2u = p.manningN * p.manningN;
    const Water& u = now();
    auto n2At = [&](int x, int y) { return manningN2.empty() ? n2u : manningN2.at(x, y); };
    auto etaAt = [&](int x, int y) { return bed.at(x, y) + u.h.at(x, y); };
    // The discharge across an edge cell's face to the edge: the mean of its two faces across.
    auto acrossX = [&](int x, int y) { return 0.5f * (flux[2].at(x, y) + flux[3].at(x, y)); };
    auto acrossY = [&](int x, int y) { return 0.5f * (flux[0].at(x, y) + flux[1].at(x, y)); };
    for (int y = r.y0; y < r.y1; ++y) {
      const float* hh = u.h.row(y);
      const float* b = bed.row(y);
      const float* n2 = manningN2.empty() ? nullptr : manningN2.row(y);
      const float dx = rowDx[size_t(y)];
      float* fx = faceX.mass.row(y);
      // East faces of the interior (x + 1 < w): face x + 1 between cells x and x + 1.
      const int xe = std::min(r.x1, w - 1);
      const float *qN = flux[2].row(y), *qS = flux[3].row(y);
      inertialFaceRow({flux[1].row(y), b, hh, b + 1, hh + 1, n2, n2 ? n2 + 1 : nullptr, qN, qS, qN + 1, qS + 1}, fx + 1,
                      r.x0, xe, dx, dtg, n2u, dry);
      if (r.x1 == w) {  // the east edge
        const float etaIn = w > 1 ? etaAt(w - 2, y) : etaAt(w - 1, y);
        fx[w] = (p.openEdges & kEdgeEast) ? inertialEdgeFace(flux[1].at(w - 1, y), acrossX(w - 1, y), b[w - 1],
                                                             hh[w - 1], etaIn, dx, dtg, n2At(w - 1, y), dry)
                                          : 0.0f;
      }
      // The west edge: positive discharge is eastwards, into the grid (0 - q keeps a zero +0, so
      // a dry edge block stays quiet).
      if (r.x0 == 0) {
        const float etaIn = w > 1 ? etaAt(1, y) : etaAt(0, y);
        fx[0] = (p.openEdges & kEdgeWest) ? 0.0f - inertialEdgeFace(0.0f - flux[0].at(0, y), acrossX(0, y), b[0], hh[0],
                                                                    etaIn, dx, dtg, n2At(0, y), dry)
                                          : 0.0f;
      }
      // South faces: face row y + 1 between rows y and y + 1.
      if (y + 1 < h) {
        const float* n2s = manningN2.empty() ? nullptr : manningN2.row(y + 1);
        inertialFaceRow({flux[3].row(y), b, hh, bed.row(y + 1), u.h.row(y + 1), n2, n2s, flux[0].row(y), flux[1].row(y),
                         flux[0].row(y + 1), flux[1].row(y + 1)},
                        faceY.mass.row(y + 1), r.x0, r.x1, dy, dtg, n2u, dry);
      } else {
        float* fs = faceY.mass.row(h);
        for (int x = r.x0; x < r.x1; ++x) {
          const float etaIn = h > 1 ? etaAt(x, h - 2) : etaAt(x, h - 1);
          fs[x] = (p.openEdges & kEdgeSouth)
                      ? inertialEdgeFace(flux[3].at(x, y), acrossY(x, y), b[x], hh[x], etaIn, dy, dtg, n2At(x, y), dry)
                      : 0.0f;
        }
      }
      if (y == 0) {
        float* fn = faceY.mass.row(0);
        for (int x = r.x0; x < r.x1; ++x) {
          const float etaIn = h > 1 ? etaAt(x, 1) : etaAt(x, 0);
          fn[x] = (p.openEdges & kEdgeNorth) ? 0.0f - inertialEdgeFace(0.0f - flux[2].at(x, 0), acrossY(x, 0), b[x],
                                                                       hh[x], etaIn, dy, dtg, n2At(x, 0), dry)
                                             : 0.0f;
        }
      }
    }
  });
}

// W30 on the interior face between cell (x, y) and its east (alongX) or south neighbour, from the
// discharge q0 it carried last: what inertialFacePass computes there (W37 recomputes the faces
// between blocks of two levels with the finer cell's q0).
float Impl::inertialFaceAt(int x, int y, bool alongX, float q0) const {
  const int xb = alongX ? x + 1 : x, yb = alongX ? y : y + 1;
  return inertialFaceAt(x, y, alongX, q0, now().h.at(x, y), now().h.at(xb, yb));
}

// The same with depths ha and hb for the two cells (W37: a coarser cell's midway through its step).
float Impl::inertialFaceAt(int x, int y, bool alongX, float q0, float ha, float hb) const {
  const int xb = alongX ? x + 1 : x, yb = alongX ? y : y + 1;
  const float n2u = p.manningN * p.manningN;
  const float n2 = manningN2.empty() ? n2u : 0.5f * (manningN2.at(x, y) + manningN2.at(xb, yb));
  // The faces across: north and south of both cells for an x face, west and east for a y face.
  const int t0 = alongX ? 2 : 0, t1 = alongX ? 3 : 1;
  const float qt = 0.25f * ((flux[t0].at(x, y) + flux[t1].at(x, y)) + (flux[t0].at(xb, yb) + flux[t1].at(xb, yb)));
  return inertialFace(q0, qt, bed.at(x, y), ha, bed.at(xb, yb), hb, alongX ? rowDx[size_t(y)] : dy, dt * p.gravityMS2,
                      n2, p.dryDepthM);
}

// One row of the local-inertial update's inputs and outputs.
struct InertialRow {
  float A, wN, wS, dy, dt;
  const float *fx, *fn, *fs;       // faces: x faces of the row, y faces above and below
  const float *lim, *limN, *limS;  // W25 limits of rows y, y - 1, y + 1 (row y at an edge)
  const float* h;
  float *oh, *ohu, *ohv, *qW, *qE, *qN, *qS;
  float* herr;  // the depth's error (W34)
};

namespace {

// The update of cell x (kEdge: neighbours may be outside the grid, whose limits are 1): each face's
// discharge scaled by its upwind cell's W25 limit, the depth from their net inflow (W18), the
// applied discharges kept as the next step's q0 and the cell's discharge as the mean of its two
// faces' on each axis. Returns the volume leaving through the grid's edge (m^3).
template <bool kEdge>
inline float inertialUpdateCell(const InertialRow& r, int x, bool inW, bool inE, bool inN, bool inS) {
  float fW = r.fx[x], fE = r.fx[x + 1], fN = r.fn[x], fS = r.fs[x];
  const float kc = r.lim[x];
  const float kw = !kEdge || inW ? r.lim[x - 1] : 1.0f, ke = !kEdge || inE ? r.lim[x + 1] : 1.0f;
  const float kn = !kEdge || inN ? r.limN[x] : 1.0f, ks = !kEdge || inS ? r.limS[x] : 1.0f;
  fW *= fW > 0.0f ? kw : kc;
  fE *= fE > 0.0f ? kc : ke;
  fN *= fN > 0.0f ? kn : kc;
  fS *= fS > 0.0f ? kc : ks;
  float hNew = r.h[x], e = r.herr[x];
  addDepthFaces(hNew, e, r.dt / r.A, fW * r.dy, fE * r.dy, fN * r.wN, fS * r.wS);  // W34
  r.oh[x] = hNew;
  r.herr[x] = e;
  r.ohu[x] = 0.5f * (fW + fE);
  r.ohv[x] = 0.5f * (fN + fS);
  r.qW[x] = fW, r.qE[x] = fE, r.qN[x] = fN, r.qS[x] = fS;
  if constexpr (!kEdge) return 0.0f;
  return ((inW ? 0.0f : maxOf(-fW, 0.0f)) + (inE ? 0.0f : maxOf(fE, 0.0f))) * r.dy * r.dt +
         (inN ? 0.0f : maxOf(-fN, 0.0f)) * r.wN * r.dt + (inS ? 0.0f : maxOf(fS, 0.0f)) * r.wS * r.dt;
}

}  // namespace

STRATA_ROW_KERNEL void inertialUpdateRow(const InertialRow& r, int x0, int x1) {
#pragma omp simd
  for (int x = x0; x < x1; ++x) inertialUpdateCell<false>(r, x, true, true, true, true);
}

// The local-inertial update (W18 with W30's faces, W25 final): the depths into next() (into now()
// with local steps, W37: the faces and limits were taken before, and a cell reads only its own
// depth), the applied face discharges into flux[0..3], the water leaving through open edges into
// the outflow sums.
void Impl::inertialUpdatePass(const BlockSet& set) {
  forRuns(set, [&](const Run& run, int) {
    for (int y = run.y0; y < run.y1; ++y) {
      const int yn = std::max(y - 1, 0), ys = std::min(y + 1, h - 1);
      const Water& u = now();
      Water& o = inPlace ? now() : next();
      const InertialRow r{rowArea[size_t(y)],
                          faceWidthY[size_t(y)],
                          faceWidthY[size_t(y) + 1],
                          dy,
                          dt,
                          faceX.mass.row(y),
                          faceY.mass.row(y),
                          faceY.mass.row(y + 1),
                          limit.row(y),
                          limit.row(yn),
                          limit.row(ys),
                          u.h.row(y),
                          o.h.row(y),
                          o.hu.row(y),
                          o.hv.row(y),
                          flux[0].row(y),
                          flux[1].row(y),
                          flux[2].row(y),
                          flux[3].row(y),
                          accum[kAccumDepthError].row(y)};
      if (!inPlace) std::copy(u.s.row(y) + run.x0, u.s.row(y) + run.x1, o.s.row(y) + run.x0);
      auto edgeCell = [&](int x) {
        const float out = inertialUpdateCell<true>(r, x, x > 0, x<w - 1, y> 0, y < h - 1);
        if (out > 0.0f) kahanAdd(accum[kAccumOutflow].at(x, y), accum[kAccumOutflow + 1].at(x, y), out);
      };
      forEdgesAndInterior(run.x0, run.x1, w, y == 0 || y == h - 1, edgeCell,
                          [&](int xa, int xb) { inertialUpdateRow(r, xa, xb); });
    }
  });
}

// ---------------------------------------------------------------------------------------------
// Levels, flood statistics, wave speed

// sim/shaders/level_boundary.comp: W26, the fixed levels at the end of the step (after the
// water update, before erosion, so every output shows them held): depth max(0, stage - bed),
// the discharge scaled with the depth (the velocity kept), the volume put in (< 0: taken out)
// summed per cell with compensation (slot 6).
void Impl::levelPass(std::span<const LevelEntry> entries) {
  Water& u = now();
  for (const auto& e : entries) {
    const int y = int(e.cell / uint32_t(w)), x = int(e.cell % uint32_t(w));
    const float h0 = u.h.at(x, y), h1 = maxOf(0.0f, e.stageM - bed.at(x, y));
    const float keep = h0 > p.dryDepthM ? h1 / h0 : 0.0f;
    float& err = accum[kAccumDepthError].at(x, y);  // the cell held h0 + err (W34); it holds h1
    u.h.at(x, y) = h1;
    u.hu.at(x, y) *= keep;
    u.hv.at(x, y) *= keep;
    kahanAdd(accum[kAccumLevel].at(x, y), accum[kAccumLevel + 1].at(x, y), ((h1 - h0) - err) * rowArea[size_t(y)]);
    err = 0.0f;
  }
}

STRATA_ROW_KERNEL void floodStatsRow(const float* h, const float* hu, const float* hv, float* maxDepth, float* maxSpeed,
                                     float* arrival, float* wetTime, int x0, int x1, float wet, float dry, float dtS,
                                     float endTimeS) {
#pragma omp simd
  for (int x = x0; x < x1; ++x) {
    const float hx = h[x];
    const float u = velocityOf(hx, hu[x], dry), v = velocityOf(hx, hv[x], dry);
    maxDepth[x] = maxOf(maxDepth[x], hx);
    maxSpeed[x] = maxOf(maxSpeed[x], std::sqrt(u * u + v * v));
    const bool isWet = hx > wet;
    const float a = arrival[x], t = wetTime[x];
    arrival[x] = (isWet & (a < 0.0f)) ? endTimeS : a;
    wetTime[x] = isWet ? t + dtS : t;
  }
}

// sim/shaders/flood_stats.comp: per cell the deepest water and fastest flow, the end of the
// first step with depth above the wet threshold, and the time spent above it.
void Impl::floodStatsPass(const BlockSet& set, float endTimeS) {
  forRuns(set, [&](const Run& r, int) {
    for (int y = r.y0; y < r.y1; ++y) {
      floodStatsRow(now().h.row(y), now().hu.row(y), now().hv.row(y), flood[0].row(y), flood[1].row(y), flood[2].row(y),
                    flood[3].row(y), r.x0, r.x1, wetThresholdM, p.dryDepthM, dt, endTimeS);
    }
  });
}

// max over [x0, x1) of a row of |u| + sqrt(g h).
// Without advection (`gravityOnly`: the local-inertial scheme, W33) max sqrt(g h).
STRATA_ROW_KERNEL float waveSpeedRow(const float* h, const float* hu, const float* hv, int x0, int x1, float g,
                                     float dry, bool gravityOnly) {
  float m = 0.0f;
  if (gravityOnly) {
#pragma omp simd reduction(max : m)
    for (int x = x0; x < x1; ++x) m = maxOf(m, h[x]);
    return std::sqrt(g * m);
  }
#pragma omp simd reduction(max : m)
  for (int x = x0; x < x1; ++x) {
    const float hx = h[x];
    const float u = velocityOf(hx, hu[x], dry), v = velocityOf(hx, hv[x], dry);
    m = maxOf(m, std::sqrt(u * u + v * v) + std::sqrt(g * hx));
  }
  return m;
}

// sim/shaders/wave_speed.comp: max over cells of |u| + sqrt(g h) (W10; sqrt(g h) with the
// local-inertial scheme, W33), over the blocks that
// are not quiet (a quiet cell's is 0). A max is exact, so the order of the reduction is free.
float Impl::maxWaveSpeed() const {
  float m = 0.0f;
  const int blocks = bw * bh;
  size_t wetBlocks = 0;
  for (int b = 0; b < blocks; ++b) wetBlocks += !(skip && quiet(size_t(b)));
  const bool parallel = passThreads > 1 && wetBlocks * kBlock * kBlock >= kMinParallelCells;
#pragma omp parallel for schedule(dynamic, 8) num_threads(passThreads) if (parallel) reduction(max : m)
  for (int b = 0; b < blocks; ++b) {
    if (skip && quiet(size_t(b))) continue;
    const int bx = b % bw, by = b / bw;
    const int x0 = bx * kBlock, x1 = std::min(x0 + kBlock, w), y0 = by * kBlock, y1 = std::min(y0 + kBlock, h);
    for (int y = y0; y < y1; ++y) {
      m = maxOf(m, waveSpeedRow(now().h.row(y), now().hu.row(y), now().hv.row(y), x0, x1, p.gravityMS2, p.dryDepthM,
                                inertial()));
    }
  }
  return m;
}

}  // namespace strata::sim::cpu
