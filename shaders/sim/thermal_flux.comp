#version 450
// E7: material the topmost layer sheds to each lower neighbour where the slope exceeds the
// talus angle; E8: banks touching water slip at wetTalusScale times the tangent. Writes only
// this cell's four outflows; layers are read-only here.
#include "../common/sim.glsl"
#include "../common/sim_layers.glsl"
layout(local_size_x = 16, local_size_y = 16) in;
layout(std430, binding = 4) readonly buffer Bed { float bed[]; };
layout(std430, binding = 6) readonly buffer StateIn { vec4 state[]; };
layout(std430, binding = 15) writeonly buffer Thermal { vec4 thermal[]; };
void main() {
  const ivec2 p = ivec2(gl_GlobalInvocationID.xy);
  if (!insideGrid(p)) return;
  const int i = cellOf(p), n = cellCount();
  const float dry = P.dryDepthM;
  thermal[i] = vec4(0.0);
  const int top = topLayer(i);
  if (top < 0) return;
  bool wet = state[i].x > dry;
  for (int d = 0; d < 4; ++d) {
    const ivec2 q = p + kDir[d];
    if (insideGrid(q)) wet = wet || state[cellOf(q)].x > dry;
  }
  const float tanT = materials[top].tanTalus * (wet ? P.wetTalusScale : 1.0);
  vec4 excess = vec4(0.0);
  float maxEx = 0.0, sumEx = 0.0;
  for (int d = 0; d < 4; ++d) {
    const ivec2 q = p + kDir[d];
    if (!insideGrid(q)) continue;
    const float dist = d < 2 ? cellDx(p.y) : P.dyM;
    excess[d] = max(0.0, (bed[i] - bed[cellOf(q)]) - tanT * dist);
    maxEx = max(maxEx, excess[d]);
    sumEx += excess[d];
  }
  if (sumEx <= 0.0) return;
  float stack = 0.0;
  for (int l = 0; l < P.layerCount; ++l) stack += layers[l * n + i];
  const float moved = min(stack, P.thermalRate * 0.5 * maxEx);
  vec4 out_;
  for (int d = 0; d < 4; ++d) out_[d] = moved * (excess[d] / sumEx);
  thermal[i] = out_;
}
