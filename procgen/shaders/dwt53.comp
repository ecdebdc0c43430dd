#version 450
// One separable pass of the CDF 5/3 lifting transform over the region [0, uRegion) of an r32f
// image, along x (uAxis 0) or y (uAxis 1), forward (uInverse 0) or inverse (uInverse 1).
// Same formulas, in the same order, as procgen/src/wavelet.cpp (forward53/inverse53);
// `precise` forbids fused multiply-adds so every driver rounds the same way.
layout(local_size_x = 16, local_size_y = 16) in;

layout(r32f, binding = SLOT_DWT_SRC) uniform readonly image2D src;
layout(r32f, binding = SLOT_DWT_DST) uniform writeonly image2D dst;

uniform ivec2 uRegion;
uniform int uAxis;
uniform int uInverse;

ivec2 gCell;
int gN;

float at(int j) {
  ivec2 q = gCell;
  if (uAxis == 0) q.x = j;
  else q.y = j;
  return imageLoad(src, q).r;
}

// Forward: x mirrored about its last sample, d clamped at both ends.
float xm(int j) { return at(j >= gN ? 2 * gN - 2 - j : j); }
float dForward(int i) {
  i = clamp(i, 0, gN / 2 - 1);
  precise float v = xm(2 * i + 1) - 0.5 * (xm(2 * i) + xm(2 * i + 2));
  return v;
}

// Inverse: coefficients in [s | d] layout.
float dCoeff(int i) { return at((gN + 1) / 2 + clamp(i, 0, gN / 2 - 1)); }
float evenSample(int i) {
  precise float v = at(i) - 0.25 * (dCoeff(i - 1) + dCoeff(i));
  return v;
}

void main() {
  gCell = ivec2(gl_GlobalInvocationID.xy);
  if (any(greaterThanEqual(gCell, uRegion))) return;
  gN = uAxis == 0 ? uRegion.x : uRegion.y;
  const int i = uAxis == 0 ? gCell.x : gCell.y;
  const int ns = (gN + 1) / 2;
  precise float v;
  if (uInverse == 0) {
    if (i < ns) {
      v = xm(2 * i) + 0.25 * (dForward(i - 1) + dForward(i));
    } else {
      v = dForward(i - ns);
    }
  } else {
    if ((i & 1) == 0) {
      v = evenSample(i / 2);
    } else {
      const int k = i / 2;
      const int right = 2 * k + 2 < gN ? k + 1 : k;
      v = dCoeff(k) + 0.5 * (evenSample(k) + evenSample(right));
    }
  }
  imageStore(dst, gCell, vec4(v));
}
