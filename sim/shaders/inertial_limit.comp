#version 450
// Flood mode, local-inertial scheme, W25: fv_limit.comp's share K of its outgoing discharges each
// cell can give, from inertial_face.comp's faces, one float each (W36: the face buffers packed).
#include "sim.glsl"
#include "sim_limit_share.glsl"
layout(local_size_x = SIM_GROUP_X, local_size_y = SIM_GROUP_Y) in;
layout(std430, binding = SLOT_STATE_IN) readonly buffer StateIn { vec4 state[]; };
layout(std430, binding = SLOT_FACE_X) readonly buffer FaceX { float faceX[]; };
layout(std430, binding = SLOT_FACE_Y) readonly buffer FaceY { float faceY[]; };
layout(std430, binding = SLOT_FV_LIMIT) writeonly buffer Limit { float limit_[]; };

void main() {
  const ivec2 p = ivec2(gl_GlobalInvocationID.xy);
  if (!insideGrid(p)) return;
  const int i = cellOf(p), w = P.width;
  limit_[i] = limitShare(p, state[i].x, faceX[p.y * (w + 1) + p.x], faceX[p.y * (w + 1) + p.x + 1],
                         faceY[p.y * w + p.x], faceY[(p.y + 1) * w + p.x]);
}
