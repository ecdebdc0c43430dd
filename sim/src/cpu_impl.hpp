#pragma once
// The CPU backend's storage and passes (CpuSolver::Impl). Every per-cell array is a Plane: rows
// of floats starting on 64-byte boundaries, so a pass is a loop over rows whose inner loop the
// compiler vectorises. Each pass is the matching compute shader under sim/shaders/ in C++ (same
// float32 operations in the same order) and keeps its ping-pong: a pass reads neighbours only from
// arrays no cell of that pass writes, so rows run on any thread in any order and the results do
// not depend on the thread count. The passes run over the active blocks only (docs/sim-water.md,
// "The CPU backend"): cpu_solver.cpp chooses them, cpu_water.cpp and cpu_erosion.cpp hold the
// passes.

#include <omp.h>

#include <cstddef>
#include <cstdint>
#include <memory>
#include <new>
#include <span>
#include <unordered_map>
#include <vector>

#include <strata/sim/bookkeeping.hpp>
#include <strata/sim/params.hpp>
#include <strata/sim/solver.hpp>

#include "cpu_kernels.hpp"

namespace strata::sim::cpu {

struct ThermalConst;  // cpu_erosion.cpp

/// Side of the square blocks of cells whose quiet, rain and evaporation flags are kept (cells).
/// The water passes run on the cells within a step's reach of a block's cells that are not quiet
/// (Impl::reachCells), so the block only sets how often the flags are looked at.
constexpr int kBlock = 8;
/// Rows of the water passes' runs: a run is a rectangle of at most this many rows (the face
/// pass computes each run's rows of primitives and sides with a row more above and two below).
/// Fewer rows trim a winding river's runs closer but cost more rows of primitives: the Grand
/// Canyon job without pictures took 36.7 / 33.2 s with 4 and 38.9 / 36.0 s with 8 on OpenMP's
/// default threads (one thread: 42.6 / 46.4 s against 40.7 / 42.2 s; docs/benchmarks.md).
constexpr int kRunRows = 4;
/// A pass over fewer cells runs on one thread: forking costs more than it saves.
constexpr size_t kMinParallelCells = 16384;
/// A pass over fewer active cells runs on one thread. A grid large enough for threads may run
/// few cells (the Grand Canyon river: ~6,200 a step), which the tuner then times on both counts.
constexpr size_t kMinParallelPassCells = 4096;

/// `rows` rows of `width` floats (zero), each row starting on a 64-byte boundary; the row stride
/// is a multiple of 16 floats.
class Plane {
 public:
  Plane() = default;
  Plane(int width, int rows)
      : stride_((size_t(width) + 15) / 16 * 16), data_(new (std::align_val_t(64)) float[stride_ * size_t(rows)]()) {}
  bool empty() const { return !data_; }
  size_t stride() const { return stride_; }
  float* row(int y) { return data_.get() + size_t(y) * stride_; }
  const float* row(int y) const { return data_.get() + size_t(y) * stride_; }
  float& at(int x, int y) { return row(y)[x]; }
  float at(int x, int y) const { return row(y)[x]; }

 private:
  struct Free {
    void operator()(float* p) const { ::operator delete[](p, std::align_val_t(64)); }
  };
  size_t stride_ = 0;
  std::unique_ptr<float[], Free> data_;
};

/// A water state: depth h, suspended sediment s, discharges hu, hv (sim.glsl's vec4 per cell).
struct Water {
  Plane h, s, hu, hv;
};

/// Flood mode's face fluxes (fv_face.comp's vec4 per face): mass flux, normal momentum flux for
/// the left / top cell and for the right / bottom cell, tangential momentum flux.
struct Faces {
  Plane mass, nL, nR, t;
};

/// Rows [y0, y1) x columns [x0, x1): a rectangle of active cells a pass walks row by row.
struct Run {
  int y0, y1, x0, x1;
};

/// A set of blocks and the runs of cells it covers, in row order. The water passes' set runs
/// on cells, not whole blocks: `on` marks the blocks its runs touch.
struct BlockSet {
  std::vector<uint8_t> on;  ///< per block, row-major
  std::vector<Run> runs;
  size_t cells = 0;
};

/// Chooses between one thread and `most` for the passes by their measured speed (issue 35): on a
/// machine whose cores are busy with other work each pass's join waits for a thread the scheduler
/// has put aside, and a run on two threads took twice as long as on one. Steps are timed in
/// windows of kWindow; the first 2 x kRounds windows alternate the two counts, then the count
/// whose median seconds per cell update over its last kRounds windows is lower runs for kRun
/// steps (`most` only when it is at least kGain faster: a thread that barely helps is not worth
/// taking from a shared machine), then the other count runs one window and the choice is made
/// again. The results do not depend on the thread count (SimCpu.ResultsDoNotDependOnTheThreadCount),
/// so the choice changes no bit.
class ThreadTuner {
 public:
  static constexpr int kWindow = 4, kRounds = 3, kRun = 256;
  static constexpr double kGain = 0.9;
  ThreadTuner() = default;
  explicit ThreadTuner(int most) : most_(most), now_(most) {}
  int threads() const { return now_; }
  /// One step took `seconds` to update `updates` cells.
  void record(double seconds, long long updates);
  /// Steps run on one thread and on `most` so far.
  long long stepsOn(bool one) const { return steps_[one ? 0 : 1]; }

