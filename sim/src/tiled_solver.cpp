#include <strata/sim/tiled_solver.hpp>

#include <algorithm>
#include <string>

#include "tile_common.hpp"

namespace strata::sim {

using detail::crop;

TiledSolver::TiledSolver(const SimInput& input, const SimParams& params, const TileOptions& options)
    : Solver(input, params), options_(options) {}

Result<TiledSolver> TiledSolver::create(const SimInput& input, const SimParams& params, const TileOptions& options,
                                        const SolverFactory& makeTile) {
  STRATA_TRY_STATUS(validate(input, params));
  if (options.tileWidth < 2 || options.tileHeight < 2 || options.halo < 1) {
    return fail("tiles: tileWidth and tileHeight must be >= 2 and halo >= 1");
  }
  if (params.localStepLevels > 0) return fail(kLocalStepsOnTheCpuOnly);
  TiledSolver t(input, params, options);
  const int width = input.baseM.width, height = input.baseM.height;
  t.tilesX_ = (width + options.tileWidth - 1) / options.tileWidth;
  const int tilesY = (height + options.tileHeight - 1) / options.tileHeight;
  for (int ty = 0; ty < tilesY; ++ty) {
    for (int tx = 0; tx < t.tilesX_; ++tx) {
      const int x0 = tx * options.tileWidth, y0 = ty * options.tileHeight;
      const int x1 = std::min(width, x0 + options.tileWidth), y1 = std::min(height, y0 + options.tileHeight);
      const int ex0 = std::max(0, x0 - options.halo), ey0 = std::max(0, y0 - options.halo);
      const int ex1 = std::min(width, x1 + options.halo), ey1 = std::min(height, y1 + options.halo);
      SimInput sub;
      sub.baseM = crop(input.baseM, ex0, ey0, ex1, ey1);
      for (const auto& l : input.layersM) sub.layersM.push_back(crop(l, ex0, ey0, ex1, ey1));
      sub.materials = input.materials;
      sub.waterDepthM = crop(input.waterDepthM, ex0, ey0, ex1, ey1);
      sub.rainMmPerHour = crop(input.rainMmPerHour, ex0, ey0, ex1, ey1);
      sub.manningN = crop(input.manningN, ex0, ey0, ex1, ey1);
      sub.infiltrationMmPerHour = crop(input.infiltrationMmPerHour, ex0, ey0, ex1, ey1);
      sub.infiltrationSuctionM = crop(input.infiltrationSuctionM, ex0, ey0, ex1, ey1);
      sub.rowDxM.assign(t.grid().rowDxM.begin() + ey0, t.grid().rowDxM.begin() + ey1);
      sub.dyM = input.dyM;
      sub.datumM = input.datumM;
      SimParams sp = params;
      sp.openEdges = detail::tileOpenEdges(params.openEdges, ex0, ey0, ex1, ey1, width, height);
      auto solver = makeTile(sub, sp);
      if (!solver) return fail("tile (" + std::to_string(tx) + ", " + std::to_string(ty) + "): " + solver.message());
      t.tiles_.push_back(Tile{x0, y0, x1, y1, ex0, ey0, ex1, ey1, std::move(solver).value()});
    }
  }
  t.recordInitialTotals();
  return t;
}

std::string TiledSolver::backendName() const {
  return std::to_string(tiles_.size()) + " tiles on " + (tiles_.empty() ? "nothing" : tiles_[0].solver->backendName());
}

int TiledSolver::ownerOf(int x, int y) const { return (y / options_.tileHeight) * tilesX_ + x / options_.tileWidth; }

void TiledSolver::forEachPart(const std::function<void(Solver&)>& f) {
  for (auto& tile : tiles_) f(*tile.solver);
}

Status TiledSolver::onSourceAdded(const Source& source) {
  // Each cell becomes its own source carrying its share, so a tile that sees only some of the
  // cells still feeds each the right amount.
  for (auto one : detail::perCellSources(source)) {
    const auto [x, y] = one.cells[0];
    for (auto& tile : tiles_) {
      if (x < tile.ex0 || x >= tile.ex1 || y < tile.ey0 || y >= tile.ey1) continue;
      one.cells = {{x - tile.ex0, y - tile.ey0}};
      STRATA_TRY_STATUS(tile.solver->addSource(one));
    }
  }
  return {};
}

Status TiledSolver::onLevelAdded(const LevelBoundary& level) {
  // Every tile holds the level on the cells it sees, halo included (the owner's value, held at
  // the same stage, replaces the halo's after each step anyway).
  for (auto& tile : tiles_) {
    LevelBoundary sub{{}, level.stageM};
    for (auto [x, y] : level.cells) {
      if (x >= tile.ex0 && x < tile.ex1 && y >= tile.ey0 && y < tile.ey1)
        sub.cells.push_back({x - tile.ex0, y - tile.ey0});
    }
    if (!sub.cells.empty()) STRATA_TRY_STATUS(tile.solver->addLevel(sub));
  }
  return {};
}

Status TiledSolver::onRainRasterChanged(const gis::Grid<float>& mmPerHour) {
  for (auto& tile : tiles_) {
    STRATA_TRY_STATUS(tile.solver->setRainRaster(crop(mmPerHour, tile.ex0, tile.ey0, tile.ex1, tile.ey1)));
  }
  return {};
}

void TiledSolver::onParamsChanged() {
  for (auto& tile : tiles_) {
    SimParams sp = params();
    sp.openEdges =
        detail::tileOpenEdges(params().openEdges, tile.ex0, tile.ey0, tile.ex1, tile.ey1, grid().width, grid().height);
    const auto status = tile.solver->setParams(sp);
    STRATA_CHECK(status.ok()) << status.message();  // validated by Solver::setParams already
  }
}

double TiledSolver::maxWaveSpeedMS() const {
  double speed = 0;
  for (const auto& tile : tiles_) speed = std::max(speed, tile.solver->maxWaveSpeedMS());
  return speed;
}

void TiledSolver::runStep(const StepInputs& step) {
  for (auto& tile : tiles_) tile.solver->stepWithDt(double(step.dtS));
  exchangeHalos();
}

void TiledSolver::exchangeHalos() {
  // Every tile's halo rows and columns, read from their owners' interiors (all reads before any
  // write: a step's halos all come from the same step).
  struct Piece {
    size_t tile;
    CellBlock block;  // global coordinates
  };
  std::vector<Piece> pieces;
  const unsigned parts = haloParts(params());
  for (size_t k = 0; k < tiles_.size(); ++k) {
    const Tile& t = tiles_[k];
    for (size_t o = 0; o < tiles_.size(); ++o) {
      if (o == k) continue;
      const Tile& src = tiles_[o];
      const int x0 = std::max(t.ex0, src.x0), x1 = std::min(t.ex1, src.x1);
      const int y0 = std::max(t.ey0, src.y0), y1 = std::min(t.ey1, src.y1);
      if (x0 >= x1 || y0 >= y1) continue;
      CellBlock b = src.solver->readBlock(x0 - src.ex0, y0 - src.ey0, x1 - x0, y1 - y0, parts);
      b.rect.x = x0;
      b.rect.y = y0;
      pieces.push_back({k, std::move(b)});
    }
  }
  for (auto& p : pieces) {
    const Tile& t = tiles_[p.tile];
    p.block.rect.x -= t.ex0;
    p.block.rect.y -= t.ey0;
    tiles_[p.tile].solver->writeBlock(p.block);
  }
}

gis::Grid<float> TiledSolver::readBed() const {
  gis::Grid<float> out(grid().width, grid().height);
  for (const auto& t : tiles_) {
    const auto g = t.solver->readBed();
    for (int y = t.y0; y < t.y1; ++y) {
      for (int x = t.x0; x < t.x1; ++x) out.at(x, y) = g.at(x - t.ex0, y - t.ey0);
    }
  }
  return out;
}

CellBlock TiledSolver::readBlock(int x0, int y0, int width, int height, unsigned parts) const {
  CellBlock out{.rect = {x0, y0, width, height}};
  STRATA_CHECK(blockFits(out, grid().width, grid().height, grid().layers)) << "readBlock outside the grid";
  for (const auto& t : tiles_) {
    const gis::CellRect own = out.rect.intersected({t.x0, t.y0, t.x1 - t.x0, t.y1 - t.y0});
    if (own.empty()) continue;
    CellBlock b = t.solver->readBlock(own.x - t.ex0, own.y - t.ey0, own.width, own.height, parts);
    b.rect = own;  // in the grid's coordinates
    copyOverlap(b, out, grid().layers);
  }
  return out;
}

void TiledSolver::writeBlock(const CellBlock& block) {
  STRATA_CHECK(blockFits(block, grid().width, grid().height, grid().layers)) << "writeBlock outside the grid";
  // Every tile that sees a cell of the block (interior or halo) takes it.
  for (auto& t : tiles_) {
    const gis::CellRect seen = block.rect.intersected({t.ex0, t.ey0, t.ex1 - t.ex0, t.ey1 - t.ey0});
    if (seen.empty()) continue;
    CellBlock b{.rect = seen};
    copyOverlap(block, b, grid().layers);
    b.rect.x -= t.ex0;  // in the tile's coordinates
    b.rect.y -= t.ey0;
    t.solver->writeBlock(b);
  }
}

std::vector<float> TiledSolver::readFaceMassFlux() const {
  const int w = grid().width, h = grid().height;
  std::vector<float> out(size_t(w + 1) * size_t(h) + size_t(w) * size_t(h + 1));
  const size_t offY = size_t(w + 1) * size_t(h);
  for (const auto& t : tiles_) {
    const auto f = t.solver->readFaceMassFlux();
    const int tw = t.ex1 - t.ex0, th = t.ey1 - t.ey0;
    const size_t tOffY = size_t(tw + 1) * size_t(th);
    // A tile owns the west and north faces of its interior cells, and the region's east and
    // south edge faces where it reaches them.
    for (int y = t.y0; y < t.y1; ++y) {
      for (int x = t.x0; x < (t.x1 == w ? w + 1 : t.x1); ++x) {
        out[size_t(y) * size_t(w + 1) + size_t(x)] = f[size_t(y - t.ey0) * size_t(tw + 1) + size_t(x - t.ex0)];
      }
    }
    for (int y = t.y0; y < (t.y1 == h ? h + 1 : t.y1); ++y) {
      for (int x = t.x0; x < t.x1; ++x) {
        out[offY + size_t(y) * size_t(w) + size_t(x)] = f[tOffY + size_t(y - t.ey0) * size_t(tw) + size_t(x - t.ex0)];
      }
    }
  }
  return out;
}

void TiledSolver::resetFloodStats() {
  for (auto& t : tiles_) t.solver->enableFloodStats(floodThresholdM());
}

std::vector<float> TiledSolver::floodStatsCells() const {
  const int w = grid().width;
  std::vector<float> out(4 * grid().cells());
  for (const auto& t : tiles_) {
    const auto f = t.solver->saveState().flood;
    const int tw = t.ex1 - t.ex0;
    for (int y = t.y0; y < t.y1; ++y) {
      for (int x = t.x0; x < t.x1; ++x) {
        std::copy_n(&f[4 * (size_t(y - t.ey0) * size_t(tw) + size_t(x - t.ex0))], 4,
                    &out[4 * (size_t(y) * size_t(w) + size_t(x))]);
      }
    }
  }
  return out;
}

void TiledSolver::setFloodStatsCells(const std::vector<float>& cells) {
  const int w = grid().width;
  for (auto& t : tiles_) {
    SolverState s = t.solver->saveState();
    const int tw = t.ex1 - t.ex0;
    for (int y = t.ey0; y < t.ey1; ++y) {
      for (int x = t.ex0; x < t.ex1; ++x) {
        std::copy_n(&cells[4 * (size_t(y) * size_t(w) + size_t(x))], 4,
                    &s.flood[4 * (size_t(y - t.ey0) * size_t(tw) + size_t(x - t.ex0))]);
      }
    }
    const auto status = t.solver->restoreState(s);
    STRATA_CHECK(status.ok()) << status.message();
  }
}

void TiledSolver::saveCells(SolverState& out) const {
  for (const auto& t : tiles_) out.parts.push_back(t.solver->saveState());
}

Status TiledSolver::restoreCells(const SolverState& in) {
  if (in.parts.size() != tiles_.size()) {
    return fail("tiles: the saved state has " + std::to_string(in.parts.size()) + " tiles, this run has " +
                std::to_string(tiles_.size()));
  }
  for (size_t k = 0; k < tiles_.size(); ++k) STRATA_TRY_STATUS(tiles_[k].solver->restoreState(in.parts[k]));
  return {};
}

}  // namespace strata::sim
