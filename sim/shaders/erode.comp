#version 450
// E1 capacity (tilt, speed, limited in deep water), E2 erosion of the topmost layer scaled by
// its erodibility, E3 deposition as the top (sediment) layer, E4 dissolution in slow water,
// E6 settling where the water is gone. Purely local: each cell reads and writes only itself.
#include "sim.glsl"
#include "sim_layers.glsl"
layout(local_size_x = SIM_GROUP_X, local_size_y = SIM_GROUP_Y) in;
layout(std430, binding = SLOT_BED) buffer Bed { float bed[]; };
layout(std430, binding = SLOT_STATE_IN) buffer StateIn { vec4 state[]; };
layout(std430, binding = SLOT_TILT) readonly buffer Tilt { float tilt[]; };
void main() {
  const ivec2 p = ivec2(gl_GlobalInvocationID.xy);
  if (!insideGrid(p)) return;
  const int i = cellOf(p), n = cellCount(), sedimentLayer = P.layerCount - 1;
  const float dt = P.dtS, dry = P.dryDepthM;
  vec4 st = state[i];
  const float h = st.x;
  float s = st.y;
  if (h > dry) {
    const float speed = sqrt(st.z * st.z + st.w * st.w) / h;
    const float depthFactor = clamp(1.0 - h / P.deepWaterM, 0.0, 1.0);
    const float capacity = P.capacityK * max(tilt[i], P.minSinTilt) * speed * depthFactor;
    int top = topLayer(i);
    if (s < capacity) {
      if (top >= 0) {
        const int k = top * n + i;
        const float amount = exactTake(layers[k], min(min(P.erosionRate * (capacity - s) * dt * materials[top].erodibility,
                                                          P.maxErosionPerStepM), layers[k]));
        layers[k] -= amount;
        s += amount;
      }
    } else {
      const int k = sedimentLayer * n + i;
      const float amount = exactGive(layers[k], min(P.depositionRate * (s - capacity) * dt, s), s);
      s -= amount;
      layers[k] += amount;
    }
    top = topLayer(i);
    if (speed < P.slowWaterMS && top >= 0) {
      const int k = top * n + i;
      const float amount = exactTake(layers[k], min(min(materials[top].dissolutionRate * h * dt, P.maxErosionPerStepM), layers[k]));
      layers[k] -= amount;
      s += amount;
    }
  } else {
    layers[sedimentLayer * n + i] += s;
    s = 0.0;
  }
  state[i].y = s;
  bed[i] = bedOf(i);
}