 private:
  double median(int k) const;  // of count k's (0: one thread, 1: most) last kRounds windows
  int most_ = 1, now_ = 1;
  int inWindow_ = 0, windows_ = 0, runLeft_ = 0;
  double seconds_ = 0, updates_ = 0;
  double rates_[2][kRounds] = {};  // seconds per cell update of each count's last windows (ring)
  int measured_[2] = {0, 0};
  long long steps_[2] = {0, 0};
};

struct Impl {
  // ---- the grid and the model ----
  int w = 0, h = 0, L = 0;
  int bw = 0, bh = 0;  // blocks across and down
  float dy = 1.0f;
  SimParams p;
  int threads = 1;      // the most threads the passes may use (per-thread scratch is allocated for these)
  int passThreads = 1;  // the threads the passes use this step (threads, or what `tuner` chose)
  bool tune = false;    // OpenMP's default count asked for: `tuner` chooses between 1 and `threads`
  ThreadTuner tuner;
  bool skip = true;
  // Per layer, MaterialConstants as columns (E1-E8).
  std::vector<float> erodibility, dissolutionRate, tanTalus, weatheringRate, criticalShear, shearErodibility;
  std::vector<float> tanFriction, sinFriction, cosFriction, cohesionHeight;
  float settling = 0.0f;              // w_s of the deposit (top) layer's material: the suspended load's (E3)
  std::vector<float> thermalShare;    // per layer: E7's share of the excess moved this step
  std::vector<float> pickShare;       // per layer: the force-based law's share of the deficit picked up this step
  std::vector<float> rowDx, rowArea;  // per row: dx and the cell area dx * dy
  std::vector<float> faceWidthY;      // per y-face (height + 1): the mean of the two rows' dx

  // ---- per-cell state ----
  Plane base, bed;         // datum-relative base and bed (base + layers)
  Plane layers;            // L * h rows: layer l, row y is row l * h + y
  size_t layerStride = 0;  // floats from one layer to the next
  Plane rain;              // raster rain (mm/h); empty when there is none
  Plane manningN2;         // n^2 per cell (W19, E1) of SimInput::manningN; empty: SimParams::manningN everywhere
  Plane infilKs, infilG;   // W11b per cell: Ks (m/s) and psi * dtheta (m); empty: no infiltration
  Water state[2];          // ping-pong: state[cur] is the current state
  int cur = 0;
  Plane flux[4], fluxDiag[4];  // pipes: outflows W, E, N, S and NW, NE, SW, SE (m^3/s)
  Plane accum[kAccumPerCell];  // (sum, error) pairs in AccumOffset order (m^3)
  Plane tilt;                  // sin(bed tilt), for erosion (E0)
  Plane thermal[4];            // material shed W, E, N, S (m over this cell) (E7)
  Plane scour;                 // what the flow took off each cell this step (m), the toe a bank may fall into (E8)
  Plane flood[4];              // max depth, max speed, arrival, wet duration
  // flood mode's intermediates
  Water stage;                        // the Heun predictor U1
  Faces faceX, faceY;                 // (w + 1) x h and w x (h + 1) faces
  Plane srcX, srcY;                   // W23 bed source of the step (the predictor's, then the Heun mean)
  Plane limit;                        // W25: the share of its outflow a cell can give
  Plane den;                          // E5: max(h A, limited outflow dt), the volume a cell's sediment share is of
  std::vector<Plane> scratch;         // per thread: the face pass's rows of primitives and face values
  std::vector<Plane> erosionScratch;  // per thread: a row of E1's shear stress and one of E2-E3's relaxation share

