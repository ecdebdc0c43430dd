#version 450
// The sky behind the terrain: one triangle over the whole screen (strata::render sky pass).
out vec2 vNdc;

void main() {
  vec2 p = vec2((gl_VertexID << 1) & 2, gl_VertexID & 2) * 2.0 - 1.0;
  vNdc = p;
  gl_Position = vec4(p, 0.0, 1.0);
}
