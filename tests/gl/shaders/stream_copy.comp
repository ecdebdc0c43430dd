#version 450
// Bandwidth probe (bench/): copies src to dst, each element read once and written once.
// VEC4 = 1: 16-byte elements in 1-D groups of 256 with a grid-stride loop (the device's best
// case). VEC4 = 0: 4-byte floats of a uWidth x uHeight grid in GROUP_X x (256 / GROUP_X) groups,
// the way the simulation's kernels walk their std430 grids.
#ifndef VEC4
#define VEC4 0
#endif
#ifndef GROUP_X
#define GROUP_X 16
#endif

#if VEC4
layout(local_size_x = 256) in;
layout(std430, binding = 0) readonly buffer Src { vec4 src[]; };
layout(std430, binding = 1) writeonly buffer Dst { vec4 dst[]; };
uniform uint uCount;

void main() {
  const uint stride = gl_NumWorkGroups.x * gl_WorkGroupSize.x;
  for (uint i = gl_GlobalInvocationID.x; i < uCount; i += stride) dst[i] = src[i];
}
#else
layout(local_size_x = GROUP_X, local_size_y = 256 / GROUP_X) in;
layout(std430, binding = 0) readonly buffer Src { float src[]; };
layout(std430, binding = 1) writeonly buffer Dst { float dst[]; };
uniform int uWidth;
uniform int uHeight;

void main() {
  const ivec2 p = ivec2(gl_GlobalInvocationID.xy);
  if (p.x >= uWidth || p.y >= uHeight) return;
  const int i = p.y * uWidth + p.x;
  dst[i] = src[i];
}
#endif
