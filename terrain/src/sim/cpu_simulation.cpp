// The CPU reference: each pass is a loop over cells whose body is the matching compute shader
// under shaders/sim/ written in C++ (same float32 arithmetic, same order), with the same
// ping-pong: a pass reads neighbours only from buffers no thread of that pass writes.
#include <strata/terrain/sim/cpu_simulation.hpp>

#include <algorithm>
#include <array>
#include <cmath>
#include <numeric>
#include <string>

namespace strata::terrain::sim {
namespace {

constexpr int kDx[4] = {-1, 1, 0, 0};  // W, E, N, S
constexpr int kDy[4] = {0, 0, -1, 1};
constexpr int kDiagDx[4] = {-1, 1, -1, 1};  // NW, NE, SW, SE; the opposite of k is 3 - k
constexpr int kDiagDy[4] = {-1, -1, 1, 1};
constexpr float kMmPerHourToMS = 1.0f / 3.6e6f;
// W1a: a head difference below 4 float32 ulps of the operands is rounding, not a gradient.
constexpr float kHeadNoise = 4.0f * 1.1920929e-7f;
// W24: a net momentum rate below 16 float32 ulps of the sum of its terms is rounding.
constexpr float kForceNoise = 16.0f * 1.1920929e-7f;

struct Face {
  float h = 0, nL = 0, nR = 0, t = 0;  // mass flux, normal momentum flux for left / right cell, tangential
};

// W13-W16: HLL flux of the hydrostatically reconstructed states (Audusse et al. 2004) between a
// left/top cell L and a right/bottom cell R; un normal, ut tangential velocity; b bed (datum-relative).
Face hllFace(float hL, float unL, float utL, float bL, float hR, float unR, float utR, float bR, float g, float dry) {
  const float dbLR = bR - bL;
  const float hLs = std::max(0.0f, hL - std::max(0.0f, dbLR));  // W13
  const float hRs = std::max(0.0f, hR - std::max(0.0f, -dbLR));
  Face f;
  float fn = 0.0f;
  if (hLs > dry || hRs > dry) {
    const float cL = std::sqrt(g * hLs), cR = std::sqrt(g * hRs);
    float sL, sR;  // W15: wave speeds, Toro's dry-bed variants
    if (hLs <= dry) {
      sL = unR - 2.0f * cR;
      sR = unR + cR;
    } else if (hRs <= dry) {
      sL = unL - cL;
      sR = unL + 2.0f * cL;
    } else {
      sL = std::min(unL - cL, unR - cR);
      sR = std::max(unL + cL, unR + cR);
    }
    const float qL = hLs * unL, qR = hRs * unR;
    const float fLn = qL * unL + 0.5f * g * hLs * hLs, fRn = qR * unR + 0.5f * g * hRs * hRs;
    if (sL >= 0.0f) {
      f.h = qL;
      fn = fLn;
    } else if (sR <= 0.0f) {
      f.h = qR;
      fn = fRn;
    } else {  // W14
      const float inv = 1.0f / (sR - sL);
      f.h = (sR * qL - sL * qR + sL * sR * (hRs - hLs)) * inv;
      fn = (sR * fLn - sL * fRn + sL * sR * (qR - qL)) * inv;
    }
    f.t = f.h > 0.0f ? f.h * utL : f.h * utR;
  }
  f.nL = fn + 0.5f * g * (hL * hL - hLs * hLs);  // W16: hydrostatic correction
  f.nR = fn + 0.5f * g * (hR * hR - hRs * hRs);
  return f;
}

float velocityOf(float h, float q, float dry) { return h > dry ? q / h : 0.0f; }

// W20: compensated (Kahan) sum into acc[0] with the running error in acc[1], so per-cell float
// accumulators of outflow and evaporation stay exact to ~1e-7 over millions of steps.
void kahanAdd(float* acc, float v) {
  const float y = v - acc[1];
  const float t = acc[0] + y;
  acc[1] = (t - acc[0]) - y;
  acc[0] = t;
}

// W21 slopes from the backward and forward differences a, b (0 at an extremum): minmod, the
// smaller one; van Leer's monotonised central (MC), sign * min(2|a|, 2|b|, |a + b| / 2).
float minmod(float a, float b) { return a * b <= 0.0f ? 0.0f : (std::abs(a) < std::abs(b) ? a : b); }
float mcSlope(float a, float b) {
  return a * b <= 0.0f
             ? 0.0f
             : std::copysign(std::min(std::min(2.0f * std::abs(a), 2.0f * std::abs(b)), 0.5f * std::abs(a + b)), a);
}

}  // namespace

Result<CpuSimulation> CpuSimulation::create(const SimInput& input, const SimParams& params) {
  STRATA_TRY_STATUS(validate(input, params));
  CpuSimulation s;
  s.p_ = params;
  const int w = input.baseM.width, h = input.baseM.height, L = int(input.layersM.size());
  s.p_.width = w;
  s.p_.height = h;
  s.p_.layerCount = L;
  s.p_.dyM = float(input.dyM);
  s.datumM_ = input.datumM;
  const size_t n = size_t(w) * size_t(h);
  for (const auto& m : input.materials) s.materials_.push_back(toSimMaterial(m));
  for (int y = 0; y < h; ++y) {
    s.rowDxD_.push_back(rowDx(input, y));
    s.rowDx_.push_back(float(s.rowDxD_.back()));
  }
  s.base_.resize(n);
  for (size_t i = 0; i < n; ++i) s.base_[i] = float(double(input.baseM.data[i]) - input.datumM);
  s.layers_.resize(n * size_t(L));
  for (int l = 0; l < L; ++l)
    std::copy(input.layersM[size_t(l)].data.begin(), input.layersM[size_t(l)].data.end(),
              s.layers_.begin() + ptrdiff_t(size_t(l) * n));
  s.bed_.resize(n);
  for (size_t i = 0; i < n; ++i) s.recomputeBed(i);
  s.state_.assign(4 * n, 0.0f);
  if (input.waterDepthM.size() > 0) {
    for (size_t i = 0; i < n; ++i) s.state_[4 * i] = input.waterDepthM.data[i];
  }
  s.stateNext_ = s.state_;
  s.stage_ = s.state_;
  s.flux_.assign(4 * n, 0.0f);
  s.limit_.assign(n, 1.0f);
  s.fluxDiag_.assign(4 * n, 0.0f);
  s.faceX_.assign(4 * size_t(w + 1) * size_t(h), 0.0f);
  s.faceY_.assign(4 * size_t(w) * size_t(h + 1), 0.0f);
  s.tilt_.assign(n, 0.0f);
  s.accum_.assign(8 * n, 0.0f);
  s.thermal_.assign(4 * n, 0.0f);
  s.rain_ = input.rainMmPerHour.size() > 0 ? input.rainMmPerHour.data : std::vector<float>(n, 0.0f);
  s.rainRateM3S_ = rainVolumeRate(s.p_, s.rain_, s.rowDxD_, w);
  s.maxRainMmH_ = double(*std::max_element(s.rain_.begin(), s.rain_.end()));
  s.minCell_ = minCellSize(s.rowDxD_, input.dyM);
  const auto st = s.stats();
  s.initialWater_ = st.storedWaterM3;
  s.initialMaterial_ = st.materialM3;
  return s;
}

Status CpuSimulation::addLevel(const LevelBoundary& level) {
  STRATA_TRY_STATUS(checkLevel(level, p_.width, p_.height));
  levels_.push_back(level);
  return {};
}

Status CpuSimulation::addSource(const Source& source) {
  for (auto [x, y] : source.cells) {
    if (x < 0 || y < 0 || x >= p_.width || y >= p_.height) {
      return fail("sim source: cell (" + std::to_string(x) + ", " + std::to_string(y) + ") is outside the " +
                  std::to_string(p_.width) + "x" + std::to_string(p_.height) + " grid");
    }
  }
  for (size_t i = 1; i < source.hydrographM3S.size(); ++i) {
    if (!(source.hydrographM3S[i].first > source.hydrographM3S[i - 1].first)) {
      return fail("sim source: hydrograph times must increase (sample " + std::to_string(i) + ")");
    }
  }
  sources_.push_back(source);
  return {};
}

// E0: sin of the bed tilt from central differences (one-sided at the edges).
float CpuSimulation::sinTilt(int x, int y) const {
  const int w = p_.width, hgt = p_.height;
  const int xl = std::max(x - 1, 0), xr = std::min(x + 1, w - 1), yu = std::max(y - 1, 0),
            yd = std::min(y + 1, hgt - 1);
  const float gx = (bed_[idx(xr, y)] - bed_[idx(xl, y)]) / (float(xr - xl) * dx(y));
  const float gy = (bed_[idx(x, yd)] - bed_[idx(x, yu)]) / (float(yd - yu) * p_.dyM);
  const float g2 = gx * gx + gy * gy;
  return std::sqrt(g2 / (1.0f + g2));
}

Status CpuSimulation::setParams(const SimParams& params) {
  const SimParams next = runtimeParams(p_, params);
  STRATA_TRY_STATUS(validateParams(next));
  p_ = next;
  rainRateM3S_ = rainVolumeRate(p_, rain_, rowDxD_, p_.width);
  return {};
}

float CpuSimulation::faceWidthY(int yFace) const {
  if (yFace <= 0) return dx(0);
  if (yFace >= p_.height) return dx(p_.height - 1);
  return 0.5f * (dx(yFace - 1) + dx(yFace));
}

int CpuSimulation::topLayer(size_t i) const {
  const size_t n = size_t(p_.width) * size_t(p_.height);
  for (int l = p_.layerCount - 1; l >= 0; --l) {
    if (layers_[size_t(l) * n + i] > 0.0f) return l;
  }
  return -1;
}

float CpuSimulation::recomputeBed(size_t i) {
  const size_t n = size_t(p_.width) * size_t(p_.height);
  float b = base_[i];
  for (int l = 0; l < p_.layerCount; ++l) b += layers_[size_t(l) * n + i];
  bed_[i] = b;
  return b;
}

double CpuSimulation::maxWaveSpeed() const {
  // shaders/sim/wave_speed.comp: max over cells of |u| + sqrt(g h) (W10).
  float m = 0.0f;
  const size_t n = size_t(p_.width) * size_t(p_.height);
  for (size_t i = 0; i < n; ++i) {
    const float h = state_[4 * i];
    const float u = velocityOf(h, state_[4 * i + 2], p_.dryDepthM), v = velocityOf(h, state_[4 * i + 3], p_.dryDepthM);
    m = std::max(m, std::sqrt(u * u + v * v) + std::sqrt(p_.gravityMS2 * h));
  }
  return double(m);
}

double CpuSimulation::nextDt() const {
  return stepDtWithSources(p_, maxWaveSpeed(), minCell_, maxRainMmH_, sources_, rowDxD_, double(p_.dyM), timeS_);
}

void CpuSimulation::step(int n) {
  for (int k = 0; k < n; ++k) takeStep(nextDt());
}

void CpuSimulation::advance(double seconds) {
  const double end = timeS_ + seconds;
  while (timeS_ < end - 1e-9 * std::max(1.0, end)) takeStep(std::min(nextDt(), end - timeS_));
}

void CpuSimulation::takeStep(double dtS) {
  p_.dtS = float(dtS);
  entries_ = mergeSources(sources_, p_.width, timeS_, timeS_ + double(float(dtS)));
  for (const auto& e : entries_) inflowM3_ += double(e.rateM3S) * double(p_.dtS);
  rainM3_ += rainRateM3S_ * double(p_.dtS);
  sourcesPass();
  if (p_.waterModel == int32_t(WaterModel::kVirtualPipes)) {
    pipeFluxPass();
    pipeUpdatePass();
  } else {
    fvFacePass(state_, false);
    fvUpdatePass(false);
    fvFacePass(stage_, true);
    fvLimitPass();
    fvUpdatePass(true);
  }
  std::swap(state_, stateNext_);
  if (!levels_.empty()) levelPass();
  if (p_.erosionEnabled) erosionPass();
  if (p_.thermalEnabled) {
    thermalFluxPass();
    thermalApplyPass();
  }
  timeS_ += double(p_.dtS);
  lastDt_ = double(p_.dtS);
  ++steps_;
}

// shaders/sim/sources.comp: rain (W11), evaporation (W11), then sources.comp's point entries (W12).
void CpuSimulation::sourcesPass() {
  const float dt = p_.dtS;
  for (int y = 0; y < p_.height; ++y) {
    for (int x = 0; x < p_.width; ++x) {
      const size_t i = idx(x, y);
      float h = state_[4 * i];
      h += (rain_[i] + p_.rainMmPerHour) * kMmPerHourToMS * dt;
      const float e = std::min(h, p_.evaporationMmPerHour * kMmPerHourToMS * dt);
      h -= e;
      kahanAdd(&accum_[8 * i + 2], e * area(y));
      state_[4 * i] = h;
    }
  }
  for (const auto& e : entries_) {
    const int y = int(e.cell / uint32_t(p_.width));
    state_[4 * e.cell] += e.rateM3S * dt / area(y);
  }
}

// shaders/sim/level_boundary.comp: W26, the fixed levels at the end of the step (after the
// water update, before erosion, so every output shows them held): depth
// max(0, stage - bed), the discharge scaled with the depth (the velocity kept), the volume put in
// (< 0: taken out) summed per cell with compensation (slot 6).
void CpuSimulation::levelPass() {
  for (const auto& e : levelEntries(levels_, p_.width, timeS_ + double(p_.dtS), datumM_)) {
    const size_t i = e.cell;
    const int y = int(e.cell / uint32_t(p_.width));
    const float h0 = state_[4 * i], h1 = std::max(0.0f, e.stageM - bed_[i]);
    const float keep = h0 > p_.dryDepthM ? h1 / h0 : 0.0f;
    state_[4 * i] = h1;
    state_[4 * i + 2] *= keep;
    state_[4 * i + 3] *= keep;
    kahanAdd(&accum_[8 * i + 6], (h1 - h0) * area(y));
  }
}

// shaders/sim/pipe_flux.comp: W1 (flux from head difference), W2 (scaling K).
void CpuSimulation::pipeFluxPass() {
  const float dt = p_.dtS, g = p_.gravityMS2;
  // W1b: with diagonal pipes the areas follow the isotropic 9-point Laplacian (axis 2/3,
  // diagonal sqrt(2)/6 of pipeAreaM2), which keeps the total conductance of the 4 pipes.
  const float A = p_.diagonalPipes ? p_.pipeAreaM2 * (2.0f / 3.0f) : p_.pipeAreaM2;
  const float Ad = p_.pipeAreaM2 * (1.41421356f / 6.0f);
  for (int y = 0; y < p_.height; ++y) {
    for (int x = 0; x < p_.width; ++x) {
      const size_t i = idx(x, y);
      const float hi = state_[4 * i], bi = bed_[i];
      float f[4];
      float sum = 0.0f;
      for (int d = 0; d < 4; ++d) {
        const int nx = x + kDx[d], ny = y + kDy[d];
        const float len = d < 2 ? dx(y) : p_.dyM;
        float dH;
        if (nx >= 0 && ny >= 0 && nx < p_.width && ny < p_.height) {
          const size_t j = idx(nx, ny);
          const float hj = state_[4 * j], bj = bed_[j];
          dH = (bi - bj) + (hi - hj);
          // W1a: heads equal to float32 resolution are equal (a lake at rest stays at rest).
          const float noise = kHeadNoise * std::max(std::max(std::abs(bi), std::abs(bj)), std::max(hi, hj));
          if (std::abs(dH) <= noise) dH = 0.0f;
        } else if (p_.openEdges & (1u << d)) {
          dH = hi;  // a dry ghost cell at the same bed level: free outflow
        } else {
          f[d] = 0.0f;
          continue;
        }
        f[d] = std::max(0.0f, flux_[4 * i + size_t(d)] + dt * A * g * dH / len);
        sum += f[d];
      }
      // W1b: optional diagonal pipes to the four corner neighbours (closed at the edges).
      float fd[4] = {0, 0, 0, 0};
      if (p_.diagonalPipes) {
        const float len = std::sqrt(dx(y) * dx(y) + p_.dyM * p_.dyM);
        for (int k = 0; k < 4; ++k) {
          const int nx = x + kDiagDx[k], ny = y + kDiagDy[k];
          if (nx < 0 || ny < 0 || nx >= p_.width || ny >= p_.height) continue;
          const size_t j = idx(nx, ny);
          const float hj = state_[4 * j], bj = bed_[j];
          float dH = (bi - bj) + (hi - hj);
          const float noise = kHeadNoise * std::max(std::max(std::abs(bi), std::abs(bj)), std::max(hi, hj));
          if (std::abs(dH) <= noise) dH = 0.0f;
          fd[k] = std::max(0.0f, fluxDiag_[4 * i + size_t(k)] + dt * Ad * g * dH / len);
          sum += fd[k];
        }
      }
      const float K = sum > 0.0f ? std::min(1.0f, hi * area(y) / (sum * dt)) : 0.0f;
      for (int d = 0; d < 4; ++d) flux_[4 * i + size_t(d)] = f[d] * K;
      for (int k = 0; k < 4; ++k) fluxDiag_[4 * i + size_t(k)] = fd[k] * K;
    }
  }
}

// shaders/sim/pipe_update.comp: W3 (depth), W4 (velocity), E5 (sediment transport), E0 (tilt).
void CpuSimulation::pipeUpdatePass() {
  const float dt = p_.dtS, dry = p_.dryDepthM;
  const int w = p_.width, hgt = p_.height;
  auto fluxAt = [&](int x, int y, int d) { return flux_[4 * idx(x, y) + size_t(d)]; };
  const bool diag = p_.diagonalPipes != 0;
  auto outTotal = [&](size_t j) {
    float out = flux_[4 * j] + flux_[4 * j + 1] + flux_[4 * j + 2] + flux_[4 * j + 3];
    if (diag) out += fluxDiag_[4 * j] + fluxDiag_[4 * j + 1] + fluxDiag_[4 * j + 2] + fluxDiag_[4 * j + 3];
    return out;
  };
  // Share of cell (x, y)'s water (and so of its suspended sediment) leaving through pipe d this
  // step: d < 4 axis pipes, d >= 4 diagonal pipes (W1b).
  auto fraction = [&](int x, int y, int d) {
    const size_t j = idx(x, y);
    const float out = outTotal(j) * dt;
    const float den = std::max(state_[4 * j] * area(y), out);
    const float f = d < 4 ? flux_[4 * j + size_t(d)] : fluxDiag_[4 * j + size_t(d - 4)];
    return den > 0.0f ? f * dt / den : 0.0f;
  };
  for (int y = 0; y < hgt; ++y) {
    for (int x = 0; x < w; ++x) {
      const size_t i = idx(x, y);
      const float A = area(y);
      const float h = state_[4 * i], s = state_[4 * i + 1];
      float in = 0.0f, sIn = 0.0f, sOut = 0.0f, inD[4] = {0, 0, 0, 0};
      for (int d = 0; d < 4; ++d) {
        const int nx = x + kDx[d], ny = y + kDy[d];
        const float fr = fraction(x, y, d);
        if (nx >= 0 && ny >= 0 && nx < w && ny < hgt) {
          inD[d] = fluxAt(nx, ny, d ^ 1);
          in += inD[d];
          sIn += state_[4 * idx(nx, ny) + 1] * area(ny) * fraction(nx, ny, d ^ 1);
        } else if (flux_[4 * i + size_t(d)] > 0.0f) {
          kahanAdd(&accum_[8 * i], flux_[4 * i + size_t(d)] * dt);
          kahanAdd(&accum_[8 * i + 4], s * A * fr);
        }
        sOut += fr;
      }
      const float* f = &flux_[4 * i];
      float qxDiag = 0.0f, qyDiag = 0.0f;
      if (diag) {
        const float len = std::sqrt(dx(y) * dx(y) + p_.dyM * p_.dyM);
        for (int k = 0; k < 4; ++k) {
          const int nx = x + kDiagDx[k], ny = y + kDiagDy[k];
          if (nx < 0 || ny < 0 || nx >= w || ny >= hgt) continue;
          const float inK = fluxDiag_[4 * idx(nx, ny) + size_t(3 - k)];
          in += inK;
          sIn += state_[4 * idx(nx, ny) + 1] * area(ny) * fraction(nx, ny, 4 + (3 - k));
          sOut += fraction(x, y, 4 + k);
          // Net flow along the pipe's direction, projected on x and y.
          const float net = fluxDiag_[4 * i + size_t(k)] - inK;
          qxDiag += 0.5f * net * float(kDiagDx[k]) * dx(y) / len;
          qyDiag += 0.5f * net * float(kDiagDy[k]) * p_.dyM / len;
        }
      }
      const float out = outTotal(i);
      const float hNew = std::max(0.0f, h + dt * (in - out) / A);
      const float sNew = s - s * sOut + sIn / A;
      // W4: mean discharge through the cell over its cross-section.
      const float hMean = 0.5f * (h + hNew);
      const float qx = 0.5f * (inD[0] - f[0] + f[1] - inD[1]) + qxDiag;
      const float qy = 0.5f * (inD[2] - f[2] + f[3] - inD[3]) + qyDiag;
      float u = 0.0f, v = 0.0f;
      if (hMean > dry) {
        u = qx / (p_.dyM * hMean);
        v = qy / (dx(y) * hMean);
      }
      float* o = &stateNext_[4 * i];
      o[0] = hNew;
      o[1] = sNew;
      o[2] = u * hNew;
      o[3] = v * hNew;
      tilt_[i] = sinTilt(x, y);
    }
  }
}

// W21: the value of cell (x, y) of stage `st` at its face `dir` (W, E, N, S): MUSCL, minmod or
// MC slopes (SimParams::slopeLimiter) of depth, surface and velocities along the face normal (first order next to an
// edge).
CpuSimulation::Side CpuSimulation::faceSide(const std::vector<float>& st, int x, int y, int dir) const {
  const float dry = p_.dryDepthM;
  auto prim = [&](int cx, int cy) {
    const size_t i = idx(cx, cy);
    const float h = st[4 * i];
    const float u = velocityOf(h, st[4 * i + 2], dry), v = velocityOf(h, st[4 * i + 3], dry);
    return dir < 2 ? Side{h, bed_[i] + h, u, v} : Side{h, bed_[i] + h, v, u};
  };
  Side c = prim(x, y);
  const int ax = dir < 2 ? 1 : 0, ay = dir < 2 ? 0 : 1;
  const int mx = x - ax, my = y - ay, px = x + ax, py = y + ay;
  if (mx < 0 || my < 0 || px >= p_.width || py >= p_.height) return c;
  const Side m = prim(mx, my), p = prim(px, py);
  const float half = (dir == 1 || dir == 3) ? 0.5f : -0.5f;
  const auto slope = p_.slopeLimiter == int32_t(SlopeLimiter::kMonotonizedCentral) ? mcSlope : minmod;
  c.h += half * slope(c.h - m.h, p.h - c.h);
  c.eta += half * slope(c.eta - m.eta, p.eta - c.eta);
  c.un += half * slope(c.un - m.un, p.un - c.un);
  c.ut += half * slope(c.ut - m.ut, p.ut - c.ut);
  return c;
}

// shaders/sim/fv_face.comp: W13-W16 on every face from the reconstructed sides (W21); ghost
// cells at the edges (W17). `average`: the Heun corrector, face = (F(U0) + F(U1)) / 2 (W22).
void CpuSimulation::fvFacePass(const std::vector<float>& st, bool average) {
  const float g = p_.gravityMS2, dry = p_.dryDepthM;
  const int w = p_.width, hgt = p_.height;
  auto store = [average](std::vector<float>& faces, size_t k, const Face& f) {
    float* o = &faces[4 * k];
    const float v[4] = {f.h, f.nL, f.nR, f.t};
    for (int c = 0; c < 4; ++c) o[c] = average ? 0.5f * (o[c] + v[c]) : v[c];
  };
  auto flux = [&](const Side& L, const Side& R) {
    return hllFace(L.h, L.un, L.ut, L.eta - L.h, R.h, R.un, R.ut, R.eta - R.h, g, dry);
  };
  // W17: a wall mirrors the normal velocity; an open edge copies the cell and lets water out only.
  auto edge = [&](const Side& inside, bool ghostOnRight, bool open) {
    Side ghost = inside;
    ghost.un = open ? (ghostOnRight ? std::max(inside.un, 0.0f) : std::min(inside.un, 0.0f)) : -inside.un;
    Face f = ghostOnRight ? flux(inside, ghost) : flux(ghost, inside);
    if (open) f.h = ghostOnRight ? std::max(f.h, 0.0f) : std::min(f.h, 0.0f);
    return f;
  };
  for (int y = 0; y < hgt; ++y) {
    for (int x = 0; x < w; ++x) {
      const Side east = faceSide(st, x, y, 1);
      store(faceX_, size_t(y) * size_t(w + 1) + size_t(x + 1),
            x + 1 < w ? flux(east, faceSide(st, x + 1, y, 0)) : edge(east, true, p_.openEdges & kEdgeEast));
      if (x == 0)
        store(faceX_, size_t(y) * size_t(w + 1), edge(faceSide(st, x, y, 0), false, p_.openEdges & kEdgeWest));
      const Side south = faceSide(st, x, y, 3);
      store(faceY_, size_t(y + 1) * size_t(w) + size_t(x),
            y + 1 < hgt ? flux(south, faceSide(st, x, y + 1, 2)) : edge(south, true, p_.openEdges & kEdgeSouth));
      if (y == 0) store(faceY_, size_t(x), edge(faceSide(st, x, y, 2), false, p_.openEdges & kEdgeNorth));
    }
  }
}

// W25: the share of a face's mass flux its upwind cell can give, that cell's limit K (1 when
// it holds enough water); (xl, yl) is the face's left / top cell, (xr, yr) its right / bottom one.
float CpuSimulation::limitOfFace(float massFlux, int xl, int yl, int xr, int yr) const {
  const int x = massFlux > 0.0f ? xl : xr, y = massFlux > 0.0f ? yl : yr;
  if (x < 0 || y < 0 || x >= p_.width || y >= p_.height) return 1.0f;  // only outflow crosses an edge
  return limit_[idx(x, y)];
}

float CpuSimulation::outflowTotalFv(int x, int y, bool limited) const {
  // Volume rate leaving cell (x, y) through its four faces (m^3/s), with W25's limits or without.
  const int w = p_.width;
  float fW = faceX_[4 * (size_t(y) * size_t(w + 1) + size_t(x))];
  float fE = faceX_[4 * (size_t(y) * size_t(w + 1) + size_t(x + 1))];
  float fN = faceY_[4 * (size_t(y) * size_t(w) + size_t(x))];
  float fS = faceY_[4 * (size_t(y + 1) * size_t(w) + size_t(x))];
  if (limited) {
    fW *= limitOfFace(fW, x - 1, y, x, y);
    fE *= limitOfFace(fE, x, y, x + 1, y);
    fN *= limitOfFace(fN, x, y - 1, x, y);
    fS *= limitOfFace(fS, x, y, x, y + 1);
  }
  return (std::max(-fW, 0.0f) + std::max(fE, 0.0f)) * p_.dyM + std::max(-fN, 0.0f) * faceWidthY(y) +
         std::max(fS, 0.0f) * faceWidthY(y + 1);
}

// shaders/sim/fv_limit.comp, W25: after the corrector's faces, the share K = min(1, h A /
// (outflow dt)) of its outgoing mass fluxes each cell can give without going below zero (as the
// pipe model's W2), so the corrector never has to clip a depth, which would create water.
void CpuSimulation::fvLimitPass() {
  const float dt = p_.dtS;
  for (int y = 0; y < p_.height; ++y) {
    for (int x = 0; x < p_.width; ++x) {
      const size_t i = idx(x, y);
      const float out = outflowTotalFv(x, y, false) * dt, have = state_[4 * i] * area(y);
      limit_[i] = out > have ? have / out : 1.0f;
    }
  }
}

// W23: the centred bed-slope source of the second-order hydrostatic reconstruction, plus the
// pressure on the slanted sides of a cell whose north and south widths differ, as momentum
// rates per unit area times the area (m^4/s^2): (x, y).
std::pair<float, float> CpuSimulation::bedSource(const std::vector<float>& st, int x, int y) const {
  const float g = p_.gravityMS2, wN = faceWidthY(y), wS = faceWidthY(y + 1);
  const Side W = faceSide(st, x, y, 0), E = faceSide(st, x, y, 1), N = faceSide(st, x, y, 2), S = faceSide(st, x, y, 3);
  const float sx = -g * 0.5f * (W.h + E.h) * ((E.eta - W.eta) - (E.h - W.h)) * p_.dyM;
  const float sy = -g * 0.5f * (N.h + S.h) * ((S.eta - N.eta) - (S.h - N.h)) * (0.5f * (wN + wS)) +
                   0.5f * g * (0.5f * (N.h * N.h + S.h * S.h)) * (wS - wN);
  return {sx, sy};
}

// shaders/sim/fv_update.comp: W18 (conservative update with the face fluxes). The predictor
// (final = false) writes U1 = U0 - dt L(U0) into stage_; the corrector (final = true) writes
// U0 - dt (L(U0) + L(U1)) / 2 into stateNext_ (W22), then W19 (Manning friction), E5, E0.
void CpuSimulation::fvUpdatePass(bool final) {
  const float dt = p_.dtS, g = p_.gravityMS2, dry = p_.dryDepthM, n2 = p_.manningN * p_.manningN;
  const int w = p_.width, hgt = p_.height;
  for (int y = 0; y < hgt; ++y) {
    for (int x = 0; x < w; ++x) {
      const size_t i = idx(x, y);
      const float A = area(y), wN = faceWidthY(y), wS = faceWidthY(y + 1), dy = p_.dyM;
      std::array<float, 4> W, E, N, S;
      std::copy_n(&faceX_[4 * (size_t(y) * size_t(w + 1) + size_t(x))], 4, W.begin());
      std::copy_n(&faceX_[4 * (size_t(y) * size_t(w + 1) + size_t(x + 1))], 4, E.begin());
      std::copy_n(&faceY_[4 * (size_t(y) * size_t(w) + size_t(x))], 4, N.begin());
      std::copy_n(&faceY_[4 * (size_t(y + 1) * size_t(w) + size_t(x))], 4, S.begin());
      if (final) {  // W25: the mass (and, with it, the tangential momentum) each upwind cell can give
        const float kW = limitOfFace(W[0], x - 1, y, x, y), kE = limitOfFace(E[0], x, y, x + 1, y);
        const float kN = limitOfFace(N[0], x, y - 1, x, y), kS = limitOfFace(S[0], x, y, x, y + 1);
        W[0] *= kW, W[3] *= kW, E[0] *= kE, E[3] *= kE, N[0] *= kN, N[3] *= kN, S[0] *= kS, S[3] *= kS;
      }
      const float h = state_[4 * i], s = state_[4 * i + 1], hu = state_[4 * i + 2], hv = state_[4 * i + 3];
      auto [sx, sy] = bedSource(state_, x, y);
      if (final) {
        const auto [sx1, sy1] = bedSource(stage_, x, y);
        sx = 0.5f * (sx + sx1);
        sy = 0.5f * (sy + sy1);
      }
      const float k = dt / A;
      float hNew = h - k * ((E[0] - W[0]) * dy + S[0] * wS - N[0] * wN);
      // W24: a net force below float32 resolution of the forces it sums is rounding, not a
      // pressure gradient (the momentum analogue of W1a): a lake at rest stays at rest.
      float fx = sx - ((E[1] - W[2]) * dy + S[3] * wS - N[3] * wN);
      float fy = sy - (S[1] * wS - N[2] * wN + (E[3] - W[3]) * dy);
      const float magX =
          std::abs(E[1] * dy) + std::abs(W[2] * dy) + std::abs(S[3] * wS) + std::abs(N[3] * wN) + std::abs(sx);
      const float magY =
          std::abs(S[1] * wS) + std::abs(N[2] * wN) + std::abs(E[3] * dy) + std::abs(W[3] * dy) + std::abs(sy);
      if (std::abs(fx) <= kForceNoise * magX) fx = 0.0f;
      if (std::abs(fy) <= kForceNoise * magY) fy = 0.0f;
      float huNew = hu + k * fx;
      float hvNew = hv + k * fy;
      hNew = std::max(hNew, 0.0f);
      if (hNew <= dry) {
        huNew = 0.0f;
        hvNew = 0.0f;
      }
      if (!final) {
        float* o = &stage_[4 * i];
        o[0] = hNew;
        o[1] = s;
        o[2] = huNew;
        o[3] = hvNew;
        continue;
      }
      if (hNew > dry && n2 > 0.0f) {  // W19: semi-implicit Manning friction
        const float speed = std::sqrt(huNew * huNew + hvNew * hvNew) / hNew;
        const float c = 1.0f + dt * g * n2 * speed / std::pow(hNew, 4.0f / 3.0f);
        huNew /= c;
        hvNew /= c;
      }
      // E5: suspended sediment moves with the water volume crossing each face, upwind.
      const float denI = std::max(h * A, outflowTotalFv(x, y, true) * dt);
      float sNew = s;
      auto exchange = [&](float volOut, int nx, int ny, bool boundary) {
        // volOut > 0: leaves this cell; < 0: enters from the neighbour.
        if (volOut > 0.0f) {
          const float moved = denI > 0.0f ? s * A * volOut / denI : 0.0f;
          sNew -= moved / A;
          if (boundary) {
            kahanAdd(&accum_[8 * i], volOut);
            kahanAdd(&accum_[8 * i + 4], moved);
          }
        } else if (volOut < 0.0f && !boundary) {
          const size_t j = idx(nx, ny);
          const float Aj = area(ny);
          const float denJ = std::max(state_[4 * j] * Aj, outflowTotalFv(nx, ny, true) * dt);
          if (denJ > 0.0f) sNew += state_[4 * j + 1] * Aj * (-volOut) / denJ / A;
        }
      };
      exchange(-W[0] * dy * dt, x - 1, y, x == 0);
      exchange(E[0] * dy * dt, x + 1, y, x == w - 1);
      exchange(-N[0] * wN * dt, x, y - 1, y == 0);
      exchange(S[0] * wS * dt, x, y + 1, y == hgt - 1);
      float* o = &stateNext_[4 * i];
      o[0] = hNew;
      o[1] = sNew;
      o[2] = huNew;
      o[3] = hvNew;
      tilt_[i] = sinTilt(x, y);
    }
  }
}

// shaders/sim/erode.comp: E1-E4 (capacity, erosion, deposition, dissolution); E6 (settling when dry).
void CpuSimulation::erosionPass() {
  const float dt = p_.dtS, dry = p_.dryDepthM;
  const size_t n = size_t(p_.width) * size_t(p_.height);
  const int sedimentLayer = p_.layerCount - 1;
  for (size_t i = 0; i < n; ++i) {
    float* st = &state_[4 * i];
    const float h = st[0];
    float s = st[1];
    if (h > dry) {
      const float speed = std::sqrt(st[2] * st[2] + st[3] * st[3]) / h;
      const float depthFactor = std::clamp(1.0f - h / p_.deepWaterM, 0.0f, 1.0f);
      const float capacity = p_.capacityK * std::max(tilt_[i], p_.minSinTilt) * speed * depthFactor;  // E1
      int top = topLayer(i);
      if (s < capacity) {
        if (top >= 0) {  // E2
          float& layer = layers_[size_t(top) * n + i];
          const float amount = std::min({p_.erosionRate * (capacity - s) * dt * materials_[size_t(top)].erodibility,
                                         p_.maxErosionPerStepM, layer});
          layer -= amount;
          s += amount;
        }
      } else {  // E3
        const float amount = std::min(p_.depositionRate * (s - capacity) * dt, s);
        s -= amount;
        layers_[size_t(sedimentLayer) * n + i] += amount;
      }
      top = topLayer(i);
      if (speed < p_.slowWaterMS && top >= 0) {  // E4
        float& layer = layers_[size_t(top) * n + i];
        const float amount = std::min({materials_[size_t(top)].dissolutionRate * h * dt, p_.maxErosionPerStepM, layer});
        layer -= amount;
        s += amount;
      }
    } else {  // E6: water gone, its load settles
      layers_[size_t(sedimentLayer) * n + i] += s;
      s = 0.0f;
    }
    st[1] = s;
    recomputeBed(i);
  }
}

// shaders/sim/thermal_flux.comp: E7 (talus transfer), E8 (wet banks slip at a lower angle).
void CpuSimulation::thermalFluxPass() {
  const float dry = p_.dryDepthM;
  const size_t n = size_t(p_.width) * size_t(p_.height);
  for (int y = 0; y < p_.height; ++y) {
    for (int x = 0; x < p_.width; ++x) {
      const size_t i = idx(x, y);
      float* out = &thermal_[4 * i];
      out[0] = out[1] = out[2] = out[3] = 0.0f;
      const int top = topLayer(i);
      if (top < 0) continue;
      bool wet = state_[4 * i] > dry;
      float excess[4] = {0, 0, 0, 0};
      for (int d = 0; d < 4; ++d) {
        const int nx = x + kDx[d], ny = y + kDy[d];
        if (nx >= 0 && ny >= 0 && nx < p_.width && ny < p_.height) wet = wet || state_[4 * idx(nx, ny)] > dry;
      }
      const float tanT = materials_[size_t(top)].tanTalus * (wet ? p_.wetTalusScale : 1.0f);
      float maxEx = 0.0f, sumEx = 0.0f;
      for (int d = 0; d < 4; ++d) {
        const int nx = x + kDx[d], ny = y + kDy[d];
        if (nx < 0 || ny < 0 || nx >= p_.width || ny >= p_.height) continue;
        const float dist = d < 2 ? dx(y) : p_.dyM;
        excess[d] = std::max(0.0f, (bed_[i] - bed_[idx(nx, ny)]) - tanT * dist);
        maxEx = std::max(maxEx, excess[d]);
        sumEx += excess[d];
      }
      if (sumEx <= 0.0f) continue;
      float stack = 0.0f;
      for (int l = 0; l < p_.layerCount; ++l) stack += layers_[size_t(l) * n + i];
      const float moved = std::min(stack, p_.thermalRate * 0.5f * maxEx);
      for (int d = 0; d < 4; ++d) out[d] = moved * (excess[d] / sumEx);
    }
  }
}

// shaders/sim/thermal_apply.comp: E7, the receiving side; shed material lands as the top layer.
// What a cell sheds comes off its stack top-down (E7b).
void CpuSimulation::thermalApplyPass() {
  const size_t n = size_t(p_.width) * size_t(p_.height);
  const int sedimentLayer = p_.layerCount - 1;
  for (int y = 0; y < p_.height; ++y) {
    for (int x = 0; x < p_.width; ++x) {
      const size_t i = idx(x, y);
      const float* out = &thermal_[4 * i];
      const float shed = out[0] + out[1] + out[2] + out[3];
      float received = 0.0f;
      for (int d = 0; d < 4; ++d) {
        const int nx = x + kDx[d], ny = y + kDy[d];
        if (nx < 0 || ny < 0 || nx >= p_.width || ny >= p_.height) continue;
        received += thermal_[4 * idx(nx, ny) + size_t(d ^ 1)] * area(ny);
      }
      // Shed material comes off the top of the stack, layer by layer; the last layer touched
      // takes the float rounding remainder so the transfer is exact.
      float remaining = shed;
      for (int l = p_.layerCount - 1; l >= 0 && remaining > 0.0f; --l) {
        float& layer = layers_[size_t(l) * n + i];
        const float take = l == 0 ? remaining : std::min(layer, remaining);
        layer -= take;
        remaining -= take;
      }
      layers_[size_t(sedimentLayer) * n + i] += received / area(y);
      recomputeBed(i);
    }
  }
}

gis::Grid<float> CpuSimulation::readWaterDepth() const {
  gis::Grid<float> g(p_.width, p_.height);
  for (size_t i = 0; i < g.size(); ++i) g.data[i] = state_[4 * i];
  return g;
}

VelocityField CpuSimulation::readVelocity() const {
  VelocityField v{gis::Grid<float>(p_.width, p_.height), gis::Grid<float>(p_.width, p_.height)};
  for (size_t i = 0; i < v.uMS.size(); ++i) {
    v.uMS.data[i] = velocityOf(state_[4 * i], state_[4 * i + 2], p_.dryDepthM);
    v.vMS.data[i] = velocityOf(state_[4 * i], state_[4 * i + 3], p_.dryDepthM);
  }
  return v;
}

std::vector<gis::Grid<float>> CpuSimulation::readLayers() const {
  const size_t n = size_t(p_.width) * size_t(p_.height);
  std::vector<gis::Grid<float>> out;
  for (int l = 0; l < p_.layerCount; ++l) {
    gis::Grid<float> g(p_.width, p_.height);
    std::copy(layers_.begin() + ptrdiff_t(size_t(l) * n), layers_.begin() + ptrdiff_t(size_t(l + 1) * n),
              g.data.begin());
    out.push_back(std::move(g));
  }
  return out;
}

gis::Grid<float> CpuSimulation::readSuspended() const {
  gis::Grid<float> g(p_.width, p_.height);
  for (size_t i = 0; i < g.size(); ++i) g.data[i] = state_[4 * i + 1];
  return g;
}

gis::Grid<float> CpuSimulation::readBed() const {
  gis::Grid<float> g(p_.width, p_.height);
  for (size_t i = 0; i < g.size(); ++i) g.data[i] = bed_[i];
  return g;
}

SimStats CpuSimulation::stats() const {
  SimStats s;
  const int w = p_.width;
  const size_t n = size_t(w) * size_t(p_.height);
  std::vector<float> h(n), sus(n), outW(n), evap(n), outS(n);
  double levelIn = 0, levelOut = 0;
  float hmax = 0.0f;
  for (size_t i = 0; i < n; ++i) {
    h[i] = state_[4 * i];
    sus[i] = state_[4 * i + 1];
    outW[i] = accum_[8 * i];
    evap[i] = accum_[8 * i + 2];
    outS[i] = accum_[8 * i + 4];
    (accum_[8 * i + 6] > 0 ? levelIn : levelOut) += double(accum_[8 * i + 6]);
    hmax = std::max(hmax, h[i]);
  }
  const double dy = double(p_.dyM);
  s.timeS = timeS_;
  s.steps = steps_;
  s.lastDtS = lastDt_;
  s.storedWaterM3 = integrate(h, rowDxD_, dy, w);
  s.initialWaterM3 = initialWater_;
  s.rainM3 = rainM3_;
  s.inflowM3 = inflowM3_ + levelIn;  // W26: level cells that gained water on balance
  s.evaporatedM3 = std::accumulate(evap.begin(), evap.end(), 0.0);
  s.outflowM3 = std::accumulate(outW.begin(), outW.end(), 0.0) - levelOut;
  s.sedimentOutflowM3 = std::accumulate(outS.begin(), outS.end(), 0.0);
  s.suspendedM3 = integrate(sus, rowDxD_, dy, w);
  s.materialM3 = s.suspendedM3 + integrate(layers_, rowDxD_, dy, w);
  s.initialMaterialM3 = initialMaterial_;
  s.maxDepthM = hmax;
  return s;
}

}  // namespace strata::terrain::sim
