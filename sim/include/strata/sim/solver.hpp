#pragma once
// One interface for every water / erosion solver: the CPU backend (CpuSolver), the GL backend
// (GlSolver) and the runners that hold several solvers (TiledSolver, AdaptiveSolver, and the
// distributed run). What they share lives here once: sources and levels, the W10 step choice,
// the water and rain budgets, statistics, flood statistics and the checkpoint fields. A backend
// implements the passes of one step and how its cells are read and written.
//
// Units: metres, seconds, m^3. Cells (x, y) = (column, row), row 0 north; per-cell arrays are
// row-major. docs/sim-water.md and docs/sim-erosion.md hold the equations.

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <strata/core/result.hpp>
#include <strata/gis/raster.hpp>
#include <strata/sim/bookkeeping.hpp>
#include <strata/sim/input.hpp>
#include <strata/sim/params.hpp>

namespace strata::sim {

/// Cell velocity (m/s): u along +x (east, columns), v along +y (south, rows).
struct VelocityField {
  gis::Grid<float> uMS;
  gis::Grid<float> vMS;
};

/// Per-cell flood statistics since enableFloodStats(), updated after every step.
struct FloodStats {
  gis::Grid<float> maxDepthM;     ///< deepest water (m)
  gis::Grid<float> maxSpeedMS;    ///< fastest flow (m/s)
  gis::Grid<float> arrivalS;      ///< end of the first step with depth above the wet threshold (s); -1 = never
  gis::Grid<float> wetDurationS;  ///< total time above the wet threshold (s)
};

/// Water and material bookkeeping since the start (volumes in m^3, summed in double).
struct SimStats {
  double timeS = 0;              ///< simulated time
  long long steps = 0;           ///< steps taken
  double lastDtS = 0;            ///< the most recent step
  double storedWaterM3 = 0;      ///< water in the domain now
  double initialWaterM3 = 0;     ///< water at the start
  double rainM3 = 0;             ///< rain added
  double inflowM3 = 0;           ///< added by sources (and fixed levels that gained on balance)
  double outflowM3 = 0;          ///< left through open edges (and fixed levels that lost on balance)
  double evaporatedM3 = 0;       ///< evaporated
  double infiltratedM3 = 0;      ///< lost to the soil
  double materialM3 = 0;         ///< all layers + suspended sediment now
  double suspendedM3 = 0;        ///< suspended sediment now
  double initialMaterialM3 = 0;  ///< all layers + suspended at the start
  double sedimentOutflowM3 = 0;  ///< suspended sediment carried out through open edges
  double maxDepthM = 0;          ///< deepest water now
  /// stored - (initial + rain + inflow - outflow - evaporated - infiltrated): 0 up to rounding.
  double waterBalanceM3() const {
    return storedWaterM3 - (initialWaterM3 + rainM3 + inflowM3 - outflowM3 - evaporatedM3 - infiltratedM3);
  }
};

/// Each cell's compensated (Kahan) sums (W20), a (sum, error) pair of floats each, m^3, and the
/// error of its compensated depth (W34): the offsets into a cell's kAccumPerCell floats of
/// CellBlock::accum and SolverState::accum. The GL kernels get the same numbers as #defines
/// (ACCUM_PER_CELL, ACCUM_OUTFLOW, ...).
enum AccumOffset : int {
  kAccumOutflow = 0,      ///< water out through open edges
  kAccumEvaporated = 2,   ///< evaporated (W11)
  kAccumSedimentOut = 4,  ///< suspended sediment out through open edges
  kAccumLevel = 6,        ///< gained (> 0) or lost at a fixed level (W26)
  kAccumInfiltrated = 8,  ///< lost to the soil (W11b)
  /// Not a sum: what the float depth h could not hold, m; the cell holds h + this (W34).
  kAccumDepthError = 10,
  kAccumPerCell = 11,
  /// The accumulators a step reads, not only adds to: the infiltrated sum (W11b's cumulative
  /// infiltration) and the depth error (W34), the last kAccumCarried of a cell's floats. The
  /// other sums only their cell's owner adds up, so halos leave them out (kBlockCarried).
  kAccumCarriedFrom = kAccumInfiltrated,
  kAccumCarried = kAccumPerCell - kAccumCarriedFrom,
};

/// Which parts of a rectangle of cells readBlock() reads (bits).
enum BlockParts : unsigned {
  kBlockState = 1u,   ///< h, s, hu, hv
  kBlockFlux = 2u,    ///< pipe outflows (and diagonal ones when the solver has them)
  kBlockLayers = 4u,  ///< layer thicknesses
  kBlockAccum = 8u,   ///< every accumulator: compensated budget sums and the depth error
  /// Only the accumulators a step reads (kAccumCarried a cell, from kAccumCarriedFrom), a part of
  /// kBlockAccum of its own: what halos carry of them (haloParts).
  kBlockCarried = 16u,
  kBlockAll = 15u,  ///< everything a solver keeps
};

/// What a halo exchange (tiles, ranks) carries under `p`: the state and the carried
/// accumulators; the fluxes where a step reads the last step's (pipes, the local-inertial
/// scheme's faces); the layers where a step changes them (erosion, thermal weathering). The
/// model and scheme are fixed at creation, and erosion and thermal weathering change layers only
/// while on, so a halo skipped while they are off already holds its owner's layers.
unsigned haloParts(const SimParams& p);

/// The persistent state of a rectangle of cells: what a halo exchange (tiles, ranks) carries.
/// An empty part is not read or, in writeBlock(), left as it is.
struct CellBlock {
  gis::CellRect rect{};           ///< the cells [x, x + width) x [y, y + height)
  std::vector<float> state{};     ///< 4 per cell: depth h, suspended s, discharges hu, hv
  std::vector<float> flux{};      ///< 4 per cell: pipe outflows W, E, N, S (m^3/s)
  std::vector<float> fluxDiag{};  ///< 4 per cell: diagonal pipes NW, NE, SW, SE (with them)
  std::vector<float> layers{};    ///< layer-major: layers[l * cells + cell] (m)
  std::vector<float> accum{};     ///< kAccumPerCell per cell: compensated sums, depth error (AccumOffset)
  std::vector<float> carried{};   ///< kAccumCarried per cell: accum's from kAccumCarriedFrom on
  size_t cells() const { return size_t(rect.width) * size_t(rect.height); }

