#include <strata/terrain/ingest.hpp>

#include <algorithm>
#include <chrono>
#include <cmath>

#include <strata/core/log.hpp>
#include <strata/core/progress.hpp>

namespace strata::terrain {

namespace {

// Reads source `s` for tile (tx, ty) into a footprint x footprint grid (NaN beyond the grid edge).
Result<gis::Grid<float>> readTile(const IngestSource& s, int tx, int ty, int footprint, int width, int height,
                                  uint64_t& cells) {
  const int x = tx * footprint, y = ty * footprint;
  const int w = std::min(footprint, width - x), h = std::min(footprint, height - y);
  auto g = s.read(x, y, w, h);
  if (!g) return fail("ingest: field '" + s.field.name + "': " + g.message());
  if (g->width != w || g->height != h) {
    return fail("ingest: field '" + s.field.name + "': reader returned " + std::to_string(g->width) + "x" +
                std::to_string(g->height) + " for a " + std::to_string(w) + "x" + std::to_string(h) + " window");
  }
  cells += uint64_t(w) * uint64_t(h);
  if (w == footprint && h == footprint) return g;
  gis::Grid<float> padded(footprint, footprint, gis::kNoData);
  for (int r = 0; r < h; ++r) std::copy_n(&g->data[g->index(0, r)], w, &padded.data[padded.index(0, r)]);
  return padded;
}

}  // namespace

Result<IngestReport> ingest(const std::filesystem::path& dir, const gis::Georef& georef,
                            const std::vector<IngestSource>& sources, const IngestOptions& options) {
  const auto start = std::chrono::steady_clock::now();
  StoreDesc desc;
  desc.georef = georef;
  desc.layout = options.layout;
  desc.metric = options.metric;
  desc.materials = options.materials;
  for (const auto& s : sources) desc.fields.push_back(s.field);
  STRATA_TRY(TileStore store, TileStore::create(dir, desc, options.cache));

  const int F = store.footprint(), nx = store.tilesX(), ny = store.tilesY();
  const size_t nf = sources.size();
  IngestReport report;
  const double totalTiles = 2.0 * nx * ny;
  Progress progress("ingest " + dir.filename().string(), totalTiles);

  // Pass 1: each field's global range.
  std::vector<float> lo(nf, std::numeric_limits<float>::infinity()), hi(nf, -std::numeric_limits<float>::infinity());
  for (int ty = 0; ty < ny; ++ty) {
    for (int tx = 0; tx < nx; ++tx) {
      for (size_t f = 0; f < nf; ++f) {
        STRATA_TRY(auto g, readTile(sources[f], tx, ty, F, georef.width, georef.height, report.cellsRead));
        for (float v : g.data) {
          if (std::isnan(v)) continue;
          lo[f] = std::min(lo[f], v);
          hi[f] = std::max(hi[f], v);
        }
      }
      progress.update(ty * nx + tx + 1);
    }
  }
  for (size_t f = 0; f < nf; ++f) {
    if (lo[f] > hi[f]) lo[f] = hi[f] = gis::kNoData;
    store.setEvaluationRange(int(f), lo[f], hi[f]);
  }

  // Pass 2: every tile at the resolution the metric picks, with periodic manifest checkpoints.
  int sinceCommit = 0;
  for (int ty = 0; ty < ny; ++ty) {
    for (int tx = 0; tx < nx; ++tx) {
      std::vector<gis::Grid<float>> fields;
      for (size_t f = 0; f < nf; ++f) {
        STRATA_TRY(auto g, readTile(sources[f], tx, ty, F, georef.width, georef.height, report.cellsRead));
        fields.push_back(std::move(g));
      }
      STRATA_TRY_STATUS(store.putTile(tx, ty, fields));
      (store.tile(tx, ty).present ? report.tilesPresent : report.tilesAbsent)++;
      if (++sinceCommit >= options.commitEveryTiles) {
        STRATA_TRY_STATUS(store.commit());
        sinceCommit = 0;
      }
      progress.update(nx * ny + ty * nx + tx + 1);
    }
  }
  // The ranges were exact, so this changes nothing; it keeps the invariant explicit.
  STRATA_TRY_STATUS(store.reevaluate());
  STRATA_TRY_STATUS(store.commit());
  report.footprint = store.footprintStats();
  report.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  progress.finish();
  log::info("terrain") << "ingest " << dir.string() << ": " << report.tilesPresent << " tiles (" << report.tilesAbsent
                       << " absent), " << int(report.footprint.savedFraction() * 100) << "% saved against dense, "
                       << report.seconds << " s";
  return report;
}

}  // namespace strata::terrain
