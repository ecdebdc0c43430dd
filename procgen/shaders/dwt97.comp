#version 450
// One separable pass of the CDF 9/7 lifting transform over the region [0, uRegion) of an r32f
// image, along x (uAxis 0) or y (uAxis 1), forward (uInverse 0) or inverse (uInverse 1). Each
// invocation recomputes the lifting steps it depends on from the input (no intermediate
// passes). Same formulas, in the same order, as procgen/src/wavelet.cpp
// (forward97/inverse97); `precise` forbids fused multiply-adds.
layout(local_size_x = 16, local_size_y = 16) in;

layout(r32f, binding = SLOT_DWT_SRC) uniform readonly image2D src;
layout(r32f, binding = SLOT_DWT_DST) uniform writeonly image2D dst;

uniform ivec2 uRegion;
uniform int uAxis;
uniform int uInverse;

const float kAlpha = -1.586134342059924;
const float kBeta = -0.052980118572961;
const float kGamma = 0.882911075530934;
const float kDelta = 0.443506852043971;
const float kK = 1.230174104914001;
const float kInvK = 0.8128930661159609;  // 1 / kK, written out: no constant folding differences

ivec2 gCell;
int gN, gNs, gNd;

float at(int j) {
  ivec2 q = gCell;
  if (uAxis == 0) q.x = j;
  else q.y = j;
  return imageLoad(src, q).r;
}
// Clamped indices are the whole-sample symmetric extension (docs/procgen.md).
int cs(int k) { return clamp(k, 0, gNs - 1); }
int cd(int i) { return clamp(i, 0, gNd - 1); }

// Forward: signal x in natural order.
float fXe(int k) { return at(2 * cs(k)); }
float fD1(int i) {
  i = cd(i);
  precise float v = at(2 * i + 1) + kAlpha * (fXe(i) + fXe(i + 1));
  return v;
}
float fS1(int k) {
  k = cs(k);
  precise float v = fXe(k) + kBeta * (fD1(k - 1) + fD1(k));
  return v;
}
float fD2(int i) {
  i = cd(i);
  precise float v = fD1(i) + kGamma * (fS1(i) + fS1(i + 1));
  return v;
}
float fS2(int k) {
  k = cs(k);
  precise float v = fS1(k) + kDelta * (fD2(k - 1) + fD2(k));
  return v;
}

// Inverse: coefficients in [s | d] layout.
float iS2(int k) {
  precise float v = at(cs(k)) * kK;
  return v;
}
float iD2(int i) {
  precise float v = at(gNs + cd(i)) * kInvK;
  return v;
}
float iS1(int k) {
  k = cs(k);
  precise float v = iS2(k) - kDelta * (iD2(k - 1) + iD2(k));
  return v;
}
float iD1(int i) {
  i = cd(i);
  precise float v = iD2(i) - kGamma * (iS1(i) + iS1(i + 1));
  return v;
}
float iXe(int k) {
  k = cs(k);
  precise float v = iS1(k) - kBeta * (iD1(k - 1) + iD1(k));
  return v;
}

void main() {
  gCell = ivec2(gl_GlobalInvocationID.xy);
  if (any(greaterThanEqual(gCell, uRegion))) return;
  gN = uAxis == 0 ? uRegion.x : uRegion.y;
  gNs = (gN + 1) / 2;
  gNd = gN / 2;
  const int i = uAxis == 0 ? gCell.x : gCell.y;
  precise float v;
  if (uInverse == 0) {
    v = i < gNs ? fS2(i) * kInvK : fD2(i - gNs) * kK;
  } else if ((i & 1) == 0) {
    v = iXe(i / 2);
  } else {
    const int k = i / 2;
    v = iD1(k) - kAlpha * (iXe(k) + iXe(k + 1));
  }
  imageStore(dst, gCell, vec4(v));
}
