#version 450
// W11: rain (uniform + raster) and evaporation, per cell, in place (each cell only its own).
#include "sim.glsl"
#include "sim_accum.glsl"
layout(local_size_x = SIM_GROUP_X, local_size_y = SIM_GROUP_Y) in;
layout(std430, binding = SLOT_STATE_IN) buffer StateIn { vec4 state[]; };
layout(std430, binding = SLOT_RAIN) readonly buffer Rain { float rainMmH[]; };
void main() {
  const ivec2 p = ivec2(gl_GlobalInvocationID.xy);
  if (!insideGrid(p)) return;
  const int i = cellOf(p);
  const float dt = P.dtS;
  float h = state[i].x;
  h += (rainMmH[i] + P.rainMmPerHour) * kMmPerHourToMS * dt;
  const float e = min(h, P.evaporationMmPerHour * kMmPerHourToMS * dt);
  h -= e;
  kahanAdd(8 * i + 2, e * cellArea(p.y));
  state[i].x = h;
}
