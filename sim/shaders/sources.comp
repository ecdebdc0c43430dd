#version 450
// W11: rain (uniform + raster) and evaporation, then W11b infiltration, per cell, in place (each
// cell only its own), into the depth with compensation (W34): the CPU backend's sourcesRow and
// infiltrationRow (sim/src/cpu_water.cpp).
#include "sim.glsl"
#include "sim_accum.glsl"
layout(local_size_x = SIM_GROUP_X, local_size_y = SIM_GROUP_Y) in;
layout(std430, binding = SLOT_STATE_IN) buffer StateIn { vec4 state[]; };
layout(std430, binding = SLOT_RAIN) readonly buffer Rain { float rainMmH[]; };
// (Ks m/s, psi * dtheta m) per cell; without infiltration one (0, 0) that every cell reads.
layout(std430, binding = SLOT_INFILTRATION) readonly buffer Infiltration { vec2 infiltration[]; };
void main() {
  const ivec2 p = ivec2(gl_GlobalInvocationID.xy);
  if (!insideGrid(p)) return;
  const int i = cellOf(p);
  const float dt = P.dtS;
  float h = state[i].x;
  h = addDepth(h, i, (rainMmH[i] + P.rainMmPerHour) * kMmPerHourToMS * dt);
  const float e = min(h, P.evaporationMmPerHour * kMmPerHourToMS * dt);
  h = addDepth(h, i, -e);
  kahanAdd(accumAt(i, ACCUM_EVAPORATED), e * cellArea(p.y));
  const vec2 soil = infiltration[min(i, infiltration.length() - 1)];
  const uint k = accumAt(i, ACCUM_INFILTRATED);
  const float area = cellArea(p.y);
  const float ksDt = soil.x * dt;  // the capacity is at least this: less water soaks in whole
  const float f = h <= ksDt ? max(h, 0.0) : min(h, infiltrationCapacity(ksDt, soil.y, accum[k] / area));
  if (f > 0.0) {
    h = addDepth(h, i, -f);
    kahanAdd(k, f * area);
  }
  state[i].x = h;
}
