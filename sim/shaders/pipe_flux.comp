#version 450
// W1: outflow of the four virtual pipes from the head difference (bed difference + depth
// difference), W1a: heads equal to float32 resolution are equal, W2: scaled by K so no cell
// gives more water than it has. Each cell writes only its own four outflows.
#include "sim.glsl"
layout(local_size_x = SIM_GROUP_X, local_size_y = SIM_GROUP_Y) in;
layout(std430, binding = SLOT_BED) readonly buffer Bed { float bed[]; };
layout(std430, binding = SLOT_STATE_IN) readonly buffer StateIn { vec4 state[]; };
layout(std430, binding = SLOT_FLUX) buffer Flux { vec4 flux[]; };
layout(std430, binding = SLOT_FLUX_DIAG) buffer FluxDiag { vec4 fluxDiag[]; };
void main() {
  const ivec2 p = ivec2(gl_GlobalInvocationID.xy);
  if (!insideGrid(p)) return;
  const int i = cellOf(p);
  const float dt = P.dtS, g = P.gravityMS2;
  // W1b: with diagonal pipes the areas follow the isotropic 9-point Laplacian (axis 2/3,
  // diagonal sqrt(2)/6 of pipeAreaM2), which keeps the total conductance of the 4 pipes.
  const float A = P.diagonalPipes != 0u ? P.pipeAreaM2 * (2.0 / 3.0) : P.pipeAreaM2;
  const float Ad = P.pipeAreaM2 * (1.41421356 / 6.0);
  const float hi = state[i].x, bi = bed[i];
  const vec4 fOld = flux[i];
  vec4 f = vec4(0.0);
  float sum = 0.0;
  for (int d = 0; d < 4; ++d) {
    const ivec2 q = p + kDir[d];
    const float len = d < 2 ? cellDx(p.y) : P.dyM;
    float dH;
    if (insideGrid(q)) {
      const int j = cellOf(q);
      const float hj = state[j].x, bj = bed[j];
      dH = (bi - bj) + (hi - hj);
      const float noise = kHeadNoise * max(max(abs(bi), abs(bj)), max(hi, hj));
      if (abs(dH) <= noise) dH = 0.0;
    } else if ((P.openEdges & (1u << uint(d))) != 0u) {
      dH = hi;  // a dry ghost cell at the same bed level: free outflow
    } else {
      continue;
    }
    f[d] = max(0.0, fOld[d] + dt * A * g * dH / len);
    sum += f[d];
  }
  // W1b: optional diagonal pipes to the four corner neighbours (closed at the edges).
  vec4 fd = vec4(0.0);
  if (P.diagonalPipes != 0u) {
    const float len = sqrt(cellDx(p.y) * cellDx(p.y) + P.dyM * P.dyM);
    const vec4 fdOld = fluxDiag[i];
    for (int k = 0; k < 4; ++k) {
      const ivec2 q = p + kDiag[k];
      if (!insideGrid(q)) continue;
      const int j = cellOf(q);
      const float hj = state[j].x, bj = bed[j];
      float dH = (bi - bj) + (hi - hj);
      const float noise = kHeadNoise * max(max(abs(bi), abs(bj)), max(hi, hj));
      if (abs(dH) <= noise) dH = 0.0;
      fd[k] = max(0.0, fdOld[k] + dt * Ad * g * dH / len);
      sum += fd[k];
    }
  }
  const float K = sum > 0.0 ? min(1.0, hi * cellArea(p.y) / (sum * dt)) : 0.0;
  flux[i] = f * K;
  fluxDiag[i] = fd * K;
}
