#version 450
// W10: max over cells of waveSpeedOf (|u| + sqrt(g h); W33: sqrt(g h) with the local-inertial
// scheme), as float bits (non-negative floats order like uints).
#include "sim.glsl"
layout(local_size_x = 256) in;
layout(std430, binding = SLOT_STATE_IN) readonly buffer StateIn { vec4 state[]; };
layout(std430, binding = SLOT_MAX_SPEED) buffer MaxSpeed { uint maxSpeedBits; };
shared float sMax[256];
void main() {
  const uint i = gl_GlobalInvocationID.x, l = gl_LocalInvocationID.x;
  float v = 0.0;
  if (i < uint(P.width * P.height)) v = waveSpeedOf(state[i]);
  sMax[l] = v;
  barrier();
  for (uint stride = 128u; stride > 0u; stride >>= 1) {
    if (l < stride) sMax[l] = max(sMax[l], sMax[l + stride]);
    barrier();
  }
  if (l == 0u) atomicMax(maxSpeedBits, floatBitsToUint(sMax[0]));
}
