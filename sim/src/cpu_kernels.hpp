#pragma once
// Per-cell float32 arithmetic the CPU passes share (the GLSL of sim/shaders/sim.glsl,
// sim_fv.glsl and sim_accum.glsl in C++): the same operations in the same order, written
// without branches (both sides computed, one selected), so loops over a row vectorise and give
// the bits the branchy form gives.

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstdint>

// The row kernels (the loops over a row's cells) are built twice, for baseline x86-64 (SSE2) and
// for x86-64-v3 (AVX2), and the loader picks one for the machine (GCC's function multiversioning;
// external linkage needed). Everything they call is inlined into them (`flatten`), so the cell
// code is built for both. Without contraction into fused multiply-adds (-ffp-contract=off) both
// give the same bits. Under AddressSanitizer nothing is flattened: every inlined helper is
// instrumented again in each kernel and clone, and cpu_erosion.cpp took 115 s to compile instead of
// 27 s (GCC 12, -O3, measured one after the other); inlining changes no value.
#if defined(__SANITIZE_ADDRESS__)  // GCC
#define STRATA_ROW_ASAN 1
#elif defined(__has_feature)
#if __has_feature(address_sanitizer)  // Clang
#define STRATA_ROW_ASAN 1
#endif
#endif
#if defined(STRATA_ROW_ASAN)
#define STRATA_ROW_FLATTEN
#else
#define STRATA_ROW_FLATTEN gnu::flatten
#endif
#if defined(__x86_64__) && defined(__GNUC__) && !defined(__clang__)
#define STRATA_ROW_KERNEL [[gnu::target_clones("default", "arch=x86-64-v3"), STRATA_ROW_FLATTEN]]
#else
#define STRATA_ROW_KERNEL [[STRATA_ROW_FLATTEN]]
#endif

