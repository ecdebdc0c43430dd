#version 450
// The brute-force reference: one vertex per texel of level 0 (planar mode), drawn as two
// triangles per grid cell from an index buffer. Same frame and outputs as ring.vert.
#include "terrain_common.glsl"

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

void main() {
  ivec2 size = ivec2(uTexSize);
  ivec2 texel = ivec2(gl_VertexID % size.x, gl_VertexID / size.x);
  float elev = texelFetch(uHeight, texel, 0).r;
  vec2 dt = vec2(texel - uCamTexelI[0]) - uCamTexelF[0];
  vec2 offset = dt / uTexelPerMetre;
  vs.dt = dt;
  vs.sph = vec3(0.0, 0.0, 1.0);  // planar only
  vs.uv = uvOf(dt);
  vs.lod = 0.0;
  vs.elev = elev;
  vs.rel = positionAt(length(offset), length(offset) > 0.0 ? offset / length(offset) : vec2(1.0, 0.0), elev, vs.up);
  gl_Position = uViewProj * vec4(vs.rel, 1.0);
}
