#version 450
// Flood statistics, after every step (docs/sim-water.md, "Flood statistics"): per cell the
// maximum depth and speed, the arrival time (end of the first step with depth above the wet
// threshold; -1 = never) and the time spent above it.
#include "sim.glsl"
#define CLOCK_QUALIFIER readonly
#include "sim_clock.glsl"
layout(local_size_x = 256) in;
layout(std430, binding = SLOT_STATE_IN) readonly buffer StateIn { vec4 state[]; };
layout(std430, binding = SLOT_FLOOD_STATS) buffer FloodStats { vec4 floodStats[]; };  // maxDepth, maxSpeed, arrival, wetTime

uniform float timeS;          // simulated time at the end of this step
uniform uint timeFromClock;   // 1: that time is the GPU's clock's (W35)
uniform float wetThresholdM;

void main() {
  const uint i = gl_GlobalInvocationID.x;
  if (i >= uint(P.width * P.height)) return;
  const vec4 s = state[i];
  vec4 f = floodStats[i];
  const float u = velocityOf(s.x, s.z), v = velocityOf(s.x, s.w);
  f.x = max(f.x, s.x);
  f.y = max(f.y, sqrt(u * u + v * v));
  if (s.x > wetThresholdM) {
    if (f.z < 0.0) f.z = timeFromClock != 0u ? float(C.timeS) : timeS;
    f.w += P.dtS;
  }
  floodStats[i] = f;
}
