// Uniforms and helpers shared by the terrain renderers (ring.vert, grid.vert, terrain.frag).
// Frames: every position is relative to the viewer, in the east-north-up frame at the point
// under the viewer (x east, y north, z up, metres), so float precision is spent where the
// viewer is (docs/render-rings.md, "Precision"). Set by strata::render::terrain (C++).

layout(binding = SLOT_HEIGHT) uniform sampler2D uHeight;  // elevation (m), r32f, full mip chain; streamed: level C of it

uniform mat4 uViewProj;       // viewer-relative metres -> clip (reversed-Z)
uniform int uPlanetary;       // 0: planar (a local tangent plane), 1: on the body's ellipsoid
uniform float uExaggeration;  // vertical exaggeration of elevations
uniform float uCamZ;          // planar: viewer z (m above the datum); planetary: viewer height above the sphere
uniform vec2 uTexelPerMetre;  // planar: level-0 texels per metre east and north (y < 0: rows grow southwards)
uniform vec2 uTexelPerRad;    // planetary: level-0 texels per radian of longitude and latitude
uniform vec2 uTexSize;        // texels of level 0
uniform int uWrapU;           // 1: the DEM wraps around in longitude (global, planetary)
uniform float uRadius;        // planetary: equatorial radius a (m)
uniform float uFlattening;    // planetary: f = (a - b) / a (0: a sphere)
uniform vec2 uCamLonLat;      // planetary: viewer longitude, REDUCED latitude (radians; for sines and cosines only)
uniform vec3 uPoleAux;        // planetary: unit polar axis in the nadir frame of the auxiliary sphere
uniform vec3 uNadirNormal;    // planetary: ellipsoid normal at the nadir, same frame
uniform mat3 uFrameRot;       // planetary: nadir frame of the auxiliary sphere -> the viewer's ENU frame
uniform vec4 uGeoToUv;        // planetary: u = (lon - x) * y, v = (lat - z) * w (radians), for shading

// Streamed elevation (StreamedElevation, docs/render-rings.md "Streaming"): levels 0..C-1 are
// N x N windows of a texture array addressed toroidally (level texel g at g mod N), each cut
// into P x P pages whose residency uClipPages records; level C and coarser are uHeight's mips.
layout(binding = SLOT_CLIP) uniform sampler2DArray uClip;       // r32f, N x N, layer l = level l
layout(binding = SLOT_CLIP_PAGES) uniform usampler2DArray uClipPages;  // 1 where the page slot holds its window's page
uniform int uStreamed;           // 1: sample the stack (uClip, uClipPages) and uHeight from level C
uniform int uClipCoarse;         // C
uniform int uClipSize;           // N (texels)
uniform int uPageShift;          // log2(P)
uniform ivec2 uClipOrigin[16];   // window corner of level l (level texels, a multiple of P)

// Camera-relative texel addressing (docs/render-rings.md, "Precision"): a terrain point is named
// by its offset `dt` from the viewer in level-0 texels, a small float near the viewer. Level l's
// texel-centre coordinate of the point is the viewer's (split on the CPU, in double, into an
// integer and a fraction) plus dt times the level's scale: texel indices are exact integers and
// the bilinear weights come from small numbers, whatever the size of the texture (a float over
// a whole-planet texture resolves metres, a float offset from the viewer a micrometre there).
uniform int uLevelCount;         // levels: the mip chain (whole DEM), or C plus uHeight's mips (streamed)
uniform ivec2 uCamTexelI[32];    // per level: floor of the viewer's texel-centre coordinate
uniform vec2 uCamTexelF[32];     // per level: the rest, in [0, 1)
uniform vec2 uLevelScale[32];    // per level: its texels per level-0 texel
uniform ivec2 uLevelSize[32];    // per level: texels

// a mod n in [0, n) for any int a (GLSL's % is undefined for negative operands).
int floorMod(int a, int n) {
  if (a < 0) a += n * ((n - 1 - a) / n);
  return a % n;
}

// The texel at integer coordinate i of level l: clamped to the level in y, and in x unless the
// DEM wraps around in longitude (then modulo the width, or, in the stack, the unwrapped index
// the windows use across the seam), as GL_CLAMP_TO_EDGE / GL_REPEAT would.
float levelTexel(int l, ivec2 i) {
  ivec2 size = uLevelSize[l];
  int y = clamp(i.y, 0, size.y - 1);
  if (uStreamed != 0 && l < uClipCoarse) {
    int x = uWrapU != 0 ? i.x : clamp(i.x, 0, size.x - 1);
    return texelFetch(uClip, ivec3(floorMod(x, uClipSize), floorMod(y, uClipSize), l), 0).r;
  }
  int x = uWrapU != 0 ? floorMod(i.x, size.x) : clamp(i.x, 0, size.x - 1);
  return texelFetch(uHeight, ivec2(x, y), uStreamed != 0 ? l - uClipCoarse : l).r;
}

// The lower-left texel of the bilinear square around the point `dt` at level l, and the weights.
ivec2 levelCorner(int l, vec2 dt, out vec2 f) {
  vec2 s = uCamTexelF[l] + dt * uLevelScale[l];
  vec2 fl = floor(s);
  f = s - fl;
  return uCamTexelI[l] + ivec2(fl);
}

float levelBilinear(int l, vec2 dt) {
  vec2 f;
  ivec2 i = levelCorner(l, dt, f);
  float a = levelTexel(l, i), b = levelTexel(l, i + ivec2(1, 0));
  float c = levelTexel(l, i + ivec2(0, 1)), d = levelTexel(l, i + ivec2(1, 1));
  return mix(mix(a, b, f.x), mix(c, d, f.x), f.y);
}

