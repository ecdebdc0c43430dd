#version 450
// Flood mode: fluxes on every face (W13-W16) from reconstructed sides (W21), ghost cells at the
// edges (W17). Each invocation owns its cell's east and south faces, plus the west face in
// column 0 and the north face in row 0. average = 1 (Heun corrector, W22): face = (old + new)/2.
#include "sim.glsl"
layout(local_size_x = SIM_GROUP_X, local_size_y = SIM_GROUP_Y) in;
layout(std430, binding = SLOT_BED) readonly buffer Bed { float bed[]; };
layout(std430, binding = SLOT_STATE_IN) readonly buffer StateIn { vec4 state[]; };  // U0 or U1, bound by the host
layout(std430, binding = SLOT_FACE_X) buffer FaceX { vec4 faceX[]; };
layout(std430, binding = SLOT_FACE_Y) buffer FaceY { vec4 faceY[]; };
uniform int average;
vec4 stateAt(int which, int i) { return state[i]; }
#include "sim_fv.glsl"

// W17: a wall mirrors the normal velocity; an open edge copies the cell, outflow only.
vec4 edgeFlux(Side inside, bool ghostOnRight, bool open_) {
  Side ghost = inside;
  ghost.un = open_ ? (ghostOnRight ? max(inside.un, 0.0) : min(inside.un, 0.0)) : -inside.un;
  vec4 f = ghostOnRight ? hllFace(inside, ghost) : hllFace(ghost, inside);
  if (open_) f.x = ghostOnRight ? max(f.x, 0.0) : min(f.x, 0.0);
  return f;
}
vec4 blendX(int k, vec4 f) { return average != 0 ? 0.5 * (faceX[k] + f) : f; }
vec4 blendY(int k, vec4 f) { return average != 0 ? 0.5 * (faceY[k] + f) : f; }

void main() {
  const ivec2 p = ivec2(gl_GlobalInvocationID.xy);
  if (!insideGrid(p)) return;
  const int w = P.width;
  const Side east = faceSide(0, p, 1);
  const int kE = p.y * (w + 1) + p.x + 1;
  faceX[kE] = blendX(kE, p.x + 1 < w ? hllFace(east, faceSide(0, p + ivec2(1, 0), 0))
                                     : edgeFlux(east, true, (P.openEdges & 2u) != 0u));
  if (p.x == 0) {
    const int kW = p.y * (w + 1);
    faceX[kW] = blendX(kW, edgeFlux(faceSide(0, p, 0), false, (P.openEdges & 1u) != 0u));
  }
  const Side south = faceSide(0, p, 3);
  const int kS = (p.y + 1) * w + p.x;
  faceY[kS] = blendY(kS, p.y + 1 < P.height ? hllFace(south, faceSide(0, p + ivec2(0, 1), 2))
                                            : edgeFlux(south, true, (P.openEdges & 8u) != 0u));
  if (p.y == 0) {
    const int kN = p.x;
    faceY[kN] = blendY(kN, edgeFlux(faceSide(0, p, 2), false, (P.openEdges & 4u) != 0u));
  }
}
