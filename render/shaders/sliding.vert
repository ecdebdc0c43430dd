#version 450
// The sliding sampling grid (SlidingGridRenderer): nested square levels of a fixed mesh, slid
// under the viewer in steps of the coarsest cells; each vertex samples the MIP level of its own
// level at a fixed texel lattice point. Same frame and outputs as ring.vert.
#include "terrain_common.glsl"

layout(location = 0) in vec3 aLattice;  // (x, y) in level-0 texels from the grid origin, z: MIP level

uniform vec2 uOriginFromViewer;  // origin minus the viewer's lattice position (texels, small)

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
  // Level-0 texels from the viewer: small numbers only.
  vec2 dt = uOriginFromViewer + aLattice.xy;
  float elev = terrainHeight(dt, aLattice.z);
  vec2 offset = dt / uTexelPerMetre;
  vs.dt = dt;
  vs.sph = vec3(0.0, 0.0, 1.0);  // planar only
  vs.uv = uvOf(dt);
  vs.lod = aLattice.z;
  vs.elev = elev;
  vs.rel = positionAt(length(offset), length(offset) > 0.0 ? offset / length(offset) : vec2(1.0, 0.0), elev, vs.up);
  gl_Position = uViewProj * vec4(vs.rel, 1.0);
}
