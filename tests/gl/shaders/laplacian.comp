#version 450
// 5-point Laplacian of an r32f image (unit spacing), clamped at the borders.
#include "grid.glsl"
layout(local_size_x = 16, local_size_y = 16) in;

layout(r32f, binding = 0) uniform readonly image2D src;
layout(r32f, binding = 1) uniform writeonly image2D dst;

layout(std430, binding = 2) readonly buffer Params { GridParams grid; };

void main() {
  const ivec2 p = ivec2(gl_GlobalInvocationID.xy);
  if (!inside(grid, p)) return;
  const ivec2 hi = grid.size - 1;
  const float c = imageLoad(src, p).r;
  const float l = imageLoad(src, clamp(p - ivec2(1, 0), ivec2(0), hi)).r;
  const float r = imageLoad(src, clamp(p + ivec2(1, 0), ivec2(0), hi)).r;
  const float d = imageLoad(src, clamp(p - ivec2(0, 1), ivec2(0), hi)).r;
  const float u = imageLoad(src, clamp(p + ivec2(0, 1), ivec2(0), hi)).r;
  imageStore(dst, p, vec4(l + r + d + u - 4.0 * c));
}
