// Flood statistics of one cell after a step (docs/sim-water.md, "Flood statistics"): the maximum
// depth and speed, the arrival time (end of the first step with depth above the wet threshold;
// -1 = never) and the time spent above it. flood_stats.comp's pass, and the fused tail of a
// device step's water update (sim_tail.glsl).
layout(std430, binding = SLOT_FLOOD_STATS) buffer FloodStats { vec4 floodStats[]; };  // maxDepth, maxSpeed, arrival, wetTime
uniform float wetThresholdM;

void floodStatsAt(uint i, vec4 s, float endS) {
  vec4 f = floodStats[i];
  const float u = velocityOf(s.x, s.z), v = velocityOf(s.x, s.w);
  f.x = max(f.x, s.x);
  f.y = max(f.y, sqrt(u * u + v * v));
  if (s.x > wetThresholdM) {
    if (f.z < 0.0) f.z = endS;
    f.w += P.dtS;
  }
  floodStats[i] = f;
}
