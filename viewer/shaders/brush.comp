#version 450
// One dab of a height brush (strata::render::viewer::TerrainEditor; docs/viewer.md, "Tools").
// Reads a copy of the window around the brush (so neighbours are pre-dab values) and writes the
// scene's elevation texture, level 0, inside the brush's bounding box.
layout(local_size_x = 8, local_size_y = 8) in;

layout(r32f, binding = SLOT_BRUSH_SRC) uniform readonly image2D uSrc;  // copy of the cells uSrcOrigin .. + size
layout(r32f, binding = SLOT_BRUSH_DST) uniform writeonly image2D uDst;  // the scene's elevations (m)

uniform ivec2 uOrigin;     // first grid cell written
uniform ivec2 uSize;       // cells written
uniform ivec2 uSrcOrigin;  // grid cell of uSrc's texel (0, 0)
uniform vec2 uCentre;      // brush centre (grid cells, continuous: cell (i, j) spans i..i+1)
uniform vec2 uRadius;      // brush radius in cells along x and y
layout(rgba32f, binding = SLOT_BRUSH_LAYERS) uniform image2D uLayers;  // layer thicknesses (m), modes 8-9
layout(binding = SLOT_BRUSH_STAMP) uniform sampler2D uStamp;  // stamp image t (bilinear, clamped), modes 4-7
uniform int uMode;         // 0 raise, 1 lower, 2 smooth, 3 flatten, 4-7 stamp: add, subtract, multiply,
                           // replace, 8 add material, 9 remove material
uniform int uLayer;        // modes 8-9: the layer (0 = bottom)
uniform float uStrength;   // raise/lower: m at the centre; smooth/flatten: blend fraction at the centre
uniform float uTarget;     // flatten: the level (m)

float src(ivec2 cell) {
  const ivec2 hi = imageSize(uSrc) - 1;
  return imageLoad(uSrc, clamp(cell - uSrcOrigin, ivec2(0), hi)).r;
}

void main() {
  const ivec2 local = ivec2(gl_GlobalInvocationID.xy);
  if (any(greaterThanEqual(local, uSize))) return;
  const ivec2 cell = uOrigin + local;
  const vec2 d = (vec2(cell) + 0.5 - uCentre) / uRadius;
  const float r2 = dot(d, d);
  // Falloff (1 - r^2)^2: 1 at the centre, 0 with zero slope at the rim.
  const float w = r2 < 1.0 ? (1.0 - r2) * (1.0 - r2) : 0.0;
  const float h = src(cell);
  float result = h;
  if (uMode == 0) {
    result = h + uStrength * w;
  } else if (uMode == 1) {
    result = h - uStrength * w;
  } else if (uMode == 2) {
    const float mean = (src(cell + ivec2(-1, -1)) + src(cell + ivec2(0, -1)) + src(cell + ivec2(1, -1)) +
                        src(cell + ivec2(-1, 0)) + h + src(cell + ivec2(1, 0)) + src(cell + ivec2(-1, 1)) +
                        src(cell + ivec2(0, 1)) + src(cell + ivec2(1, 1))) / 9.0;
    result = mix(h, mean, clamp(uStrength * w, 0.0, 1.0));
  } else if (uMode == 3) {
    result = mix(h, uTarget, clamp(uStrength * w, 0.0, 1.0));
  }
  bool inside = w > 0.0;
  if (uMode >= 4) {
    // The stamp covers the brush's square (centre +- radius) with weight 1; f = strength * t.
    const vec2 uv = (vec2(cell) + 0.5 - (uCentre - uRadius)) / (2.0 * uRadius);
    inside = all(greaterThanEqual(uv, vec2(0.0))) && all(lessThanEqual(uv, vec2(1.0)));
    const float f = uStrength * textureLod(uStamp, uv, 0.0).r;
    if (uMode == 4) result = h + f;
    if (uMode == 5) result = h - f;
    if (uMode == 6) result = h * f;
    if (uMode == 7) result = f;
  }
  if (uMode >= 8 && inside) {
    // The layer's thickness changes by s w (removal stops at zero); the surface moves with it.
    vec4 t = imageLoad(uLayers, cell);
    const float delta = uMode == 8 ? uStrength * w : -min(uStrength * w, t[uLayer]);
    t[uLayer] += delta;
    imageStore(uLayers, cell, t);
    result = h + delta;
  }
  // Cells outside the brush are written with their own value: bit for bit unchanged.
  imageStore(uDst, cell, vec4(inside ? result : h));
}
