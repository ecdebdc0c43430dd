#include "pieces.hpp"

#include <strata/core/files.hpp>
#include <strata/scenario/domain.hpp>

namespace strata::scenario::detail {
namespace fs = std::filesystem;

Result<std::vector<Piece>> readPieces(const sim::Solver& solver, const InputWindow& input, bool erosion) {
  std::vector<Piece> pieces;
  const int layerCount = solver.grid().layers;
  for (const auto& r : solver.localRects()) {
    Piece p;
    p.rect = r;
    const size_t cells = size_t(r.width) * size_t(r.height);
    const sim::CellBlock b = solver.readLocal(r, erosion ? sim::kBlockState | sim::kBlockLayers : sim::kBlockState);
    p.depth = gis::Grid<float>(r.width, r.height);
    for (size_t i = 0; i < cells; ++i) p.depth.data[i] = b.state[4 * i];
    p.flood = solver.readLocalFloodStats(r);
    STRATA_TRY(auto in, input(r));
    p.inside = gis::Grid<uint8_t>(r.width, r.height);
    for (size_t i = 0; i < cells; ++i) p.inside.data[i] = in.baseM.data[i] != kWallElevationM ? 1 : 0;
    if (erosion) {
      p.suspended = gis::Grid<float>(r.width, r.height);
      for (size_t i = 0; i < cells; ++i) p.suspended.data[i] = b.state[4 * i + 1];
      for (int l = 0; l < layerCount; ++l) {
        gis::Grid<float> g(r.width, r.height);
        std::copy_n(b.layers.begin() + ptrdiff_t(size_t(l) * cells), cells, g.data.begin());
        p.layers.push_back(std::move(g));
      }
      p.initialLayers = std::move(in.layersM);
    }
    pieces.push_back(std::move(p));
  }
  return pieces;
}

Status writeRaster(const Ranks& ranks, const fs::path& file, const gis::Georef& georef,
                   const gis::WriteOptions& options, const std::vector<gis::GridWindow>& windows) {
  const std::string tmp = ranks.fromLead(ranks.lead() ? temporaryPathFor(file).string() : std::string());
  STRATA_TRY_STATUS(ranks.agree(ranks.lead() ? gis::createGeoTiff(tmp, georef, options) : Status{}));
  for (int r = 0; r < ranks.size(); ++r) {
    Status status;
    if (r == ranks.rank() && !windows.empty()) status = gis::writeGeoTiffWindows(tmp, windows, options.nodata);
    status = ranks.agree(status);
    if (!status.ok()) {
      if (ranks.lead()) fs::remove(tmp);
      return status;
    }
  }
  return ranks.agree(ranks.lead() ? commitTemporary(tmp, file) : Status{});
}

Status writeMapFile(const Ranks& ranks, const fs::path& file, const gis::Georef& georef,
                    const gis::WriteOptions& options, const std::vector<Piece>& pieces,
                    const std::function<gis::Grid<float>(const Piece&)>& values) {
  std::vector<gis::GridWindow> windows;
  for (const auto& p : pieces) windows.push_back({p.rect.x, p.rect.y, values(p)});
  return writeRaster(ranks, file, georef, options, windows);
}

bool beats(const Extreme& a, const Extreme& b) {
  if (a.value != b.value) return a.value > b.value;
  return a.y != b.y ? a.y < b.y : a.x < b.x;
}

Extreme largest(const Ranks& ranks, const Extreme& mine) {
  const auto all = ranks.allGather({mine.value, double(mine.x), double(mine.y), mine.with});
  Extreme best = mine;
  for (size_t at = 0; at + 3 < all.size(); at += 4) {
    const Extreme e{all[at], int(all[at + 1]), int(all[at + 2]), all[at + 3]};
    if (beats(e, best)) best = e;
  }
  return best;
}

}  // namespace strata::scenario::detail
