#version 450
// W3: depth from the net pipe flow, W4: velocity from the mean flow through the cell,
// E5: suspended sediment carried with each pipe's share of the water (upwind, conservative),
// E0: bed tilt. Reads stateIn and fluxes (also of neighbours), writes stateOut: no races.
#include "sim.glsl"
#include "sim_accum.glsl"
layout(local_size_x = SIM_GROUP_X, local_size_y = SIM_GROUP_Y) in;
layout(std430, binding = SLOT_BED) readonly buffer Bed { float bed[]; };
layout(std430, binding = SLOT_STATE_IN) readonly buffer StateIn { vec4 state[]; };
layout(std430, binding = SLOT_STATE_OUT) writeonly buffer StateOut { vec4 stateOut[]; };
layout(std430, binding = SLOT_FLUX) readonly buffer Flux { vec4 flux[]; };
layout(std430, binding = SLOT_FLUX_DIAG) readonly buffer FluxDiag { vec4 fluxDiag[]; };
layout(std430, binding = SLOT_TILT) writeonly buffer Tilt { float tilt[]; };
#include "sim_tilt.glsl"

float outTotal(int j) {
  const vec4 f = flux[j];
  float out_ = f.x + f.y + f.z + f.w;
  if (P.diagonalPipes != 0u) {
    const vec4 fd = fluxDiag[j];
    out_ += fd.x + fd.y + fd.z + fd.w;
  }
  return out_;
}

// Share of cell q's water (and so of its suspended sediment) leaving through pipe d this step:
// d < 4 axis pipes, d >= 4 diagonal pipes (W1b).
float fraction(ivec2 q, int d) {
  const int j = cellOf(q);
  const float out_ = outTotal(j) * P.dtS;
  const float den = max(state[j].x * cellArea(q.y), out_);
  const float f = d < 4 ? flux[j][d] : fluxDiag[j][d - 4];
  return den > 0.0 ? f * P.dtS / den : 0.0;
}

void main() {
  const ivec2 p = ivec2(gl_GlobalInvocationID.xy);
  if (!insideGrid(p)) return;
  const int i = cellOf(p);
  const float dt = P.dtS, dry = P.dryDepthM, A = cellArea(p.y);
  const float h = state[i].x, s = state[i].y;
  const vec4 f = flux[i];
  float inflow = 0.0, sIn = 0.0, sOut = 0.0;
  vec4 inD = vec4(0.0);
  for (int d = 0; d < 4; ++d) {
    const ivec2 q = p + kDir[d];
    const float fr = fraction(p, d);
    if (insideGrid(q)) {
      inD[d] = flux[cellOf(q)][d ^ 1];
      inflow += inD[d];
      sIn += state[cellOf(q)].y * cellArea(q.y) * fraction(q, d ^ 1);
    } else if (f[d] > 0.0) {
      kahanAdd(accumAt(i, ACCUM_OUTFLOW), f[d] * dt);
      kahanAdd(accumAt(i, ACCUM_SEDIMENT_OUT), s * A * fr);
    }
    sOut += fr;
  }
  float qxDiag = 0.0, qyDiag = 0.0;
  if (P.diagonalPipes != 0u) {
    const float len = sqrt(cellDx(p.y) * cellDx(p.y) + P.dyM * P.dyM);
    for (int k = 0; k < 4; ++k) {
      const ivec2 q = p + kDiag[k];
      if (!insideGrid(q)) continue;
      const float inK = fluxDiag[cellOf(q)][3 - k];
      inflow += inK;
      sIn += state[cellOf(q)].y * cellArea(q.y) * fraction(q, 4 + (3 - k));
      sOut += fraction(p, 4 + k);
      const float net = fluxDiag[i][k] - inK;
      qxDiag += 0.5 * net * float(kDiag[k].x) * cellDx(p.y) / len;
      qyDiag += 0.5 * net * float(kDiag[k].y) * P.dyM / len;
    }
  }
  const float outflow = outTotal(i);
  const float hNew = max(0.0, h + dt * (inflow - outflow) / A);
  const float sNew = s - s * sOut + sIn / A;
  const float hMean = 0.5 * (h + hNew);
  const float qx = 0.5 * (inD[0] - f.x + f.y - inD[1]) + qxDiag;
  const float qy = 0.5 * (inD[2] - f.z + f.w - inD[3]) + qyDiag;
  float u = 0.0, v = 0.0;
  if (hMean > dry) {
    u = qx / (P.dyM * hMean);
    v = qy / (cellDx(p.y) * hMean);
  }
  stateOut[i] = vec4(hNew, sNew, u * hNew, v * hNew);
  tilt[i] = sinTilt(p);
}
