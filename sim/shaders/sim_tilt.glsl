// E0: sin of the bed tilt from central differences (one-sided at the edges). Needs `bed`.
float sinTilt(ivec2 p) {
  const int xl = max(p.x - 1, 0), xr = min(p.x + 1, P.width - 1);
  const int yu = max(p.y - 1, 0), yd = min(p.y + 1, P.height - 1);
  const float gx = (bed[cellOf(ivec2(xr, p.y))] - bed[cellOf(ivec2(xl, p.y))]) / (float(xr - xl) * cellDx(p.y));
  const float gy = (bed[cellOf(ivec2(p.x, yd))] - bed[cellOf(ivec2(p.x, yu))]) / (float(yd - yu) * P.dyM);
  const float g2 = gx * gx + gy * gy;
  return sqrt(g2 / (1.0 + g2));
}
