#version 450
// W35: the step chosen and applied on the GPU, so that a run of steps reads nothing back. After
// wave_speed.comp: W10's step from the wave speed and the sources' peak depth rate over the step's
// window (the same arithmetic as sim/src/bookkeeping.cpp's stepDtWithSources, in double), the last
// step shortened to land on C.endS; the point sources' mean discharge over the step (mergeSources,
// W12); the step into P.dtS, the clock and the inflow budget forward; and the group counts of
// the step's passes (0 once the clock has reached C.endS, so the steps queued after it run
// nothing); with C.pointSources (W36: a step without the rain pass, so that nothing comes between)
// the point sources poured in as point_sources.comp pours them. One invocation.
#define SIM_PARAMS_WRITABLE
#define CLOCK_QUALIFIER
#include "sim.glsl"
#include "sim_accum.glsl"
#include "sim_clock.glsl"
layout(local_size_x = 1) in;
layout(std430, binding = SLOT_STATE_IN) buffer StateIn { vec4 state[]; };
layout(std430, binding = SLOT_MAX_SPEED) buffer MaxSpeed { uint maxSpeedBits; };
layout(std430, binding = SLOT_SOURCES) buffer Sources { SourceEntry entries[]; };
layout(std430, binding = SLOT_SERIES) readonly buffer Series { dvec2 samples[]; };
layout(std430, binding = SLOT_TERMS) readonly buffer Terms { Term terms[]; };
#define POUR_INTO_STATE
#include "sim_pour.glsl"

// core/src/time_series.cpp: straight lines between samples, the end values held.
double seriesAt(uint first, uint count, double t) {
  if (t <= samples[first].x) return samples[first].y;
  if (t >= samples[first + count - 1u].x) return samples[first + count - 1u].y;
  uint i = first + 1u;
  while (!(t < samples[i].x)) ++i;  // the first sample after t
  const dvec2 a = samples[i - 1u], b = samples[i];
  return a.y + (b.y - a.y) * (t - a.x) / (b.x - a.x);
}
double seriesIntegral(uint first, uint count, double t0, double t1) {
  if (!(t1 > t0)) return 0.0lf;
  double sum = 0.0lf;
  const double firstT = samples[first].x, lastT = samples[first + count - 1u].x;
  if (t0 < firstT) sum += samples[first].y * (min(t1, firstT) - t0);
  if (t1 > lastT) sum += samples[first + count - 1u].y * (t1 - max(t0, lastT));
  for (uint i = first + 1u; i < first + count; ++i) {
    const dvec2 a = samples[i - 1u], b = samples[i];
    const double lo = max(t0, a.x), hi = min(t1, b.x);
    if (!(hi > lo)) continue;
    const double vLo = a.y + (b.y - a.y) * (lo - a.x) / (b.x - a.x);
    const double vHi = a.y + (b.y - a.y) * (hi - a.x) / (b.x - a.x);
    sum += 0.5lf * (vLo + vHi) * (hi - lo);
  }
  return sum;
}
double seriesMaxOver(uint first, uint count, double t0, double t1) {
  double m = max(seriesAt(first, count, t0), seriesAt(first, count, t1));
  for (uint i = first; i < first + count; ++i) {
    if (samples[i].x > t0 && samples[i].x < t1) m = max(m, samples[i].y);
  }
  return m;
}

// W10 (bookkeeping.cpp's stepDt): the longest dt <= maxDtS with dt (S + sqrt(g r dt)) <= reach,
// or dt sqrt(S^2 + g r dt) <= reach for the local-inertial scheme (W33).
double travel(double dt, double s, double k) {
  return C.inertial != 0u ? dt * sqrt(s * s + k * k * dt) : dt * (s + k * sqrt(dt));
}
double stepDt(double s, double r) {
  const double cap = C.maxDtS;
  if (C.adaptive == 0u || (s <= 0.0lf && r <= 0.0lf)) return cap;
  const double k = sqrt(C.gravityMS2 * max(r, 0.0lf));
  if (travel(cap, s, k) <= C.reachM) return cap;
  double lo = 0.0lf, hi = cap;
  for (int i = 0; i < 60; ++i) {
    const double mid = 0.5lf * (lo + hi);
    if (travel(mid, s, k) <= C.reachM) {
      lo = mid;
    } else {
      hi = mid;
    }
  }
  return lo;
}

// bookkeeping.cpp's sourceDepthRate: per cell the sum of its sources' peaks over [t0, t1] over
// its area, the largest of them, plus the rain's bound.
double sourceDepthRate(double t0, double t1) {
  double cellRate = 0.0lf, sum = 0.0lf;
  for (uint k = 0u; k < C.termCount; ++k) {
    const Term tm = terms[k];
    sum += seriesMaxOver(tm.first, tm.count, t0, t1) / tm.cellCount;
    if (k + 1u == C.termCount || terms[k + 1u].entry != tm.entry) {
      cellRate = max(cellRate, sum / tm.areaM2);
      sum = 0.0lf;
    }
  }
  return cellRate + C.rainRateMS;
}

void main() {
  const double t = C.timeS, end = C.endS;
  const bool running = C.done == 0u && t < end - 1e-9lf * max(1.0lf, abs(end));
  for (uint i = 0u; i < 3u * CLOCK_SHAPES; ++i) C.dispatchNow[i] = running ? C.dispatchFull[i] : 0u;
  if (!running) {
    C.done = 1u;
    return;
  }
  const double s = double(uintBitsToFloat(maxSpeedBits));
  maxSpeedBits = 0u;  // W36: a fused water update adds the next step's wave speed to it
  double chosen = C.maxDtS;
  if (C.adaptive != 0u) {
    const double window = stepDt(s, 0.0lf);
    chosen = stepDt(s, sourceDepthRate(t, t + window));
  }
  const float dt = float(min(chosen, end - t));
  const double t1 = t + double(dt);
  // W12: each entry's mean discharge over [t, t1], its sources' in their order.
  double q = 0.0lf, inflow = 0.0lf;
  for (uint k = 0u; k < C.termCount; ++k) {
    const Term tm = terms[k];
    if (t1 > t) q += seriesIntegral(tm.first, tm.count, t, t1) / (t1 - t) / tm.cellCount;
    if (k + 1u == C.termCount || terms[k + 1u].entry != tm.entry) {
      entries[tm.entry].rateM3S = float(q);
      inflow += double(float(q)) * double(dt);
      q = 0.0lf;
    }
  }
  P.dtS = dt;
  if (C.pointSources != 0u) {  // point_sources.comp's W12, each entry once (after its last term)
    for (uint k = 0u; k < C.termCount; ++k) {
      if (k + 1u < C.termCount && terms[k + 1u].entry == terms[k].entry) continue;
      pourPointSource(entries[terms[k].entry]);
    }
  }
  C.timeS = t1;
  C.inflowM3 += inflow;
  C.minChosenDtS = min(C.minChosenDtS, chosen);
  C.lastChosenDtS = chosen;
  C.lastDtS = dt;
  C.steps += 1u;
}
