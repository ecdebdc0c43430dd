// W20: compensated (Kahan) sums of per-cell volumes: accum[k] holds the sum, accum[k + 1] its
// running error. `precise` keeps the compiler from reassociating the error term away. A cell's
// pairs are ACCUM_PER_CELL floats at ACCUM_PER_CELL * cell + ACCUM_OUTFLOW, ... (#defines of
// sim::AccumOffset).
layout(std430, binding = SLOT_ACCUM) buffer AccumBlock { float accum[]; };
void kahanAdd(int k, float v) {
  precise float y = v - accum[k + 1];
  precise float t = accum[k] + y;
  precise float c = (t - accum[k]) - y;
  accum[k + 1] = c;
  accum[k] = t;
}
