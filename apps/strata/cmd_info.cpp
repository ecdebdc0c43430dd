// strata info FILE...: what a DEM is and where it lies (driver, CRS, body, extent, resolution,
// value range, nodata share); for a tile store folder, its summary with the achieved error.
#include <cstdio>
#include <filesystem>
#include <memory>
#include <string>
#include <vector>

#include <strata/gis/dem_summary.hpp>
#include <strata/terrain/tile_store.hpp>

#include "commands.hpp"

namespace strata::app {

namespace {
void printSummary(const gis::DemSummary& s) {
  const gis::DemInfo& i = s.info;
  const gis::Georef& g = i.georef;
  std::printf("%s\n", i.path.c_str());
  std::printf("  driver      %s\n", i.driver.c_str());
  if (g.epsg) {
    std::printf("  CRS         %s (EPSG:%d)\n", g.crsName.c_str(), *g.epsg);
  } else {
    std::printf("  CRS         %s (no EPSG code)\n", g.crsName.c_str());
  }
  std::printf("  body        %s (a = %.1f m, %s)\n", g.body.name.c_str(), g.body.semiMajorM,
              g.body.isSphere() ? "sphere" : ("1/f = " + std::to_string(1 / g.body.flattening)).c_str());
  std::printf("  size        %d x %d, %s", g.width, g.height, i.bandType.c_str());
  if (i.scale != 1 || i.offset != 0) std::printf(", scale %g, offset %g", i.scale, i.offset);
  if (i.offsetIsBodyRadius) std::printf(" (radius: heights above the %.0f m sphere)", g.body.semiMajorM);
  if (i.nodata) std::printf(", nodata %g", *i.nodata);
  std::printf("\n");
  const char* unit = g.geographic ? "deg" : "m";
  std::printf("  extent      x %.6f .. %.6f, y %.6f .. %.6f %s\n", s.minX, s.maxX, s.minY, s.maxY, unit);
  std::printf("  lon/lat     lon %.6f .. %.6f, lat %.6f .. %.6f deg\n", s.minLon, s.maxLon, s.minLat, s.maxLat);
  std::printf("  resolution  %.3f m x %.3f m at the centre\n", s.pixelWidthM, s.pixelHeightM);
  std::printf("  values      min %.3f, max %.3f, mean %.3f m\n", s.minM, s.maxM, s.meanM);
  std::printf("  nodata      %.3f %% of %zu cells\n", 100.0 * s.noDataFraction, s.cells);
}
}  // namespace

void addInfoCommand(CLI::App& app) {
  auto* cmd = app.add_subcommand(
      "info", "Describe DEMs (driver, CRS, body, extent, resolution, values, nodata) or tile stores");
  struct Options {
    std::vector<std::string> files;
    std::string assignCrs, assignGeotransform;
  };
  auto o = std::make_shared<Options>();
  cmd->add_option("files", o->files, "DEM files (any raster GDAL reads) or tile store folders")->required();
  cmd->add_option("--assign-crs", o->assignCrs, "CRS for files that have none (EPSG:n, WKT or PROJ)");
  cmd->add_option("--assign-geotransform", o->assignGeotransform,
                  "Geotransform c0,c1,c2,c3,c4,c5 (GDAL's order) for files that have none");
  cmd->callback([o] {
    bool failed = false;
    std::optional<gis::GeoTransform> assignGt;
    if (!o->assignGeotransform.empty()) {
      auto gt = gis::parseGeoTransform(o->assignGeotransform, "--assign-geotransform");
      if (!gt) {
        exitCommand("info", gt.message());
      }
      assignGt = *gt;
    }
    for (const std::string& f : o->files) {
      std::error_code ec;
      if (std::filesystem::is_directory(f, ec) &&
          std::filesystem::exists(std::filesystem::path(f) / "manifest.toml", ec)) {
        auto store = terrain::TileStore::open(f, {.budgetBytes = size_t(16) << 20, .prefetch = false},
                                              {.allowIncomplete = true});
        if (!store) {
          std::fprintf(stderr, "strata info: %s\n", store.message().c_str());
          failed = true;
          continue;
        }
        std::printf("%s (tile store)\n%s", f.c_str(), terrain::describeStore(*store).c_str());
        continue;
      }
      auto ro = gis::assignMissingGeoref(f, o->assignCrs, assignGt);
      auto s = ro ? gis::summarizeDem(f, *ro) : Result<gis::DemSummary>(fail(ro.message()));
      if (!s) {
        std::fprintf(stderr, "strata info: %s\n", s.message().c_str());
        failed = true;
        continue;
      }
      printSummary(*s);
    }
    if (failed) throw CLI::RuntimeError(1);
  });
}

}  // namespace strata::app
