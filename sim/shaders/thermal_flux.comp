#version 450
// E7 and E8 for each layer of the stack, from the top down (each layer at its own angles, rate and
// cohesion, no more than its own thickness; a layer below is reached only through layers shed
// whole). E7, weathering: half of the excess over the talus slope times 1 - exp(-r dt). E8, bank
// failure: towards a neighbour the flow scoured this step, a bank steeper than the layer's
// friction angle whose height exceeds Culmann's critical height sends half its excess over that
// angle, up to bankFillShare of the neighbour's scour. Writes only this cell's four outflows;
// layers are read-only here.
#include "sim.glsl"
#include "sim_layers.glsl"
layout(local_size_x = SIM_GROUP_X, local_size_y = SIM_GROUP_Y) in;
layout(std430, binding = SLOT_BED) readonly buffer Bed { float bed[]; };
layout(std430, binding = SLOT_THERMAL) writeonly buffer Thermal { vec4 thermal[]; };
layout(std430, binding = SLOT_SCOUR) readonly buffer Scour { float scour[]; };
// 1 - exp(-a), without the cancellation for small a (as erode.comp).
float oneMinusExp(float a) { return a < 1e-3 ? a * (1.0 - a * (0.5 - a * (1.0 / 6.0))) : 1.0 - exp(-a); }
void main() {
  const ivec2 p = ivec2(gl_GlobalInvocationID.xy);
  if (!insideGrid(p)) return;
  const int i = cellOf(p), n = cellCount();
  const float bi = bed[i], A = cellArea(p.y);
  vec4 drop = vec4(0.0), noise = vec4(0.0), dist = vec4(0.0), credit = vec4(0.0);
  bvec4 inside = bvec4(false);
  for (int d = 0; d < 4; ++d) {
    const ivec2 q = p + kDir[d];
    if (!insideGrid(q)) continue;
    inside[d] = true;
    dist[d] = d < 2 ? cellDx(p.y) : P.dyM;
    const float bj = bed[cellOf(q)];
    drop[d] = bi - bj;
    // An excess within float32 resolution of the beds is rounding, not a slope (as W1a).
    noise[d] = kHeadNoise * max(abs(bi), abs(bj));
    credit[d] = P.bankFillShare * scour[cellOf(q)] * (cellArea(q.y) / A);
  }
  vec4 out_ = vec4(0.0);
  float shedAbove = 0.0;
  for (int l = P.layerCount - 1; l >= 0; --l) {
    const float t = layers[l * n + i];
    if (t <= 0.0) continue;  // empty: the layer below is reached
    const SimMaterial m = materials[l];
    const float share = oneMinusExp(m.weatheringRatePerS * P.dtS);
    vec4 want = vec4(0.0);
    float maxW = 0.0, sumW = 0.0;
    for (int d = 0; d < 4; ++d) {
      if (!inside[d]) continue;
      const float dr = drop[d] - shedAbove;
      const float e = dr - m.tanTalus * dist[d];
      const float weather = 0.5 * ((e > noise[d] ? e : 0.0) * share);
      const float ef = dr - m.tanFriction * dist[d];
      // Culmann: drop > H_c, times len / drop, with sin(beta) = drop / len and
      // len cos(beta - phi') = dist cos(phi') + drop sin(phi').
      const float len = sqrt(dr * dr + dist[d] * dist[d]);
      const bool fails = ef > noise[d] && len - (dist[d] * m.cosFriction + dr * m.sinFriction) > m.cohesionHeightM * m.cosFriction;
      const float slump = fails ? min(0.5 * ef, credit[d]) : 0.0;
      want[d] = max(weather, slump);
      maxW = max(maxW, want[d]);
      sumW += want[d];
    }
    if (sumW <= 0.0) break;
    const float moved = exactTake(t, min(t, maxW));
    const float inv = moved / sumW;
    for (int d = 0; d < 4; ++d) {
      const float part = want[d] * inv;
      out_[d] += part;
      credit[d] = max(credit[d] - part, 0.0);
    }
    shedAbove += moved;
    if (moved < t) break;  // this layer stays: the ones below are covered
  }
  thermal[i] = out_;
}
