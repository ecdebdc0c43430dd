#version 450
// The ring renderer's vertex shader: the fixed polar mesh (RingMesh) placed around the viewer.
// Circles are equidistant in the angle seen from a softened viewpoint at height H = f(h) above
// the nadir, so r = H tan(rho * alphaMax) on a plane (on a sphere: the ray from the softened
// viewpoint meets the sphere); elevations are averaged over several samples spanning the gap
// to the neighbouring circles, at a MIP level that keeps the texel density per sample interval
// that of the first circle. The maths: docs/render-rings.md.
#include "terrain_common.glsl"

layout(location = 0) in vec2 aPolar;  // (normalised radius i/n, angle from east towards north)

uniform float uCircles;       // n
uniform float uAlphaMax;      // half-angle of the cap (radians), seen from the softened viewpoint
uniform float uSoftH;         // softened viewer height H = f(h) (m)
uniform float uSoftK;         // planetary: (R + H)^2 - R^2 = H (2R + H) (m^2)
uniform float uFirstSpacingM; // radius of circle 1 (m)
uniform float uTexelM;        // texel size of level 0 (m)
uniform int uMaxSamples;      // cap on the samples per vertex
uniform int uFlags;           // bit 0: multi-sampling, bit 1: MIP selection

out VertexData {
  vec3 rel;
  vec2 uv;
  float lod;
  float elev;
  vec3 up;
}
vs;

// Distance from the nadir (planar: metres on the plane; planetary: metres of arc) of the
// circle at normalised radius rho.
float radiusAt(float rho) {
  float a = rho * uAlphaMax;
  if (uPlanetary == 0) return uSoftH * tan(a);
  float d = uRadius + uSoftH;
  float c = cos(a), s = sin(a);
  // Ray from the viewpoint at distance d from the centre, angle a from the nadir, meets the
  // sphere at t = (d^2 - R^2) / (d cos a + sqrt(d^2 cos^2 a - (d^2 - R^2))) (no cancellation).
  float t = uSoftK / (d * c + sqrt(max(d * d * c * c - uSoftK, 0.0)));
  return uRadius * atan(t * s, d - t * c);
}

void main() {
  float rho = aPolar.x;
  vec2 dir = vec2(cos(aPolar.y), sin(aPolar.y));
  float step = 1.0 / uCircles;
  float r = radiusAt(rho);
  // Spacing to the neighbouring circles (one-sided at the centre and at the rim).
  float spacing;
  if (rho <= 0.0) {
    spacing = radiusAt(step);
  } else if (rho >= 1.0 - 0.5 * step) {
    spacing = r - radiusAt(rho - step);
  } else {
    spacing = 0.5 * (radiusAt(rho + step) - radiusAt(rho - step));
  }
  int samples = 1;
  if ((uFlags & 1) != 0) samples = clamp(int(ceil(spacing / uFirstSpacingM)), 1, uMaxSamples);
  float lod = 0.0;
  if ((uFlags & 2) != 0) lod = max(0.0, log2(spacing / max(uFirstSpacingM, uTexelM)));

  float elev = 0.0;
  if (rho <= 0.0) {
    // The centre vertex averages a small ring of samples (it has no radial direction).
    for (int k = 0; k < samples; ++k) {
      float a = 6.2831853 * (float(k) + 0.5) / float(samples);
      elev += terrainHeight(uvAt(0.25 * spacing * float(samples > 1), vec2(cos(a), sin(a))), lod);
    }
  } else {
    for (int k = 0; k < samples; ++k) {
      float d = r + spacing * ((float(k) + 0.5) / float(samples) - 0.5);
      elev += terrainHeight(uvAt(d, dir), lod);
    }
  }
  elev /= float(samples);

  vs.uv = uvAt(r, dir);
  vs.lod = lod;
  vs.elev = elev;
  vs.rel = positionAt(r, dir, elev, vs.up);
  gl_Position = uViewProj * vec4(vs.rel, 1.0);
}
