#include <strata/terrain/ingest.hpp>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>

#include <strata/core/interrupt.hpp>
#include <strata/core/log.hpp>
#include <strata/core/progress.hpp>

#include "exr_codec.hpp"

namespace strata::terrain {

namespace {

namespace fs = std::filesystem;
using Clock = std::chrono::steady_clock;

// Reads source `s` for tile (tx, ty) into a footprint x footprint grid (NaN beyond the grid edge).
Result<gis::Grid<float>> readTile(const IngestSource& s, int tx, int ty, int footprint, int width, int height,
                                  uint64_t& cells) {
  const int x = tx * footprint, y = ty * footprint;
  const int w = std::min(footprint, width - x), h = std::min(footprint, height - y);
  auto g = s.read(x, y, w, h);
  if (!g) return fail("field '" + s.field.name + "': " + g.message());
  if (g->width != w || g->height != h) {
    return fail("field '" + s.field.name + "': reader returned " + std::to_string(g->width) + "x" +
                std::to_string(g->height) + " for a " + std::to_string(w) + "x" + std::to_string(h) + " window");
  }
  cells += uint64_t(w) * uint64_t(h);
  if (w == footprint && h == footprint) return g;
  gis::Grid<float> padded(footprint, footprint, gis::kNoData);
  for (int r = 0; r < h; ++r) std::copy_n(&g->data[g->index(0, r)], w, &padded.data[padded.index(0, r)]);
  return padded;
}

// Printable ASCII (bytes outside it as %XX): identities go into the manifest as text and are
// compared in this form.
std::string printable(const std::string& s) {
  std::string out;
  for (unsigned char c : s) {
    if (c >= 0x20 && c < 0x7F && c != '%') {
      out += char(c);
    } else {
      char buf[4];
      std::snprintf(buf, sizeof buf, "%%%02X", unsigned(c));
      out += buf;
    }
  }
  return out;
}

bool sameTransform(const gis::GeoTransform& a, const gis::GeoTransform& b) { return std::equal(a.c, a.c + 6, b.c); }

// What differs between the store being resumed and the ingest asked for now (empty: nothing).
std::string difference(const StoreDesc& have, const StoreDesc& want, const BuildState& state,
                       const std::vector<std::string>& sources) {
  const auto& a = have.georef;
  const auto& b = want.georef;
  if (a.width != b.width || a.height != b.height) {
    return "the grid is " + std::to_string(a.width) + "x" + std::to_string(a.height) + ", the inputs give " +
           std::to_string(b.width) + "x" + std::to_string(b.height);
  }
  if (!sameTransform(a.transform, b.transform)) return "the geotransform differs";
  if (a.crsWkt != b.crsWkt || a.epsg != b.epsg) return "the CRS differs";
  if (have.layout != want.layout) return "the layout (--global) differs";
  const auto& m = have.metric;
  const auto& n = want.metric;
  if (m.kind != n.kind || m.minExp != n.minExp || m.maxExp != n.maxExp || m.maxErrorM != n.maxErrorM) {
    return "the metric (--metric, --min-exp, --max-exp, --max-error) differs";
  }
  if (have.fields.size() != want.fields.size()) return "the number of fields differs";
  for (size_t f = 0; f < have.fields.size(); ++f) {
    const auto& x = have.fields[f];
    const auto& y = want.fields[f];
    if (x.name != y.name || x.kind != y.kind || x.material != y.material) return "field '" + x.name + "' differs";
  }
  if (!state.sources.empty() && state.sources != sources) {
    for (size_t f = 0; f < sources.size() && f < state.sources.size(); ++f) {
      if (state.sources[f] != sources[f]) {
        return "field '" + have.fields[f].name + "' was read from " + state.sources[f] + ", now from " + sources[f];
      }
    }
    return "the sources differ";
  }
  return {};
}

}  // namespace

Result<IngestReport> ingest(const fs::path& dir, const gis::Georef& georef, const std::vector<IngestSource>& sources,
                            const IngestOptions& options) {
  const auto start = Clock::now();
  const detail::EncodeThreads threads;  // tiles compressed on every core while the ingest runs
  if (options.commitEveryTiles < 1 || !(options.commitEverySeconds > 0)) {
    return fail("ingest: checkpoints need commitEveryTiles >= 1 and commitEverySeconds > 0");
  }
  StoreDesc desc;
  desc.georef = georef;
  desc.layout = options.layout;
  desc.metric = options.metric;
  desc.materials = options.materials;
  std::vector<std::string> identities;
  for (const auto& s : sources) {
    desc.fields.push_back(s.field);
    identities.push_back(printable(s.identity));
  }
  const bool haveIdentities =
      std::any_of(identities.begin(), identities.end(), [](const std::string& i) { return !i.empty(); });
  IngestReport report;

  std::error_code ec;
  const bool dirExisted = fs::exists(dir, ec);
  std::optional<TileStore> opened;
  if (options.resume) {
    STRATA_TRY(TileStore s, TileStore::open(dir, options.cache, {.allowIncomplete = true}));
    STRATA_TRY_STATUS(s.lockForWriting());
    if (s.buildState().complete) {
      report.alreadyComplete = true;
      report.footprint = s.footprintStats();
      for (size_t f = 0; f < sources.size(); ++f) report.errors.push_back(s.errorSummary(int(f)));
      return report;
    }
    const std::string diff = difference(s.desc(), desc, s.buildState(), identities);
    if (!diff.empty()) return fail(dir.string() + ": cannot resume: " + diff);
    opened.emplace(std::move(s));
  } else {
    STRATA_TRY(TileStore s, TileStore::create(dir, desc, options.cache));
    BuildState st = s.buildState();
    st.pass = options.metric.kind == TileMetric::Range ? 1 : 2;
    st.tilesDone = 0;
    if (haveIdentities) st.sources = identities;
    s.setBuildState(st);
    STRATA_TRY_STATUS(s.commit());
    opened.emplace(std::move(s));
  }
  TileStore& store = *opened;
  const int F = store.footprint(), nx = store.tilesX(), ny = store.tilesY();
  const int64_t total = int64_t(nx) * int64_t(ny);
  const size_t nf = sources.size();
  BuildState state = store.buildState();
  if (options.resume) {
    report.resumedAt = state.tilesDone;
    log::info("terrain") << "resuming " << dir.string() << " in pass " << state.pass << " at tile " << state.tilesDone
                         << " of " << total;
  }
  Progress progress("ingest " + dir.filename().string(), double(total) * (state.pass == 1 ? 2 : 1));

  // Commits the progress (tilesDone tiles of the current pass) and returns `why` with advice.
  auto stop = [&](int64_t tilesDone, const std::string& why) -> Error {
    state.tilesDone = tilesDone;
    store.setBuildState(state);
    auto c = store.commit();
    return fail(why + "; " + dir.string() + " is left incomplete after " + std::to_string(tilesDone) + " of " +
                std::to_string(total) + " tiles (pass " + std::to_string(state.pass) + ")" +
                (c ? "; continue with `strata ingest --resume` and the same arguments"
                   : " and its progress could not be recorded: " + c.message()));
  };

  // Pass 1 (Range metric only): each field's global range; no tile is written.
  const bool rangesPass = state.pass == 1;
  if (rangesPass) {
    std::vector<float> lo(nf, std::numeric_limits<float>::infinity()), hi(nf, -std::numeric_limits<float>::infinity());
    for (int64_t k = 0; k < total; ++k) {
      const int tx = int(k % nx), ty = int(k / nx);
      for (size_t f = 0; f < nf; ++f) {
        auto g = readTile(sources[f], tx, ty, F, georef.width, georef.height, report.cellsRead);
        if (!g) return stop(0, "ingest: " + g.message());
        for (float v : g->data) {
          if (std::isnan(v)) continue;
          lo[f] = std::min(lo[f], v);
          hi[f] = std::max(hi[f], v);
        }
      }
      if (interrupted()) return stop(0, "ingest: interrupted");
      progress.update(double(k + 1));
    }
    for (size_t f = 0; f < nf; ++f) {
      if (lo[f] > hi[f]) lo[f] = hi[f] = gis::kNoData;
      store.setEvaluationRange(int(f), lo[f], hi[f]);
    }
    state.pass = 2;
    state.tilesDone = 0;
    store.setBuildState(state);
    STRATA_TRY_STATUS(store.commit());
  }

  // Pass 2: every tile at the resolution the metric picks, from where the last checkpoint was.
  const double pass1 = rangesPass ? double(total) : 0.0;
  int sinceCommit = 0;
  auto lastCommit = Clock::now();
  for (int64_t k = state.tilesDone; k < total; ++k) {
    const int tx = int(k % nx), ty = int(k / nx);
    std::vector<gis::Grid<float>> fields;
    for (size_t f = 0; f < nf; ++f) {
      auto g = readTile(sources[f], tx, ty, F, georef.width, georef.height, report.cellsRead);
      if (!g) return stop(k, "ingest: " + g.message());
      fields.push_back(std::move(*g));
    }
    if (auto put = store.putTile(tx, ty, fields); !put) return stop(k, "ingest: " + put.message());
    if (++sinceCommit >= options.commitEveryTiles ||
        std::chrono::duration<double>(Clock::now() - lastCommit).count() >= options.commitEverySeconds) {
      state.tilesDone = k + 1;
      store.setBuildState(state);
      STRATA_TRY_STATUS(store.commit());
      sinceCommit = 0;
      lastCommit = Clock::now();
    }
    if (interrupted() && k + 1 < total) return stop(k + 1, "ingest: interrupted");
    progress.update(pass1 + double(k + 1));
  }

  // The field ranges from the tiles (under the Range metric they were exact already).
  STRATA_TRY_STATUS(store.reevaluate());
  for (int ty = 0; ty < ny; ++ty) {
    for (int tx = 0; tx < nx; ++tx) (store.tile(tx, ty).present ? report.tilesPresent : report.tilesAbsent)++;
  }
  if (report.tilesPresent == 0) {
    std::string what = "ingest: no data: every cell of the " + std::to_string(georef.width) + "x" +
                       std::to_string(georef.height) + " grid is nodata in every field";
    if (!options.resume) {
      // Nothing was written but the manifest and the lock: remove what this ingest created.
      fs::remove(dir / "manifest.toml", ec);
      fs::remove(dir / "writer.lock", ec);
      fs::remove(dir / "tiles", ec);  // only if empty
      if (!dirExisted) fs::remove(dir, ec);
      opened.reset();
      return fail(what + " (nothing stored)");
    }
    return stop(total, what);
  }
  state.complete = true;
  state.tilesDone = total;
  store.setBuildState(state);
  STRATA_TRY_STATUS(store.commit());
  report.footprint = store.footprintStats();
  for (size_t f = 0; f < nf; ++f) report.errors.push_back(store.errorSummary(int(f)));
  report.seconds = std::chrono::duration<double>(Clock::now() - start).count();
  progress.finish();
  log::info("terrain") << "ingest " << dir.string() << ": " << report.tilesPresent << " tiles (" << report.tilesAbsent
                       << " absent), " << 100.0 * report.footprint.savedFraction() << "% saved against dense, "
                       << report.seconds << " s";
  return report;
}

}  // namespace strata::terrain
