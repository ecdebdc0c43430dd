#pragma once
// A simulation region larger than one GPU run can hold, run as tiles with halo exchange: each
// tile is a Simulation over its cells plus a halo of neighbouring cells; after every step the
// halos are refreshed from the tiles that own those cells, so the result equals the untiled
// run (the same kernels on the same values). Between steps the tiles' state passes through
// host memory, which is what lets a region exceed the GPU's memory budget; it is not meant to
// be fast. All tiles take the same global step (W10 over every tile).

#include <vector>

#include <strata/core/result.hpp>
#include <strata/gis/raster.hpp>
#include <strata/render/sim/simulation.hpp>

namespace strata::render::sim {

struct TileOptions {
  int tileWidth = 512;   ///< interior cells per tile in x
  int tileHeight = 512;  ///< interior cells per tile in y
  /// Halo width (cells). One step reads at most 7 cells away (flood mode: MUSCL faces of the
  /// predictor and corrector, the centred source, the sediment donors), so 8 is enough.
  int halo = 8;
};

class TiledSimulation {
 public:
  static Result<TiledSimulation> create(const SimInput& input, const SimParams& params, const TileOptions& options);

  /// Adds an inflow source (cells in global coordinates).
  Status addSource(const Source& source);
  /// Takes `n` global steps.
  void step(int n = 1);

  gis::Grid<float> readWaterDepth() const;           ///< m, whole region
  std::vector<gis::Grid<float>> readLayers() const;  ///< m, whole region, bottom to top
  SimStats stats() const;                            ///< volumes over the whole region
  int tileCount() const { return int(tiles_.size()); }

 private:
  struct Tile {
    int x0, y0, x1, y1;      // interior, global cells [x0, x1) x [y0, y1)
    int ex0, ey0, ex1, ey1;  // interior + halo
    Simulation sim;
  };
  TiledSimulation() = default;
  int ownerOf(int x, int y) const;
  void exchangeHalos();

  SimParams p_{};
  TileOptions options_{};
  int width_ = 0, height_ = 0, tilesX_ = 0;
  std::vector<double> rowDxD_;
  std::vector<Tile> tiles_;
  std::vector<Source> sources_;
  double timeS_ = 0, lastDt_ = 0, rainM3_ = 0, inflowM3_ = 0, rainRateM3S_ = 0, minCell_ = 1;
  double initialWater_ = 0, initialMaterial_ = 0;
  long long steps_ = 0;
};

}  // namespace strata::render::sim
