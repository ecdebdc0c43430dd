// W25: the share K = min(1, h A / (outflow dt)) of its outgoing mass fluxes cell p can give
// without going below zero, from its four faces' mass fluxes per unit width (+ east / south) and
// its depth (fv_limit.comp, inertial_limit.comp).
float limitShare(ivec2 p, float h, float fW, float fE, float fN, float fS) {
  const float outVol = ((max(-fW, 0.0) + max(fE, 0.0)) * P.dyM + max(-fN, 0.0) * faceWidthY(p.y) +
                        max(fS, 0.0) * faceWidthY(p.y + 1)) * P.dtS;
  const float have = h * cellArea(p.y);
  return outVol > have ? have / outVol : 1.0;
}
