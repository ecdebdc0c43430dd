// Uniforms and helpers shared by the terrain renderers (ring.vert, grid.vert, terrain.frag).
// Frames: every position is relative to the viewer, in the east-north-up frame at the point
// under the viewer (x east, y north, z up, metres), so float precision is spent where the
// viewer is (docs/render-rings.md, "Precision"). Set by strata::render::terrain (C++).

layout(binding = 0) uniform sampler2D uHeight;  // elevation (m), r32f, full mip chain; streamed: level C of it

uniform mat4 uViewProj;       // viewer-relative metres -> clip (reversed-Z)
uniform int uPlanetary;       // 0: planar (a local tangent plane), 1: on the body's ellipsoid
uniform float uExaggeration;  // vertical exaggeration of elevations
uniform float uCamZ;          // planar: viewer z (m above the datum); planetary: viewer height above the sphere
uniform vec2 uUvCam;          // texture coordinates under the viewer
uniform vec2 uUvPerMetre;     // planar: d(u, v) / d(east, north) (v grows southwards: y < 0)
uniform vec2 uTexSize;        // texels of level 0
uniform int uWrapU;           // 1: the DEM wraps around in longitude (global, planetary)
uniform float uRadius;        // planetary: equatorial radius a (m)
uniform float uFlattening;    // planetary: f = (a - b) / a (0: a sphere)
uniform vec2 uCamLonLat;      // planetary: viewer longitude, REDUCED latitude (radians; for sines and cosines only)
uniform vec3 uPoleAux;        // planetary: unit polar axis in the nadir frame of the auxiliary sphere
uniform vec3 uNadirNormal;    // planetary: ellipsoid normal at the nadir, same frame
uniform mat3 uFrameRot;       // planetary: nadir frame of the auxiliary sphere -> the viewer's ENU frame
uniform vec4 uGeoToUv;        // planetary: u = (lon - x) * y, v = (lat - z) * w (radians); x, z only for shading

// Streamed elevation (StreamedElevation, docs/render-rings.md "Streaming"): levels 0..C-1 are
// N x N windows of a texture array addressed toroidally (level texel g at g mod N), each cut
// into P x P pages whose residency uClipPages records; level C and coarser are uHeight's mips.
layout(binding = 3) uniform sampler2DArray uClip;         // r32f, N x N, layer l = level l
layout(binding = 4) uniform usampler2DArray uClipPages;  // 1 where the page slot holds its window's page
uniform int uStreamed;           // 1: sample the stack (uClip, uClipPages) and uHeight from level C
uniform int uClipCoarse;         // C
uniform float uClipSize;         // N (texels)
uniform int uPageShift;          // log2(P)
uniform ivec2 uClipOrigin[16];   // window corner of level l (level texels, a multiple of P)
uniform vec2 uCoarseUvScale;     // uv -> uHeight's texture coordinates (1 unless streamed)

// Level-l texel coordinates of `uv`, clamped to the level's extent as GL_CLAMP_TO_EDGE would
// (not in x when the DEM wraps in longitude: the windows continue across the seam).
vec2 levelTexel(vec2 uv, int l) {
  vec2 size = ceil(uTexSize / exp2(float(l)));
  vec2 p = uv * uTexSize / exp2(float(l));
  vec2 q = clamp(p, vec2(0.5), size - 0.5);
  return vec2(uWrapU != 0 ? p.x : q.x, q.y);
}

// Whether bilinear sampling of level l at level texel p only touches resident pages.
bool clipResident(int l, vec2 p) {
  ivec2 i0 = ivec2(floor(p - 0.5)), i1 = i0 + 1;
  ivec2 o = uClipOrigin[l];
  int n = int(uClipSize);
  if (any(lessThan(i0, o)) || any(greaterThanEqual(i1, o + n))) return false;
  int k = n >> uPageShift;
  // Slots: page index modulo k, floored (columns can be negative across the seam; GLSL's % is
  // undefined for negative operands, and >> on ints is arithmetic: a floored division).
  ivec2 pa = i0 >> uPageShift, pb = i1 >> uPageShift;
  ivec2 a = pa - k * ivec2(floor(vec2(pa) / float(k))), b = pb - k * ivec2(floor(vec2(pb) / float(k)));
  return texelFetch(uClipPages, ivec3(a, l), 0).r != 0u && texelFetch(uClipPages, ivec3(b.x, a.y, l), 0).r != 0u &&
         texelFetch(uClipPages, ivec3(a.x, b.y, l), 0).r != 0u && texelFetch(uClipPages, ivec3(b, l), 0).r != 0u;
}

