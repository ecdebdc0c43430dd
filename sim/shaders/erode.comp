#version 450
// E1-E3 the step's net exchange between the bed and the load (shear-stress law: entrainment
// k_d (tau - tau_c) of the topmost layer, settling w_s c into the top (sediment) layer; or the
// force-based capacity law), E4 dissolution in slow water, E6 settling where the water is gone;
// what the flow took off the bed goes to `scour` (E8's toe). Purely local: each cell reads and
// writes only itself.
#include "sim.glsl"
#include "sim_layers.glsl"
layout(local_size_x = SIM_GROUP_X, local_size_y = SIM_GROUP_Y) in;
layout(std430, binding = SLOT_BED) buffer Bed { float bed[]; };
layout(std430, binding = SLOT_STATE_IN) buffer StateIn { vec4 state[]; };
layout(std430, binding = SLOT_TILT) readonly buffer Tilt { float tilt[]; };
layout(std430, binding = SLOT_SCOUR) writeonly buffer Scour { float scour[]; };
layout(std430, binding = SLOT_MANNING) readonly buffer Manning { float manningN2[]; };  // n^2 per cell; < 0: P.manningN

// (1 - exp(-l)) / l, 1 at l = 0: what a relaxation at rate k moves over a step, as a share of
// (target - now) k dt, with l = k dt.
float relaxShare(float l) {
  if (l < 1e-3) return 1.0 - l * (0.5 - l * (1.0 / 6.0));
  return (1.0 - exp(-l)) / l;
}
// 1 - exp(-a), without the cancellation for small a.
float oneMinusExp(float a) { return a < 1e-3 ? a * (1.0 - a * (0.5 - a * (1.0 / 6.0))) : 1.0 - exp(-a); }

void main() {
  const ivec2 p = ivec2(gl_GlobalInvocationID.xy);
  if (!insideGrid(p)) return;
  const int i = cellOf(p), n = cellCount(), sedimentLayer = P.layerCount - 1;
  const float dt = P.dtS, dry = P.dryDepthM;
  vec4 st = state[i];
  const float h = st.x;
  float s = st.y, scoured = 0.0;
  if (h > dry) {
    const float q2 = st.z * st.z + st.w * st.w;
    const float speed = sqrt(q2) / h;
    int top = topLayer(i);
    float net;  // > 0: the flow takes from the bed
    if (P.erosionLaw == 0) {
      const float n2 = manningN2[i] >= 0.0 ? manningN2[i] : P.manningN * P.manningN;
      const float rhoGn2 = P.waterDensityKgM3 * P.gravityMS2 * n2;
      const float tau = rhoGn2 * (q2 / (h * h)) / pow(h, 1.0 / 3.0);
      const float entrain = top >= 0 ? materials[top].shearErodibility * max(tau - materials[top].criticalShearPa, 0.0) : 0.0;
      const float ws = materials[sedimentLayer].settlingVelocityMS;
      net = (entrain - ws * s / h) * dt * relaxShare(ws * dt / h);
    } else {
      const float depthFactor = clamp(1.0 - h / P.deepWaterM, 0.0, 1.0);
      const float capacity = P.capacityK * max(tilt[i], P.minSinTilt) * speed * depthFactor;
      const float gap = capacity - s;
      const float rate = gap > 0.0 ? P.erosionRate * (top >= 0 ? materials[top].erodibility : 0.0) : P.depositionRate;
      net = gap * oneMinusExp(rate * dt);
    }
    if (net > 0.0) {
      if (top >= 0) {
        const int k = top * n + i;
        const float amount = exactTake(layers[k], min(net, layers[k]));
        layers[k] -= amount;
        s += amount;
        scoured += amount;
      }
    } else if (net < 0.0) {
      const int k = sedimentLayer * n + i;
      const float amount = exactGive(layers[k], min(-net, s), s);
      s -= amount;
      layers[k] += amount;
    }
    top = topLayer(i);
    if (speed < P.slowWaterMS && top >= 0) {
      const int k = top * n + i;
      const float amount = exactTake(layers[k], min(materials[top].dissolutionRate * h * dt, layers[k]));
      layers[k] -= amount;
      s += amount;
      scoured += amount;
    }
  } else {
    layers[sedimentLayer * n + i] += s;
    s = 0.0;
  }
  state[i].y = s;
  scour[i] = scoured;
  bed[i] = bedOf(i);
}
