#version 450
// E7: each layer of the stack, from the top down, sheds where the slope to a neighbour exceeds
// its own talus angle, at its own weathering rate and no more than its own thickness; a layer
// below is reached only through layers shed whole. E8: a bank above flowing water of real depth
// slips at wetTalusScale times the angle, at bankSlipRatePerS. Writes only this cell's four
// outflows; layers are read-only here.
#include "sim.glsl"
#include "sim_layers.glsl"
layout(local_size_x = SIM_GROUP_X, local_size_y = SIM_GROUP_Y) in;
layout(std430, binding = SLOT_BED) readonly buffer Bed { float bed[]; };
layout(std430, binding = SLOT_STATE_IN) readonly buffer StateIn { vec4 state[]; };
layout(std430, binding = SLOT_THERMAL) writeonly buffer Thermal { vec4 thermal[]; };
// thermalRate * r dt / (1 + r dt): the share of an excess moved in a step (E7).
float stepShare(float rate) {
  precise float a = rate * P.dtS;
  precise float share = P.thermalRate * (a / (1.0 + a));
  return share;
}
void main() {
  const ivec2 p = ivec2(gl_GlobalInvocationID.xy);
  if (!insideGrid(p)) return;
  const int i = cellOf(p), n = cellCount();
  const float slipShare = stepShare(P.bankSlipRatePerS);
  const float bi = bed[i];
  vec4 drop = vec4(0.0), noise = vec4(0.0), dist = vec4(0.0);
  bvec4 inside = bvec4(false), undercut = bvec4(false);
  for (int d = 0; d < 4; ++d) {
    const ivec2 q = p + kDir[d];
    if (!insideGrid(q)) continue;
    inside[d] = true;
    const vec4 sj = state[cellOf(q)];
    dist[d] = d < 2 ? cellDx(p.y) : P.dyM;
    // E8: the neighbour holds flowing water of real depth.
    const float speed = sqrt(sj.z * sj.z + sj.w * sj.w) / max(sj.x, P.bankDepthM);
    undercut[d] = sj.x > P.bankDepthM && speed > P.slowWaterMS;
    const float bj = bed[cellOf(q)];
    drop[d] = bi - bj;
    // An excess within float32 resolution of the beds is rounding, not a slope (as W1a).
    noise[d] = kHeadNoise * max(abs(bi), abs(bj));
  }
  vec4 out_ = vec4(0.0);
  float shedAbove = 0.0;
  for (int l = P.layerCount - 1; l >= 0; --l) {
    const float t = layers[l * n + i];
    if (t <= 0.0) continue;  // empty: the layer below is reached
    const float tanT = materials[l].tanTalus;
    const float share = stepShare(materials[l].weatheringRatePerS);
    vec4 weighted = vec4(0.0);
    float maxW = 0.0, sumW = 0.0;
    for (int d = 0; d < 4; ++d) {
      if (!inside[d]) continue;
      const float e = (drop[d] - shedAbove) - (undercut[d] ? tanT * P.wetTalusScale : tanT) * dist[d];
      weighted[d] = (e > noise[d] ? e : 0.0) * (undercut[d] ? slipShare : share);
      maxW = max(maxW, weighted[d]);
      sumW += weighted[d];
    }
    if (sumW <= 0.0) break;
    const float moved = exactTake(t, min(t, 0.5 * maxW));
    const float inv = moved / sumW;
    for (int d = 0; d < 4; ++d) out_[d] += weighted[d] * inv;
    shedAbove += moved;
    if (moved < t) break;  // this layer stays: the ones below are covered
  }
  thermal[i] = out_;
}