  /// The one list of a block's parts: f(part's BlockParts bit, its values, floats per cell of a
  /// plane, planes) for each, in one order (the layers are `layers` planes, layer-major; the
  /// others one plane of interleaved floats). Whatever walks the parts (fits, copies, encodings,
  /// checkpoints) walks this.
  template <class Block, class F>
  static void forEachPart(Block& b, int layers, F&& f) {
    f(kBlockState, b.state, size_t(4), size_t(1));
    f(kBlockFlux, b.flux, size_t(4), size_t(1));
    f(kBlockFlux, b.fluxDiag, size_t(4), size_t(1));
    f(kBlockLayers, b.layers, size_t(1), size_t(layers));
    f(kBlockAccum, b.accum, size_t(kAccumPerCell), size_t(1));
    f(kBlockCarried, b.carried, size_t(kAccumCarried), size_t(1));
  }
};

/// Copies what `src` holds of the cells in both rectangles into `dst` (each part `src` has,
/// sized to dst.rect where `dst` lacks it); both rectangles in the same coordinates. The one
/// overlap copy: tiles' and ranks' halos, and reads and writes of blocks that span parts.
void copyOverlap(const CellBlock& src, CellBlock& dst, int layers);

/// A solver's own counters: time, steps and the budgets of what it added.
struct SolverCounters {
  double timeS = 0, lastDtS = 0, rainM3 = 0, inflowM3 = 0, initialWaterM3 = 0, initialMaterialM3 = 0;
  /// What the cells' infiltration sums held at the last restartAt(): they are the soil's state
  /// (W11b's cumulative infiltration), kept through a restart, so the budget subtracts them.
  double infiltratedBeforeM3 = 0;
  int64_t steps = 0;
};

/// Everything a solver needs to continue exactly where it was (a checkpoint). A single solver
/// fills the counters and the per-cell arrays; a runner adds its own arrays and one part per
/// solver it holds.
struct SolverState {
  SolverCounters counters;
  float wetThresholdM = -1;        ///< flood statistics threshold (< 0: off)
  std::vector<float> state;        ///< 4 per cell: h, s, hu, hv
  std::vector<float> flux;         ///< 4 per cell: pipe outflows
  std::vector<float> fluxDiag;     ///< 4 per cell with diagonal pipes
  std::vector<float> layers;       ///< layer-major thicknesses
  std::vector<float> accum;        ///< kAccumPerCell per cell: compensated sums (AccumOffset)
  std::vector<float> flood;        ///< 4 per cell: max depth, max speed, arrival, wet duration
  std::vector<float> extra;        ///< a runner's own per-cell data
  std::vector<double> numbers;     ///< a runner's own counters
  std::vector<int32_t> tags;       ///< a runner's own integers (e.g. tile levels)
  std::vector<SolverState> parts;  ///< the states of the solvers a runner holds

