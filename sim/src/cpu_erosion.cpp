// The CPU backend's erosion passes (docs/sim-erosion.md): erosion, deposition and dissolution
// (E1-E4, E6), then thermal weathering and bank failure (E7, E8) as two passes, the flux a cell
// sheds to each neighbour and what it receives. One function per pass; each cell's arithmetic is
// the matching kernel's under sim/shaders/, written with selects instead of branches so a row's
// cells run as vectors (for up to kVectorLayers layers, a compile-time count; more layers take
// the same code with the count at run time).
#include <algorithm>
#include <cmath>
#include <cstring>

#include "cpu_impl.hpp"
#include "cpu_rows.hpp"

namespace strata::sim::cpu {

// A row's layer stacks: layer l of cell x at lay[l * stride + x], bottom to top.
struct Stack {
  float* lay;
  size_t stride;
  int count;
  float& at(int l, int x) const { return lay[size_t(l) * stride + size_t(x)]; }
};

struct ErosionConst {
  float dt, dry, rhoGn2;  // rhoGn2: rho g n^2 of the bed shear stress (E1)
  float rhoG;             // rho g, times a roughness map's n^2 where there is one
  bool forceBased;        // ErosionLaw::kForceBased
  float deepWater, capacityK, minSinTilt, dropShare, slowWater, settling;
  // per layer; pickShare: the force-based law's 1 - exp(-Ks erodibility dt)
  const float *pickShare, *dissolutionRate, *criticalShear, *shearErodibility;
};

struct ThermalConst {
  int w, h;
  float dt, dy, fillShare;
  const float *tanTalus, *share;  // per layer; share: stepShare of its weathering rate this step
  const float *tanFriction, *sinFriction, *cosFriction, *cohesionHeight;  // per layer (E8)
};

// One row of thermal_flux.comp's inputs: row y and its neighbours above and below (row y itself
// at an edge), and its four outflows.
struct ThermalRow {
  int y;
  float dx, A, AN, AS;                        // cell areas of rows y, y - 1, y + 1
  const float *b, *bN, *bS, *sc, *scN, *scS;  // beds and this step's toe scour
  float* out[4];
};

namespace {

constexpr int kVectorLayers = 8;

// Calls f(std::integral_constant<int, L>) for L layers up to kVectorLayers, else with 0 (the
// count at run time).
template <class F>
void withLayerCount(int layers, F&& f) {
  switch (layers) {
    case 1: return f(std::integral_constant<int, 1>{});
    case 2: return f(std::integral_constant<int, 2>{});
    case 3: return f(std::integral_constant<int, 3>{});
    case 4: return f(std::integral_constant<int, 4>{});
    case 5: return f(std::integral_constant<int, 5>{});
    case 6: return f(std::integral_constant<int, 6>{});
    case 7: return f(std::integral_constant<int, 7>{});
    case 8: return f(std::integral_constant<int, 8>{});
    default: return f(std::integral_constant<int, 0>{});
  }
}
static_assert(kVectorLayers == 8, "withLayerCount lists the vectorised counts");

// Topmost layer with material, or -1 (sim_layers.glsl's topLayer).
template <int kL>
inline int topLayer(const Stack& st, int x) {
  const int n = kL > 0 ? kL : st.count;
  int top = -1;
  for (int l = 0; l < n; ++l) top = st.at(l, x) > 0.0f ? l : top;
  return top;
}

// Layer `top`'s thickness at cell x, and a material constant of layer `top` (0 for -1); every
// layer is read, whatever `top` is, so the loop over cells has no branch. (No lambda: a closure
// holding references to a loop's locals stops `#pragma omp simd` from vectorising it.)
template <int kL>
inline float layerAt(const Stack& st, int x, int top) {
  float v = 0.0f;
  for (int l = 0; l < (kL > 0 ? kL : st.count); ++l) {
    const float vl = st.at(l, x);
    v = top == l ? vl : v;
  }
  return v;
}
template <int kL>
inline float materialAt(const float* perLayer, int n, int top) {
  float v = 0.0f;
  for (int l = 0; l < (kL > 0 ? kL : n); ++l) {
    const float vl = perLayer[l];
    v = top == l ? vl : v;
  }
  return v;
}

// Takes `amount` off layer `top` where `apply`.
template <int kL>
inline void takeFrom(const Stack& st, int x, int top, float amount, bool apply) {
  for (int l = 0; l < (kL > 0 ? kL : st.count); ++l) {
    const float v = st.at(l, x);
    st.at(l, x) = (apply & (top == l)) ? v - amount : v;
  }
}

// E9 (docs/sim-erosion.md): what a store of `from` m really loses when `amount` (<= from) is
// taken off it in float32: from - fl(from - amount), which is exact (Sterbenz), so the receiver
// gets what the store lost and not a value the store could not represent (a 1e-7 m pick-up from
// a 20 m layer used to leave the layer unchanged and create the material in the load).
inline float exactTake(float from, float amount) {
  const float left = from - amount;
  return from - left;
}

// E9, the receiving side: what a store of `to` m really gains when `amount` is added, when the
// store is the larger of the two (then fl(to + amount) - to is exact); 0 when that would exceed
// `limit` (what the giver holds: rounding up past it would take more than there is).
inline float exactGive(float to, float amount, float limit) {
  const float sum = to + amount;
  const float gained = to >= amount ? sum - to : amount;
  return gained <= limit ? gained : 0.0f;
}

template <int kL>
inline float stackBed(const Stack& st, float base, int x) {
  float b = base;
  for (int l = 0; l < (kL > 0 ? kL : st.count); ++l) b += st.at(l, x);
  return b;
}

// 1 - exp(-a), without the cancellation for small a (erode.comp's oneMinusExp).
inline float oneMinusExp(float a) {
  const float series = a * (1.0f - a * (0.5f - a * (1.0f / 6.0f)));
  return a < 1e-3f ? series : 1.0f - std::exp(-a);
}

// (1 - exp(-l)) / l, 1 at l = 0: what a quantity relaxing at rate k towards a target moves over
// a step, as a share of (target - now) k dt, with l = k dt (E2, E3). Exact for any step, so the
// exchange does not depend on it.
inline float relaxShare(float l) {
  const float series = 1.0f - l * (0.5f - l * (1.0f / 6.0f));
  const float lw = maxOf(l, 1e-3f);  // never a division by 0, even on the side not used
  const float exact = (1.0f - expNeg(lw)) / lw;
  // The series below 1e-3 (no cancellation), as arithmetic: GCC 12 makes a branch of the select
  // in the AVX2 clone, and the loop around it stops vectorising.
  const float small = float(l < 1e-3f);
  return exact + small * (series - exact);
}

// sim/shaders/erode.comp for one cell: E1-E3 (the step's net exchange between the bed and the
// load), E4 (dissolution), E6 (settling where dry); what the flow took off the bed goes to
// `scour` (E8's toe).
template <int kL, bool kForceBased>
inline void erodeCell(const ErosionConst& c, const Stack& st, float* s, float* bed, const float* base, const float* h,
                      const float* hu, const float* hv, const float* tilt, float* scour, const float* shear,
                      const float* relax, int x) {
  const int n = kL > 0 ? kL : st.count, sedimentLayer = n - 1;
  const float hx = h[x], sx = s[x];
  const bool wet = hx > c.dry;
  const float hw = wet ? hx : 1.0f;  // a depth to divide by
  const float q2 = hu[x] * hu[x] + hv[x] * hv[x];
  const float speed = std::sqrt(q2) / hw;
  const int top = topLayer<kL>(st, x);
  const float topLayerM = layerAt<kL>(st, x, top);
  float net;  // > 0: the flow takes from the bed
  if constexpr (!kForceBased) {
    // E1-E3, shear-stress law: tau = rho g n^2 |u|^2 / h^(1/3); the load s relaxes towards
    // E h / w_s at the rate w_s / h, entrainment E = k_d (tau - tau_c) of the topmost layer.
    const float excess = maxOf(shear[x] - materialAt<kL>(c.criticalShear, n, top), 0.0f);
    const float entrain = materialAt<kL>(c.shearErodibility, n, top) * excess;  // 0 for top = -1
    net = (entrain - c.settling * sx / hw) * c.dt * relax[x];
  } else {
    // E1-E3, force-based law: capacity C from tilt and speed, falling to 0 in deep water; the
    // load relaxes towards C at Ks erodibility (below it) or Kd (above it).
    const float shallow = 1.0f - hx / c.deepWater;  // std::clamp(shallow, 0, 1), as values
    const float depthFactor = shallow < 0.0f ? 0.0f : (1.0f < shallow ? 1.0f : shallow);
    const float capacity = c.capacityK * maxOf(tilt[x], c.minSinTilt) * speed * depthFactor;
    const float gap = capacity - sx;
    net = gap * (gap > 0.0f ? materialAt<kL>(c.pickShare, n, top) : c.dropShare);
  }
  // E2: the flow takes from the topmost layer.
  const float eroded = exactTake(topLayerM, minOf(maxOf(net, 0.0f), topLayerM));
  const bool erode = wet & (net > 0.0f) & (top >= 0);
  takeFrom<kL>(st, x, top, eroded, erode);
  // E3: the load settles as the top (sediment) layer.
  const float sed = st.at(sedimentLayer, x);
  const float deposited = exactGive(sed, minOf(-net, sx), sx);
  const bool deposit = wet & (net < 0.0f);
  float s1 = erode ? sx + eroded : (deposit ? sx - deposited : sx);
  st.at(sedimentLayer, x) = deposit ? sed + deposited : sed;
  // E4: slow water dissolves the (new) topmost layer.
  const int top2 = topLayer<kL>(st, x);
  const float dissolution = materialAt<kL>(c.dissolutionRate, n, top2);
  const float top2M = layerAt<kL>(st, x, top2);
  const float dissolved = exactTake(top2M, minOf(dissolution * hx * c.dt, top2M));
  const bool dissolve = wet & (speed < c.slowWater) & (top2 >= 0);
  takeFrom<kL>(st, x, top2, dissolved, dissolve);
  s1 = dissolve ? s1 + dissolved : s1;
  scour[x] = (erode ? eroded : 0.0f) + (dissolve ? dissolved : 0.0f);
  // E6: where the water is gone its load settles.
  const float sed2 = st.at(sedimentLayer, x);
  st.at(sedimentLayer, x) = wet ? sed2 : sed2 + s1;
  s[x] = wet ? s1 : 0.0f;
  bed[x] = stackBed<kL>(st, base[x], x);
}

}  // namespace

// erode.comp for the cells [x0, x1) of a row.
// E1's bed shear stress and E2-E3's relaxation share of each cell of a row, for the shear-stress
// law: plain arithmetic in a loop of its own, which vectorises (the layer walk of the cell loop
// does not: GCC 12 keeps branches in it).
STRATA_ROW_KERNEL void shearRow(const ErosionConst& c, const float* h, const float* hu, const float* hv,
                                const float* n2row, float* shear, float* relax, int x0, int x1) {
  auto cells = [&](auto kMap) {
#pragma omp simd
    for (int x = x0; x < x1; ++x) {
      const float hw = h[x] > c.dry ? h[x] : 1.0f;
      const float q2 = hu[x] * hu[x] + hv[x] * hv[x];
      float rhoGn2 = c.rhoGn2;
      if constexpr (decltype(kMap)::value) rhoGn2 = c.rhoG * n2row[x];
      shear[x] = rhoGn2 * (q2 / (hw * hw)) / cubeRoot(hw);  // rho g n^2 |u|^2 / h^(1/3)
      relax[x] = relaxShare(c.settling * c.dt / hw);
    }
  };
  n2row ? cells(std::true_type{}) : cells(std::false_type{});
}

STRATA_ROW_KERNEL void erosionRow(const ErosionConst& c, const Stack& st, float* s, float* bed, const float* base,
                                  const float* h, const float* hu, const float* hv, const float* tilt, float* scour,
                                  const float* n2row, float* shear, float* relax, int x0, int x1) {
  if (!c.forceBased) shearRow(c, h, hu, hv, n2row, shear, relax, x0, x1);
  auto cells = [&](auto kForce) {
    withLayerCount(st.count, [&](auto kL) {
#pragma omp simd
      for (int x = x0; x < x1; ++x) {
        erodeCell<decltype(kL)::value, decltype(kForce)::value>(c, st, s, bed, base, h, hu, hv, tilt, scour, shear,
                                                                relax, x);
      }
    });
  };
  c.forceBased ? cells(std::true_type{}) : cells(std::false_type{});
}

// sim/shaders/erode.comp: E1-E4 (the exchange between bed and load, dissolution); E6 (settling
// when dry); the toe scour of E8. Purely local: each cell reads and writes only itself. Runs over the active blocks: in
// a quiet cell (no water, no load) it changes nothing.
void Impl::erosionPass() {
  pickShare.resize(erodibility.size());
  for (size_t l = 0; l < erodibility.size(); ++l) pickShare[l] = oneMinusExp(p.erosionRate * erodibility[l] * dt);
  forRuns(water, [&](const Run& r, int thread) {
    const ErosionConst c{dt,
                         p.dryDepthM,
                         p.waterDensityKgM3 * p.gravityMS2 * p.manningN * p.manningN,
                         p.waterDensityKgM3 * p.gravityMS2,
                         p.erosionLaw == ErosionLaw::kForceBased,
                         p.deepWaterM,
                         p.capacityK,
                         p.minSinTilt,
                         oneMinusExp(p.depositionRate * dt),
                         p.slowWaterMS,
                         settling,
                         pickShare.data(),
                         dissolutionRate.data(),
                         criticalShear.data(),
                         shearErodibility.data()};
    Water& u = now();
    Plane& sc = erosionScratch[size_t(thread)];
    for (int y = r.y0; y < r.y1; ++y) {
      erosionRow(c, Stack{layers.row(y), layerStride, L}, u.s.row(y), bed.row(y), base.row(y), u.h.row(y), u.hu.row(y),
                 u.hv.row(y), tilt.row(y), scour.row(y), manningN2.empty() ? nullptr : manningN2.row(y), sc.row(0),
                 sc.row(1), r.x0, r.x1);
    }
  });
}

namespace {

// E7: the share of a talus excess moved in a step of dt at `rate` (1/s): 1 - exp(-r dt). Moving
// half of it (the drop falls twice what the cell gives, with equal areas) relaxes the excess as
// exp(-r t), whatever the step.
inline float stepShare(float rate, float dt) { return oneMinusExp(rate * dt); }

// What a layer of a cell would send towards each neighbour this step (m over this cell), given
// the drops to the neighbours below what the layers above shed (`drop`), the float noise of the
// beds, the distances, and E8's bound per direction (`credit`).
// E7, weathering: half of the excess over the talus slope, times the layer's share this step.
// E8, bank failure: towards a neighbour the flow scoured this step, a bank steeper than the
// layer's friction angle phi' whose height exceeds Culmann's critical height
// (4 c' / gamma) sin(beta) cos(phi') / (1 - cos(beta - phi')) (0 for loose grains) sends half of
// its excess over phi', up to the credit. The larger of the two counts.
struct LayerWants {
  float want[4], maxW, sumW;
};
inline LayerWants layerWants(const ThermalConst& c, int l, const bool in[4], const float drop[4], const float noise[4],
                             const float dist[4], const float credit[4]) {
  LayerWants r{{0.0f, 0.0f, 0.0f, 0.0f}, 0.0f, 0.0f};
  const float tanT = c.tanTalus[l], share = c.share[l];
  const float tanF = c.tanFriction[l], sinF = c.sinFriction[l], cosF = c.cosFriction[l], hc = c.cohesionHeight[l];
  for (int d = 0; d < 4; ++d) {
    const float e = drop[d] - tanT * dist[d];
    const float weather = 0.5f * ((e > noise[d] ? e : 0.0f) * share);
    const float ef = drop[d] - tanF * dist[d];
    // Culmann: drop > H_c, times len / drop (> 0 where ef > 0), with sin(beta) = drop / len and
    // len cos(beta - phi') = dist cos(phi') + drop sin(phi'): no division.
    const float len = std::sqrt(drop[d] * drop[d] + dist[d] * dist[d]);
    const bool fails = (ef > noise[d]) & (len - (dist[d] * cosF + drop[d] * sinF) > hc * cosF);
    const float slump = fails ? minOf(0.5f * ef, credit[d]) : 0.0f;
    r.want[d] = in[d] ? maxOf(weather, slump) : 0.0f;
    r.maxW = maxOf(r.maxW, r.want[d]);
    r.sumW += r.want[d];
  }
  return r;
}

// The inputs of a cell's thermal flux: which neighbours exist, the drops to them, the float noise
// of the two beds (an excess within it is rounding, not a slope, as W1a), the distances and E8's
// credit towards each (bankFillShare of what the flow took off the neighbour this step, in m
// over this cell).
struct Around {
  bool in[4];
  float drop[4], noise[4], dist[4], credit[4];
};
template <bool kEdge>
inline Around around(const ThermalConst& c, const ThermalRow& r, int x) {
  Around a;
  const bool in[4] = {!kEdge || x > 0, !kEdge || x < c.w - 1, !kEdge || r.y > 0, !kEdge || r.y < c.h - 1};
  const int xw = in[0] ? x - 1 : x, xe = in[1] ? x + 1 : x;
  const float bj[4] = {r.b[xw], r.b[xe], r.bN[x], r.bS[x]};
  const float scj[4] = {r.sc[xw], r.sc[xe], r.scN[x], r.scS[x]};
  const float Aj[4] = {r.A, r.A, r.AN, r.AS};
  for (int d = 0; d < 4; ++d) {
    a.in[d] = in[d];
    a.dist[d] = d < 2 ? r.dx : c.dy;
    a.drop[d] = r.b[x] - bj[d];
    a.noise[d] = kHeadNoise * maxOf(std::abs(r.b[x]), std::abs(bj[d]));
    a.credit[d] = in[d] ? c.fillShare * scj[d] * (Aj[d] / r.A) : 0.0f;
  }
  return a;
}

// thermalFluxCell for the topmost layer alone (the layers below are reached only through it, so
// where it does not shed this is the whole result; the row runs it vectorised and then the full
// cell where anything is shed). Its arithmetic is thermalFluxCell's for that layer.
template <bool kEdge, int kL>
inline void thermalFluxTopCell(const ThermalConst& c, const ThermalRow& r, const Stack& st, int x) {
  const Around a = around<kEdge>(c, r, x);
  const int top = topLayer<kL>(st, x);
  const float t = layerAt<kL>(st, x, top);
  const LayerWants lw = layerWants(c, top < 0 ? 0 : top, a.in, a.drop, a.noise, a.dist, a.credit);
  const bool sheds = (top >= 0) & (lw.sumW > 0.0f);
  const float moved = sheds ? exactTake(t, minOf(t, lw.maxW)) : 0.0f;
  const float inv = sheds ? moved / lw.sumW : 0.0f;
  for (int d = 0; d < 4; ++d) r.out[d][x] = lw.want[d] * inv;
}

// sim/shaders/thermal_flux.comp for one cell: E7 and E8 for each layer of the stack, from the top
// down (each layer at its own angles, rate and cohesion, no more than its own thickness; a layer
// below is reached only through layers shed whole).
template <bool kEdge, int kL>
inline void thermalFluxCell(const ThermalConst& c, const ThermalRow& r, const Stack& st, int x) {
  Around a = around<kEdge>(c, r, x);
  const int n = kL > 0 ? kL : st.count;
  float out[4] = {0.0f, 0.0f, 0.0f, 0.0f};
  const float drop0[4] = {a.drop[0], a.drop[1], a.drop[2], a.drop[3]};
  float shedAbove = 0.0f;
  bool reach = true;  // every layer above this one is empty or shed whole
  for (int l = n - 1; l >= 0; --l) {
    const float t = st.at(l, x);
    for (int d = 0; d < 4; ++d) a.drop[d] = drop0[d] - shedAbove;
    const LayerWants lw = layerWants(c, l, a.in, a.drop, a.noise, a.dist, a.credit);
    const bool sheds = reach & (t > 0.0f) & (lw.sumW > 0.0f);
    const float moved = sheds ? exactTake(t, minOf(t, lw.maxW)) : 0.0f;
    const float inv = sheds ? moved / lw.sumW : 0.0f;
    for (int d = 0; d < 4; ++d) {
      const float part = lw.want[d] * inv;
      out[d] += part;
      a.credit[d] = maxOf(a.credit[d] - part, 0.0f);
    }
    shedAbove += moved;
    reach = reach & (moved >= t);
  }
  for (int d = 0; d < 4; ++d) r.out[d][x] = out[d];
}

}  // namespace

// thermal_flux.comp for the cells [x0, x1) of a row.
STRATA_ROW_KERNEL void thermalFluxRow(const ThermalConst& c, const ThermalRow& r, const Stack& st, int x0, int x1) {
  withLayerCount(st.count, [&](auto kL) {
    constexpr int kLayers = decltype(kL)::value;
    forRowCells(x0, x1, c.w, r.y == 0 || r.y == c.h - 1,
                [&](auto e, int x) { thermalFluxTopCell<decltype(e)::value, kLayers>(c, r, st, x); });
    // Where the topmost layer sheds all of itself (to rounding: what it sends may sum to a hair
    // under the thickness), the layers below shed too: the full cell, whose first layer repeats
    // the same arithmetic. Elsewhere the topmost layer's result is the cell's.
    for (int x = x0; x < x1; ++x) {
      const float sent = r.out[0][x] + r.out[1][x] + r.out[2][x] + r.out[3][x];
      if (sent > 0.0f && sent >= 0.999f * layerAt<kLayers>(st, x, topLayer<kLayers>(st, x))) {
        thermalFluxCell<true, kLayers>(c, r, st, x);
      }
    }
  });
}

ThermalConst Impl::thermalConst() {
  thermalShare.resize(weatheringRate.size());
  for (size_t l = 0; l < weatheringRate.size(); ++l) thermalShare[l] = stepShare(weatheringRate[l], dt);
  return {w,
          h,
          dt,
          dy,
          p.bankFillShare,
          tanTalus.data(),
          thermalShare.data(),
          tanFriction.data(),
          sinFriction.data(),
          cosFriction.data(),
          cohesionHeight.data()};
}

// sim/shaders/thermal_flux.comp: E7 (weathering to the talus angle), E8 (banks falling into the
// scoured toe). Each cell writes only its own four outflows. Runs over the blocks whose inputs
// (bed, layers, scour of the cell and its neighbours) may have changed since their last
// evaluation, and records per block whether any of its cells sheds material.
void Impl::thermalFluxPass() {
  const ThermalConst c = thermalConst();
  forRuns(thermalEval, [&](const Run& r, int) {
    for (int bx = r.x0 / kBlock; bx * kBlock < r.x1; ++bx) thermalMoving[size_t(r.y0 / kBlock * bw + bx)] = 0;
    for (int y = r.y0; y < r.y1; ++y) {
      const int yn = std::max(y - 1, 0), ys = std::min(y + 1, h - 1);
      const ThermalRow row{y,
                           rowDx[size_t(y)],
                           rowArea[size_t(y)],
                           rowArea[size_t(yn)],
                           rowArea[size_t(ys)],
                           bed.row(y),
                           bed.row(yn),
                           bed.row(ys),
                           scour.row(y),
                           scour.row(yn),
                           scour.row(ys),
                           {thermal[0].row(y), thermal[1].row(y), thermal[2].row(y), thermal[3].row(y)}};
      const Stack st{layers.row(y), layerStride, L};
      thermalFluxRow(c, row, st, r.x0, r.x1);
      // Per block of the row: does a cell of it shed?
      for (int bx = r.x0 / kBlock; bx * kBlock < r.x1; ++bx) {
        bool any = false;
        for (int d = 0; d < 4; ++d) {
          for (int x = bx * kBlock; x < std::min((bx + 1) * kBlock, r.x1); ++x) any = any || row.out[d][x] != 0.0f;
        }
        if (any) thermalMoving[size_t(y / kBlock * bw + bx)] = 1;
      }
    }
  });
}

namespace {

// sim/shaders/thermal_apply.comp for one cell: what it sheds comes off its stack top-down
// (E7b; the last layer touched takes the float rounding remainder so the transfer is exact),
// what its neighbours shed towards it (per their area) lands on the top layer.
template <bool kEdge, int kL>
inline void thermalApplyCell(const ThermalConst& c, int y, const float* const out[4], const float* outN2,
                             const float* outS3, float area, float areaN, float areaS, const Stack& st, float* bed,
                             const float* base, int x) {
  const bool in[4] = {!kEdge || x > 0, !kEdge || x < c.w - 1, !kEdge || y > 0, !kEdge || y < c.h - 1};
  const int xw = in[0] ? x - 1 : x, xe = in[1] ? x + 1 : x;
  const int n = kL > 0 ? kL : st.count;
  const float shed = out[0][x] + out[1][x] + out[2][x] + out[3][x];
  // From W (its east outflow), E (west), N (south), S (north), in that order.
  const float from[4] = {out[1][xw] * area, out[0][xe] * area, outN2[x] * areaN, outS3[x] * areaS};
  float received = 0.0f;
  for (int d = 0; d < 4; ++d) {
    if (!kEdge || in[d]) received += from[d];
  }
  // E7b: what it sheds comes off the top of the stack, layer by layer, as the flux pass reached
  // down (its per-layer amounts are values the layers lose exactly; the sum of the four parts
  // may differ from them by a rounding, hence the min: no layer goes below 0).
  float remaining = shed;
  for (int l = n - 1; l >= 0; --l) {
    const float layer = st.at(l, x);
    const float take = minOf(layer, remaining);
    st.at(l, x) = layer - take;
    remaining -= take;
  }
  st.at(n - 1, x) += received / area;
  bed[x] = stackBed<kL>(st, base[x], x);
}

}  // namespace

// thermal_apply.comp for the cells [x0, x1) of a row: its outflows `out`, the south outflows of
// the row above and the north outflows of the row below, the rows' cell areas.
STRATA_ROW_KERNEL void thermalApplyRow(const ThermalConst& c, int y, const float* const out[4], const float* outN2,
                                       const float* outS3, float area, float areaN, float areaS, const Stack& st,
                                       float* bed, const float* base, int x0, int x1) {
  withLayerCount(st.count, [&](auto kL) {
    forRowCells(x0, x1, c.w, y == 0 || y == c.h - 1, [&](auto e, int x) {
      thermalApplyCell<decltype(e)::value, decltype(kL)::value>(c, y, out, outN2, outS3, area, areaN, areaS, st, bed,
                                                                base, x);
    });
  });
}

// sim/shaders/thermal_apply.comp: E7, the receiving side; shed material lands as the top layer.
// Runs over the blocks with a cell that sheds and their neighbours: elsewhere nothing is shed or
// received.
void Impl::thermalApplyPass() {
  const ThermalConst c = thermalConst();
  forRuns(thermalApply, [&](const Run& r, int) {
    for (int y = r.y0; y < r.y1; ++y) {
      const int yn = std::max(y - 1, 0), ys = std::min(y + 1, h - 1);
      const float* const out[4] = {thermal[0].row(y), thermal[1].row(y), thermal[2].row(y), thermal[3].row(y)};
      const Stack st{layers.row(y), layerStride, L};
      const float area = rowArea[size_t(y)], areaN = rowArea[size_t(yn)], areaS = rowArea[size_t(ys)];
      const float *outN2 = thermal[3].row(yn), *outS3 = thermal[2].row(ys);
      float* bd = bed.row(y);
      const float* bs = base.row(y);
      thermalApplyRow(c, y, out, outN2, outS3, area, areaN, areaS, st, bd, bs, r.x0, r.x1);
    }
  });
}

}  // namespace strata::sim::cpu
