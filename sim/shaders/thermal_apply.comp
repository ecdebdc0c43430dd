#version 450
// E7, receiving side: take what this cell sheds from its topmost layer, add what neighbours
// shed towards it (scaled by their area) to the top (sediment) layer. Reads neighbours only
// from `thermal`, which this pass does not write.
#include "sim.glsl"
#include "sim_layers.glsl"
layout(local_size_x = SIM_GROUP_X, local_size_y = SIM_GROUP_Y) in;
layout(std430, binding = SLOT_BED) writeonly buffer Bed { float bed[]; };
layout(std430, binding = SLOT_THERMAL) readonly buffer Thermal { vec4 thermal[]; };
void main() {
  const ivec2 p = ivec2(gl_GlobalInvocationID.xy);
  if (!insideGrid(p)) return;
  const int i = cellOf(p), n = cellCount();
  const vec4 out_ = thermal[i];
  const float shed = out_.x + out_.y + out_.z + out_.w;
  float received = 0.0;
  for (int d = 0; d < 4; ++d) {
    const ivec2 q = p + kDir[d];
    if (!insideGrid(q)) continue;
    received += thermal[cellOf(q)][d ^ 1] * cellArea(q.y);
  }
  // E7b: what it sheds comes off the top of the stack, layer by layer, as the flux pass reached
  // down (its per-layer amounts are values the layers lose exactly; the sum of the four parts may
  // differ from them by a rounding, hence the min: no layer goes below 0).
  float remaining = shed;
  for (int l = P.layerCount - 1; l >= 0; --l) {
    const int k = l * n + i;
    const float take = min(layers[k], remaining);
    layers[k] -= take;
    remaining -= take;
  }
  layers[(P.layerCount - 1) * n + i] += received / cellArea(p.y);
  bed[i] = bedOf(i);
}
