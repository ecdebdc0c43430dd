#pragma once
// CPU reference solver of the water and erosion model (docs/sim-water.md, docs/sim-erosion.md):
// the same passes, in the same order and in float32, as the GPU kernels under shaders/sim/, so
// tests can pin the kernels down on small grids. Single-threaded; meant for grids up to ~256^2.

#include <vector>

#include <strata/core/result.hpp>
#include <strata/gis/raster.hpp>
#include <strata/terrain/sim/sim_host.hpp>
#include <strata/terrain/sim/sim_params.hpp>

namespace strata::terrain::sim {

/// Cell velocity (m/s): u along +x (east, columns), v along +y (south, rows).
struct VelocityField {
  gis::Grid<float> uMS;
  gis::Grid<float> vMS;
};

class CpuSimulation {
 public:
  /// Validates and copies the input; `params.width/height/layerCount/dyM` are taken from it.
  static Result<CpuSimulation> create(const SimInput& input, const SimParams& params);

  /// Adds an inflow source (spring, inflow line with a hydrograph); cells must be inside.
  Status addSource(const Source& source);
  /// Adds a fixed water level (W26) on its cells; cells must be inside, stage times increasing.
  Status addLevel(const LevelBoundary& level);
  /// Changes the run-time parameters (rain, evaporation, friction, erosion constants, edges, time
  /// step rule) from the next step on; grid size, layers and water model stay as created.
  Status setParams(const SimParams& params);
  /// Takes `n` steps (each of stepDt(), W10).
  void step(int n = 1);
  /// Steps until `seconds` more have been simulated (the last step is shortened to land on it).
  void advance(double seconds);

  gis::Grid<float> readWaterDepth() const;           ///< m
  VelocityField readVelocity() const;                ///< m/s
  std::vector<gis::Grid<float>> readLayers() const;  ///< thicknesses, bottom to top (m)
  gis::Grid<float> readSuspended() const;            ///< suspended sediment (m of material)
  gis::Grid<float> readBed() const;                  ///< bed elevation above datumM() (m; float keeps mm)
  double datumM() const { return datumM_; }          ///< the datum elevations are stored against (m)
  SimStats stats() const;
  const SimParams& params() const { return p_; }

 private:
  CpuSimulation() = default;
  void takeStep(double dtS);
  double maxWaveSpeed() const;
  double nextDt() const;  // W10 with this step's sources
  float dx(int y) const { return rowDx_[size_t(y)]; }
  float area(int y) const { return rowDx_[size_t(y)] * p_.dyM; }
  float faceWidthY(int yFace) const;
  size_t idx(int x, int y) const { return size_t(y) * size_t(p_.width) + size_t(x); }
  int topLayer(size_t i) const;
  float recomputeBed(size_t i);
  float outflowTotalFv(int x, int y, bool limited) const;
  float limitOfFace(float massFlux, int xl, int yl, int xr, int yr) const;
  void fvLimitPass();

  void sourcesPass();
  void levelPass();
  void pipeFluxPass();
  void pipeUpdatePass();
  struct Side {
    float h, eta, un, ut;  // depth, surface, normal and tangential velocity at a face
  };
  Side faceSide(const std::vector<float>& st, int x, int y, int dir) const;
  std::pair<float, float> bedSource(const std::vector<float>& st, int x, int y) const;
  float sinTilt(int x, int y) const;
  void fvFacePass(const std::vector<float>& st, bool average);
  void fvUpdatePass(bool final);
  void erosionPass();
  void thermalFluxPass();
  void thermalApplyPass();

  SimParams p_{};
  std::vector<SimMaterial> materials_;
  std::vector<float> rowDx_;
  std::vector<double> rowDxD_;
  std::vector<float> base_, bed_, layers_;  // layers_: [layer][cell]
  std::vector<float> state_, stateNext_;    // vec4 per cell: h, s, hu, hv
  std::vector<float> stage_;                // flood mode: the Heun predictor U1
  std::vector<float> flux_;                 // vec4 per cell: pipe outflows W, E, N, S (m^3/s)
  std::vector<float> fluxDiag_;             // vec4 per cell: diagonal outflows NW, NE, SW, SE (m^3/s)
  std::vector<float> faceX_, faceY_;        // vec4 per face (flood mode)
  std::vector<float> limit_;                // W25: per cell, the share of its outflow it can give
  std::vector<float> tilt_;                 // sin(bed tilt)
  std::vector<float> accum_;                // 8 per cell: (sum, error) of water out, evaporated, sediment out,
                                            // net water put in by fixed levels (m^3)
  std::vector<float> rain_;                 // raster (mm/h)
  std::vector<float> thermal_;              // vec4 per cell: material shed W, E, N, S (m over this cell)
  std::vector<Source> sources_;
  std::vector<SourceEntry> entries_;
  std::vector<LevelBoundary> levels_;
  double timeS_ = 0, lastDt_ = 0, rainM3_ = 0, inflowM3_ = 0, rainRateM3S_ = 0, minCell_ = 1, maxRainMmH_ = 0;
  double initialWater_ = 0, initialMaterial_ = 0, datumM_ = 0;
  long long steps_ = 0;
};

}  // namespace strata::terrain::sim
