#pragma once
// The seed's adaptive tiles (Vanek, Benes et al. 2011) for flood mode: the region is cut into
// square tiles, each run as a solver (any backend, made by a SolverFactory) at a level L of the
// region's mip pyramid (2^L x 2^L base cells per cell; bed, layers and rain are box means of the
// base grid). An importance map from flow speed and depth change, re-evaluated every few steps,
// picks each tile's level: flowing water runs at full resolution, dry land and still water run
// coarse. Halos are filled from the neighbouring tiles by restriction (area-weighted means) or
// prolongation (the coarse cell's volume spread over the fine cells to one water level); fluxes
// across coarse/fine tile edges are matched after every step (refluxing), so water is conserved.
// All tiles take the same step (W10 over every tile at its own cell size). docs/sim-water.md,
// "Adaptive tiles".
//
// An adaptive run is a whole region: it is not nested inside another runner (writeBlock and
// readFaceMassFlux, which only such runners call, are contract violations here).

#include <memory>
#include <vector>

#include <strata/core/result.hpp>
#include <strata/gis/raster.hpp>
#include <strata/sim/solver.hpp>

namespace strata::sim {

struct AdaptiveOptions {
  int tileSize = 64;     ///< base cells per tile side; the grid's sides must be multiples of it
  int maxLevel = 2;      ///< coarsest level; tileSize must be a multiple of 2^maxLevel
  int halo = 8;          ///< halo width in the tile's own cells (8: what one flood step reads, as TileOptions)
  int regridEvery = 10;  ///< K: steps between importance evaluations
  /// Importance of a tile (A1): max over its cells and `lookaheadCells` base cells around it of
  /// max(|u| / speedRefMS, |h - h_prev| / depthChangeRefM) over cells wetter than wetDepthM,
  /// h_prev being the depth at the previous evaluation. Tiles holding a source count as infinite.
  float speedRefMS = 0.05f;
  float depthChangeRefM = 0.02f;
  float wetDepthM = 0.01f;
  int lookaheadCells = 8;
  float refineAbove = 1.0f;    ///< importance >= this: the tile goes to level 0
  float coarsenBelow = 0.25f;  ///< below this for `coarsenAfter` evaluations in a row: one level coarser
  int coarsenAfter = 2;
  bool reflux = true;  ///< match coarse/fine face fluxes after each step (conservation); off only to measure it
};

class AdaptiveSolver final : public Solver {
 public:
  /// Flood mode only (cflAlpha > 0), without erosion or thermal weathering.
  static Result<AdaptiveSolver> create(const SimInput& input, const SimParams& params, const AdaptiveOptions& options,
                                       const SolverFactory& makeTile);
  AdaptiveSolver(AdaptiveSolver&&) noexcept = default;
  AdaptiveSolver& operator=(AdaptiveSolver&&) noexcept = default;

  double nextDt() override;
  // Reads are at base resolution (coarse tiles prolonged); the layers do not change (no erosion).
  gis::Grid<float> readBed() const override;
  SimStats stats() const override;  ///< volumes over all tiles at their levels
  std::string backendName() const override;
  double maxWaveSpeedMS() const override;
  CellBlock readBlock(int x0, int y0, int width, int height, unsigned parts = kBlockAll) const override;
  void writeBlock(const CellBlock& block) override;
  std::vector<float> readFaceMassFlux() const override;

  /// Each tile's level, row-major over tiles (tilesX() per row).
  std::vector<int> levels() const;
  int tilesX() const { return tilesX_; }
  /// Cell updates per step so far, summed over the tiles' interiors, relative to a full-resolution
  /// run of the same steps (1 = no saving).
  double cellFraction() const;
  /// The same with the halos counted (a tile of n cells a side at its level computes
  /// (n + 2 halo)^2 cells, so coarse tiles pay relatively more halo).
  double computedCellFraction() const;
  /// Water added where a reflux correction would have made a depth negative and the depth was
  /// set to 0 instead (m^3): part of the balance error, reported separately.
  double clampedWaterM3() const { return clampedM3_; }

 private:
  struct Tile {
    int x0, y0;                                 // base cells [x0, x0 + tileSize) x [y0, y0 + tileSize)
    int level = 0;                              // current level
    int quietEvaluations = 0;                   // evaluations in a row below coarsenBelow
    bool pinned = false;                        // holds a source: stays at level 0
    std::vector<std::unique_ptr<Solver>> sims;  // per level (made when first used; they keep their outflow totals)
    std::vector<int> ex0, ey0, ex1, ey1;        // per level: interior + halo, level cells
  };
  struct Pyramid {  // one level of the region's mip pyramid
    int width = 0, height = 0;
    gis::Grid<float> baseM, rainMmH;  // absolute base elevation (m), rain raster (mm/h)
    gis::Grid<float> manningN;        // the roughness map, box means (empty: the uniform n)
    std::vector<gis::Grid<float>> layersM;
    std::vector<float> bed;      // relative to the datum, as the solvers compute it
    std::vector<double> rowDxM;  // per level row
  };
  AdaptiveSolver(const SimInput& input, const SimParams& params, const AdaptiveOptions& options,
                 const SolverFactory& makeTile);
  void runStep(const StepInputs& step) override;
  Status onSourceAdded(const Source& source) override;
  void forEachPart(const std::function<void(Solver&)>& f) override;
  void clearAccumulators() override;
  Status onLevelAdded(const LevelBoundary& level) override;
  void saveCells(SolverState& out) const override;
  Status restoreCells(const SolverState& in) override;

  int ownerOf(int bx, int by) const;
  Status ensureSim(Tile& tile, int level);
  // The state of level-`level` cell (cx, cy) from `tileState` (the tile at its own level).
  void cellAt(const Tile& tile, const std::vector<float>& tileState, int level, int cx, int cy, float out[4]) const;
  std::vector<float> stateOf(const Tile& tile) const;
  std::vector<std::vector<float>> readStates() const;
  void writeState(Tile& tile, const std::vector<float>& state);
  void reflux(std::vector<std::vector<float>>& states, double dtS);
  void fillHalos(const std::vector<std::vector<float>>& states);
  std::vector<float> mergedState(const std::vector<std::vector<float>>& states) const;  // 4 per base cell
  std::vector<float> mergedNow() const;
  void regrid();

  SimInput input_{};
  AdaptiveOptions o_{};
  SolverFactory makeTile_;
  int width_ = 0, height_ = 0, tilesX_ = 0, tilesY_ = 0;
  std::vector<Pyramid> mips_;
  std::vector<double> minCell_;  // per level
  std::vector<Tile> tiles_;
  std::vector<float> prevDepth_;  // base resolution, at the last evaluation
  double clampedM3_ = 0, cellUpdates_ = 0, computedUpdates_ = 0;
  bool started_ = false;
};

}  // namespace strata::sim
