#version 450
// The sky along each pixel's ray from the viewer (atmosphere.glsl), drawn before the terrain.
#include "atmosphere.glsl"

in vec2 vNdc;
uniform mat4 uInvViewProj;  // clip -> viewer-relative east-north-up (m)
uniform float uSkyAltM;     // the viewer's altitude above the datum (m)

layout(location = 0) out vec4 oColour;
layout(location = 1) out float oElevation;

void main() {
  vec4 p = uInvViewProj * vec4(vNdc, 0.5, 1.0);
  vec3 dir = normalize(p.xyz / p.w);
  oColour = vec4(skyLight(uSkyAltM, dir), 1.0);
  oElevation = uintBitsToFloat(0x7fc00000u);  // no terrain: NaN, as the target's clear value
}
