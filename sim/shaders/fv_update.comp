#version 450
// Flood mode: W18 conservative update from the face fluxes, W23 centred bed-slope source,
// W24 force noise floor, W25 outflow limits (corrector). final = 0: Heun predictor U1 = U0 - dt L(U0) into `stage`;
// final = 1: U0 - dt (L(U0) + L(U1)) / 2 into stateOut (W22; the depth with compensation, W34),
// then W19 Manning friction, E5 sediment transport, W12b the point sources' second halves, E0
// tilt; the corrector ends with the step's tail when fused (W36, sim_tail.glsl).
#include "sim.glsl"
#include "sim_accum.glsl"
#include "sim_limit.glsl"
#include "sim_tail.glsl"
#include "sim_pour.glsl"
layout(local_size_x = SIM_GROUP_X, local_size_y = SIM_GROUP_Y) in;
layout(std430, binding = SLOT_BED) readonly buffer Bed { float bed[]; };
layout(std430, binding = SLOT_STATE_IN) readonly buffer StateIn { vec4 state[]; };
layout(std430, binding = SLOT_STATE_OUT) writeonly buffer StateOut { vec4 stateOut[]; };
layout(std430, binding = SLOT_STAGE) buffer Stage { vec4 stage[]; };
layout(std430, binding = SLOT_FACE_X) readonly buffer FaceX { vec4 faceX[]; };
layout(std430, binding = SLOT_FACE_Y) readonly buffer FaceY { vec4 faceY[]; };
layout(std430, binding = SLOT_TILT) writeonly buffer Tilt { float tilt[]; };
layout(std430, binding = SLOT_MANNING) readonly buffer Manning { float manningN2[]; };  // n^2 per cell; < 0: P.manningN
uniform int final_;
uniform uint pours;  // W12b: the step has point sources (their second halves wait in ACCUM_POUR)
vec4 stateAt(int which, int i) { return which == 0 ? state[i] : stage[i]; }
#include "sim_fv.glsl"
#include "sim_tilt.glsl"

// W23: centred bed-slope source and the pressure on slanted sides of unequal-width rows.
vec2 bedSource(int which, ivec2 p) {
  const float g = P.gravityMS2, wN = faceWidthY(p.y), wS = faceWidthY(p.y + 1);
  const Side W = faceSide(which, p, 0), E = faceSide(which, p, 1), N = faceSide(which, p, 2), S = faceSide(which, p, 3);
  const float sx = -g * 0.5 * (W.h + E.h) * ((E.eta - W.eta) - (E.h - W.h)) * P.dyM;
  const float sy = -g * 0.5 * (N.h + S.h) * ((S.eta - N.eta) - (S.h - N.h)) * (0.5 * (wN + wS)) +
                   0.5 * g * (0.5 * (N.h * N.h + S.h * S.h)) * (wS - wN);
  return vec2(sx, sy);
}

// Volume rate leaving cell q through its four faces (m^3/s), with W25's limits (corrector only).
float outflowTotal(ivec2 q) {
  const int w = P.width;
  float fW = faceX[q.y * (w + 1) + q.x].x, fE = faceX[q.y * (w + 1) + q.x + 1].x;
  float fN = faceY[q.y * w + q.x].x, fS = faceY[(q.y + 1) * w + q.x].x;
  fW *= limitOfFace(fW, q - ivec2(1, 0), q);
  fE *= limitOfFace(fE, q, q + ivec2(1, 0));
  fN *= limitOfFace(fN, q - ivec2(0, 1), q);
  fS *= limitOfFace(fS, q, q + ivec2(0, 1));
  return (max(-fW, 0.0) + max(fE, 0.0)) * P.dyM + max(-fN, 0.0) * faceWidthY(q.y) + max(fS, 0.0) * faceWidthY(q.y + 1);
}

