// strata ingest STORE: builds a terrain tile store, streaming, from a synthetic scene (for
// benchmarks and demos of any size). Peak memory is a few tiles, whatever the input size.
#include <cstdio>

#include <strata/terrain/ingest.hpp>
#include <strata/terrain/synthetic.hpp>

#include "commands.hpp"

namespace strata::app {

void addIngestCommand(CLI::App& app) {
  auto* cmd = app.add_subcommand("ingest", "Build a terrain tile store (tiles at the resolution their relief needs)");
  struct Options {
    std::string store;
    int synthetic = 0;
    int minExp = 5, maxExp = 10;
    double cellSizeM = 30;
  };
  auto o = std::make_shared<Options>();
  cmd->add_option("store", o->store, "New store folder")->required();
  cmd->add_option("--synthetic", o->synthetic, "Ingest a synthetic N x N scene (flat, ramped and rough blocks)");
  cmd->add_option("--min-exp", o->minExp, "Coarsest tile resolution 2^min-exp samples a side")->capture_default_str();
  cmd->add_option("--max-exp", o->maxExp, "Finest tile resolution 2^max-exp = the tile footprint in cells")
      ->capture_default_str();
  cmd->add_option("--cell-size", o->cellSizeM, "Synthetic scene cell size (m)")->capture_default_str();
  cmd->callback([o] {
    if (o->synthetic <= 0) {
      std::fprintf(stderr, "strata ingest: give a source (--synthetic N)\n");
      throw CLI::RuntimeError(1);
    }
    gis::Georef g;
    g.epsg = 3857;
    g.crsName = "WGS 84 / Pseudo-Mercator";
    g.transform = {{0.0, o->cellSizeM, 0.0, 0.0, 0.0, -o->cellSizeM}};
    g.width = g.height = o->synthetic;
    terrain::SyntheticScene scene;
    scene.blockCells = 1 << o->maxExp;
    terrain::IngestOptions opts;
    opts.metric = {o->minExp, o->maxExp};
    auto rep = terrain::ingest(o->store, g,
                               {{{"bedrock", terrain::LayerKind::Bedrock, ""}, terrain::syntheticReader(scene)}}, opts);
    if (!rep) {
      std::fprintf(stderr, "strata ingest: %s\n", rep.message().c_str());
      throw CLI::RuntimeError(1);
    }
    std::printf("%s: %d tiles (%d absent), %.1f%% saved against dense, %.1f s\n", o->store.c_str(), rep->tilesPresent,
                rep->tilesAbsent, 100.0 * rep->footprint.savedFraction(), rep->seconds);
  });
}

}  // namespace strata::app
