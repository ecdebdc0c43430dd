#include <strata/render/sim/tiled_simulation.hpp>

#include <algorithm>
#include <string>

#include <strata/terrain/sim/sim_host.hpp>

#include "tile_common.hpp"

namespace strata::render::sim {

namespace ts = strata::terrain::sim;

using detail::crop;

Result<TiledSimulation> TiledSimulation::create(const SimInput& input, const SimParams& params,
                                                const TileOptions& options) {
  STRATA_TRY_STATUS(ts::validate(input, params));
  if (options.tileWidth < 2 || options.tileHeight < 2 || options.halo < 1) {
    return fail("tiles: tileWidth and tileHeight must be >= 2 and halo >= 1");
  }
  TiledSimulation t;
  t.p_ = params;
  t.options_ = options;
  t.width_ = input.baseM.width;
  t.height_ = input.baseM.height;
  t.p_.width = t.width_;
  t.p_.height = t.height_;
  t.p_.layerCount = int(input.layersM.size());
  t.p_.dyM = float(input.dyM);
  for (int y = 0; y < t.height_; ++y) t.rowDxD_.push_back(ts::rowDx(input, y));
  t.minCell_ = ts::minCellSize(t.rowDxD_, input.dyM);
  const size_t n = size_t(t.width_) * size_t(t.height_);
  t.rainRateM3S_ =
      ts::rainVolumeRate(t.p_, input.rainMmPerHour.size() > 0 ? input.rainMmPerHour.data : std::vector<float>(n, 0.0f),
                         t.rowDxD_, t.width_);
  t.tilesX_ = (t.width_ + options.tileWidth - 1) / options.tileWidth;
  const int tilesY = (t.height_ + options.tileHeight - 1) / options.tileHeight;
  for (int ty = 0; ty < tilesY; ++ty) {
    for (int tx = 0; tx < t.tilesX_; ++tx) {
      const int x0 = tx * options.tileWidth, y0 = ty * options.tileHeight;
      const int x1 = std::min(t.width_, x0 + options.tileWidth), y1 = std::min(t.height_, y0 + options.tileHeight);
      const int ex0 = std::max(0, x0 - options.halo), ey0 = std::max(0, y0 - options.halo);
      const int ex1 = std::min(t.width_, x1 + options.halo), ey1 = std::min(t.height_, y1 + options.halo);
      SimInput sub;
      sub.baseM = crop(input.baseM, ex0, ey0, ex1, ey1);
      for (const auto& l : input.layersM) sub.layersM.push_back(crop(l, ex0, ey0, ex1, ey1));
      sub.materials = input.materials;
      sub.waterDepthM = crop(input.waterDepthM, ex0, ey0, ex1, ey1);
      sub.rainMmPerHour = crop(input.rainMmPerHour, ex0, ey0, ex1, ey1);
      sub.rowDxM = input.rowDxM.size() == 1
                       ? input.rowDxM
                       : std::vector<double>(input.rowDxM.begin() + ey0, input.rowDxM.begin() + ey1);
      sub.dyM = input.dyM;
      sub.datumM = input.datumM;
      SimParams sp = params;
      sp.openEdges = detail::tileOpenEdges(params.openEdges, ex0, ey0, ex1, ey1, t.width_, t.height_);
      auto sim = Simulation::create(sub, sp);
      if (!sim) return fail("tile (" + std::to_string(tx) + ", " + std::to_string(ty) + "): " + sim.message());
      t.tiles_.push_back(Tile{x0, y0, x1, y1, ex0, ey0, ex1, ey1, std::move(sim).value()});
    }
  }
  const auto st = t.stats();
  t.initialWater_ = st.storedWaterM3;
  t.initialMaterial_ = st.materialM3;
  return t;
}

int TiledSimulation::ownerOf(int x, int y) const {
  return (y / options_.tileHeight) * tilesX_ + x / options_.tileWidth;
}

Status TiledSimulation::addSource(const Source& source) {
  for (auto [x, y] : source.cells) {
    if (x < 0 || y < 0 || x >= width_ || y >= height_) {
      return fail("sim source: cell (" + std::to_string(x) + ", " + std::to_string(y) + ") is outside the " +
                  std::to_string(width_) + "x" + std::to_string(height_) + " grid");
    }
  }
  // Each cell becomes its own source carrying its share, so a tile that sees only some of the
  // cells still feeds each the right amount.
  for (auto one : detail::perCellSources(source)) {
    const auto [x, y] = one.cells[0];
    for (auto& tile : tiles_) {
      if (x < tile.ex0 || x >= tile.ex1 || y < tile.ey0 || y >= tile.ey1) continue;
      one.cells = {{x - tile.ex0, y - tile.ey0}};
      STRATA_TRY_STATUS(tile.sim.addSource(one));
    }
  }
  sources_.push_back(source);
  return {};
}

void TiledSimulation::exchangeHalos() {
  std::vector<Simulation::RawState> raw;
  raw.reserve(tiles_.size());
  for (const auto& tile : tiles_) raw.push_back(tile.sim.readRaw());
  const int L = p_.layerCount;
  std::vector<Simulation::RawState> updated = raw;
  for (size_t k = 0; k < tiles_.size(); ++k) {
    const Tile& t = tiles_[k];
    const int w = t.ex1 - t.ex0;
    const size_t cells = size_t(w) * size_t(t.ey1 - t.ey0);
    for (int y = t.ey0; y < t.ey1; ++y) {
      for (int x = t.ex0; x < t.ex1; ++x) {
        if (x >= t.x0 && x < t.x1 && y >= t.y0 && y < t.y1) continue;
        const size_t o = size_t(ownerOf(x, y));
        const Tile& src = tiles_[o];
        const int sw = src.ex1 - src.ex0;
        const size_t srcCells = size_t(sw) * size_t(src.ey1 - src.ey0);
        const size_t i = size_t(y - t.ey0) * size_t(w) + size_t(x - t.ex0);
        const size_t j = size_t(y - src.ey0) * size_t(sw) + size_t(x - src.ex0);
        for (int c = 0; c < 4; ++c) {
          updated[k].state[4 * i + size_t(c)] = raw[o].state[4 * j + size_t(c)];
          updated[k].flux[4 * i + size_t(c)] = raw[o].flux[4 * j + size_t(c)];
          if (p_.diagonalPipes) updated[k].fluxDiag[4 * i + size_t(c)] = raw[o].fluxDiag[4 * j + size_t(c)];
        }
        for (int l = 0; l < L; ++l) updated[k].layers[size_t(l) * cells + i] = raw[o].layers[size_t(l) * srcCells + j];
      }
    }
  }
  for (size_t k = 0; k < tiles_.size(); ++k) tiles_[k].sim.writeRaw(updated[k]);
}

void TiledSimulation::step(int n) {
  for (int s = 0; s < n; ++s) {
    double speed = 0;
    if (p_.cflAlpha > 0) {
      for (auto& tile : tiles_) speed = std::max(speed, tile.sim.maxWaveSpeedMS());
    }
    // W10 with the sources: each tile bounds the depth rate its own rain and source cells get.
    double rate = 0;
    if (p_.cflAlpha > 0) {
      const double window = ts::stepDt(p_, speed, minCell_);
      for (auto& tile : tiles_) rate = std::max(rate, tile.sim.sourceDepthRateMS(timeS_ + window));
    }
    const double dt = ts::stepDt(p_, speed, minCell_, rate);
    for (const auto& e : ts::mergeSources(sources_, width_, timeS_, timeS_ + double(float(dt)))) {
      inflowM3_ += double(e.rateM3S) * double(float(dt));
    }
    rainM3_ += rainRateM3S_ * double(float(dt));
    for (auto& tile : tiles_) tile.sim.stepWithDt(dt);
    exchangeHalos();
    timeS_ += double(float(dt));
    lastDt_ = double(float(dt));
    ++steps_;
  }
}

gis::Grid<float> TiledSimulation::readWaterDepth() const {
  gis::Grid<float> out(width_, height_);
  for (const auto& t : tiles_) {
    const auto h = t.sim.readWaterDepth();
    for (int y = t.y0; y < t.y1; ++y) {
      for (int x = t.x0; x < t.x1; ++x) out.at(x, y) = h.at(x - t.ex0, y - t.ey0);
    }
  }
  return out;
}

std::vector<gis::Grid<float>> TiledSimulation::readLayers() const {
  std::vector<gis::Grid<float>> out(size_t(p_.layerCount), gis::Grid<float>(width_, height_));
  for (const auto& t : tiles_) {
    const auto layers = t.sim.readLayers();
    for (size_t l = 0; l < layers.size(); ++l) {
      for (int y = t.y0; y < t.y1; ++y) {
        for (int x = t.x0; x < t.x1; ++x) out[l].at(x, y) = layers[l].at(x - t.ex0, y - t.ey0);
      }
    }
  }
  return out;
}

SimStats TiledSimulation::stats() const {
  // Interior cells only: halo cells are copies of cells another tile owns.
  const size_t n = size_t(width_) * size_t(height_);
  const int L = p_.layerCount;
  std::vector<float> h(n), sus(n), layers(n * size_t(L));
  SimStats out;
  float hmax = 0.0f;
  for (const auto& t : tiles_) {
    const auto raw = t.sim.readRaw();
    const int w = t.ex1 - t.ex0;
    const size_t cells = size_t(w) * size_t(t.ey1 - t.ey0);
    for (int y = t.y0; y < t.y1; ++y) {
      for (int x = t.x0; x < t.x1; ++x) {
        const size_t i = size_t(y - t.ey0) * size_t(w) + size_t(x - t.ex0), g = size_t(y) * size_t(width_) + size_t(x);
        h[g] = raw.state[4 * i];
        sus[g] = raw.state[4 * i + 1];
        hmax = std::max(hmax, h[g]);
        for (int l = 0; l < L; ++l) layers[size_t(l) * n + g] = raw.layers[size_t(l) * cells + i];
        out.outflowM3 += double(raw.accum[8 * i]);
        out.evaporatedM3 += double(raw.accum[8 * i + 2]);
        out.sedimentOutflowM3 += double(raw.accum[8 * i + 4]);
      }
    }
  }
  const double dy = double(p_.dyM);
  out.timeS = timeS_;
  out.steps = steps_;
  out.lastDtS = lastDt_;
  out.storedWaterM3 = ts::integrate(h, rowDxD_, dy, width_);
  out.initialWaterM3 = initialWater_;
  out.rainM3 = rainM3_;
  out.inflowM3 = inflowM3_;
  out.suspendedM3 = ts::integrate(sus, rowDxD_, dy, width_);
  out.materialM3 = out.suspendedM3 + ts::integrate(layers, rowDxD_, dy, width_);
  out.initialMaterialM3 = initialMaterial_;
  out.maxDepthM = hmax;
  return out;
}

}  // namespace strata::render::sim
