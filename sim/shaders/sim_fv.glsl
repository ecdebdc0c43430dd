// Flood mode (finite volumes): reconstruction (W21) and the HLL flux with hydrostatic
// reconstruction (W13-W16). The including shader defines `vec4 stateAt(int which, int i)`
// (which = 0: U0, 1: the Heun predictor U1) and declares `bed`.
vec4 stateAt(int which, int i);

struct Side {
  float h, eta, un, ut;  // depth, surface, normal and tangential velocity at a face
};

// W21 slopes from the backward and forward differences a, b (0 at an extremum): minmod, the
// smaller one, or van Leer's monotonised central (MC), sign * min(2|a|, 2|b|, |a + b| / 2).
float limitedSlope(float a, float b) {
  if (a * b <= 0.0) return 0.0;
  if (P.slopeLimiter == 1) return sign(a) * min(min(2.0 * abs(a), 2.0 * abs(b)), 0.5 * abs(a + b));
  return abs(a) < abs(b) ? a : b;
}

Side primOf(int which, ivec2 c, int dir) {
  const int i = cellOf(c);
  const vec4 s = stateAt(which, i);
  const float u = velocityOf(s.x, s.z), v = velocityOf(s.x, s.w);
  return dir < 2 ? Side(s.x, bed[i] + s.x, u, v) : Side(s.x, bed[i] + s.x, v, u);
}

// W21: cell c's value at its face dir (W, E, N, S): limited slopes along the face normal. A cell
// on the grid's edge along the normal has one neighbour: W27, at an open edge its depth and
// surface continue the slope from that neighbour (the depth's bounded so that neither face goes
// below zero); anything else is first order there.
Side faceSide(int which, ivec2 c, int dir) {
  Side m0 = primOf(which, c, dir);
  const ivec2 a = dir < 2 ? ivec2(1, 0) : ivec2(0, 1);
  const bool lo = !insideGrid(c - a), hi = !insideGrid(c + a);
  const float half_ = (dir == 1 || dir == 3) ? 0.5 : -0.5;
  if (lo || hi) {
    const uint openLow = dir < 2 ? 1u : 4u, openHigh = dir < 2 ? 2u : 8u;  // W, E / N, S bits
    if (lo == hi || (P.openEdges & (lo ? openLow : openHigh)) == 0u) return m0;
    const Side n = primOf(which, lo ? c + a : c - a, dir);
    const float sh = lo ? n.h - m0.h : m0.h - n.h, se = lo ? n.eta - m0.eta : m0.eta - n.eta;
    m0.h += half_ * clamp(sh, -2.0 * m0.h, 2.0 * m0.h);
    m0.eta += half_ * se;
    return m0;
  }
  const Side m = primOf(which, c - a, dir), pp = primOf(which, c + a, dir);
  m0.h += half_ * limitedSlope(m0.h - m.h, pp.h - m0.h);
  m0.eta += half_ * limitedSlope(m0.eta - m.eta, pp.eta - m0.eta);
  m0.un += half_ * limitedSlope(m0.un - m.un, pp.un - m0.un);
  m0.ut += half_ * limitedSlope(m0.ut - m.ut, pp.ut - m0.ut);
  return m0;
}

// W13-W16: (mass flux, normal momentum flux for the left cell, for the right cell, tangential).
vec4 hllFace(Side L, Side R) {
  const float g = P.gravityMS2, dry = P.dryDepthM;
  const float hL = L.h, hR = R.h, unL = L.un, unR = R.un;
  const float bL = L.eta - L.h, bR = R.eta - R.h;
  const float dbLR = bR - bL;
  const float hLs = max(0.0, hL - max(0.0, dbLR));
  const float hRs = max(0.0, hR - max(0.0, -dbLR));
  float fh = 0.0, fn = 0.0, ft = 0.0;
  if (hLs > dry || hRs > dry) {
    const float cL = sqrt(g * hLs), cR = sqrt(g * hRs);
    float sL, sR;
    if (hLs <= dry) {
      sL = unR - 2.0 * cR;
      sR = unR + cR;
    } else if (hRs <= dry) {
      sL = unL - cL;
      sR = unL + 2.0 * cL;
    } else {
      sL = min(unL - cL, unR - cR);
      sR = max(unL + cL, unR + cR);
    }
    const float qL = hLs * unL, qR = hRs * unR;
    const float fLn = qL * unL + 0.5 * g * hLs * hLs, fRn = qR * unR + 0.5 * g * hRs * hRs;
    if (sL >= 0.0) {
      fh = qL;
      fn = fLn;
    } else if (sR <= 0.0) {
      fh = qR;
      fn = fRn;
    } else {
      const float inv = 1.0 / (sR - sL);
      fh = (sR * qL - sL * qR + sL * sR * (hRs - hLs)) * inv;
      fn = (sR * fLn - sL * fRn + sL * sR * (qR - qL)) * inv;
    }
    ft = fh > 0.0 ? fh * L.ut : fh * R.ut;
  }
  return vec4(fh, fn + 0.5 * g * (hL * hL - hLs * hLs), fn + 0.5 * g * (hR * hR - hRs * hRs), ft);
}
