#version 450
// Flood mode, local-inertial scheme (W30-W32): each cell's east and south faces (and the west face
// in column 0, the north face in row 0) from the water surfaces and last step's applied discharges
// (flux: W, E, N, S per cell), into faceX / faceY, one float a face (W36: a quarter of the
// finite-volume scheme's vec4 faces' bytes), unlimited; inertial_limit.comp's W25 follows.
#include "sim.glsl"
#include "sim_inertial.glsl"
layout(local_size_x = SIM_GROUP_X, local_size_y = SIM_GROUP_Y) in;
layout(std430, binding = SLOT_BED) readonly buffer Bed { float bed[]; };
layout(std430, binding = SLOT_STATE_IN) readonly buffer StateIn { vec4 state[]; };
layout(std430, binding = SLOT_FLUX) readonly buffer Flux { vec4 flux[]; };
layout(std430, binding = SLOT_FACE_X) writeonly buffer FaceX { float faceX[]; };
layout(std430, binding = SLOT_FACE_Y) writeonly buffer FaceY { float faceY[]; };
layout(std430, binding = SLOT_MANNING) readonly buffer Manning { float manningN2[]; };  // n^2 per cell; < 0: P.manningN

float n2Of(int i) { return manningN2[i] >= 0.0 ? manningN2[i] : P.manningN * P.manningN; }
float etaOf(int i) { return bed[i] + state[i].x; }

void main() {
  const ivec2 p = ivec2(gl_GlobalInvocationID.xy);
  if (!insideGrid(p)) return;
  const int i = cellOf(p), w = P.width, h = P.height;
  const float dtg = P.dtS * P.gravityMS2, dx = cellDx(p.y), b = bed[i], d = state[i].x, n2 = n2Of(i);
  const vec4 q0 = flux[i];
  // The discharge across each of the cell's faces: the mean of the four nearest faces across
  // (one cell's two at an edge).
  const float acrossX = 0.5 * (q0.z + q0.w), acrossY = 0.5 * (q0.x + q0.y);
  // East face (face p.x + 1 of the row).
  float qE = 0.0;
  if (p.x + 1 < w) {
    const int j = i + 1;
    const float qt = 0.25 * ((q0.z + q0.w) + (flux[j].z + flux[j].w));
    qE = inertialFace(q0.y, qt, b, d, bed[j], state[j].x, dx, dtg, 0.5 * (n2 + n2Of(j)));
  } else if ((P.openEdges & 2u) != 0u) {
    qE = inertialEdgeFace(q0.y, acrossX, b, d, w > 1 ? etaOf(i - 1) : b + d, dx, dtg, n2);
  }
  faceX[p.y * (w + 1) + p.x + 1] = qE;
  if (p.x == 0) {  // the west edge (0 - q keeps a zero +0)
    const float qW = (P.openEdges & 1u) != 0u
                         ? 0.0 - inertialEdgeFace(0.0 - q0.x, acrossX, b, d, w > 1 ? etaOf(i + 1) : b + d, dx, dtg, n2)
                         : 0.0;
    faceX[p.y * (w + 1)] = qW;
  }
  // South face (face row p.y + 1).
  float qS = 0.0;
  if (p.y + 1 < h) {
    const int j = i + w;
    const float qt = 0.25 * ((q0.x + q0.y) + (flux[j].x + flux[j].y));
    qS = inertialFace(q0.w, qt, b, d, bed[j], state[j].x, P.dyM, dtg, 0.5 * (n2 + n2Of(j)));
  } else if ((P.openEdges & 8u) != 0u) {
    qS = inertialEdgeFace(q0.w, acrossY, b, d, h > 1 ? etaOf(i - w) : b + d, P.dyM, dtg, n2);
  }
  faceY[(p.y + 1) * w + p.x] = qS;
  if (p.y == 0) {  // the north edge
    const float qN = (P.openEdges & 4u) != 0u
                         ? 0.0 - inertialEdgeFace(0.0 - q0.z, acrossY, b, d, h > 1 ? etaOf(i + w) : b + d, P.dyM, dtg, n2)
                         : 0.0;
    faceY[p.x] = qN;
  }
}