  /// Calls f(name, field) for every field in one fixed order: the one list that checkpoint
  /// writers and readers walk (scalars, float and int vectors, then the parts).
  template <class Self, class F>
  static void forEachField(Self& s, F&& f) {
    f("counters", s.counters);
    f("wet_threshold_m", s.wetThresholdM);
    f("state", s.state);
    f("flux", s.flux);
    f("flux_diag", s.fluxDiag);
    f("layers", s.layers);
    f("accum", s.accum);
    f("flood", s.flood);
    f("extra", s.extra);
    f("numbers", s.numbers);
    f("tags", s.tags);
    f("parts", s.parts);
  }
};

class Solver;
/// Makes a solver (a backend's create() behind one signature): what runners that hold several
/// solvers (tiles, ranks) build their parts with.
using SolverFactory = std::function<Result<std::unique_ptr<Solver>>(const SimInput&, const SimParams&)>;

class Solver {
 public:
  virtual ~Solver();
  Solver(const Solver&) = delete;
  Solver& operator=(const Solver&) = delete;

  /// Adds an inflow source (spring, inflow line with a hydrograph); cells must be inside.
  Status addSource(const Source& source);
  /// Adds a fixed water level (W26) on its cells; cells must be inside.
  Status addLevel(const LevelBoundary& level);
  /// Changes the run-time parameters (rain, evaporation, friction, erosion constants, edges, time
  /// step rule) from the next step on; the water model and diagonal pipes stay as created.
  Status setParams(const SimParams& params);
  /// Replaces the rain raster (mm/h per cell, >= 0; empty = none) from the next step on: the
  /// frames of a radar rain series. The CPU and GL backends and tiles take it; a runner whose
  /// cells are elsewhere (MPI ranks, adaptive levels) refuses.
  Status setRainRaster(const gis::Grid<float>& mmPerHour);

  /// Takes `n` steps, each of the W10 length.
  void step(int n = 1);
  /// Steps until `seconds` more have been simulated (the last step is shortened to land on it):
  /// advanceBatch to the end.
  void advance(double seconds);
  /// What advanceBatch did: the steps taken, and the shortest and the last step W10 chose for
  /// them (before the last was shortened to land on the end; 0 without a step).
  struct Batch {
    int64_t steps = 0;
    double minChosenDtS = 0, lastChosenDtS = 0;
  };
  /// Steps of the W10 length towards `endS`, the last one shortened to land on it, until it is
  /// reached() or `maxSteps` were taken. A backend that chooses its steps itself takes them
  /// without waiting for the host between steps (the GL backend, W35: one read of its clock per
  /// run of steps); otherwise nextDt() and stepWithDt() for each.
  Batch advanceBatch(double endS, int64_t maxSteps);
  /// Whether time `t` has reached `target` (within 1e-9 of it, relative): the one rule of
  /// advance, advanceBatch and the runs of scenarios.
  static bool reached(double t, double target) { return !(t < target - 1e-9 * std::max(1.0, std::abs(target))); }
  /// One step of exactly `dtS` seconds (runners that hold several solvers choose one step for all).
  void stepWithDt(double dtS);
  /// Advances the clock (time, steps, budgets) by one step of `dtS` without running the passes:
  /// for runners that know a step would change none of this solver's cells (an idle block of a
  /// distributed run: every cell dry and still, no rain, sources, levels or thermal weathering).
  void skipStep(double dtS);
  /// The W10 length of the next step.
  virtual double nextDt();

