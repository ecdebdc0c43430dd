// strata export STORE OUT.tif: writes a window of one field of a store, at any level of detail,
// as a georeferenced GeoTIFF (float32, DEFLATE, tiled; NaN written as nodata).
#include <cstdio>

#include <strata/gis/dem_io.hpp>
#include <strata/terrain/tile_store.hpp>

#include "commands.hpp"

namespace strata::app {

void addExportCommand(CLI::App& app) {
  auto* cmd = app.add_subcommand("export", "Write a window of a terrain store to GeoTIFF");
  struct Options {
    std::string store, out, field = "bedrock";
    std::vector<int> window;
    int lod = 0;
    bool cog = false;
  };
  auto o = std::make_shared<Options>();
  cmd->add_option("store", o->store, "Store folder")->required();
  cmd->add_option("output", o->out, "GeoTIFF to write")->required();
  cmd->add_option("--field", o->field, "Field to export")->capture_default_str();
  cmd->add_option("--window", o->window, "X Y WIDTH HEIGHT in cells of the level (default: the whole level)")
      ->expected(4);
  cmd->add_option("--lod", o->lod, "Level of detail: cells 2^lod base cells wide")->capture_default_str();
  cmd->add_flag("--cog", o->cog, "Write a Cloud Optimized GeoTIFF");
  cmd->callback([o] {
    auto die = [](const std::string& m) {
      std::fprintf(stderr, "strata export: %s\n", m.c_str());
      throw CLI::RuntimeError(1);
    };
    auto store = terrain::TileStore::open(o->store);
    if (!store) die(store.message());
    const int field = store->fieldIndex(o->field);
    if (field < 0) die(o->store + ": no field '" + o->field + "'");
    if (o->lod < 0 || o->lod > store->maxLod())
      die("--lod " + std::to_string(o->lod) + " outside 0.." + std::to_string(store->maxLod()));
    terrain::Window w{0, 0, store->levelWidth(o->lod), store->levelHeight(o->lod)};
    if (!o->window.empty()) w = {o->window[0], o->window[1], o->window[2], o->window[3]};
    if (w.width <= 0 || w.height <= 0) die("--window: empty window");
    auto values = store->readWindow(field, w, o->lod);
    if (!values) die(values.message());
    gis::Raster r;
    r.georef = store->windowGeoref(w, o->lod);
    r.values = std::move(*values);
    gis::WriteOptions wo;
    wo.cog = o->cog;
    if (auto s = gis::writeGeoTiff(o->out, r, wo); !s) die(s.message());
    std::printf("%s: %s %dx%d at level %d from %s\n", o->out.c_str(), o->field.c_str(), w.width, w.height, o->lod,
                o->store.c_str());
  });
}

}  // namespace strata::app
