// strata check STORE: verifies a tile store (manifest, CRS, every tile's size, checksum,
// decoding, georeference, values against its recorded range and error, orphan files, whether
// its ingest finished) and summarises it.
// strata check SCENARIO.toml: every problem of a scenario file in one pass, in file order
// (file:line: key 'k': ...), raster paths included, without running it.
// Exit status 1, with one line per problem on stderr, when anything is wrong.
#include <cstdio>
#include <filesystem>

#include <strata/scenario/scenario.hpp>
#include <strata/terrain/tile_store.hpp>

#include "commands.hpp"

namespace strata::app {

void addCheckCommand(CLI::App& app) {
  auto* cmd = app.add_subcommand(
      "check",
      "Verify a terrain tile store (complete, manifest and CRS, tile checksums, decoding, values, orphans) or a "
      "scenario file (every problem in one pass, raster paths included, without running it)");
  auto dir = std::make_shared<std::string>();
  cmd->add_option("store_or_scenario", *dir, "Store folder (holds manifest.toml) or scenario file (.toml)")->required();
  cmd->callback([dir] {
    // A scenario: a file, or a path ending in .toml; anything else is a store folder.
    std::error_code ec;
    const std::filesystem::path path(*dir);
    if (std::filesystem::is_regular_file(path, ec) || path.extension() == ".toml") {
      const auto problems = scenario::checkScenarioFile(*dir);
      for (const auto& p : problems) std::fprintf(stderr, "strata check: %s\n", p.c_str());
      if (!problems.empty()) {
        std::printf("result    %zu problem(s)\n", problems.size());
        throw CLI::RuntimeError(1);
      }
      std::printf("result    OK: %s would run\n", dir->c_str());
      return;
    }
    auto store =
        terrain::TileStore::open(*dir, {.budgetBytes = size_t(64) << 20, .prefetch = false}, {.allowIncomplete = true});
    if (!store) {
      exitCommand("check", store.message());
    }
    std::printf("store     %s\n%s", dir->c_str(), terrain::describeStore(*store).c_str());
    const auto problems = store->verify();
    for (const auto& p : problems) std::fprintf(stderr, "strata check: %s/%s\n", dir->c_str(), p.message.c_str());
    const bool incomplete = !store->buildState().complete;
    if (incomplete) {
      std::fprintf(stderr, "strata check: %s: incomplete: its ingest did not finish (`strata ingest --resume`)\n",
                   dir->c_str());
    }
    if (!problems.empty() || incomplete) {
      std::printf("result    %zu problem(s)%s\n", problems.size(), incomplete ? ", store incomplete" : "");
      throw CLI::RuntimeError(1);
    }
    std::printf("result    OK\n");
  });
}

}  // namespace strata::app
