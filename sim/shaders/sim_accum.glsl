// W20: compensated (Kahan) sums of per-cell volumes: accum[k] holds the sum, accum[k + 1] its
// running error. `precise` keeps the compiler from reassociating the error term away. The buffer
// is plane-major, ACCUM_PER_CELL planes of the grid's cells (slot ACCUM_OUTFLOW, ... of cell i at
// accumAt(i, slot); #defines of sim::AccumOffset), so a pass reads each plane coalesced; the host
// moves CellBlock's cell-major sums to and from it (GlSolver).
layout(std430, binding = SLOT_ACCUM) buffer AccumBlock { float accum[]; };
uint accumAt(int cell, int slot) { return uint(slot) * uint(P.width) * uint(P.height) + uint(cell); }
void kahanAdd(uint k, float v) {
  precise float y = v - accum[k + uint(P.width) * uint(P.height)];
  precise float t = accum[k] + y;
  precise float c = (t - accum[k]) - y;
  accum[k + uint(P.width) * uint(P.height)] = c;
  accum[k] = t;
}
// W34: cell i's depth held as h + its ACCUM_DEPTH_ERROR slot, two floats: each change added with
// TwoSum, its exact rounding error into the slot, then folded back (Fast2Sum), never below 0
// (at or below 0: 0 with no error). The CPU backend's twoSumInto, settleDepth, addDepth and
// addDepthFaces (sim/src/cpu_kernels.hpp), operation for operation.
void twoSumInto(inout float h, inout float err, float v) {
  precise float s = h + v;
  precise float b = s - h;
  precise float e = err + ((h - (s - b)) + (v - b));
  err = e;
  h = s;
}
float settleDepth(float h, float err, uint a) {
  precise float s = h + err;
  precise float e = err - (s - h);
  const bool wet = s > 0.0;
  accum[a] = wet ? e : 0.0;
  return wet ? s : 0.0;
}
// The new depth of cell i after a change d.
float addDepth(float h, int i, float d) {
  const uint a = accumAt(i, ACCUM_DEPTH_ERROR);
  precise float t = h;
  precise float c = accum[a];
  twoSumInto(t, c, d);
  return settleDepth(t, c, a);
}
// The new depth of cell i after its four faces' terms k (f w) (> 0 into the cell for W and N),
// each added on its own: the neighbour across a face computes the same float term.
float addDepthFaces(float h, int i, float k, float inW, float outE, float inN, float outS) {
  const uint a = accumAt(i, ACCUM_DEPTH_ERROR);
  precise float t = h;
  precise float c = accum[a];
  twoSumInto(t, c, k * inW);
  twoSumInto(t, c, -(k * outE));
  twoSumInto(t, c, k * inN);
  twoSumInto(t, c, -(k * outS));
  return settleDepth(t, c, a);
}
