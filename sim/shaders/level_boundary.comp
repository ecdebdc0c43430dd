#version 450
// W26: fixed water levels (a Dirichlet condition), at the end of the step's water update (before
// erosion): each listed cell gets depth
// max(0, stage - bed), its discharge scaled with the depth (the velocity kept); the volume put in
// (< 0: taken out) is summed per cell, compensated (W20), in the accumulator pair at slot 6 (the
// one pair free: a plain float sum loses the small late exchanges of a nearly full basin), from
// what the cell held (h + its depth error, W34; the error is then 0). One invocation per entry,
// each cell listed once.
#include "sim.glsl"
#include "sim_accum.glsl"
layout(local_size_x = 64) in;
layout(std430, binding = SLOT_BED) readonly buffer Bed { float bed[]; };
layout(std430, binding = SLOT_STATE_IN) buffer StateIn { vec4 state[]; };
layout(std430, binding = SLOT_LEVELS) readonly buffer Levels { LevelEntry entries[]; };
uniform uint entryCount;
void main() {
  const uint k = gl_GlobalInvocationID.x;
  if (k >= entryCount) return;
  const LevelEntry e = entries[k];
  const int i = int(e.cell);
  const int y = i / P.width;
  const vec4 s = state[i];
  const float h1 = max(0.0, e.stageM - bed[i]);
  const float keep = s.x > P.dryDepthM ? h1 / s.x : 0.0;
  state[i] = vec4(h1, s.y, s.z * keep, s.w * keep);
  const uint ke = accumAt(i, ACCUM_DEPTH_ERROR);
  kahanAdd(accumAt(i, ACCUM_LEVEL), ((h1 - s.x) - accum[ke]) * cellArea(y));
  accum[ke] = 0.0;
}
