// Uniforms and helpers shared by the terrain renderers (ring.vert, grid.vert, terrain.frag).
// Frames: every position is relative to the viewer, in the east-north-up frame at the point
// under the viewer (x east, y north, z up, metres), so float precision is spent where the
// viewer is (docs/render-rings.md, "Precision"). Set by strata::render::terrain (C++).

layout(binding = 0) uniform sampler2D uHeight;  // elevation (m), r32f, full mip chain

uniform mat4 uViewProj;       // viewer-relative metres -> clip (reversed-Z)
uniform int uPlanetary;       // 0: planar (a local tangent plane), 1: on a sphere of radius uRadius
uniform float uExaggeration;  // vertical exaggeration of elevations
uniform float uCamZ;          // planar: viewer z (m above the datum); planetary: viewer height above the sphere
uniform vec2 uUvCam;          // texture coordinates under the viewer
uniform vec2 uUvPerMetre;     // planar: d(u, v) / d(east, north) (v grows southwards: y < 0)
uniform vec2 uTexSize;        // texels of level 0
uniform int uWrapU;           // 1: the DEM wraps around in longitude (global, planetary)
uniform float uRadius;        // planetary: sphere radius (m)
uniform vec2 uCamLonLat;      // planetary: viewer longitude, latitude (radians; for sines and cosines only)
uniform vec4 uGeoToUv;        // planetary: u = (lon - x) * y, v = (lat - z) * w (radians); x, z only for shading

// Longitude and latitude (radians) of the point at great-circle angle `gamma` from the viewer's
// nadir in direction `dir` (unit east, north), RELATIVE to the nadir's: written so that no
// absolute angle is rounded (at 10,000 km from the centre a float radian is 0.6 m), hence no
// jitter when the viewer moves by less than that (docs/render-rings.md, "Precision").
vec2 deltaLonLatAt(float gamma, vec2 dir) {
  float sl = sin(uCamLonLat.y), cl = cos(uCamLonLat.y);
  float s = sin(0.5 * gamma);
  float e = sin(gamma) * dir.x, n = sin(gamma) * dir.y, u = 1.0 - 2.0 * s * s;
  float x = u * cl - n * sl;                // towards the viewer's meridian in the equator plane
  float rho = sqrt(x * x + e * e);          // cos(latitude)
  float z = n * cl + u * sl;                // sin(latitude)
  float sinD = n - sl * e * e / (rho + x);  // sin(lat - lat0) without cancellation
  float cosD = rho * cl + z * sl;
  return vec2(atan(e, x), atan(sinD, cosD));
}

// Texture coordinates of the terrain point at horizontal distance `dist` (planar: metres on
// the plane; planetary: metres of arc) in direction `dir` from the viewer's nadir, relative
// to the texture coordinates under the viewer (computed in double on the CPU).
vec2 uvAt(float dist, vec2 dir) {
  if (uPlanetary == 0) return uUvCam + dir * dist * uUvPerMetre;
  vec2 d = deltaLonLatAt(dist / uRadius, dir);
  return uUvCam + vec2(d.x * uGeoToUv.y, d.y * uGeoToUv.w);
}

// The viewer-relative position of the terrain point at distance `dist` in direction `dir`
// with elevation `elevM` (not yet exaggerated). Planetary: the drop of the sphere below the
// tangent plane is written as 2 sin^2(gamma/2), which keeps metre precision near the viewer.
vec3 positionAt(float dist, vec2 dir, float elevM, out vec3 up) {
  float z = uExaggeration * elevM;
  if (uPlanetary == 0) {
    up = vec3(0.0, 0.0, 1.0);
    return vec3(dir * dist, z - uCamZ);
  }
  float gamma = dist / uRadius;
  float re = uRadius + z;
  float s = sin(0.5 * gamma);
  up = vec3(sin(gamma) * dir, cos(gamma));
  return vec3(re * sin(gamma) * dir, z - uCamZ - re * 2.0 * s * s);
}
