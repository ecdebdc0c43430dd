// strata ingest STORE: builds a terrain tile store, streaming, from DEMs (mosaicked onto an
// explicit grid or the union of the inputs, per-input blend modes) or from a synthetic scene.
// Peak memory is a few tiles (plus a row of input blocks), whatever the input size. Ctrl-C
// stops at a tile boundary; `--resume` continues an interrupted ingest.
#include <sys/stat.h>

#include <cmath>
#include <cstdio>
#include <filesystem>

#include <strata/core/interrupt.hpp>
#include <strata/gis/dem_io.hpp>
#include <strata/terrain/dem_sources.hpp>
#include <strata/terrain/ingest.hpp>
#include <strata/terrain/synthetic.hpp>

#include "commands.hpp"

namespace strata::app {

namespace {

bool fileExists(const std::string& path) {
  struct stat st {};
  return ::stat(path.c_str(), &st) == 0 || path.rfind("/vsi", 0) == 0;
}

// "PATH" -> a replace input. The older "PATH@MODE" still works where it is unambiguous: PATH@MODE
// is not a file, PATH is, and MODE is a blend mode. A path containing '@' is taken as it is.
gis::MosaicInput parseInput(const std::string& spec) {
  gis::MosaicInput in;
  in.path = spec;
  if (fileExists(spec)) {
    const auto at = spec.rfind('@');
    if (at != std::string::npos && gis::parseBlendSpec(spec.substr(at + 1)) && fileExists(spec.substr(0, at))) {
      exitCommand("ingest", "'" + spec + "' is ambiguous: both it and '" + spec.substr(0, at) +
                                "' exist; name the blend mode with --blend MODE PATH");
    }
    return in;
  }
  const auto at = spec.rfind('@');
  if (at == std::string::npos) return in;
  auto mode = gis::parseBlendSpec(spec.substr(at + 1));
  if (!mode || !fileExists(spec.substr(0, at))) return in;  // reading it names the missing file
  in.path = spec.substr(0, at);
  in.mode = mode->mode;
  in.fillNoData = mode->fillNoData;
  return in;
}

// What an input is, for resume's check that the sources did not change: path, size, time, mode.
std::string identity(const gis::MosaicInput& in) {
  struct stat st {};
  std::string id = in.path;
  if (::stat(in.path.c_str(), &st) == 0) {
    id += " (" + std::to_string(st.st_size) + " B, mtime " + std::to_string(st.st_mtim.tv_sec) + "." +
          std::to_string(st.st_mtim.tv_nsec) + ")";
  }
  id += " " + std::string(gis::toString(in.mode)) + (in.fillNoData ? "+fill" : "");
  if (in.assignCrs) id += " crs=" + *in.assignCrs;
  if (in.assignTransform) {
    id += " gt=";
    for (double c : in.assignTransform->c) id += std::to_string(c) + ",";
  }
  return id;
}

double finite(double v, const std::string& option, double lo, double hi) {
  if (!std::isfinite(v) || v < lo || v > hi) {
    exitCommand("ingest",
                option + " " + number(v) + ": expected a finite number in [" + number(lo) + ", " + number(hi) + "]");
  }
  return v;
}

}  // namespace

void addIngestCommand(CLI::App& app) {
  auto* cmd = app.add_subcommand(
      "ingest", "Build a terrain tile store (each tile the coarsest resolution within --max-error of the source)");
  struct Options {
    std::string store;
    std::vector<gis::MosaicInput> bedrock;  // --dem and --blend, in command-line order
    std::vector<std::string> layers, water;
    int synthetic = 0;
    int minExp = 5, maxExp = 10;
    std::string metric = "max-error";
    double maxErrorM = terrain::kDefaultMaxErrorM;
    bool global = false, resume = false;
    double cellSizeM = 30;
    std::vector<double> extent, resolution;
    std::string crs, resampling = "bilinear", assignCrs, assignGeotransform;
  };
  auto o = std::make_shared<Options>();
  cmd->add_option("store", o->store, "New store folder (or the interrupted one, with --resume)")->required();
  cmd->add_option_function<std::string>(
         "--dem", [o](const std::string& p) { o->bedrock.push_back(parseInput(p)); },
         "Bedrock DEM; repeat to mosaic in order (each replaces the cells it has data for). Any path works; the "
         "older PATH@MODE still does where PATH@MODE is not itself a file")
      ->trigger_on_parse()
      ->multi_option_policy(CLI::MultiOptionPolicy::TakeAll);
  cmd->add_option_function<std::vector<std::string>>(
         "--blend",
         [o](const std::vector<std::string>& v) {
           for (size_t i = 0; i + 1 < v.size(); i += 2) {
             auto mode = gis::parseBlendSpec(v[i]);
             if (!mode)
               exitCommand("ingest", "--blend " + v[i] + ": " + mode.message() + " (add '+fill' to fill no data)");
             gis::MosaicInput in;
             in.path = v[i + 1];
             in.mode = mode->mode;
             in.fillNoData = mode->fillNoData;
             o->bedrock.push_back(in);
           }
         },
         "MODE PATH: a bedrock DEM blended in order with the ones before it (replace, add, subtract, multiply, max, "
         "min; add/subtract/multiply leave no data where the layer has none, unless MODE ends in +fill)")
      ->expected(2)
      ->trigger_on_parse()
      ->multi_option_policy(CLI::MultiOptionPolicy::TakeAll);
  cmd->add_option("--layer", o->layers,
                  "Material layer NAME:MATERIAL=PATH[@MODE][,PATH[@MODE]...] (thickness in metres), bottom to top");
  cmd->add_option("--water", o->water, "Water depth raster(s), PATH[@MODE]");
  cmd->add_option("--extent", o->extent, "Output grid XMIN YMIN XMAX YMAX in its CRS (default: the union of the DEMs)")
      ->expected(4);
  cmd->add_option("--resolution", o->resolution,
                  "Output cell size X [Y] in CRS units (default: the finest DEM's, so the first DEM's cells are kept)")
      ->expected(1, 2);
  cmd->add_option("--crs", o->crs, "Output CRS (EPSG:n, WKT or PROJ; default: the first DEM's)");
  cmd->add_option("--resampling", o->resampling,
                  "Kernel for DEMs not on the output grid: nearest, bilinear, cubic, min, min-if-coarser")
      ->capture_default_str();
  cmd->add_option("--assign-crs", o->assignCrs, "CRS for input DEMs that have none (EPSG:n, WKT or PROJ)");
  cmd->add_option("--assign-geotransform", o->assignGeotransform,
                  "Geotransform c0,c1,c2,c3,c4,c5 (GDAL's order) for input DEMs that have none");
  cmd->add_option("--synthetic", o->synthetic, "Instead of DEMs: a synthetic N x N scene (flat, ramped, rough blocks)");
  cmd->add_option("--metric", o->metric,
                  "max-error: each tile the coarsest within --max-error of every source cell; range: the seed's relief "
                  "metric (no error bound)")
      ->capture_default_str();
  cmd->add_option("--max-error", o->maxErrorM,
                  "Largest vertical error allowed, metres (0: lossless; coarse tiles only where exact)")
      ->capture_default_str();
  cmd->add_option("--min-exp", o->minExp, "Coarsest tile resolution 2^min-exp samples a side")->capture_default_str();
  cmd->add_option("--max-exp", o->maxExp, "Finest tile resolution 2^max-exp = the tile footprint in cells")
      ->capture_default_str();
  cmd->add_flag("--global", o->global, "Global layout (a geographic grid covering the whole body)");
  cmd->add_flag("--resume", o->resume, "Continue the interrupted ingest into STORE (give the same arguments)");
  cmd->add_option("--cell-size", o->cellSizeM, "Synthetic scene cell size (m)")->capture_default_str();
  cmd->callback([o] {
    installInterruptHandler();
    terrain::IngestOptions opts;
    if (o->minExp < 0 || o->minExp > 14 || o->maxExp < 0 || o->maxExp > 14 || o->minExp > o->maxExp) {
      exitCommand("ingest", "--min-exp " + std::to_string(o->minExp) + " / --max-exp " + std::to_string(o->maxExp) +
                                ": need 0 <= min-exp <= max-exp <= 14");
    }
    opts.metric = {o->minExp, o->maxExp};
    if (o->metric == "max-error") {
      opts.metric.kind = terrain::TileMetric::MaxError;
    } else if (o->metric == "range") {
      opts.metric.kind = terrain::TileMetric::Range;
    } else {
      exitCommand("ingest", "--metric '" + o->metric + "': expected max-error or range");
    }
    opts.metric.maxErrorM = finite(o->maxErrorM, "--max-error", 0, 1e6);
    opts.layout = o->global ? terrain::TileLayout::Global : terrain::TileLayout::Planar;
    opts.resume = o->resume;
    gis::Georef grid;
    std::vector<terrain::IngestSource> sources;
    if (o->synthetic != 0) {
      if (!o->bedrock.empty()) exitCommand("ingest", "give either --synthetic or --dem, not both");
      if (o->synthetic < 1 || o->synthetic > (1 << 20))
        exitCommand("ingest", "--synthetic " + std::to_string(o->synthetic) + ": 1..2^20");
      finite(o->cellSizeM, "--cell-size", 1e-6, 1e7);
      grid.epsg = 3857;
      grid.crsName = "WGS 84 / Pseudo-Mercator";
      grid.transform = {{0.0, o->cellSizeM, 0.0, 0.0, 0.0, -o->cellSizeM}};
      grid.width = grid.height = o->synthetic;
      terrain::SyntheticScene scene;
      scene.blockCells = 1 << o->maxExp;
      sources.push_back({{"bedrock", terrain::LayerKind::Bedrock, ""},
                         terrain::syntheticReader(scene),
                         "synthetic " + std::to_string(o->synthetic) + " cells of " + std::to_string(o->cellSizeM) +
                             " m, blocks of " + std::to_string(scene.blockCells)});
    } else {
      if (o->bedrock.empty()) exitCommand("ingest", "give a source (--dem PATH or --synthetic N)");
      // Inputs of every field; the assigned georeference goes to those without one.
      std::vector<std::vector<gis::MosaicInput>> fields{o->bedrock};
      std::vector<std::pair<terrain::StoreField, std::string>> extra;
      auto splitList = [](const std::string& paths) {
        std::vector<gis::MosaicInput> inputs;
        if (fileExists(paths)) return std::vector<gis::MosaicInput>{parseInput(paths)};
        size_t start = 0;
        while (start <= paths.size()) {
          const auto comma = paths.find(',', start);
          inputs.push_back(parseInput(paths.substr(start, comma - start)));
          if (comma == std::string::npos) break;
          start = comma + 1;
        }
        return inputs;
      };
      for (const auto& l : o->layers) {
        const auto colon = l.find(':'), eq = l.find('=');
        if (colon == std::string::npos || eq == std::string::npos || eq < colon) {
          exitCommand("ingest", "--layer '" + l + "': expected NAME:MATERIAL=PATH");
        }
        extra.push_back({{l.substr(0, colon), terrain::LayerKind::Material, l.substr(colon + 1, eq - colon - 1)}, l});
        fields.push_back(splitList(l.substr(eq + 1)));
      }
      for (const auto& w : o->water) {
        extra.push_back({{"water", terrain::LayerKind::Water, ""}, w});
        fields.push_back(splitList(w));
      }
      std::optional<gis::GeoTransform> assignGt;
      if (!o->assignGeotransform.empty()) {
        auto gt = gis::parseGeoTransform(o->assignGeotransform, "--assign-geotransform");
        if (!gt) exitCommand("ingest", gt.message());
        assignGt = *gt;
      }
      auto resampling = [&]() -> gis::Resampling {
        const std::string& r = o->resampling;
        if (r == "nearest") return gis::Resampling::Nearest;
        if (r == "bilinear") return gis::Resampling::Bilinear;
        if (r == "cubic") return gis::Resampling::Cubic;
        if (r == "min") return gis::Resampling::Minimum;
        if (r == "min-if-coarser") return gis::Resampling::MinimumIfCoarser;
        exitCommand("ingest", "--resampling '" + r + "': expected nearest, bilinear, cubic, min or min-if-coarser");
      }();
      bool crsUsed = false, gtUsed = false;
      for (auto& inputs : fields) {
        for (auto& in : inputs) {
          in.resampling = resampling;
          if (o->assignCrs.empty() && !assignGt) continue;
          auto has = gis::georefPresence(in.path);
          if (!has) exitCommand("ingest", has.message());
          if (!o->assignCrs.empty() && !has->crs) in.assignCrs = o->assignCrs, crsUsed = true;
          if (assignGt && !has->transform) in.assignTransform = assignGt, gtUsed = true;
        }
      }
      if (!o->assignCrs.empty() && !crsUsed)
        exitCommand("ingest", "--assign-crs: every input has a CRS of its own (it fills in a missing one)");
      if (assignGt && !gtUsed)
        exitCommand("ingest",
                    "--assign-geotransform: every input has a geotransform of its own (it fills in a missing one)");

      gis::MosaicGridOptions go;
      if (!o->crs.empty()) go.crs = o->crs;
      if (!o->extent.empty()) go.extent = std::array<double, 4>{o->extent[0], o->extent[1], o->extent[2], o->extent[3]};
      if (!o->resolution.empty()) {
        go.resolution =
            std::array<double, 2>{o->resolution[0], o->resolution.size() > 1 ? o->resolution[1] : o->resolution[0]};
      }
      auto g = gis::mosaicGrid(fields[0], go);
      if (!g) exitCommand("ingest", g.message());
      grid = *g;
      for (size_t f = 0; f < fields.size(); ++f) {
        std::string id;
        for (const auto& in : fields[f]) id += (id.empty() ? "" : "; ") + identity(in);
        auto reader = terrain::mosaicReader(fields[f], grid);
        if (!reader)
          exitCommand("ingest", (f == 0 ? std::string() : "'" + extra[f - 1].second + "': ") + reader.message());
        terrain::StoreField field =
            f == 0 ? terrain::StoreField{"bedrock", terrain::LayerKind::Bedrock, ""} : extra[f - 1].first;
        sources.push_back({std::move(field), std::move(*reader), id});
      }
    }
    auto rep = terrain::ingest(o->store, grid, sources, opts);
    if (!rep) exitCommand("ingest", rep.message());
    if (rep->alreadyComplete) {
      std::printf("%s: already complete; nothing to resume\n", o->store.c_str());
      return;
    }
    std::printf("%s: %d x %d cells, %d tiles (%d absent), %.1f%% saved against dense, %.1f s%s\n", o->store.c_str(),
                grid.width, grid.height, rep->tilesPresent, rep->tilesAbsent, 100.0 * rep->footprint.savedFraction(),
                rep->seconds,
                rep->resumedAt >= 0 ? (" (resumed at tile " + std::to_string(rep->resumedAt) + ")").c_str() : "");
    for (size_t f = 0; f < sources.size(); ++f) {
      const auto& e = rep->errors[f];
      std::printf("  %s: max error %.4g m, RMS %.4g m over %llu cells%s\n", sources[f].field.name.c_str(), e.maxM,
                  e.rmsM, static_cast<unsigned long long>(e.cells),
                  opts.metric.kind == terrain::TileMetric::MaxError
                      ? (" (tolerance " + number(opts.metric.maxErrorM) + " m)").c_str()
                      : " (range metric: no tolerance)");
    }
  });
}

}  // namespace strata::app