  float dt = 0.0f;
  bool anySuspended = false;  // some cell may carry sediment (sediment transport can be skipped otherwise)
  bool floodStats = false;
  float wetThresholdM = 0.0f;

  // ---- active blocks (cpu_solver.cpp) ----
  // Per block: the smallest rectangle of its cells that are not quiet (water state or pipe
  // outflows not +0); empty (x1 <= x0) when the block is quiet.
  std::vector<Run> extent;
  std::vector<uint8_t> needCell;      // per cell (w x h, row-major): the water passes run here this step
  std::vector<uint8_t> needPrevCell;  // per cell: what last step needed (it runs once more)
  std::vector<uint8_t> columns;       // scratch: a row group's columns with a cell to run
  // Per row, the columns [first, second) outside which needCell (spanRun) and needPrevCell
  // (spanPrev) are 0; spanNeed: this step's marks while they are made.
  std::vector<std::pair<int, int>> spanRun, spanPrev, spanNeed;
  std::vector<uint8_t> forced;         // written from outside since the last step (writeBlock)
  std::vector<uint8_t> evapResidual;   // some cell's evaporation sum has a nonzero compensation term
  std::vector<uint8_t> rainBlock;      // some cell has raster rain
  std::vector<uint8_t> thermalMoving;  // some cell sheds material (thermal flux last evaluated)
  std::vector<uint8_t> thermalForced;  // layers written from outside since the last step
  std::vector<uint8_t> work;           // scratch of one block set
  bool dirty = true;                   // every block runs this step and the next (new or restored state)
  bool thermalDirty = true;            // every block's thermal flux is evaluated this step
  BlockSet water, sources, thermalEval, thermalApply, lastThermalApply;
  long long cellUpdates = 0;

  Impl(const SimInput& input, const SimParams& params, int threads, bool skip);

  Water& now() { return state[cur]; }
  const Water& now() const { return state[cur]; }
  Water& next() { return state[1 - cur]; }
  size_t cells() const { return size_t(w) * size_t(h); }
  /// The block of a row-major cell index.
  size_t blockOf(uint32_t cell) const {
    return size_t(int(cell / uint32_t(w)) / kBlock * bw + int(cell % uint32_t(w)) / kBlock);
  }
  float bedOf(int x, int y) const;
  void recomputeBed(int x, int y);

  /// Calls f(run, thread) for every run of `set`, on the solver's threads when the set is large.
  template <class F>
  void forRuns(const BlockSet& set, F&& f) const {
    const int n = int(set.runs.size());
    const bool parallel = passThreads > 1 && n > 1 && set.cells >= kMinParallelPassCells;
#pragma omp parallel for schedule(dynamic, 1) num_threads(passThreads) if (parallel)
    for (int k = 0; k < n; ++k) f(set.runs[size_t(k)], omp_get_thread_num());
  }

  // ---- one step ----
  void step(const std::vector<SourceEntry>& sources, const std::vector<LevelEntry>& levels, float dtS, double endS);
  void planStep(const std::vector<SourceEntry>& sources, const std::vector<LevelEntry>& levels);
  void finishStep(long long updates);
  void fillRuns(BlockSet& set) const;
  void fillWaterRuns();
  void dilate(std::vector<uint8_t>& on);
  int reachCells() const;
  void needCells(int x0, int x1, int y0, int y1, int margin);
  Run busyExtent(int bx, int by) const;
  bool quiet(size_t block) const { return extent[block].x1 <= extent[block].x0; }
  bool blockEvapResidual(int bx, int by) const;
  void markAll();  // state replaced: all flags recomputed, every block runs for two steps
  void allocateFor(const SimParams& params);
  void setRain(const gis::Grid<float>& mmPerHour);