  // The whole grid's fields, read through readBlock(); a backend may read them faster itself.
  virtual gis::Grid<float> readWaterDepth() const;           ///< m
  virtual VelocityField readVelocity() const;                ///< m/s (0 where the depth is below dryDepthM)
  virtual std::vector<gis::Grid<float>> readLayers() const;  ///< thicknesses, bottom to top (m)
  virtual gis::Grid<float> readSuspended() const;            ///< suspended sediment (m of material)
  virtual gis::Grid<float> readBed() const = 0;              ///< bed above datumM() (m; float keeps mm)
  /// Volumes since the start.
  virtual SimStats stats() const;
  /// stats() with only the counters filled (time, steps, last step, rain and source budgets,
  /// the initial totals): cheap, nothing read from the cells.
  SimStats counterStats() const;

  /// Sets the clock before the first step (a run with a spin-up starts at -spin-up, so that the
  /// sources and levels hold their t = 0 values through it).
  void startClockAt(double timeS);
  /// The run starts over at `timeS` (the end of a spin-up): the budgets (inflow, rain, outflow,
  /// evaporation, level exchanges) back to 0, the initial water and material those stored now,
  /// and the clock at `timeS`. A spin-up that reached its steady state early ends here too: its
  /// sources and levels held their t = 0 values all through it, so the time skipped would have
  /// changed nothing. The caller keeps that promise: the clock moves without a step.
  void restartAt(double timeS);

  /// Starts per-cell flood statistics with `wetThresholdM` (>= 0) as the wet/dry depth (m).
  void enableFloodStats(float wetThresholdM);
  /// The statistics so far (no depth, no speed, never arrived, never wet if never enabled).
  virtual FloodStats readFloodStats() const;

  // What this process holds of the grid, read without gathering: a solver over MPI ranks holds
  // only its rank's blocks, and outputs are written per rank from these (local, not collective).
  /// The rectangles of cells this process holds: the whole grid, or its rank's blocks.
  virtual std::vector<gis::CellRect> localRects() const;
  /// `parts` of a rectangle inside one of localRects() (global cells).
  virtual CellBlock readLocal(const gis::CellRect& rect, unsigned parts) const;
  /// The flood statistics of a rectangle inside one of localRects().
  virtual FloodStats readLocalFloodStats(const gis::CellRect& rect) const;
  /// The bed (above datumM()) of a rectangle inside one of localRects().
  virtual gis::Grid<float> readLocalBed(const gis::CellRect& rect) const;

  /// The state to continue from later (a checkpoint).
  SolverState saveState() const;
  /// Continues from a saved state of a solver of the same grid and parameters (set the
  /// parameters in force at that time, e.g. rain, with setParams).
  Status restoreState(const SolverState& state);

  const SimParams& params() const { return params_; }
  const CellGrid& grid() const { return grid_; }
  double datumM() const { return grid_.datumM; }
  double timeS() const { return c_.timeS; }
  /// What runs the passes, for reports: e.g. "CPU, 2 threads" or "GL on NVIDIA H100".
  virtual std::string backendName() const = 0;

