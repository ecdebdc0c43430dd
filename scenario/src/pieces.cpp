#include "pieces.hpp"

#include <strata/core/bytes.hpp>
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
      p.bed = solver.readLocalBed(r);
    }
    pieces.push_back(std::move(p));
  }
  return pieces;
}

gis::WriteOptions elevationMapOptions() {
  gis::WriteOptions o;
  o.description = "bed elevation the model used (conditioned)";
  o.units = "m";
  return o;
}

gis::WriteOptions conditioningMapOptions() {
  gis::WriteOptions o;
  o.description = "bed change made by conditioning the DEM: cut < 0 < raised (breach_inflows, fill_depressions)";
  o.units = "m";
  return o;
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

int pictureStride(int width, int height, int cells) {
  cells = std::max(cells, 2);
  return std::max(1, (std::max(width, height) + cells - 1) / cells);
}

gis::Grid<float> gatherStrided(const Ranks& ranks, const std::vector<Piece>& pieces, int stride, int width, int height,
                               const std::function<float(const Piece&, size_t)>& value) {
  const int sw = (width + stride - 1) / stride, sh = (height + stride - 1) / stride;
  std::vector<uint64_t> at;  // in the strided grid
  std::vector<float> values;
  for (const auto& p : pieces) {
    const auto& r = p.rect;
    for (int y = r.y + (stride - r.y % stride) % stride; y < r.y + r.height; y += stride) {
      for (int x = r.x + (stride - r.x % stride) % stride; x < r.x + r.width; x += stride) {
        at.push_back(uint64_t(y / stride) * uint64_t(sw) + uint64_t(x / stride));
        values.push_back(value(p, size_t(y - r.y) * size_t(r.width) + size_t(x - r.x)));
      }
    }
  }
  ByteWriter w;
  w.vec(at);
  w.vec(values);
  const auto parts = ranks.gatherToLead(w.out);
  if (!ranks.lead()) return {};
  gis::Grid<float> out(sw, sh, gis::kNoData);
  for (const auto& part : parts) {
    ByteReader r{part};
    r.vec(at);
    r.vec(values);
    STRATA_CHECK(r.ok && at.size() == values.size()) << "a rank's picture cells came damaged";
    for (size_t i = 0; i < at.size(); ++i) out.data[at[i]] = values[i];
  }
  return out;
}

Result<gis::Raster> readStrided(const fs::path& path, int stride) {
  STRATA_TRY(auto file, gis::DemFile::open(path.string()));
  const gis::Georef& g = file.info().georef;
  gis::Raster out;
  out.georef = g;
  out.georef.width = (g.width + stride - 1) / stride;
  out.georef.height = (g.height + stride - 1) / stride;
  // Cell i of the result is cell k i of the raster: its centre where that cell's centre is.
  out.georef.transform.c[0] -= 0.5 * (stride - 1) * g.transform.c[1];
  out.georef.transform.c[3] -= 0.5 * (stride - 1) * g.transform.c[5];
  out.georef.transform.c[1] *= stride;
  out.georef.transform.c[5] *= stride;
  out.values = gis::Grid<float>(out.georef.width, out.georef.height);
  const int band = std::max(stride, 256 / stride * stride);  // rows read at a time
  for (int y0 = 0; y0 < g.height; y0 += band) {
    STRATA_TRY(auto rows, file.readPadded({0, y0, g.width, std::min(band, g.height - y0)}));
    for (int y = 0; y < rows.height; y += stride) {
      for (int x = 0; x < g.width; x += stride) out.values.at(x / stride, (y0 + y) / stride) = rows.at(x, y);
    }
  }
  return out;
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
