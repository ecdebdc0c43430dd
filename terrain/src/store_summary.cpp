// describeStore: a tile store in a few lines, for `strata info` and `strata check`.
#include <cstdio>
#include <map>

#include <strata/terrain/tile_store.hpp>

namespace strata::terrain {

namespace {
std::string format(const char* fmt, auto... args) {
  char buf[512];
  std::snprintf(buf, sizeof buf, fmt, args...);
  return buf;
}
}  // namespace

std::string describeStore(const TileStore& store) {
  const auto& d = store.desc();
  const auto& g = d.georef;
  std::string out;
  out += format("grid      %d x %d cells, %s layout, CRS %s%s\n", store.width(), store.height(),
                d.layout == TileLayout::Global ? "global" : "planar", g.crsName.empty() ? "(none)" : g.crsName.c_str(),
                g.epsg ? (" (EPSG:" + std::to_string(*g.epsg) + ")").c_str() : "");
  out += format("tiles     %d x %d of %d cells, resolution 2^%d..2^%d\n", store.tilesX(), store.tilesY(),
                store.footprint(), d.metric.minExp, d.metric.maxExp);
  if (d.metric.kind == TileMetric::MaxError) {
    out += format("metric    max-error: each tile the coarsest within %g m of every source cell\n", d.metric.maxErrorM);
  } else {
    out += "metric    range (the seed's relief metric; no error bound)\n";
  }
  const auto& b = store.buildState();
  const int64_t total = int64_t(store.tilesX()) * store.tilesY();
  if (b.complete) {
    out += "build     complete\n";
  } else {
    out += format(
        "build     INCOMPLETE: ingest stopped in pass %d after %lld of %lld tiles (resume it with "
        "`strata ingest --resume`)\n",
        b.pass, static_cast<long long>(b.tilesDone), static_cast<long long>(total));
  }
  for (size_t f = 0; f < d.fields.size(); ++f) {
    const auto [lo, hi] = store.globalRange(int(f));
    const auto e = store.errorSummary(int(f));
    out += format("field     %-12s %-8s %-10s range %g .. %g m\n", d.fields[f].name.c_str(), toString(d.fields[f].kind),
                  d.fields[f].material.c_str(), double(lo), double(hi));
    out += format("error     %-12s max %.4g m, RMS %.4g m over %llu cells with data\n", d.fields[f].name.c_str(),
                  e.maxM, e.rmsM, static_cast<unsigned long long>(e.cells));
  }
  std::map<int, int> histogram;
  int absent = 0;
  for (int ty = 0; ty < store.tilesY(); ++ty) {
    for (int tx = 0; tx < store.tilesX(); ++tx) {
      const auto& t = store.tile(tx, ty);
      t.present ? ++histogram[t.exp] : ++absent;
    }
  }
  out += "levels   ";
  for (const auto& [e, n] : histogram) out += format(" 2^%d: %d", e, n);
  out += format("  (absent: %d)\n", absent);
  const auto fp = store.footprintStats();
  out += format("storage   %.1f%% saved against a dense grid (%llu of %llu samples; %.1f MiB of tile files)\n",
                100.0 * fp.savedFraction(), static_cast<unsigned long long>(fp.storedSamples),
                static_cast<unsigned long long>(fp.denseSamples), double(fp.fileBytes) / (1 << 20));
  return out;
}

}  // namespace strata::terrain
