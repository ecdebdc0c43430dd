#version 450
// Overlay quads (strata::render::Overlay: text boxes, the scale bar): four corners per quad in window
// pixels (y down) pulled from a buffer, two triangles each.
layout(std430, binding = SLOT_OVERLAY_CORNERS) readonly buffer Corners { vec2 corners[]; };
uniform vec2 uViewport;  // window size (pixels)

void main() {
  const int kCorner[6] = int[6](0, 1, 2, 0, 2, 3);
  const vec2 p = corners[(gl_VertexID / 6) * 4 + kCorner[gl_VertexID % 6]];
  gl_Position = vec4(p.x / uViewport.x * 2.0 - 1.0, 1.0 - p.y / uViewport.y * 2.0, 0.0, 1.0);
}