float clipSample(int l, vec2 uv) {
  if (l >= uClipCoarse) return textureLod(uHeight, uv * uCoarseUvScale, 0.0).r;
  return textureLod(uClip, vec3(levelTexel(uv, l) / uClipSize, float(l)), 0.0).r;
}

// Elevation at `uv`, MIP level `lod`, from the stack: the finest resident level at or above
// floor(lod) (a late page shows a coarser stand-in, never a hole), blended towards the next
// level as trilinear filtering would when the wanted level itself is resident.
float streamedHeight(vec2 uv, float lod) {
  if (lod >= float(uClipCoarse)) return textureLod(uHeight, uv * uCoarseUvScale, lod - float(uClipCoarse)).r;
  int lo = int(floor(lod));
  int l = lo;
  while (l < uClipCoarse && !clipResident(l, levelTexel(uv, l))) ++l;
  float h = clipSample(l, uv);
  float t = lod - float(lo);
  if (l > lo || t <= 0.0) return h;
  if (l + 1 < uClipCoarse && !clipResident(l + 1, levelTexel(uv, l + 1))) return h;
  return mix(h, clipSample(l + 1, uv), t);
}

// Elevation (m) at texture coordinates `uv`, MIP level `lod`: the whole-DEM texture, or the stack.
float terrainHeight(vec2 uv, float lod) {
  if (uStreamed != 0) return streamedHeight(uv, max(lod, 0.0));
  return textureLod(uHeight, uv, lod).r;
}

// Longitude and latitude (radians) of the point at great-circle angle `gamma` from the viewer's
// nadir in direction `dir` (unit east, north), RELATIVE to the nadir's: written so that no
// absolute angle is rounded (at 10,000 km from the centre a float radian is 0.6 m), hence no
// jitter when the viewer moves by less than that (docs/render-rings.md, "Precision"). On an
// ellipsoid these are angles on the auxiliary sphere: longitude and reduced latitude.
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
  // Reduced -> geodetic latitude difference, tan(phi) = tan(beta) / (1 - f): scaled by
  // d(phi)/d(beta) at the midpoint (exact for a sphere; second order otherwise).
  float g = 1.0 - uFlattening, bm = uCamLonLat.y + 0.5 * d.y;
  float dPhi = d.y * g / (g * g * cos(bm) * cos(bm) + sin(bm) * sin(bm));
  return uUvCam + vec2(d.x * uGeoToUv.y, dPhi * uGeoToUv.w);
}

// The viewer-relative position of the terrain point at distance `dist` in direction `dir`
// with elevation `elevM` (not yet exaggerated). Planetary: the point is placed on the auxiliary
// sphere relative to the nadir's point (the drop below the tangent plane written as
// 2 sin^2(gamma/2), which keeps metre precision near the viewer), the ellipsoid is the one more
// transform (polar components scaled by 1 - f, linear, so relative vectors stay relative), and
// the elevation goes along the ellipsoid normal.
vec3 positionAt(float dist, vec2 dir, float elevM, out vec3 up) {
  float z = uExaggeration * elevM;
  if (uPlanetary == 0) {
    up = vec3(0.0, 0.0, 1.0);
    return vec3(dir * dist, z - uCamZ);
  }
  float gamma = dist / uRadius;
  float s = sin(0.5 * gamma);
  vec3 v = uRadius * vec3(sin(gamma) * dir, -2.0 * s * s);  // from the nadir's surface point
  vec3 q = uRadius * vec3(sin(gamma) * dir, cos(gamma));    // from the centre
  v -= uFlattening * dot(v, uPoleAux) * uPoleAux;
  q -= uFlattening * dot(q, uPoleAux) * uPoleAux;
  float g = 1.0 - uFlattening;
  vec3 n = normalize(q + (1.0 / (g * g) - 1.0) * dot(q, uPoleAux) * uPoleAux);
  up = uFrameRot * n;
  return uFrameRot * (v + z * n - uCamZ * uNadirNormal);
}