namespace strata::sim::cpu {

constexpr float kMmPerHourToMS = 1.0f / 3.6e6f;
// W1a: a head difference below 4 float32 ulps of the operands is rounding, not a gradient.
constexpr float kHeadNoise = 4.0f * 1.1920929e-7f;
// W24: a net momentum rate below 16 float32 ulps of the sum of its terms is rounding.
constexpr float kForceNoise = 16.0f * 1.1920929e-7f;

// std::min and std::max on values: the same results (including NaN and signed zeros), but no
// reference to a temporary, which inside `#pragma omp simd` turns into a branch and stops the
// loop from vectorising.
inline float minOf(float a, float b) { return b < a ? b : a; }
inline float maxOf(float a, float b) { return a < b ? b : a; }

// x^(1/3) for x > 0 (normal floats), in arithmetic a vector loop can hold (std::pow and std::cbrt
// are scalar library calls, and a call stops GCC from vectorising the loop around it): the
// exponent divided by 3 on the bits (within 4 % of the root), then four Newton steps
// y <- (2 y + x / y^2) / 3, which square the relative error each: within 2 ulp of std::cbrt over
// 1e-30 .. 1e30 (SimCpu.VectorMathMatchesTheLibrary). The GLSL kernels use pow().
inline float cubeRoot(float x) {
  const uint32_t bits = std::bit_cast<uint32_t>(x);
  float y = std::bit_cast<float>(bits / 3u + 709921077u);
  for (int i = 0; i < 4; ++i) y = (2.0f * y + x / (y * y)) * (1.0f / 3.0f);
  return y;
}

// exp(-a) for a >= 0, in vector-loop arithmetic (as cubeRoot): a = n ln 2 + x with n the nearest
// integer and |x| <= ln 2 / 2 (Cody and Waite's two-part ln 2, so x keeps its bits), e^-x by its
// Taylor polynomial of degree 7 (remainder below 2e-9), 2^-n on the exponent bits; 0 beyond
// a = 87 (below float's normal range). Within 2 ulp of std::exp
// (SimCpu.VectorMathMatchesTheLibrary). The GLSL kernels use exp().
inline float expNeg(float a) {
  const float b = minOf(a, 87.0f);
  const float n = float(int(b * 1.44269504f + 0.5f));  // b >= 0: truncation is the floor
  const float x = (b - n * 0.693359375f) - n * -2.12194440e-4f;
  float p = 1.0f / 5040.0f;
  p = p * -x + 1.0f / 720.0f;
  p = p * -x + 1.0f / 120.0f;
  p = p * -x + 1.0f / 24.0f;
  p = p * -x + 1.0f / 6.0f;
  p = p * -x + 0.5f;
  p = p * -x + 1.0f;
  p = p * -x + 1.0f;
  const float scale = std::bit_cast<float>(uint32_t(127 - int(n)) << 23);  // 2^-n, n <= 126
  const float inRange = float(a < 87.0f);  // a select would become a branch in GCC 12's AVX2 clone
  return inRange * (p * scale);
}

// W11b: u - ln(1 + u) for u >= 0, without the cancellation of its two terms where u is small
// (a series to u^9 below 0.1, where its remainder is under 1e-8 of the sum).
inline float uMinusLog1p(float u) {
  if (u >= 0.1f) return u - std::log(1.0f + u);
  float p = 1.0f / 9.0f;
  p = 1.0f / 8.0f - u * p;
  p = 1.0f / 7.0f - u * p;
  p = 1.0f / 6.0f - u * p;
  p = 1.0f / 5.0f - u * p;
  p = 1.0f / 4.0f - u * p;
  p = 1.0f / 3.0f - u * p;
  p = 0.5f - u * p;
  return u * u * p;
}

// W11b: the depth (m) the soil can take in over a step under ponding, from the cumulative
// infiltration F (m): Green and Ampt (1911) integrated over the step, d - G ln(1 + d / (F + G))
// = Ks dt with G = psi * dtheta (m), written d F / (F + G) + G (u - ln(1 + u)) - Ks dt = 0,
// u = d / (F + G), and solved by three Newton steps from Ks dt + sqrt(2 G Ks dt) (the function is
// convex: the steps converge from either side). Relative error under 6e-6 in float over Ks dt
// 1e-10..0.1 m, G 1e-4..0.5 m, F 0..3 m (against bisection in double). G = 0: a constant loss.
// Exact for any step while the cell stays ponded, so the loss does not depend on the time step.
// sim/shaders/sim.glsl has the same function.
inline float infiltrationCapacity(float ksDt, float g, float f) {
  if (!(g > 0.0f) || !(ksDt > 0.0f)) return ksDt;
  const float a = f + g;
  float d = ksDt + std::sqrt(2.0f * g * ksDt);
  for (int k = 0; k < 3; ++k) {
    const float r = d * f / a + g * uMinusLog1p(d / a) - ksDt;
    d = std::max(ksDt, d - r * (a + d) / (f + d));
  }
  return d;
}

inline float velocityOf(float h, float q, float dry) {
  const float v = q / h;
  return h > dry ? v : 0.0f;
}

// W20: compensated (Kahan) sum into `sum` with the running error in `err`, so per-cell float
// accumulators of outflow and evaporation stay exact to ~1e-7 over millions of steps.
inline void kahanAdd(float& sum, float& err, float v) {
  const float y = v - err;
  const float t = sum + y;
  err = (t - sum) - y;
  sum = t;
}

// W34: a cell's depth held as h + err, two floats. twoSumInto adds v to h and the exact rounding
// error of that sum to err (Knuth's TwoSum: six float operations, no branch); settleDepth folds
// err into h (Fast2Sum: h the rounded sum, err exactly what it could not hold) and keeps the
// depth at or above 0 (a result at or below 0, rounding where W25 empties a cell or a cell dried
// by evaporation or the soil, is 0 with no error). The only rounding left is err's own, ~1e-7 of
// an error that is itself below an ulp of h.
inline void twoSumInto(float& h, float& err, float v) {
  const float s = h + v;
  const float b = s - h;
  err += (h - (s - b)) + (v - b);
  h = s;
}
inline void settleDepth(float& h, float& err) {
  const float s = h + err;
  err -= s - h;
  h = s;
  const bool wet = h > 0.0f;
  h = wet ? h : 0.0f;
  err = wet ? err : 0.0f;
}
inline void addDepth(float& h, float& err, float d) {
  twoSumInto(h, err, d);
  settleDepth(h, err);
}
// W34 for a flux update: the depth changed by what its four faces bring, each face's term
// k (f w) (k = dt / A, f the face's flux, w its width; > 0 into the cell for W and N) added on its
// own. The neighbour across a face computes the same float term, so what one cell gains the
// other loses exactly (summed first, each cell's net would round on its own).
inline void addDepthFaces(float& h, float& err, float k, float inW, float outE, float inN, float outS) {
  twoSumInto(h, err, k * inW);
  twoSumInto(h, err, -(k * outE));
  twoSumInto(h, err, k * inN);
  twoSumInto(h, err, -(k * outS));
  settleDepth(h, err);
}

// W21 slopes from the backward and forward differences a, b (0 at an extremum): minmod, the
// smaller one; van Leer's monotonised central (MC), sign * min(2|a|, 2|b|, |a + b| / 2).
inline float minmod(float a, float b) {
  const float m = std::abs(a) < std::abs(b) ? a : b;
  return a * b <= 0.0f ? 0.0f : m;
}
inline float mcSlope(float a, float b) {
  const float m = std::copysign(minOf(minOf(2.0f * std::abs(a), 2.0f * std::abs(b)), 0.5f * std::abs(a + b)), a);
  return a * b <= 0.0f ? 0.0f : m;
}
template <bool kMC>
inline float limitedSlope(float a, float b) {
  if constexpr (kMC) {
    return mcSlope(a, b);
  } else {
    return minmod(a, b);
  }
}

/// A cell's value at one of its faces (W21): depth, surface, normal and tangential velocity.
struct Side {
  float h, eta, un, ut;
};

/// Flood mode's flux through a face (fv_face.comp's vec4): mass, normal momentum for the left /
/// top cell and for the right / bottom cell, tangential momentum.
struct FaceFlux {
  float mass, nL, nR, t;
};

// W13-W16: HLL flux of the hydrostatically reconstructed states (Audusse et al. 2004) between a
// left / top side L and a right / bottom side R.
inline FaceFlux hllFace(Side L, Side R, float g, float dry) {
  const float hL = L.h, hR = R.h, unL = L.un, unR = R.un;
  const float bL = L.eta - L.h, bR = R.eta - R.h;
  const float dbLR = bR - bL;
  const float hLs = maxOf(0.0f, hL - maxOf(0.0f, dbLR));  // W13
  const float hRs = maxOf(0.0f, hR - maxOf(0.0f, -dbLR));
  const bool wetL = hLs > dry, wetR = hRs > dry;
  const float cL = std::sqrt(g * hLs), cR = std::sqrt(g * hRs);
  // W15: wave speeds, Toro's dry-bed variants (left dry / right dry / both wet).
  const float sLdryL = unR - 2.0f * cR, sRdryL = unR + cR;
  const float sLdryR = unL - cL, sRdryR = unL + 2.0f * cL;
  const float sLwet = minOf(unL - cL, unR - cR), sRwet = maxOf(unL + cL, unR + cR);
  const float sL = !wetL ? sLdryL : (!wetR ? sLdryR : sLwet);
  const float sR = !wetL ? sRdryL : (!wetR ? sRdryR : sRwet);
  const float qL = hLs * unL, qR = hRs * unR;
  const float fLn = qL * unL + 0.5f * g * hLs * hLs, fRn = qR * unR + 0.5f * g * hRs * hRs;
  const float inv = 1.0f / (sR - sL);  // W14
  const float hStar = (sR * qL - sL * qR + sL * sR * (hRs - hLs)) * inv;
  const float nStar = (sR * fLn - sL * fRn + sL * sR * (qR - qL)) * inv;
  const bool wet = wetL || wetR;
  const float fhWet = sL >= 0.0f ? qL : (sR <= 0.0f ? qR : hStar);
  const float fnWet = sL >= 0.0f ? fLn : (sR <= 0.0f ? fRn : nStar);
  const float fh = wet ? fhWet : 0.0f, fn = wet ? fnWet : 0.0f;
  const float ft = wet ? (fh > 0.0f ? fh * L.ut : fh * R.ut) : 0.0f;
  // W16: hydrostatic correction.
  return {fh, fn + 0.5f * g * (hL * hL - hLs * hLs), fn + 0.5f * g * (hR * hR - hRs * hRs), ft};
}

// W17: a wall mirrors the normal velocity; an open edge copies the cell and lets water out only.
inline FaceFlux edgeFlux(Side inside, bool ghostOnRight, bool open, float g, float dry) {
  Side ghost = inside;
  ghost.un = open ? (ghostOnRight ? maxOf(inside.un, 0.0f) : minOf(inside.un, 0.0f)) : -inside.un;
  FaceFlux f = ghostOnRight ? hllFace(inside, ghost, g, dry) : hllFace(ghost, inside, g, dry);
  if (open) f.mass = ghostOnRight ? maxOf(f.mass, 0.0f) : minOf(f.mass, 0.0f);
  return f;
}

}  // namespace strata::sim::cpu
