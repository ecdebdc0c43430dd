// The water / erosion simulation as the compute kernels see it. SimParams, SimMaterial and
// SourceEntry mirror sim/include/strata/sim/gl/gl_layout.hpp; tests/gl/gpu_layouts_test.cpp checks
// that they agree. Buffer bindings are fixed here (slots: sim/include/strata/sim/gl/shader_slots.hpp);
// sim/src/gl/gl_solver.cpp binds them. Equation numbers (W.., E..) refer to docs/sim-water.md and
// docs/sim-erosion.md; sim/src/cpu_*.cpp is the same code in C++.
struct SimParams {
  int width;
  int height;
  int layerCount;
  int waterModel;
  uint openEdges;
  uint erosionEnabled;
  uint thermalEnabled;
  uint diagonalPipes;
  float dyM;
  float gravityMS2;
  float dtS;
  float maxDtS;
  float cflAlpha;
  float dryDepthM;
  float pipeAreaM2;
  float manningN;
  float rainMmPerHour;
  float evaporationMmPerHour;
  float capacityK;
  float erosionRate;
  float depositionRate;
  float deepWaterM;
  float minSinTilt;
  float slowWaterMS;
  int erosionLaw;  // ErosionLaw: 0 shear stress, 1 force-based (E1-E3)
  float waterDensityKgM3;
  float bankFillShare;
  int slopeLimiter;  // SlopeLimiter: 0 minmod, 1 MC (W21)
  int floodScheme;   // FloodScheme: 0 finite volume, 1 local inertial (W30-W33)
  float pad1;
  float pad2;
  float pad3;
};

// The work-group shape of the grid kernels (the sources, pipe, erosion, thermal and flood passes).
#define SIM_GROUP_X 16
#define SIM_GROUP_Y 16

struct SimMaterial {
  float erodibility;
  float dissolutionRate;
  float tanTalus;
  float weatheringRatePerS;
  float criticalShearPa;
  float shearErodibility;
  float settlingVelocityMS;
  float tanFriction;
  float sinFriction;
  float cosFriction;
  float cohesionHeightM;
  float pad0;
};

struct SourceEntry {
  uint cell;
  float rateM3S;
};

struct LevelEntry {
  uint cell;
  float stageM;
};

#ifdef SIM_PARAMS_WRITABLE  // step_clock.comp sets P.dtS (W35)
layout(std430, binding = SLOT_PARAMS) buffer SimParamsBlock { SimParams P; };
#else
layout(std430, binding = SLOT_PARAMS) readonly buffer SimParamsBlock { SimParams P; };
#endif
layout(std430, binding = SLOT_ROW_DX) readonly buffer RowDxBlock { float rowDx[]; };

const ivec2 kDir[4] = ivec2[4](ivec2(-1, 0), ivec2(1, 0), ivec2(0, -1), ivec2(0, 1));  // W, E, N, S
// Diagonal pipes (W1b): NW, NE, SW, SE; the opposite of k is 3 - k.
const ivec2 kDiag[4] = ivec2[4](ivec2(-1, -1), ivec2(1, -1), ivec2(-1, 1), ivec2(1, 1));
const float kMmPerHourToMS = 1.0 / 3.6e6;
const float kHeadNoise = 4.0 * 1.1920929e-7;   // W1a
const float kForceNoise = 16.0 * 1.1920929e-7; // W24

bool insideGrid(ivec2 p) { return p.x >= 0 && p.y >= 0 && p.x < P.width && p.y < P.height; }
int cellOf(ivec2 p) { return p.y * P.width + p.x; }
float cellDx(int y) { return rowDx[y]; }
float cellArea(int y) { return rowDx[y] * P.dyM; }
// W12: the depth a point-source entry pours into its cell over the step P.dtS (point_sources.comp,
// and step_clock.comp where no rain pass comes between, W36).
float pointSourceDepth(SourceEntry e) { return e.rateM3S * P.dtS / cellArea(int(e.cell) / P.width); }
// Width of the y-face between rows yFace - 1 and yFace (the mean of the two rows' dx).
float faceWidthY(int yFace) {
  if (yFace <= 0) return rowDx[0];
  if (yFace >= P.height) return rowDx[P.height - 1];
  return 0.5 * (rowDx[yFace - 1] + rowDx[yFace]);
}
float velocityOf(float h, float q) { return h > P.dryDepthM ? q / h : 0.0; }
// W10: a cell's wave speed |u| + sqrt(g h) (W33: sqrt(g h) with the local-inertial scheme, whose
// step has no advection in it).
float waveSpeedOf(vec4 s) {
  const float u = velocityOf(s.x, s.z), w = velocityOf(s.x, s.w);
  return (P.floodScheme == 1 ? 0.0 : sqrt(u * u + w * w)) + sqrt(P.gravityMS2 * s.x);
}

// W11b: u - ln(1 + u) for u >= 0, a series below 0.1 (sim/src/cpu_kernels.hpp's uMinusLog1p).
float uMinusLog1p(float u) {
  if (u >= 0.1) return u - log(1.0 + u);
  float p = 1.0 / 9.0;
  p = 1.0 / 8.0 - u * p;
  p = 1.0 / 7.0 - u * p;
  p = 1.0 / 6.0 - u * p;
  p = 1.0 / 5.0 - u * p;
  p = 1.0 / 4.0 - u * p;
  p = 1.0 / 3.0 - u * p;
  p = 0.5 - u * p;
  return u * u * p;
}
// W11b: the depth the soil can take in over a step under ponding from cumulative infiltration f:
// Green-Ampt integrated over the step, three Newton steps; g = 0: a constant loss ksDt
// (sim/src/cpu_kernels.hpp's infiltrationCapacity, which gives the derivation and accuracy).
float infiltrationCapacity(float ksDt, float g, float f) {
  if (!(g > 0.0) || !(ksDt > 0.0)) return ksDt;
  const float a = f + g;
  float d = ksDt + sqrt(2.0 * g * ksDt);
  for (int k = 0; k < 3; ++k) {
    const float r = d * f / a + g * uMinusLog1p(d / a) - ksDt;
    d = max(ksDt, d - r * (a + d) / (f + d));
  }
  return d;
}
