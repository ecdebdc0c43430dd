#version 450
// Sum, min and max of an int buffer: a shared-memory tree per work group, then one atomic
// per group. Integer arithmetic, so the result is exact and can be checked exactly.
layout(local_size_x = 256) in;

layout(std430, binding = 0) readonly buffer Input { int values[]; };
layout(std430, binding = 1) buffer Output { int sum; int minimum; int maximum; };

uniform uint count;

shared int sSum[256];
shared int sMin[256];
shared int sMax[256];

void main() {
  const uint i = gl_GlobalInvocationID.x;
  const uint l = gl_LocalInvocationID.x;
  const bool valid = i < count;
  sSum[l] = valid ? values[i] : 0;
  sMin[l] = valid ? values[i] : 2147483647;
  sMax[l] = valid ? values[i] : -2147483647 - 1;
  barrier();
  for (uint stride = 128u; stride > 0u; stride >>= 1) {
    if (l < stride) {
      sSum[l] += sSum[l + stride];
      sMin[l] = min(sMin[l], sMin[l + stride]);
      sMax[l] = max(sMax[l], sMax[l + stride]);
    }
    barrier();
  }
  if (l == 0u) {
    atomicAdd(sum, sSum[0]);
    atomicMin(minimum, sMin[0]);
    atomicMax(maximum, sMax[0]);
  }
}
