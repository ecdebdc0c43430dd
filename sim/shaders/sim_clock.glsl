// W35: the clock of a GL run that chooses its steps on the GPU (GlSolver's device steps,
// step_clock.comp). Mirrors sim/include/strata/sim/gl/gl_layout.hpp's GpuClock and GpuTerm
// (tests/gl/gpu_layouts_test.cpp checks that they agree).

// One point-source entry's share of one source (W12): what the source pours into the entry's
// cell is its discharge / cellCount; its samples are samples[first, first + count).
struct Term {
  uint entry;
  uint first;
  uint count;
  uint pad;
  double cellCount;  // the source's cells
  double areaM2;     // the entry cell's area
};

// Group counts of the passes a device step dispatches indirectly, by shape.
#define CLOCK_SHAPE_GRID 0     // SIM_GROUP_X x SIM_GROUP_Y groups over the grid
#define CLOCK_SHAPE_CELLS 1    // 256 cells a group (flood statistics)
#define CLOCK_SHAPE_ENTRIES 2  // 64 point-source entries a group
#define CLOCK_SHAPES 3

layout(std430, binding = SLOT_CLOCK) CLOCK_QUALIFIER buffer ClockBlock {
  double timeS;          // the run's time (s), as Solver's clock adds the float steps
  double endS;           // the steps end on it (the last one shortened to land there)
  double inflowM3;       // the sources' volume since the host last read the clock
  double minChosenDtS;   // the shortest step W10 chose (before any shortening) since then
  double lastChosenDtS;  // the step W10 chose last
  double maxDtS;         // SimParams::maxDtS
  double reachM;         // cflAlpha * the smallest cell side (W10)
  double gravityMS2;
  double rainRateMS;     // the rain's bound on a cell's depth rate (uniform + raster maximum), m/s
  double pad0;
  float lastDtS;         // the last step taken
  uint steps;            // taken since the host last read the clock
  uint done;             // 1 once timeS reached endS: the passes dispatch no group
  uint adaptive;         // cflAlpha > 0 (W10); else every step is maxDtS
  uint termCount;        // Terms (the point-source entries' shares of the sources)
  uint inertial;         // the local-inertial scheme: W10's sqrt(S^2 + g r dt) (W33)
  uint pointSources;     // 1: the clock pours the point sources in itself (W36: no rain pass)
  uint pad3;
  uint dispatchNow[3 * CLOCK_SHAPES];   // what the passes dispatch this step
  uint dispatchFull[3 * CLOCK_SHAPES];  // the same while the clock runs
} C;
