#version 450
// Flood mode, W25: after the corrector's faces, the share K = min(1, h A / (outflow dt)) of its
// outgoing mass fluxes each cell can give without going below zero (as the pipe model's W2);
// fv_update.comp scales each face's mass flux by its upwind cell's K, so no depth is clipped.
#include "sim.glsl"
#include "sim_limit_share.glsl"
layout(local_size_x = SIM_GROUP_X, local_size_y = SIM_GROUP_Y) in;
layout(std430, binding = SLOT_STATE_IN) readonly buffer StateIn { vec4 state[]; };
layout(std430, binding = SLOT_FACE_X) readonly buffer FaceX { vec4 faceX[]; };
layout(std430, binding = SLOT_FACE_Y) readonly buffer FaceY { vec4 faceY[]; };
layout(std430, binding = SLOT_FV_LIMIT) writeonly buffer Limit { float limit_[]; };

void main() {
  const ivec2 p = ivec2(gl_GlobalInvocationID.xy);
  if (!insideGrid(p)) return;
  const int i = cellOf(p), w = P.width;
  const float fW = faceX[p.y * (w + 1) + p.x].x, fE = faceX[p.y * (w + 1) + p.x + 1].x;
  const float fN = faceY[p.y * w + p.x].x, fS = faceY[(p.y + 1) * w + p.x].x;
  limit_[i] = limitShare(p, state[i].x, fW, fE, fN, fS);
}