  // ---- passes (cpu_water.cpp) ----
  void sourcesPass(const std::vector<SourceEntry>& entries, float share = 1.0f);
  void rainPass(const BlockSet& set);                                           // W11, W11b on the set's cells
  void pointSources(std::span<const SourceEntry> entries, float share = 1.0f);  // W12, W12b
  // W11 or W11b can change a cell: rain (uniform or a raster), evaporation or infiltration.
  bool rainOrLosses() const {
    return p.rainMmPerHour != 0.0f || !rain.empty() || p.evaporationMmPerHour != 0.0f || !infilKs.empty();
  }
  void pipeFluxPass();
  void pipeUpdatePass();
  void fvFacePass(const Water& u, bool average);
  void fvLimitPass() { fvLimitPass(water); }
  void fvLimitPass(const BlockSet& set);
  void fvDenPass();
  void fvUpdatePass(bool final);
  void tiltRows(int y, int x0, int x1);  // E0 for cells [x0, x1) of row y
  void levelPass(std::span<const LevelEntry> entries);
  void floodStatsPass(float endTimeS) { floodStatsPass(water, endTimeS); }
  void floodStatsPass(const BlockSet& set, float endTimeS);
  float maxWaveSpeed() const;
  float outflowLimited(int x, int y) const;  // W25-limited volume rate leaving a cell (m^3/s)
  float fvSedimentEdge(int x, int y, const FaceFlux limited[4]);
  // The local-inertial scheme (W30-W33): faceX.mass / faceY.mass hold each face's new discharge
  // per unit width, fvLimitPass its W25 limits, and flux[0..3] every cell's W, E, N, S face
  // discharges as the last step applied them (the state the next step starts from).
  bool inertial() const { return p.floodScheme == FloodScheme::kLocalInertial; }
  void inertialFacePass() { inertialFacePass(water); }
  void inertialFacePass(const BlockSet& set);
  void inertialUpdatePass() { inertialUpdatePass(water); }
  void inertialUpdatePass(const BlockSet& set);
  float inertialFaceAt(int x, int y, bool alongX, float q0) const;
  float inertialFaceAt(int x, int y, bool alongX, float q0, float ha, float hb) const;  // with these depths
  bool inPlace = false;  // inertialUpdatePass updates now() (W37), not next()

  // ---- local time steps (W37, cpu_local_steps.cpp) ----
  /// A face between blocks of two levels: it steps with the finer level (cells a, b: the cell west
  /// or north of it and the cell east or south), and what it carries reaches the coarser cell
  /// each time the finer cell takes it.
  struct LevelFace {
    int x, y;                                      // cell a
    bool alongX;                                   // an x face (b = (x + 1, y)), else a y face (b = (x, y + 1))
    bool fineIsA;                                  // a is the finer cell
    int level;                                     // the finer cell's
    size_t coarse;                                 // the coarser cell's LevelCell
    int xb() const { return alongX ? x + 1 : x; }  // cell b
    int yb() const { return alongX ? y : y + 1; }
  };
  /// A cell beside a finer block: its W25 limit over its own step, the volume it may still give
  /// through its faces to finer cells, its faces to finer cells (bits W, E, N, S), and the depth
  /// it holds at the midpoint of its step beyond the depth it has then (W37's time interpolation).
  struct LevelCell {
    int x, y, level;
    float limit, budget;
    uint8_t finer;
    float ahead;
  };
  std::vector<uint8_t> blockLevel;  // per block
  // Per block: max sqrt(g h), the sources' depth rate and the faces' inflow rate (m/s).
  std::vector<float> blockSpeed, blockRate, blockInflow;
  std::vector<BlockSet> levelWater, levelRain;  // the water and sources sets' runs of each level
  std::vector<LevelFace> levelFaces;
  std::vector<LevelCell> levelCells;
  // Faces whose flux is integrated over the local steps (Solver::integrateFaces): each one's cells
  // a (west / north) and b (east / south), either outside the grid at an edge; the slot of each
  // of readFaceMassFlux's indices; the volume per unit width through each over the last step.
  struct IntegratedFace {
    int xa, ya, xb, yb;
    bool alongX, hasA, hasB;
  };
  std::vector<IntegratedFace> integrated;
  std::unordered_map<size_t, size_t> integratedSlot;
  std::vector<double> integratedQdt;
  double integratedStepS = 0;  // the step they were integrated over (0: none yet)
  void integrateLevel(int m, float dtLevel);
  void localStep(const std::vector<SourceEntry>& entries, const std::vector<LevelEntry>& levels, float dtS, double endS,
                 double rainRateMS);
  int planLevels(const std::vector<SourceEntry>& entries, float dtS, double rainRateMS);
  void splitByLevel(const BlockSet& in, std::vector<BlockSet>& out, int levels) const;
  void spread(std::vector<float>& perBlock) const;
  void findLevelFaces();
  int levelOf(int x, int y) const { return blockLevel[size_t((y / kBlock) * bw + x / kBlock)]; }
  int levelOf(uint32_t cell) const { return blockLevel[blockOf(cell)]; }

  // ---- passes (cpu_erosion.cpp) ----
  void erosionPass();
  void erodeCell(int x, int y);
  ThermalConst thermalConst();  // E7's shares of this step in thermalShare
  void thermalFluxPass();
  void thermalApplyPass();
};

}  // namespace strata::sim::cpu