  // For runners that hold solvers (tiles, ranks).
  /// max over cells of |u| + sqrt(g h) (m/s), as W10 uses it.
  virtual double maxWaveSpeedMS() const = 0;
  /// Bound on the depth per second this solver's rain and sources add to one cell from now to
  /// `t1S` (m/s; sourceDepthRate, W10).
  double sourceDepthRateMS(double t1S) const;
  /// The `parts` of the persistent state of a rectangle of cells inside the grid.
  virtual CellBlock readBlock(int x0, int y0, int width, int height, unsigned parts = kBlockAll) const = 0;
  /// Replaces the non-empty parts of the state of block.width x block.height cells at (x0, y0)
  /// (inside the grid; each part of its full size; `carried` after `accum`); the bed follows the
  /// layers.
  virtual void writeBlock(const CellBlock& block) = 0;
  /// Flood mode: the mass flux per unit width (m^2/s, positive east / south) the last step moved
  /// through each face (the Heun average, W22, scaled by W25's outflow limits): x faces
  /// ((width + 1) x height, face x is the west face of cell x), then y faces (width x (height + 1),
  /// face y is the north face of row y).
  virtual std::vector<float> readFaceMassFlux() const = 0;
  /// The same at some faces only (indices into readFaceMassFlux()'s vector, each inside it): what
  /// a cross-section sums after every step. By default picked from the whole vector; a backend
  /// that can read single faces cheaply reads only those.
  virtual std::vector<float> readFaceMassFluxAt(const std::vector<size_t>& faces) const;
  /// The faces (indices as above) whose flux a caller integrates over the steps, as a
  /// cross-section does: a backend whose step is made of shorter ones (local time steps, W37)
  /// then gives at these faces the mean over its last step, so that flux times step is the volume
  /// that crossed. By default nothing to do (one step applies one flux).
  virtual void integrateFaces(const std::vector<size_t>& faces) { (void)faces; }

 protected:
  /// Sets up the shared bookkeeping from a validated input.
  Solver(const SimInput& input, const SimParams& params);
  /// For a runner whose cells live in other processes (the ranks of a distributed run): the
  /// grid's shape alone. Its rain comes from rainTotals(): call updateRainTotals() once the
  /// parts exist.
  Solver(const CellGrid& grid, const SimParams& params);
  Solver(Solver&&) noexcept = default;
  Solver& operator=(Solver&&) noexcept = default;
  /// Records the water and material at the start; backends call it at the end of create().
  void recordInitialTotals();

  /// What one step needs besides the state: its length, the time at its start, the sources'
  /// mean discharge per cell over it (W12) and the fixed levels at its end (W26).
  struct StepInputs {
    float dtS = 0;
    double startS = 0;
    const std::vector<SourceEntry>& sources;
    const std::vector<LevelEntry>& levels;
  };
  /// Runs the passes of one step (docs/sim-water.md, "One step"), and updates the flood
  /// statistics when floodThresholdM() >= 0.
  virtual void runStep(const StepInputs& step) = 0;
  /// W35: what advanceBatch asks of a backend that chooses its steps itself.
  struct DeviceRequest {
    double timeS = 0, endS = 0;
    int64_t maxSteps = 0;
    double rainRateMS = 0;  ///< the rain's bound on a cell's depth rate (W10's r without sources)
  };
  /// What it did: the steps, the clock after them, the sources' volume, the last step taken and
  /// the shortest and last step W10 chose.
  struct DeviceRun {
    int64_t steps = 0;
    double timeS = 0, inflowM3 = 0, lastDtS = 0, minChosenDtS = 0, lastChosenDtS = 0;
  };
  /// Steps towards request.endS chosen and taken by the backend itself, with sources() and the
  /// flood statistics as stepWithDt takes them; nullopt: it cannot (advanceBatch steps from the
  /// host). The base class accounts for the result (clock, steps, budgets).
  virtual std::optional<DeviceRun> runOnDevice(const DeviceRequest& /*request*/) { return std::nullopt; }
  /// params() changed (setParams).
  virtual void onParamsChanged() {}
  /// The rain raster is to change (setRainRaster, the grid checked); by default refused.
  virtual Status onRainRasterChanged(const gis::Grid<float>& mmPerHour);
  /// The rain raster's largest value (mm/h, W10's bound) and the rain falling on the whole grid
  /// under params() (m^3/s, rainVolumeRate): from the input's raster by default; a runner whose
  /// cells are elsewhere sums its parts'.
  struct RainTotals {
    double maxRasterMmH = 0, volumeM3S = 0;
  };
  virtual RainTotals rainTotals() const;
  /// Takes rainTotals() (setParams does it; see the grid-only constructor).
  void updateRainTotals();
  /// A source or level was added (runners hand them on to the solvers they hold).
  virtual Status onSourceAdded(const Source& /*source*/) { return {}; }
  /// The solvers a runner steps (tiles, blocks), each once: they follow the run's clock (a
  /// part's sources and levels follow its own clock). None for a backend.
  virtual void forEachPart(const std::function<void(Solver&)>& /*f*/) {}
  /// restartAt(): every cell's accumulators (outflow, evaporation, level exchanges) back to 0;
  /// the infiltration sums stay (they are the soil's state).
  virtual void clearAccumulators();
  virtual Status onLevelAdded(const LevelBoundary& /*level*/) { return {}; }

