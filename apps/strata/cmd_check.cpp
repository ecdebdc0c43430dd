// strata check STORE: verifies a tile store (manifest, every tile's size, checksum and decoding)
// and summarises it. Exit status 1, with one line per problem on stderr, when anything is wrong.
#include <cstdio>
#include <map>

#include <strata/terrain/tile_store.hpp>

#include "commands.hpp"

namespace strata::app {

void addCheckCommand(CLI::App& app) {
  auto* cmd = app.add_subcommand("check", "Verify a terrain tile store: manifest, tile checksums and decoding");
  auto dir = std::make_shared<std::string>();
  cmd->add_option("store", *dir, "Store folder (holds manifest.toml)")->required();
  cmd->callback([dir] {
    auto store = terrain::TileStore::open(*dir, {.budgetBytes = size_t(64) << 20, .prefetch = false});
    if (!store) {
      std::fprintf(stderr, "strata check: %s\n", store.message().c_str());
      throw CLI::RuntimeError(1);
    }
    const auto& d = store->desc();
    std::printf("store     %s\n", dir->c_str());
    std::printf("grid      %d x %d cells, %s layout, CRS %s\n", store->width(), store->height(),
                d.layout == terrain::TileLayout::Global ? "global" : "planar",
                d.georef.crsName.empty() ? "(none)" : d.georef.crsName.c_str());
    std::printf("tiles     %d x %d of %d cells, resolution 2^%d..2^%d\n", store->tilesX(), store->tilesY(),
                store->footprint(), d.metric.minExp, d.metric.maxExp);
    for (size_t f = 0; f < d.fields.size(); ++f) {
      const auto [lo, hi] = store->globalRange(int(f));
      std::printf("field     %-12s %-8s %-10s range %g .. %g\n", d.fields[f].name.c_str(),
                  terrain::toString(d.fields[f].kind), d.fields[f].material.c_str(), double(lo), double(hi));
    }
    std::map<int, int> histogram;
    int absent = 0;
    for (int ty = 0; ty < store->tilesY(); ++ty) {
      for (int tx = 0; tx < store->tilesX(); ++tx) {
        const auto& t = store->tile(tx, ty);
        t.present ? ++histogram[t.exp] : ++absent;
      }
    }
    std::printf("levels   ");
    for (const auto& [e, n] : histogram) std::printf(" 2^%d: %d", e, n);
    std::printf("  (absent: %d)\n", absent);
    const auto fp = store->footprintStats();
    std::printf("storage   %.1f%% saved against a dense grid (%llu of %llu samples; %.1f MiB of tile files)\n",
                100.0 * fp.savedFraction(), static_cast<unsigned long long>(fp.storedSamples),
                static_cast<unsigned long long>(fp.denseSamples), double(fp.fileBytes) / (1 << 20));
    const auto problems = store->verify();
    for (const auto& p : problems) std::fprintf(stderr, "strata check: %s/%s\n", dir->c_str(), p.message.c_str());
    if (!problems.empty()) {
      std::printf("result    %zu corrupt tile(s)\n", problems.size());
      throw CLI::RuntimeError(1);
    }
    std::printf("result    OK\n");
  });
}

}  // namespace strata::app
