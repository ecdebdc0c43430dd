#version 450
// Terrain shading shared by the renderers: sun lighting with normals from the height texture and
// cast shadows, a hypsometric tint, material layers blended by thickness, a draped raster, water
// coloured by depth, a graticule, haze.
#include "terrain_common.glsl"
#include "atmosphere.glsl"

in VertexData {
  vec3 rel;
  vec2 dt;  // level-0 texels from the viewer
  vec3 sph;  // planetary: direction from the body's centre, nadir frame
  vec2 uv;
  float lod;
  float elev;
  vec3 up;
}
fs;

layout(binding = SLOT_WATER) uniform sampler2D uWater;  // water depth (m), optional
layout(binding = SLOT_LAYERS) uniform sampler2D uLayers;  // thickness (m) of up to four layers, bottom first, optional
layout(binding = SLOT_SEDIMENT) uniform sampler2D uSediment;  // suspended sediment (m of material), optional
uniform int uHasWater;
layout(binding = SLOT_WATER_STATE) uniform sampler2D uWaterState;  // simulation state (h, s, hu, hv), optional
uniform int uHasSediment;
uniform int uHasWaterState;
layout(binding = SLOT_VOID_MASK) uniform sampler2D uVoidMask;  // 1 with data, 0 over voids drawn as holes, optional
uniform int uHasVoidMask;
layout(binding = SLOT_DRAPE) uniform sampler2D uDrape;  // a raster draped on the terrain (RGBA8), optional
uniform int uHasDrape;
uniform float uDrapeOpacity;
layout(binding = SLOT_LONLAT) uniform sampler2D uLonLat;  // lon/lat (deg) of the cell centres, for the graticule
uniform float uGraticuleDeg;     // lines of longitude and latitude this far apart (deg); 0: none
layout(binding = SLOT_SHADOW) uniform sampler2D uShadow;  // fraction of the sun each cell sees, optional
uniform int uHasShadow;
uniform vec2 uOverviewUvScale;   // uShadow's and uLonLat's coordinates are uv times this (streamed scenes)
uniform float uAmbient;          // light where the sun does not reach
uniform vec3 uSiltColour;        // water colour at high sediment concentration
uniform float uSiltConcentration; // concentration s / h at which water is 1 - 1/e of the way to silt
uniform int uHasLayers;
uniform float uSeaLevelM;        // water below this elevation when uHasSea
uniform int uHasSea;
uniform float uWaterDepthScaleM; // depth at which water looks 1/e of the way to deep
uniform float uWaterFadeM;       // water shallower than this fades out (0: none)
uniform float uLayerOpaqueM;     // thickness at which a layer hides 1/e of what is below
uniform vec3 uLayerColour[4];
uniform vec2 uElevRange;         // elevations (m) at the two ends of the tint
uniform int uPalette;            // 0: hypsometric (Earth), 1: grey (airless bodies), 2: rust (Mars), 3: uRamp*
uniform int uRampCount;          // a user's ramp (gdaldem color-relief stops, ascending)
uniform float uRampElev[64];
uniform vec3 uRampColour[64];
uniform vec3 uSunDir;            // unit, towards the sun, in the viewer's ENU frame
uniform vec3 uPole;              // planetary: unit vector to the north pole, viewer's ENU frame
uniform vec4 uSky;               // haze colour
uniform float uFogM;             // haze distance (m); 0: none

layout(location = 0) out vec4 oColour;
layout(location = 1) out float oElevation;

vec3 hypsometric(float t) {
  const vec3 c0 = vec3(0.22, 0.42, 0.20), c1 = vec3(0.55, 0.55, 0.33), c2 = vec3(0.62, 0.47, 0.33);
  const vec3 c3 = vec3(0.55, 0.52, 0.50), c4 = vec3(0.95, 0.95, 0.97);
  t = clamp(t, 0.0, 1.0);
  if (t < 0.3) return mix(c0, c1, t / 0.3);
  if (t < 0.6) return mix(c1, c2, (t - 0.3) / 0.3);
  if (t < 0.85) return mix(c2, c3, (t - 0.6) / 0.25);
  return mix(c3, c4, (t - 0.85) / 0.15);
}

