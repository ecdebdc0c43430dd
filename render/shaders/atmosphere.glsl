// A body's air (strata::render::Atmosphere, render/atmosphere.hpp): optical depths through two
// exponential layers, the colour light scattered along a path brings, the sky along a ray.
// Included by sky.frag and terrain.frag. Altitudes are above the datum (m).

uniform int uHasAir;
uniform vec3 uAirRayleigh;      // molecular extinction at the datum (1/m), per channel
uniform float uAirRayleighScaleM;
uniform float uAirHaze;         // haze extinction at the datum (1/m)
uniform float uAirHazeScaleM;
uniform vec3 uAirHazeColour;
uniform float uAirBrightness;
uniform float uAirRadius;       // the body's radius (m), for grazing rays
uniform float uAirSun;          // sunlight on the air at the viewer (airSunAt), 0 (night) to 1
uniform vec3 uAirSunDir;        // towards the sun, in the viewer's east-north-up frame

// Optical depth per unit datum extinction along a straight segment of length `len` from
// altitude z0 to z1 (density exp(-z / H)).
float airColumn(float z0, float z1, float len, float H) {
  float e0 = exp(-max(z0, -2.0 * H) / H), dz = z1 - z0;
  if (abs(dz) < 1e-3 * len + 1e-3) return e0 * len;
  return abs(e0 - exp(-max(z1, -2.0 * H) / H)) * H * len / abs(dz);
}

// Optical depth per unit datum extinction from altitude h to space along a ray whose elevation
// has sine s; negative where the ray meets the body. Upwards H / s, with the Chapman grazing
// value sqrt(pi R H / 2) at the horizontal; below it, the path down to the ray's lowest point
// (altitude a) and back up, less the half behind the viewer.
float airRay(float h, float s, float H) {
  float R = uAirRadius, grazing = sqrt(3.14159265 * R * H / 2.0);
  float eh = exp(-max(h, -2.0 * H) / H);
  if (s >= 0.0) return eh * H / sqrt(s * s + (H / grazing) * (H / grazing));
  float a = (R + h) * sqrt(max(1.0 - s * s, 0.0)) - R;
  if (a < 0.0) return -1.0;
  return grazing * (2.0 * exp(-a / H) - eh);
}

// Optical depth per unit datum extinction from altitude h along the ray tangent to the datum
// (the limb), less the half behind its tangent point that a viewer above it does not see.
float airLimb(float h, float H) {
  float grazing = sqrt(3.14159265 * uAirRadius * H / 2.0);
  return grazing * (2.0 - exp(-max(h, -2.0 * H) / H));
}

// Sunlight on the air where the local up is `up` (viewer's frame): full with the sun 8 degrees
// up, none 6 below (twilight).
float airSunAt(vec3 up, vec3 sunDir) { return smoothstep(-0.1, 0.14, dot(up, sunDir)); }

// Light scattered towards the viewer along a path of molecular and haze depths tR, tM (per unit
// datum extinction) lit by `sun` (airSunAt), and the path's transmittance.
vec3 airLight(float tR, float tM, float sun, out vec3 transmittance) {
  vec3 tau = uAirRayleigh * tR + vec3(uAirHaze * tM);
  transmittance = exp(-tau);
  vec3 scatter = (uAirRayleigh * tR + uAirHazeColour * uAirHaze * tM) / max(tau, vec3(1e-12));
  return uAirBrightness * sun * scatter * (1.0 - transmittance);
}

// The sky seen from altitude h along the ray `dir` (unit, viewer's east-north-up; rays into the
// body get the horizon's colour: terrain drawn over them, or the haze at the limb). The air along
// a downward ray is densest at its lowest point, and lit by the sun there: above a limb on the
// night side the glow is dark, as the ground under it (lit as at the viewer, a bright rim stood
// over a black band of night ground).
vec3 skyLight(float h, vec3 dir) {
  float s = dir.z;
  float tR = airRay(h, s, uAirRayleighScaleM), tM = airRay(h, s, uAirHazeScaleM);
  float sun = uAirSun;
  if (tR < 0.0 || tM < 0.0) {
    // Into the datum's sphere with no terrain drawn over it (relief below the datum, exaggerated
    // or not, has its horizon lower): the limb's haze, a ray tangent to the datum (from orbit a
    // horizontal ray at the viewer's altitude meets no air: a black band stood between the limb's
    // glow and the ground).
    tR = airLimb(h, uAirRayleighScaleM);
    tM = airLimb(h, uAirHazeScaleM);
  }
  if (s < 0.0) {
    vec3 lowest = vec3(0.0, 0.0, uAirRadius + h) - (uAirRadius + h) * s * dir;  // from the centre
    sun = airSunAt(normalize(lowest), uAirSunDir);
  }
  vec3 t;
  return airLight(tR, tM, sun, t);
}