  /// Per-cell sums for stats(): the cells' depth, suspended load and layers, and the totals of
  /// their compensated accumulators. By default from readBlock() over the whole grid.
  struct Totals {
    std::vector<float> depth, suspended, layers;  ///< per cell (layers layer-major)
    double outflowM3 = 0, evaporatedM3 = 0, infiltratedM3 = 0, sedimentOutflowM3 = 0;
    double levelInM3 = 0, levelOutM3 = 0;  ///< W26: cells that gained / lost on balance
  };
  virtual Totals totals() const;

  /// Flood statistics: backends that update them inside their step keep them on their own cells;
  /// the others leave them to this class, which updates them on the host after every step.
  virtual bool keepsFloodStats() const { return false; }
  /// (Backends that keep them) start from no depth, no speed, never arrived, never wet.
  virtual void resetFloodStats() {}
  /// (Backends that keep them) 4 per cell: max depth, max speed, arrival, wet duration.
  virtual std::vector<float> floodStatsCells() const { return {}; }
  virtual void setFloodStatsCells(const std::vector<float>& /*cells*/) {}
  /// A runner whose parts' states carry the flood statistics (a distributed run's blocks): its
  /// saveState leaves them out at its own level and restoreState expects none there.
  virtual bool floodStatsInParts() const { return false; }
  float floodThresholdM() const { return wetThresholdM_; }

  /// The per-cell arrays of a checkpoint (state, flux, fluxDiag, layers, accum: by default the
  /// whole grid through readBlock/writeBlock; a runner saves its parts instead); restoreCells
  /// checks their sizes.
  virtual void saveCells(SolverState& out) const;
  virtual Status restoreCells(const SolverState& in);

  const std::vector<Source>& sources() const { return sources_; }
  const std::vector<LevelBoundary>& levels() const { return levels_; }
  double maxRainRasterMmH() const { return maxRainRasterMmH_; }

 private:
  void updateHostFloodStats();
  void takeStep(double dtS, bool run);
  void setClock(double timeS);  // this solver's and its parts'

  SimParams params_;
  CellGrid grid_;
  std::vector<Source> sources_;
  std::vector<LevelBoundary> levels_;
  std::vector<float> rainRaster_;  // mm/h, for the rain volume rate
  double maxRainRasterMmH_ = 0, rainRateM3S_ = 0;
  SolverCounters c_;
  float wetThresholdM_ = -1;
  std::vector<float> hostFlood_;  // 4 per cell, when the backend does not keep them
};

/// Checks a block against a width x height grid with `layers` layers: inside, and each non-empty
/// part of its full size. Backends call it (STRATA_CHECK) before writing a block.
bool blockFits(const CellBlock& block, int width, int height, int layers);

/// An empty FloodStats of `width` x `height` (no depth, no speed, never arrived, never wet),
/// and its 4-per-cell form.
std::vector<float> initialFloodStatsCells(size_t cells);
FloodStats floodStatsFromCells(const std::vector<float>& cells, int width, int height);
/// The part of `stats` (of a grid) inside `rect` (inside that grid).
FloodStats cropFloodStats(const FloodStats& stats, const gis::CellRect& rect);
/// The part of a grid inside `rect` (inside it).
gis::Grid<float> cropGrid(const gis::Grid<float>& grid, const gis::CellRect& rect);

}  // namespace strata::sim
