#version 450
// W12: inflow of springs and inflow lines, into the depth with compensation (W34); one
// invocation per entry, each cell listed once; W12b: half of it with finite volumes.
#include "sim.glsl"
#include "sim_accum.glsl"
layout(local_size_x = 64) in;
layout(std430, binding = SLOT_STATE_IN) buffer StateIn { vec4 state[]; };
layout(std430, binding = SLOT_SOURCES) readonly buffer Sources { SourceEntry entries[]; };
#define POUR_INTO_STATE
#include "sim_pour.glsl"
uniform uint entryCount;
void main() {
  const uint k = gl_GlobalInvocationID.x;
  if (k < entryCount) pourPointSource(entries[k]);
}
