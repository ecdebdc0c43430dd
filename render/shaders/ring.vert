#version 450
// The ring renderer's vertex shader: the fixed polar mesh (RingMesh) placed around the viewer.
// Circles are equidistant in the angle seen from a softened viewpoint at height H = f(h) above
// the nadir, so r = H tan(rho * alphaMax) on a plane (on a sphere: the ray from the softened
// viewpoint meets the sphere); elevations are averaged over several samples spanning the gap
// to the neighbouring circles, each at the MIP level of its own share of the gap, so that the
// vertex's elevation is its cell's footprint, filtered once. The maths: docs/render-rings.md.
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
  vec2 dt;  // level-0 texels from the viewer
  vec3 sph;  // planetary: direction from the body's centre, nadir frame (sphereDirAt)
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
  // The vertex stands for a cell `spacing` deep (radially) and `across` wide (to its neighbours
  // on the circle). Its elevation is that cell's mean, filtered ONCE: `samples` points spread
  // over the depth, each read at the MIP level whose texels are as large as its share of the
  // depth (or as the cell's width, where that is larger). Reading every sample at the level of
  // the whole depth, as before issue 17, filtered the cell twice (a footprint three times as deep).
  int samples = 1;
  if ((uFlags & 1) != 0) samples = clamp(int(ceil(spacing / uFirstSpacingM)), 1, uMaxSamples);
  float across = rho > 0.0 ? 6.2831853 * r / (6.0 * rho * uCircles) : spacing;
  float lod = 0.0;
  if ((uFlags & 2) != 0) lod = max(0.0, log2(max(spacing / float(samples), across) / uTexelM));

  float elev = 0.0;
  if (rho <= 0.0) {
    // The centre vertex is the ground under the viewer, where the viewer's height above the
    // ground is measured: one sample at the nadir.
    samples = 1;
    lod = (uFlags & 2) != 0 ? max(0.0, log2(spacing / uTexelM)) : 0.0;
    elev = terrainHeight(vec2(0.0), lod);
  } else {
    // On a body, a texel's east-west side is cos(latitude) times its north-south side: the
    // footprint spans 1 / cos(latitude) times as many columns as rows, so each sample averages
    // that many taps along the parallel (at most 8; beyond, a coarser level).
    int taps = 1;
    float tapStep = 0.0;
    float lodHere = lod;
    if (uPlanetary != 0 && (uFlags & 2) != 0) {
      vec3 p = sphereDirAt(r / uRadius, dir);
      float x = p.z * cos(uCamLonLat.y) - p.y * sin(uCamLonLat.y);
      float cosLat = max(sqrt(x * x + p.x * p.x), 1e-6);
      float need = exp2(lod) / cosLat;  // level-0 columns per level-lod row
      taps = clamp(int(ceil(need / exp2(lod))), 1, 8);
      lodHere = max(lod, log2(need / float(taps)));
      tapStep = need / float(taps);
    }
    for (int k = 0; k < samples; ++k) {
      float d = r + spacing * ((float(k) + 0.5) / float(samples) - 0.5);
      vec2 c = dtAt(d, dir);
      for (int t = 0; t < taps; ++t) {
        elev += terrainHeight(c + vec2((float(t) + 0.5 - 0.5 * float(taps)) * tapStep, 0.0), lodHere) / float(taps);
      }
    }
  }
  elev /= float(samples);

  vs.dt = dtAt(r, dir);
  vs.sph = uPlanetary != 0 ? sphereDirAt(r / uRadius, dir) : vec3(0.0, 0.0, 1.0);
  vs.uv = uvOf(vs.dt);
  vs.lod = lod;
  vs.elev = elev;
  vs.rel = positionAt(r, dir, elev, vs.up);
  gl_Position = uViewProj * vec4(vs.rel, 1.0);
}
