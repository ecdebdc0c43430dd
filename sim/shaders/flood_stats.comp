#version 450
// Flood statistics, after every step (sim_stats.glsl), as a pass of their own: host steps, and
// device steps whose water update is not the step's last change (sim_tail.glsl).
#include "sim.glsl"
#define CLOCK_QUALIFIER readonly
#include "sim_clock.glsl"
#include "sim_stats.glsl"
layout(local_size_x = 256) in;
layout(std430, binding = SLOT_STATE_IN) readonly buffer StateIn { vec4 state[]; };

uniform float timeS;         // simulated time at the end of this step
uniform uint timeFromClock;  // 1: that time is the GPU's clock's (W35)

void main() {
  const uint i = gl_GlobalInvocationID.x;
  if (i >= uint(P.width * P.height)) return;
  floodStatsAt(i, state[i], timeFromClock != 0u ? float(C.timeS) : timeS);
}
