// strata info FILE...: what a DEM is and where it lies (driver, CRS, body, extent, resolution,
// value range, nodata share).
#include <cstdio>
#include <memory>
#include <string>
#include <vector>

#include <strata/gis/dem_summary.hpp>

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
  auto* cmd = app.add_subcommand("info", "Describe DEMs: driver, CRS, body, extent, resolution, values, nodata");
  auto files = std::make_shared<std::vector<std::string>>();
  cmd->add_option("files", *files, "DEM files (any raster GDAL reads)")->required();
  cmd->callback([files] {
    bool failed = false;
    for (const std::string& f : *files) {
      auto s = gis::summarizeDem(f);
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