// A user's ramp: linear between stops, the end colours beyond them (gdaldem color-relief).
vec3 userRamp(float e) {
  if (!(e > uRampElev[0])) return uRampColour[0];
  for (int i = 1; i < uRampCount; ++i) {
    if (e < uRampElev[i]) {
      float t = (e - uRampElev[i - 1]) / max(uRampElev[i] - uRampElev[i - 1], 1e-6);
      return mix(uRampColour[i - 1], uRampColour[i], t);
    }
  }
  return uRampColour[uRampCount - 1];
}

void main() {
  // Planetary: the fragment's texel offset from its own direction on the body, not interpolated
  // between the vertices' offsets: longitude wraps at the meridian opposite the viewer (a triangle
  // across it interpolated through the whole globe: a seam from the pole) and is far from linear
  // across a triangle near a pole.
  vec2 q = uPlanetary != 0 ? dtOfSphereDir(normalize(fs.sph)) : fs.dt;
  vec2 uv = uPlanetary != 0 ? uvOf(q) : fs.uv;
  if (uv.y < 0.0 || uv.y > 1.0 || (uWrapU == 0 && (uv.x < 0.0 || uv.x > 1.0))) discard;
  // Voids drawn as holes: nothing where the bilinear mask says the point is nearer a void cell's
  // centre than a valid one's (the hole's edge runs midway between them).
  if (uHasVoidMask != 0 && textureLod(uVoidMask, uv, 0.0).r < 0.5) discard;

  // Surface gradient (m/m, exaggerated) from central differences one texel of the vertex's
  // MIP level apart.
  float lod = fs.lod;
  float d = exp2(lod);
  vec2 grad;
  vec3 east = vec3(1.0, 0.0, 0.0), north = vec3(0.0, 1.0, 0.0), up = vec3(0.0, 0.0, 1.0);
  if (uPlanetary == 0) {
    float hx = terrainHeight(q + vec2(d, 0.0), lod) - terrainHeight(q - vec2(d, 0.0), lod);
    float hy = terrainHeight(q + vec2(0.0, d), lod) - terrainHeight(q - vec2(0.0, d), lod);
    grad = vec2(hx, hy) / (2.0 * d / uTexelPerMetre);
  } else {
    // On a body: the four points d texels of latitude away along the great circles east-west
    // and north-south through the fragment, so both differences span the same ground at any
    // latitude. (Stepping d columns along the parallel spans cos(lat) as much ground: one column
    // near a pole is a sliver, and its differences were noise, a starburst; d / cos(lat) columns
    // at a level as much coarser went round the globe within a few texels of the pole, where a
    // level that coarse also averages half the polar cap: a dark dot on the pole.) The
    // fragment's own east and north in the viewer's nadir frame, where the pole lies at
    // (0, cos lat0, sin lat0); at the pole itself any pair does.
    vec3 p = normalize(fs.sph);
    vec3 pole = vec3(0.0, cos(uCamLonLat.y), sin(uCamLonLat.y));
    vec3 e = cross(pole, p);
    e = dot(e, e) > 1e-14 ? normalize(e) : normalize(cross(abs(p.x) < 0.9 ? vec3(1.0, 0.0, 0.0) : vec3(0.0, 1.0, 0.0), p));
    vec3 nth = cross(p, e);
    float a = d / uTexelPerRad.y;  // d texels of latitude, as an angle
    float hx = terrainHeight(dtOfSphereDir(normalize(p + a * e)), lod) -
               terrainHeight(dtOfSphereDir(normalize(p - a * e)), lod);
    float hy = terrainHeight(dtOfSphereDir(normalize(p + a * nth)), lod) -
               terrainHeight(dtOfSphereDir(normalize(p - a * nth)), lod);
    grad = vec2(hx, hy) / (2.0 * a * uRadius);
    up = normalize(fs.up);
    east = normalize(cross(uPole, up));
    north = cross(up, east);
  }
  grad *= uExaggeration;
  vec3 nLocal = normalize(vec3(-grad, 1.0));
  vec3 n = nLocal.x * east + nLocal.y * north + nLocal.z * up;

  float elev = fs.elev;
  float t = clamp((elev - uElevRange.x) / max(uElevRange.y - uElevRange.x, 1.0), 0.0, 1.0);
  vec3 albedo = uPalette == 1   ? mix(vec3(0.30), vec3(0.80), t)
                : uPalette == 2 ? mix(vec3(0.42, 0.20, 0.10), vec3(0.85, 0.62, 0.42), t)
                : uPalette == 3 ? userRamp(elev)
                                : hypsometric(t);
  if (uHasLayers != 0) {
    vec4 thick = textureLod(uLayers, uv, lod);
    for (int k = 0; k < 4; ++k) albedo = mix(albedo, uLayerColour[k], 1.0 - exp(-max(thick[k], 0.0) / uLayerOpaqueM));
  }
  if (uHasDrape != 0) {
    // The pixel's own footprint (the mesh's level of detail, `lod`, is far coarser than a pixel
    // near the viewer), from the texel offsets q, which do not wrap where uv does.
    vec4 d = textureGrad(uDrape, uv, dFdx(q) / uTexSize, dFdy(q) / uTexSize);
    albedo = mix(albedo, d.rgb, d.a * uDrapeOpacity);
  }
  float sunLit = 1.0;
  if (uHasShadow != 0) {
    sunLit = textureGrad(uShadow, uv * uOverviewUvScale, dFdx(q) / uTexSize * uOverviewUvScale,
                         dFdy(q) / uTexSize * uOverviewUvScale).r;
  }
  float light = uAmbient + (1.0 - uAmbient) * max(dot(n, uSunDir), 0.0) * sunLit;
  vec3 colour = albedo * light;

  float depth = 0.0, simDepth = 0.0;
  float sediment = 0.0;
  if (uHasWater != 0) simDepth = textureLod(uWater, uv, lod).r;
  if (uHasSediment != 0) sediment = textureLod(uSediment, uv, lod).r;
  if (uHasWaterState != 0) {
    vec4 st = textureLod(uWaterState, uv, lod);
    simDepth = max(simDepth, st.r);
    sediment = max(sediment, st.g);
  }
  depth = max(depth, simDepth);
  if (uHasSea != 0) depth = max(depth, uSeaLevelM - elev);
  if (depth > 0.0) {
    float k = 1.0 - exp(-depth / uWaterDepthScaleM);
    vec3 water = mix(vec3(0.25, 0.62, 0.70), vec3(0.02, 0.10, 0.32), k);
    if (sediment > 0.0 && simDepth > 0.0) {
      // Suspended sediment tints the simulated water by its concentration s / h.
      float conc = sediment / simDepth;
      water = mix(water, uSiltColour, 1.0 - exp(-conc / uSiltConcentration));
    }
    float sunOnWater = 0.6 + 0.4 * max(dot(up, uSunDir), 0.0);
    // Thin water fades in (uWaterFadeM > 0): bilinear depth between a wet cell and a dry one is
    // not drawn at full strength, so a wet cell's footprint is not a hard-edged square.
    float fade = uWaterFadeM > 0.0 ? smoothstep(0.0, uWaterFadeM, depth) : 1.0;
    colour = mix(colour, water * sunOnWater, (0.55 + 0.45 * k) * fade);
  }
  if (uGraticuleDeg > 0.0) {
    // Distance in pixels to the nearest line of each family (the lon/lat's own screen derivative),
    // a line 1.5 pixels wide with soft edges; a family whose lines come closer than ~5 pixels
    // fades out rather than whiten the view.
    vec2 g = textureLod(uLonLat, uv * uOverviewUvScale, 0.0).rg / uGraticuleDeg;
    vec2 fw = max(fwidth(g), vec2(1e-12));
    vec2 px = abs(fract(g + 0.5) - 0.5) / fw;
    vec2 line = (1.0 - smoothstep(0.75, 1.5, px)) * (1.0 - smoothstep(0.1, 0.2, fw));
    colour = mix(colour, vec3(1.0), 0.8 * max(line.x, line.y));
  }
  if (uHasAir != 0) {
    // Aerial perspective: the air between the viewer and the point dims it and adds the light it
    // scatters (atmosphere.glsl), from the viewer's altitude to the point's. The air's density
    // follows the point's true altitude: exaggerated relief is a drawing of the ground, not of
    // the air (x10 put Mars's polar troughs 50 km below the datum, in air 7 times denser than
    // at the datum: the cap washed out and the limb went black).
    float len = length(fs.rel);
    float z1 = elev;
    vec3 transmittance;
    vec3 air = airLight(airColumn(uCamZ, z1, len, uAirRayleighScaleM), airColumn(uCamZ, z1, len, uAirHazeScaleM),
                        airSunAt(up, uSunDir), transmittance);
    colour = colour * transmittance + air;
  }
  if (uFogM > 0.0) colour = mix(colour, uSky.rgb, 1.0 - exp(-length(fs.rel) / uFogM));

  oColour = vec4(colour, 1.0);
  oElevation = elev;
}
