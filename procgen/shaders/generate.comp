#version 450
// Template of a user generation script (procgen/src/generator.cpp splices the user's
// GLSL in at the marker below). Level form: level(p, lvl) gives every coefficient of the
// wavelet pyramid (Mallat layout), then the inverse transform runs. Height form: height(p)
// gives every cell directly. p is in output cells (x right, y down), at the coefficient's centre.
#include "builtins.glsl"
layout(local_size_x = 16, local_size_y = 16) in;

layout(r32f, binding = SLOT_FIELD) uniform writeonly image2D uOut;

//@strata-user-script
#ifndef STRATA_USER_SCRIPT
// The template compiled on its own (a check that compiles every embedded shader): a flat field.
float height(vec2 p) { return 0.0; }
#endif

void main() {
  const ivec2 c = ivec2(gl_GlobalInvocationID.xy);
  if (any(greaterThanEqual(c, uSize))) return;
#ifdef STRATA_FORM_LEVEL
  // Find the level whose detail bands hold c (the coarse LL band when l reaches uLevels).
  ivec2 r = uSize;
  int l = 0;
  for (; l < uLevels; ++l) {
    const ivec2 h = (r + 1) / 2;
    if (c.x >= h.x || c.y >= h.y) break;
    r = h;
  }
  ivec2 local = c;
  if (l < uLevels) {
    const ivec2 h = (r + 1) / 2;
    const bool bx = c.x >= h.x, by = c.y >= h.y;
    BAND = (bx ? 1 : 0) + (by ? 2 : 0);
    local -= ivec2(bx ? h.x : 0, by ? h.y : 0);
  } else {
    BAND = 0;
  }
  const vec2 p = (vec2(local) + 0.5) * levelSpacing(l);
  imageStore(uOut, c, vec4(level(p, l)));
#else
  imageStore(uOut, c, vec4(height(vec2(c) + 0.5)));
#endif
}
