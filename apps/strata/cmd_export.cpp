// strata export STORE OUT.tif: writes a window of one field of a store, at any level of detail,
// as a georeferenced GeoTIFF (float32, DEFLATE, tiled; NaN written as nodata) carrying the
// store's achieved vertical error as metadata. Never writes inside a store, never replaces an
// existing file without --overwrite, and refuses an incomplete store.
#include <cstdio>
#include <filesystem>
#include <fstream>

#include <strata/gis/dem_io.hpp>
#include <strata/terrain/tile_store.hpp>

#include "commands.hpp"

namespace strata::app {

namespace {

namespace fs = std::filesystem;

// Whether `dir` holds a Strata tile store (a manifest that says so).
bool isStore(const fs::path& dir) {
  std::ifstream in(dir / "manifest.toml");
  std::string line;
  for (int i = 0; i < 8 && std::getline(in, line); ++i) {
    if (line.rfind("format = \"strata-tile-store\"", 0) == 0) return true;
  }
  return false;
}

// The store folder `out` would be written into (the source store or any other), if any.
std::optional<fs::path> storeAround(const fs::path& out, const fs::path& store) {
  std::error_code ec;
  const fs::path storeDir = fs::weakly_canonical(store, ec);
  for (fs::path p = fs::weakly_canonical(fs::absolute(out, ec), ec).parent_path(); !p.empty(); p = p.parent_path()) {
    if ((!storeDir.empty() && p == storeDir) || isStore(p)) return p;
    if (p == p.root_path()) break;
  }
  return std::nullopt;
}

}  // namespace

void addExportCommand(CLI::App& app) {
  auto* cmd = app.add_subcommand("export", "Write a window of a terrain store to GeoTIFF");
  struct Options {
    std::string store, out, field = "bedrock";
    std::vector<int> window;
    int lod = 0;
    bool cog = false, overwrite = false;
  };
  auto o = std::make_shared<Options>();
  cmd->add_option("store", o->store, "Store folder")->required();
  cmd->add_option("output", o->out, "GeoTIFF to write (not inside a store)")->required();
  cmd->add_option("--field", o->field, "Field to export")->capture_default_str();
  cmd->add_option("--window", o->window, "X Y WIDTH HEIGHT in cells of the level (default: the whole level)")
      ->expected(4);
  cmd->add_option("--lod", o->lod, "Level of detail: cells 2^lod base cells wide")->capture_default_str();
  cmd->add_flag("--cog", o->cog, "Write a Cloud Optimized GeoTIFF");
  cmd->add_flag("--overwrite", o->overwrite, "Replace OUTPUT if it exists");
  cmd->callback([o] {
    if (auto inside = storeAround(o->out, o->store)) {
      exitCommand("export", o->out + ": inside the tile store " + inside->string() + "; write the GeoTIFF elsewhere");
    }
    std::error_code ec;
    if (!o->overwrite && fs::exists(o->out, ec))
      exitCommand("export", o->out + ": already exists (pass --overwrite to replace it)");
    auto store = terrain::TileStore::open(o->store);
    if (!store) exitCommand("export", store.message());
    const int field = store->fieldIndex(o->field);
    if (field < 0) exitCommand("export", o->store + ": no field '" + o->field + "'");
    if (o->lod < 0 || o->lod > store->maxLod())
      exitCommand("export", "--lod " + std::to_string(o->lod) + " outside 0.." + std::to_string(store->maxLod()));
    const int lw = store->levelWidth(o->lod), lh = store->levelHeight(o->lod);
    gis::CellRect w{0, 0, lw, lh};
    if (!o->window.empty()) w = {o->window[0], o->window[1], o->window[2], o->window[3]};
    if (w.width <= 0 || w.height <= 0 || w.width > (1 << 20) || w.height > (1 << 20)) {
      exitCommand("export", "--window: width and height must be 1..2^20 cells");
    }
    const bool global = store->desc().layout == terrain::TileLayout::Global;
    if (!global && (w.x < 0 || w.y < 0 || int64_t(w.x) + w.width > lw || int64_t(w.y) + w.height > lh)) {
      exitCommand("export", "--window " + std::to_string(w.x) + " " + std::to_string(w.y) + " " +
                                std::to_string(w.width) + " " + std::to_string(w.height) + " reaches outside level " +
                                std::to_string(o->lod) + "'s " + std::to_string(lw) + " x " + std::to_string(lh) +
                                " cells");
    }
    auto values = store->readWindow(field, w, o->lod);
    if (!values) exitCommand("export", values.message());
    size_t nodata = 0;
    for (float v : values->data) nodata += std::isnan(v);
    const size_t cells = values->data.size();
    if (nodata == cells) {
      exitCommand(
          "export",
          o->store + ": the window holds no data (the store has no tile there: no source covered it); nothing written");
    }
    gis::Raster r;
    r.georef = store->windowGeoref(w, o->lod);
    r.values = std::move(*values);
    gis::WriteOptions wo;
    wo.cog = o->cog;
    wo.overwrite = o->overwrite;
    // The achieved error of the tiles under the window (their level-0 reconstruction).
    const int s = 1 << o->lod;
    const gis::CellRect base{w.x * s, w.y * s, w.width * s, w.height * s};
    const auto err = store->errorSummary(field, global ? std::nullopt : std::optional<gis::CellRect>(base));
    const auto& metric = store->desc().metric;
    wo.metadata = {
        {"STRATA_MAX_ERROR_M", number(err.maxM)},
        {"STRATA_RMS_ERROR_M", number(err.rmsM)},
        {"STRATA_ERROR_TOLERANCE_M",
         metric.kind == terrain::TileMetric::MaxError ? number(metric.maxErrorM) : std::string("none (range metric)")},
        {"STRATA_LOD", std::to_string(o->lod)},
        {"STRATA_FIELD", o->field}};
    if (auto st = gis::writeGeoTiff(o->out, r, wo); !st) {
      exitCommand(
          "export",
          st.message() + (st.message().find("already exists") != std::string::npos ? " (pass --overwrite)" : ""));
    }
    std::printf("%s: %s %dx%d at level %d from %s; tiles' error max %s m, RMS %s m\n", o->out.c_str(), o->field.c_str(),
                w.width, w.height, o->lod, o->store.c_str(), number(err.maxM).c_str(), number(err.rmsM).c_str());
    if (nodata > 0) {
      std::printf("%s: %zu of %zu cells are nodata (no source data there)\n", o->out.c_str(), nodata, cells);
    }
  });
}

}  // namespace strata::app