// The cell's update; true when it wrote the step's final state (the corrector) into `sOut`.
bool updateCell(ivec2 p, out vec4 sOut) {
  const int i = cellOf(p), w = P.width;
  const float dt = P.dtS, g = P.gravityMS2, dry = P.dryDepthM;
  const float n2 = manningN2[i] >= 0.0 ? manningN2[i] : P.manningN * P.manningN;
  const float A = cellArea(p.y), wN = faceWidthY(p.y), wS = faceWidthY(p.y + 1), dy = P.dyM;
  vec4 W = faceX[p.y * (w + 1) + p.x], E = faceX[p.y * (w + 1) + p.x + 1];
  vec4 N = faceY[p.y * w + p.x], S = faceY[(p.y + 1) * w + p.x];
  if (final_ != 0) {  // W25: the mass (and, with it, the tangential momentum) each upwind cell can give
    const float kW = limitOfFace(W.x, p - ivec2(1, 0), p), kE = limitOfFace(E.x, p, p + ivec2(1, 0));
    const float kN = limitOfFace(N.x, p - ivec2(0, 1), p), kS = limitOfFace(S.x, p, p + ivec2(0, 1));
    W.xw *= kW;
    E.xw *= kE;
    N.xw *= kN;
    S.xw *= kS;
  }
  const vec4 s0 = state[i];
  const float h = s0.x, s = s0.y, hu = s0.z, hv = s0.w;
  vec2 src = bedSource(0, p);
  if (final_ != 0) src = 0.5 * (src + bedSource(1, p));
  const float k = dt / A;
  float hNew = final_ != 0 ? addDepthFaces(h, i, k, W.x * dy, E.x * dy, N.x * wN, S.x * wS)
                           : h - k * ((E.x - W.x) * dy + S.x * wS - N.x * wN);
  float fx = src.x - ((E.y - W.z) * dy + S.w * wS - N.w * wN);
  float fy = src.y - (S.y * wS - N.z * wN + (E.w - W.w) * dy);
  const float magX = abs(E.y * dy) + abs(W.z * dy) + abs(S.w * wS) + abs(N.w * wN) + abs(src.x);
  const float magY = abs(S.y * wS) + abs(N.z * wN) + abs(E.w * dy) + abs(W.w * dy) + abs(src.y);
  if (abs(fx) <= kForceNoise * magX) fx = 0.0;
  if (abs(fy) <= kForceNoise * magY) fy = 0.0;
  float huNew = hu + k * fx;
  float hvNew = hv + k * fy;
  hNew = max(hNew, 0.0);
  if (hNew <= dry) {
    huNew = 0.0;
    hvNew = 0.0;
  }
  // W19: Manning friction, implicit, in both stages.
  if (hNew > dry && n2 > 0.0) {
    const float speed = sqrt(huNew * huNew + hvNew * hvNew) / hNew;
    const float c = 0.5 + 0.5 * sqrt(1.0 + 4.0 * (dt * g * n2 * speed / pow(hNew, 4.0 / 3.0)));
    huNew /= c;
    hvNew /= c;
  }
  if (final_ == 0) {
    stage[i] = vec4(hNew, s, huNew, hvNew);
    return false;
  }
  // E5: suspended sediment moves with the water volume crossing each face, upwind.
  const float denI = max(h * A, outflowTotal(p) * dt);
  float sNew = s;
  const float vols[4] = float[4](-W.x * dy * dt, E.x * dy * dt, -N.x * wN * dt, S.x * wS * dt);
  const bool edge[4] = bool[4](p.x == 0, p.x == w - 1, p.y == 0, p.y == P.height - 1);
  for (int d = 0; d < 4; ++d) {
    const float volOut = vols[d];
    if (volOut > 0.0) {
      const float moved = denI > 0.0 ? s * A * volOut / denI : 0.0;
      sNew -= moved / A;
      if (edge[d]) {
        kahanAdd(accumAt(i, ACCUM_OUTFLOW), volOut);
        kahanAdd(accumAt(i, ACCUM_SEDIMENT_OUT), moved);
      }
    } else if (volOut < 0.0 && !edge[d]) {
      const ivec2 q = p + kDir[d];
      const int j = cellOf(q);
      const float Aj = cellArea(q.y);
      const float denJ = max(state[j].x * Aj, outflowTotal(q) * dt);
      if (denJ > 0.0) sNew += state[j].y * Aj * (-volOut) / denJ / A;
    }
  }
  // W12b: the second half of the step's point source, into the new state (its first half came
  // before the predictor's faces).
  const float later = pours != 0u ? accum[pourAt(i)] : 0.0;
  if (later != 0.0) {
    hNew = addDepth(hNew, i, later);
    accum[pourAt(i)] = 0.0;
  }
  sOut = vec4(hNew, sNew, huNew, hvNew);
  stateOut[i] = sOut;
  tilt[i] = sinTilt(p);
  return true;
}

void main() {
  const ivec2 p = ivec2(gl_GlobalInvocationID.xy);
  vec4 s = vec4(0.0);
  const bool wrote = insideGrid(p) && updateCell(p, s);
  stepTail(p, wrote, s);
}
