#pragma once
// A simulation region run as tiles with halo exchange: each tile is a solver (any backend, made
// by a SolverFactory) over its cells plus a halo of neighbouring cells; after every step the
// halos are refreshed from the tiles that own those cells, so the result equals the untiled run
// (the same passes on the same values). Between steps the halos pass through host memory, which
// is what lets a region exceed one device's memory; it is not meant to be fast. All tiles take
// the same global step (W10 over every tile).

#include <memory>
#include <vector>

#include <strata/core/result.hpp>
#include <strata/sim/solver.hpp>

namespace strata::sim {

struct TileOptions {
  int tileWidth = 512;   ///< interior cells per tile in x
  int tileHeight = 512;  ///< interior cells per tile in y
  /// Halo width (cells). One step reads at most 7 cells away (flood mode: MUSCL faces of the
  /// predictor and corrector, the centred source, the sediment donors), so 8 is enough.
  int halo = 8;
};

class TiledSolver final : public Solver {
 public:
  static Result<TiledSolver> create(const SimInput& input, const SimParams& params, const TileOptions& options,
                                    const SolverFactory& makeTile);
  TiledSolver(TiledSolver&&) noexcept = default;
  TiledSolver& operator=(TiledSolver&&) noexcept = default;

  gis::Grid<float> readBed() const override;
  std::string backendName() const override;
  double maxWaveSpeedMS() const override;
  CellBlock readBlock(int x0, int y0, int width, int height, unsigned parts = kBlockAll) const override;
  void writeBlock(const CellBlock& block) override;
  std::vector<float> readFaceMassFlux() const override;
  int tileCount() const { return int(tiles_.size()); }

 private:
  struct Tile {
    int x0, y0, x1, y1;      // interior, global cells [x0, x1) x [y0, y1)
    int ex0, ey0, ex1, ey1;  // interior + halo
    std::unique_ptr<Solver> solver;
  };
  TiledSolver(const SimInput& input, const SimParams& params, const TileOptions& options);
  void runStep(const StepInputs& step) override;
  void onParamsChanged() override;
  Status onRainRasterChanged(const gis::Grid<float>& mmPerHour) override;
  Status onSourceAdded(const Source& source) override;
  void forEachPart(const std::function<void(Solver&)>& f) override;
  Status onLevelAdded(const LevelBoundary& level) override;
  bool keepsFloodStats() const override { return true; }
  void resetFloodStats() override;
  std::vector<float> floodStatsCells() const override;
  void setFloodStatsCells(const std::vector<float>& cells) override;
  void saveCells(SolverState& out) const override;
  Status restoreCells(const SolverState& in) override;

  int ownerOf(int x, int y) const;
  void exchangeHalos();

  TileOptions options_{};
  int tilesX_ = 0;
  std::vector<Tile> tiles_;
};

}  // namespace strata::sim