// Whether the bilinear square with lower-left texel i0 of stack level l only touches resident
// pages.
bool clipResident(int l, ivec2 i0) {
  ivec2 size = uLevelSize[l];
  ivec2 i1 = i0 + 1;
  if (uWrapU == 0) {
    i0.x = clamp(i0.x, 0, size.x - 1);
    i1.x = clamp(i1.x, 0, size.x - 1);
  }
  i0.y = clamp(i0.y, 0, size.y - 1);
  i1.y = clamp(i1.y, 0, size.y - 1);
  ivec2 o = uClipOrigin[l];
  if (any(lessThan(i0, o)) || any(greaterThanEqual(i1, o + uClipSize))) return false;
  int k = uClipSize >> uPageShift;
  // Slots: page index modulo k, floored (columns can be negative across the seam; >> on ints is
  // arithmetic: a floored division).
  ivec2 pa = i0 >> uPageShift, pb = i1 >> uPageShift;
  ivec2 a = ivec2(floorMod(pa.x, k), floorMod(pa.y, k)), b = ivec2(floorMod(pb.x, k), floorMod(pb.y, k));
  return texelFetch(uClipPages, ivec3(a, l), 0).r != 0u && texelFetch(uClipPages, ivec3(b.x, a.y, l), 0).r != 0u &&
         texelFetch(uClipPages, ivec3(a.x, b.y, l), 0).r != 0u && texelFetch(uClipPages, ivec3(b, l), 0).r != 0u;
}

bool levelResident(int l, vec2 dt) {
  if (uStreamed == 0 || l >= uClipCoarse) return true;
  vec2 f;
  return clipResident(l, levelCorner(l, dt, f));
}

// Elevation (m) at the point `dt` (level-0 texels from the viewer), MIP level `lod`, trilinear
// between levels. Streamed: from the finest resident level at or above floor(lod) (a late page
// shows a coarser stand-in, never a hole), blended towards the next one when the wanted level
// itself is resident.
float terrainHeight(vec2 dt, float lod) {
  lod = clamp(lod, 0.0, float(uLevelCount - 1));
  int lo = int(floor(lod));
  float t = lod - float(lo);
  int l = lo;
  while (!levelResident(l, dt)) ++l;
  float h = levelBilinear(l, dt);
  if (l > lo || t <= 0.0 || l + 1 >= uLevelCount || !levelResident(l + 1, dt)) return h;
  return mix(h, levelBilinear(l + 1, dt), t);
}

// Texture coordinates (0..1 over the DEM) of the point `dt`: for the fields drawn over the
// terrain (water, layers, voids), which need no better than a float's resolution.
vec2 uvOf(vec2 dt) { return (vec2(uCamTexelI[0]) + (uCamTexelF[0] + dt + 0.5)) / uTexSize; }

// Longitude and latitude (radians) of the point at great-circle angle `gamma` from the viewer's
// nadir in direction `dir` (unit east, north), RELATIVE to the nadir's: written so that no
// absolute angle is rounded (at 10,000 km from the centre a float radian is 0.6 m), hence no
// jitter when the viewer moves by less than that (docs/render-rings.md, "Precision"). On an
// ellipsoid these are angles on the auxiliary sphere: longitude and reduced latitude.
// The unit vector to that point from the centre of the auxiliary sphere, in the nadir's frame
// (east, north, up): small east and north components near the viewer, exact to float.
vec3 sphereDirAt(float gamma, vec2 dir) {
  float s = sin(0.5 * gamma);
  return vec3(sin(gamma) * dir, 1.0 - 2.0 * s * s);
}

// deltaLonLatAt for the point in direction p (unit, nadir frame, as sphereDirAt gives).
vec2 deltaLonLatOf(vec3 p) {
  float sl = sin(uCamLonLat.y), cl = cos(uCamLonLat.y);
  float e = p.x, n = p.y, u = p.z;
  float x = u * cl - n * sl;                // towards the viewer's meridian in the equator plane
  float rho = sqrt(x * x + e * e);          // cos(latitude)
  float z = n * cl + u * sl;                // sin(latitude)
  // sin(lat - lat0): near the viewer (x > 0) without cancellation; beyond a pole (x < 0, the
  // meridian opposite the viewer) rho + x vanishes there, so the direct form (0/0 drew a spike
  // along that meridian).
  float sinD = x > 0.0 ? n - sl * e * e / (rho + x) : z * cl - rho * sl;
  float cosD = rho * cl + z * sl;
  return vec2(atan(e, x), atan(sinD, cosD));
}

vec2 deltaLonLatAt(float gamma, vec2 dir) { return deltaLonLatOf(sphereDirAt(gamma, dir)); }

// Planetary: level-0 texels from the viewer of the point in direction p (unit, nadir frame).
vec2 dtOfSphereDir(vec3 p) {
  vec2 d = deltaLonLatOf(p);
  // Reduced -> geodetic latitude difference, tan(phi) = tan(beta) / (1 - f): scaled by
  // d(phi)/d(beta) at the midpoint (exact for a sphere; second order otherwise).
  float g = 1.0 - uFlattening, bm = uCamLonLat.y + 0.5 * d.y;
  float dPhi = d.y * g / (g * g * cos(bm) * cos(bm) + sin(bm) * sin(bm));
  return vec2(d.x, dPhi) * uTexelPerRad;
}

// The point at horizontal distance `dist` (planar: metres on the plane; planetary: metres of
// arc) in direction `dir` from the viewer's nadir, as level-0 texels from the viewer.
vec2 dtAt(float dist, vec2 dir) {
  if (uPlanetary == 0) return dir * dist * uTexelPerMetre;
  return dtOfSphereDir(sphereDirAt(dist / uRadius, dir));
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
