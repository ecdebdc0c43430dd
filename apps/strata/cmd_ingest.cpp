// strata ingest STORE: builds a terrain tile store, streaming, from DEMs (mosaicked onto the
// first one's grid, per-field blend modes) or from a synthetic scene. Peak memory is a few tiles
// (plus GDAL's block cache), whatever the input size.
#include <cstdio>

#include <strata/gis/dem_io.hpp>
#include <strata/terrain/dem_sources.hpp>
#include <strata/terrain/ingest.hpp>
#include <strata/terrain/synthetic.hpp>

#include "commands.hpp"

namespace strata::app {

namespace {

[[noreturn]] void die(const std::string& message) {
  std::fprintf(stderr, "strata ingest: %s\n", message.c_str());
  throw CLI::RuntimeError(1);
}

// "PATH" or "PATH@MODE" -> a mosaic input.
gis::MosaicInput parseInput(const std::string& spec) {
  gis::MosaicInput in;
  const auto at = spec.rfind('@');
  in.path = spec.substr(0, at);
  if (at != std::string::npos) {
    auto mode = gis::parseBlendMode(spec.substr(at + 1));
    if (!mode) die("'" + spec + "': " + mode.message());
    in.mode = *mode;
  }
  return in;
}

}  // namespace

void addIngestCommand(CLI::App& app) {
  auto* cmd = app.add_subcommand("ingest", "Build a terrain tile store (tiles at the resolution their relief needs)");
  struct Options {
    std::string store;
    std::vector<std::string> dems, layers, water;
    int synthetic = 0;
    int minExp = 5, maxExp = 10;
    bool global = false;
    double cellSizeM = 30;
  };
  auto o = std::make_shared<Options>();
  cmd->add_option("store", o->store, "New store folder")->required();
  cmd->add_option("--dem", o->dems,
                  "Bedrock DEM, PATH[@MODE]; repeat to mosaic in order (modes: replace, add, subtract, multiply, max, "
                  "min). The first DEM's grid is the store's grid");
  cmd->add_option("--layer", o->layers,
                  "Material layer NAME:MATERIAL=PATH[@MODE][,PATH[@MODE]...] (thickness in metres), bottom to top");
  cmd->add_option("--water", o->water, "Water depth raster(s), PATH[@MODE]");
  cmd->add_option("--synthetic", o->synthetic, "Instead of DEMs: a synthetic N x N scene (flat, ramped, rough blocks)");
  cmd->add_option("--min-exp", o->minExp, "Coarsest tile resolution 2^min-exp samples a side")->capture_default_str();
  cmd->add_option("--max-exp", o->maxExp, "Finest tile resolution 2^max-exp = the tile footprint in cells")
      ->capture_default_str();
  cmd->add_flag("--global", o->global, "Global layout (a geographic grid covering the whole body)");
  cmd->add_option("--cell-size", o->cellSizeM, "Synthetic scene cell size (m)")->capture_default_str();
  cmd->callback([o] {
    terrain::IngestOptions opts;
    opts.metric = {o->minExp, o->maxExp};
    opts.layout = o->global ? terrain::TileLayout::Global : terrain::TileLayout::Planar;
    gis::Georef grid;
    std::vector<terrain::IngestSource> sources;
    if (o->synthetic > 0) {
      if (!o->dems.empty()) die("give either --synthetic or --dem, not both");
      grid.epsg = 3857;
      grid.crsName = "WGS 84 / Pseudo-Mercator";
      grid.transform = {{0.0, o->cellSizeM, 0.0, 0.0, 0.0, -o->cellSizeM}};
      grid.width = grid.height = o->synthetic;
      terrain::SyntheticScene scene;
      scene.blockCells = 1 << o->maxExp;
      sources.push_back({{"bedrock", terrain::LayerKind::Bedrock, ""}, terrain::syntheticReader(scene)});
    } else {
      if (o->dems.empty()) die("give a source (--dem PATH or --synthetic N)");
      std::vector<gis::MosaicInput> bedrock;
      for (const auto& d : o->dems) bedrock.push_back(parseInput(d));
      auto info = gis::probeDem(bedrock[0].path);
      if (!info) die(info.message());
      grid = info->georef;
      auto reader = terrain::mosaicReader(bedrock, grid);
      if (!reader) die(reader.message());
      sources.push_back({{"bedrock", terrain::LayerKind::Bedrock, ""}, std::move(*reader)});
      auto addField = [&](terrain::StoreField field, const std::string& paths, const std::string& spec) {
        std::vector<gis::MosaicInput> inputs;
        size_t start = 0;
        while (start <= paths.size()) {
          const auto comma = paths.find(',', start);
          inputs.push_back(parseInput(paths.substr(start, comma - start)));
          if (comma == std::string::npos) break;
          start = comma + 1;
        }
        auto r = terrain::mosaicReader(inputs, grid);
        if (!r) die("'" + spec + "': " + r.message());
        sources.push_back({std::move(field), std::move(*r)});
      };
      for (const auto& l : o->layers) {
        const auto colon = l.find(':'), eq = l.find('=');
        if (colon == std::string::npos || eq == std::string::npos || eq < colon) {
          die("--layer '" + l + "': expected NAME:MATERIAL=PATH");
        }
        addField({l.substr(0, colon), terrain::LayerKind::Material, l.substr(colon + 1, eq - colon - 1)},
                 l.substr(eq + 1), l);
      }
      for (const auto& w : o->water) addField({"water", terrain::LayerKind::Water, ""}, w, w);
    }
    auto rep = terrain::ingest(o->store, grid, sources, opts);
    if (!rep) die(rep.message());
    std::printf("%s: %d tiles (%d absent), %.1f%% saved against dense, %.1f s\n", o->store.c_str(), rep->tilesPresent,
                rep->tilesAbsent, 100.0 * rep->footprint.savedFraction(), rep->seconds);
  });
}

}  // namespace strata::app
