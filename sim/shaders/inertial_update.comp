#version 450
// Flood mode, local-inertial scheme: the update (W18 with W30's faces, W25 final). Each face's
// discharge scaled by its upwind cell's limit; the depth from their net inflow into stateOut; the
// applied discharges into flux (W, E, N, S: the next step's q0), the depth with compensation
// (W34); the cell's discharge the mean
// of its two faces' on each axis; what leaves through an open edge into the outflow sum (W20);
// the step's tail when fused (W36, sim_tail.glsl).
#include "sim.glsl"
#include "sim_accum.glsl"
#include "sim_limit.glsl"
#include "sim_tail.glsl"
layout(local_size_x = SIM_GROUP_X, local_size_y = SIM_GROUP_Y) in;
layout(std430, binding = SLOT_STATE_IN) readonly buffer StateIn { vec4 state[]; };
layout(std430, binding = SLOT_STATE_OUT) writeonly buffer StateOut { vec4 stateOut[]; };
layout(std430, binding = SLOT_FACE_X) readonly buffer FaceX { float faceX[]; };  // one float a face (W36)
layout(std430, binding = SLOT_FACE_Y) readonly buffer FaceY { float faceY[]; };
layout(std430, binding = SLOT_FLUX) writeonly buffer Flux { vec4 flux[]; };

vec4 updateCell(ivec2 p) {
  const int i = cellOf(p), w = P.width, h = P.height;
  const float dt = P.dtS, A = cellArea(p.y), wN = faceWidthY(p.y), wS = faceWidthY(p.y + 1), dy = P.dyM;
  float fW = faceX[p.y * (w + 1) + p.x], fE = faceX[p.y * (w + 1) + p.x + 1];
  float fN = faceY[p.y * w + p.x], fS = faceY[(p.y + 1) * w + p.x];
  fW *= limitOfFace(fW, p - ivec2(1, 0), p);
  fE *= limitOfFace(fE, p, p + ivec2(1, 0));
  fN *= limitOfFace(fN, p - ivec2(0, 1), p);
  fS *= limitOfFace(fS, p, p + ivec2(0, 1));
  const vec4 s = state[i];
  const float hNew = addDepthFaces(s.x, i, dt / A, fW * dy, fE * dy, fN * wN, fS * wS);
  const vec4 sNew = vec4(hNew, s.y, 0.5 * (fW + fE), 0.5 * (fN + fS));
  stateOut[i] = sNew;
  flux[i] = vec4(fW, fE, fN, fS);
  const float leaving = ((p.x == 0 ? max(-fW, 0.0) : 0.0) + (p.x == w - 1 ? max(fE, 0.0) : 0.0)) * dy * dt +
                    (p.y == 0 ? max(-fN, 0.0) : 0.0) * wN * dt + (p.y == h - 1 ? max(fS, 0.0) : 0.0) * wS * dt;
  if (leaving > 0.0) kahanAdd(accumAt(i, ACCUM_OUTFLOW), leaving);
  return sNew;
}

void main() {
  const ivec2 p = ivec2(gl_GlobalInvocationID.xy);
  const bool inside = insideGrid(p);
  vec4 s = vec4(0.0);
  if (inside) s = updateCell(p);
  stepTail(p, inside, s);
}
