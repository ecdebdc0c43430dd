// The local-inertial scheme's face discharge (W30-W32); sim/src/cpu_water.cpp's inertialFace and
// inertialEdgeFace are the same code in C++ (the CPU's h^(1/3) is cubeRoot, here pow).

// W30-W31: the discharge per unit width (m^2/s, + towards b) on the face between cells a (west /
// north) and b, `dist` apart, which carried q0 last step while qt crossed it: q* = q0 - g hf dt
// deta / dist, then Manning friction implicit on the magnitude (backward Euler, as W19); 0 when
// the water above the higher bed is dry.
float inertialFace(float q0, float qt, float ba, float ha, float bb, float hb, float dist, float dtg, float n2) {
  const float ea = ba + ha, eb = bb + hb;
  const float hf = max(ea, eb) - max(ba, bb);
  float dEta = eb - ea;
  dEta = abs(dEta) <= kHeadNoise * max(abs(ea), abs(eb)) ? 0.0 : dEta;
  const bool wet = hf > P.dryDepthM;
  const float hw = wet ? hf : 1.0;
  const float qStar = q0 - dtg * hw * dEta / dist;
  const float a = dtg * n2 / (hw * hw * pow(hw, 1.0 / 3.0));
  const float c = 0.5 + 0.5 * sqrt(1.0 + 4.0 * a * sqrt(qStar * qStar + qt * qt));
  return wet ? qStar / c : 0.0;
}

// W32: out through an open edge (>= 0, away from the grid) of an edge cell (bed be, depth he)
// whose inner neighbour's surface is etaIn: a ghost cell continues the water surface's slope.
float inertialEdgeFace(float q0Out, float qt, float be, float he, float etaIn, float dist, float dtg, float n2) {
  const float eta = be + he;
  return max(inertialFace(q0Out, qt, be, he, be, he - (etaIn - eta), dist, dtg, n2), 0.0);
}
