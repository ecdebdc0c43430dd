#pragma once
// GPU water and erosion simulation (GL 4.5 compute, shaders/sim/*.comp): the same model, API and
// parameters as the CPU reference strata::terrain::sim::CpuSimulation, which tests compare it
// with. All state lives in GPU buffers; a step reads nothing back unless the time step is
// adaptive (cflAlpha > 0: one 4-byte read of the max wave speed per step). Needs a current
// GL 4.5 context (render::gl::HeadlessContext or a window) for its whole life.

#include <memory>
#include <vector>

#include <strata/core/result.hpp>
#include <strata/gis/raster.hpp>
#include <strata/render/gl/objects.hpp>
#include <strata/terrain/sim/cpu_simulation.hpp>
#include <strata/terrain/sim/sim_params.hpp>

namespace strata::render::sim {

using strata::terrain::sim::LevelBoundary;
using strata::terrain::sim::SimInput;
using strata::terrain::sim::SimParams;
using strata::terrain::sim::SimStats;
using strata::terrain::sim::Source;
using strata::terrain::sim::VelocityField;

/// Per-cell flood statistics since the start (enableFloodStats), updated after every step.
struct FloodStats {
  gis::Grid<float> maxDepthM;     ///< deepest water (m)
  gis::Grid<float> maxSpeedMS;    ///< fastest flow (m/s)
  gis::Grid<float> arrivalS;      ///< first time the depth exceeded the wet threshold (s); -1 = never
  gis::Grid<float> wetDurationS;  ///< total time above the wet threshold (s)
};

class Simulation {
 public:
  /// Validates the input, compiles the kernels and uploads the state.
  static Result<Simulation> create(const SimInput& input, const SimParams& params);
  Simulation(Simulation&&) noexcept;
  Simulation& operator=(Simulation&&) noexcept;
  ~Simulation();

  /// Adds an inflow source (spring, inflow line with a hydrograph); cells must be inside.
  Status addSource(const Source& source);
  /// Adds a fixed water level (W26) on its cells; cells must be inside, stage times increasing.
  Status addLevel(const LevelBoundary& level);
  /// Changes the run-time parameters (rain, evaporation, friction, erosion constants, edges, time
  /// step rule) from the next step on; grid size, layers and water model stay as created.
  Status setParams(const SimParams& params);
  /// Takes `n` steps (each of terrain::sim::stepDt, W10).
  void step(int n = 1);
  /// Steps until `seconds` more have been simulated (the last step is shortened to land on it).
  void advance(double seconds);

  gis::Grid<float> readWaterDepth() const;           ///< m
  VelocityField readVelocity() const;                ///< m/s
  std::vector<gis::Grid<float>> readLayers() const;  ///< thicknesses, bottom to top (m)
  gis::Grid<float> readSuspended() const;            ///< suspended sediment (m of material)
  gis::Grid<float> readBed() const;                  ///< bed elevation above datumM() (m)
  double datumM() const;                             ///< the datum elevations are stored against (m)
  /// The current state on the GPU: 4 floats per cell (h, s, hu, hv), row-major. Valid until the
  /// next step (the state ping-pongs); for GPU-side copies such as drawing the water.
  const gl::Buffer& stateBuffer() const;
  /// Volumes since the start (reads the state back; summed in double on the CPU).
  SimStats stats() const;
  const SimParams& params() const;
  /// Starts per-step flood statistics with `wetThresholdM` as the wet/dry depth (m).
  void enableFloodStats(float wetThresholdM);
  /// The statistics so far (all -1/0 grids if never enabled).
  FloodStats readFloodStats() const;

  /// Everything a run needs to continue exactly where it was (a checkpoint).
  struct Counters {
    double timeS = 0, lastDtS = 0, rainM3 = 0, inflowM3 = 0, initialWaterM3 = 0, initialMaterialM3 = 0;
    long long steps = 0;
    float dtS = 0;
  };
  struct Snapshot;
  Snapshot snapshot() const;
  /// Restores a snapshot of a simulation of the same grid and parameters (set the parameters in
  /// force at that time, e.g. rain, with setParams).
  Status restore(const Snapshot& snapshot);

  /// Bytes of GPU buffers this simulation holds.
  size_t gpuBytes() const;

  /// For tiled runs (TiledSimulation): the persistent per-cell state as stored on the GPU.
  struct RawState {
    std::vector<float> state;     ///< 4 per cell: h, s, hu, hv
    std::vector<float> flux;      ///< 4 per cell: pipe outflows W, E, N, S
    std::vector<float> fluxDiag;  ///< diagonal pipes NW, NE, SW, SE: 4 per cell (4 floats in all without them)
    std::vector<float> layers;    ///< layer-major: layers[l * cells + cell]
    std::vector<float> accum;     ///< 8 per cell: (sum, error) of outflow, evaporation, sediment outflow
  };
  RawState readRaw() const;
  /// Replaces state, flux and layers (accum is kept) and recomputes the bed from them.
  /// (restore() replaces accum too.)
  void writeRaw(const RawState& raw);
  /// max over cells of |u| + sqrt(g h) (m/s), as the adaptive step uses it (W10).
  double maxWaveSpeedMS();
  /// One step of exactly `dtS` seconds (tiles must all take the same step).
  void stepWithDt(double dtS);
  /// Bound on the depth per second this simulation's rain and sources add to one cell from
  /// now to `t1S` (m/s; terrain::sim::sourceDepthRate, W10).
  double sourceDepthRateMS(double t1S) const;

  /// For adaptive runs (AdaptiveSimulation): the state alone, 4 floats per cell (h, s, hu, hv),
  /// without the round trip of the other buffers that readRaw/writeRaw make.
  std::vector<float> readStateRaw() const;
  void writeStateRaw(const std::vector<float>& state);
  /// Flood mode: the mass flux per unit width (m^2/s, positive east / south) the last step moved
  /// through each face (the Heun average, W22, scaled by W25's outflow limits): x faces ((width + 1) x height, face x
  /// is the west face of cell x) then y faces (width x (height + 1), face y is the north face of row y).
  std::vector<float> readFaceMassFlux() const;

 private:
  struct Impl;
  explicit Simulation(std::unique_ptr<Impl> impl);
  std::unique_ptr<Impl> impl_;
};

struct Simulation::Snapshot {
  Counters counters;
  RawState raw;
  FloodStats flood;
};

}  // namespace strata::render::sim
