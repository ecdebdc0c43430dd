#include <strata/scenario/compare.hpp>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <map>

#include <strata/core/files.hpp>
#include <strata/gis/dem_io.hpp>
#include <strata/scenario/report.hpp>

#include "styles.hpp"

namespace strata::scenario {
namespace {

namespace fs = std::filesystem;

// Maps where "no data" means "none" (never wet, never fast): compared as 0. Elsewhere (arrival
// time, hazard rating, the bed) a cell without data in either run has no difference.
bool noDataIsZero(const std::string& name) {
  return name == "max_depth" || name == "final_depth" || name == "max_speed" || name == "inundation_duration" ||
         name == "terrain_change" || name == "suspended_sediment";
}

std::string fmt(const char* f, double v) {
  char buf[64];
  std::snprintf(buf, sizeof buf, f, v);
  return buf;
}

}  // namespace

Result<std::vector<std::string>> compareRuns(const CompareOptions& o) {
  std::error_code ec;
  for (const auto& run : {o.runA, o.runB}) {
    if (!fs::is_directory(run, ec)) return fail(run.string() + ": not a run folder");
  }
  if (fs::exists(o.outDir, ec) && !fs::is_empty(o.outDir, ec)) {
    return fail(o.outDir.string() + ": exists and is not empty (choose a new folder)");
  }
  STRATA_TRY(auto a, readSeriesCsv(o.runA / "series.csv"));
  STRATA_TRY(auto b, readSeriesCsv(o.runB / "series.csv"));
  fs::create_directories(o.outDir / "maps", ec);
  if (ec) return fail(o.outDir.string() + ": cannot create it: " + ec.message());
  std::vector<std::string> written;

  // The maps both runs have, B - A, on the same grid.
  std::vector<std::string> names;
  for (const auto& e : fs::directory_iterator(o.runA / "maps", ec)) {
    if (e.path().extension() == ".tif" && fs::exists(o.runB / "maps" / e.path().filename())) {
      names.push_back(e.path().stem().string());
    }
  }
  std::sort(names.begin(), names.end());
  if (names.empty()) return fail(o.runA.string() + " and " + o.runB.string() + ": no map in common");
  gis::ReadOptions read;
  read.allowAllNoData = true;
  std::vector<std::string> differ, identical;  // maps with a difference somewhere, and without any
  for (const auto& name : names) {
    const fs::path pa = o.runA / "maps" / (name + ".tif"), pb = o.runB / "maps" / (name + ".tif");
    STRATA_TRY(auto ra, gis::readDem(pa.string(), read));
    STRATA_TRY(auto rb, gis::readDem(pb.string(), read));
    const auto &ga = ra.georef, &gb = rb.georef;
    bool same = ga.width == gb.width && ga.height == gb.height && ga.crsWkt == gb.crsWkt;
    for (int k = 0; k < 6 && same; ++k)
      same = std::abs(ga.transform.c[k] - gb.transform.c[k]) <= 1e-9 * (1 + std::abs(ga.transform.c[k]));
    if (!same) {
      return fail(pb.string() + ": not on the grid of " + pa.string() +
                  " (size, geotransform or CRS differ): compare runs of the same region and cell size");
    }
    if (name == "elevation") {  // the hillshade under the plots: run A's bed
      gis::WriteOptions w;
      w.description = "bed elevation of run A";
      w.units = "m";
      STRATA_TRY_STATUS(gis::writeGeoTiff((o.outDir / "maps" / "elevation.tif").string(), ra, w));
      written.push_back("maps/elevation.tif");
    }
    gis::Raster d = ra;
    const bool zero = noDataIsZero(name);
    for (size_t i = 0; i < d.values.size(); ++i) {
      float x = ra.values.data[i], y = rb.values.data[i];
      if (zero) {
        if (!std::isfinite(x) && std::isfinite(y)) x = 0;
        if (!std::isfinite(y) && std::isfinite(x)) y = 0;
      }
      d.values.data[i] = std::isfinite(x) && std::isfinite(y) ? y - x : gis::kNoData;
    }
    double big = 0;
    for (float v : d.values.data) {
      if (std::isfinite(v)) big = std::max(big, double(std::abs(v)));
    }
    if (big == 0) {  // the same in both runs (e.g. the bed of a what-if that changes the water)
      identical.push_back(name);
      continue;
    }
    differ.push_back(name);
    gis::WriteOptions w;
    w.description = "difference of " + name + ": run B less run A";
    w.units = ra.georef.verticalUnit == "m" && (name.ends_with("depth") || name == "elevation" ||
                                                name == "terrain_change" || name == "conditioning")
                  ? "m"
                  : "";
    w.metadata = {{"STRATA_RUN_A", o.runA.string()}, {"STRATA_RUN_B", o.runB.string()}};
    const std::string file = "maps/" + name + "_difference.tif";
    STRATA_TRY_STATUS(gis::writeGeoTiff((o.outDir / file).string(), d, w));
    written.push_back(file);
    // A diverging style, symmetric about 0.
    STRATA_TRY_STATUS(writeFileAtomic(o.outDir / ("maps/" + name + "_difference.qml"),
                                      detail::rasterStyle("terrain_change", -big, big, 0)));
    written.push_back("maps/" + name + "_difference.qml");
  }

  // The headline numbers side by side.
  auto last = [](auto& c, const char* k) { return c.count(k) ? c.at(k).back() : NAN; };
  auto most = [](auto& c, const char* k) {
    return c.count(k) ? *std::max_element(c.at(k).begin(), c.at(k).end()) : NAN;
  };
  struct Row {
    const char* what;
    double a, b;
    const char* unit;
    bool hideZero = false;  // a row of what neither run had (erosion, infiltration)
  };
  const std::vector<Row> rows{
      {"simulated", last(a, "time_s") / 3600, last(b, "time_s") / 3600, "h"},
      {"water that entered (inflow + rain)", last(a, "inflow_m3") + last(a, "rain_m3"),
       last(b, "inflow_m3") + last(b, "rain_m3"), "m³"},
      {"most water in the region", most(a, "water_volume_m3"), most(b, "water_volume_m3"), "m³"},
      {"largest flooded area", most(a, "flooded_area_km2"), most(b, "flooded_area_km2"), "km²"},
      {"water that left through the edges", last(a, "outflow_m3"), last(b, "outflow_m3"), "m³"},
      {"water that soaked into the ground", last(a, "infiltration_m3"), last(b, "infiltration_m3"), "m³", true},
      {"deepest water", most(a, "max_depth_m"), most(b, "max_depth_m"), "m"},
      {"ground eroded", last(a, "eroded_m3"), last(b, "eroded_m3"), "m³", true},
      {"ground deposited", last(a, "deposited_m3"), last(b, "deposited_m3"), "m³", true},
  };
  std::string md = "# What changed: " + o.runB.string() + " against " + o.runA.string() + "\n\n";
  md += "| | A: `" + o.runA.string() + "` | B: `" + o.runB.string() + "` | B − A | change |\n|---|---|---|---|---|\n";
  for (const auto& r : rows) {
    if (!std::isfinite(r.a) || !std::isfinite(r.b) || (r.a == 0 && r.b == 0 && r.hideZero)) continue;
    const bool volume = std::string(r.unit) == "m³";
    auto text = [&](double v) { return volume ? volumeText(v) : fmt("%.3g", v) + " " + r.unit; };
    md += "| " + std::string(r.what) + " | " + text(r.a) + " | " + text(r.b) + " | " + text(r.b - r.a) + " | " +
          (r.a != 0 ? fmt("%+.1f%%", 100 * (r.b - r.a) / std::abs(r.a)) : std::string("-")) + " |\n";
  }
  md += "\nDifference maps (B − A; `maps/NAME_difference.tif`, each with a QGIS style):\n\n";
  if (o.plots) {
    STRATA_TRY(auto plots, writePlots(o.outDir, false));
    for (const auto& p : plots) {
      if (p.starts_with("plots/")) {
        md += "![" + fs::path(p).stem().string() + "](" + p + ")\n";
        written.push_back(p);
      }
    }
  } else {
    for (const auto& n : differ) md += "- `maps/" + n + "_difference.tif`\n";
  }
  if (!identical.empty()) {
    md += "\nThe same in both runs, cell for cell (no difference map):";
    for (size_t i = 0; i < identical.size(); ++i) md += std::string(i ? "," : "") + " `" + identical[i] + "`";
    md += ".\n";
  }
  STRATA_TRY_STATUS(writeFileAtomic(o.outDir / "compare.md", md));
  written.push_back("compare.md");
  return written;
}

}  // namespace strata::scenario
