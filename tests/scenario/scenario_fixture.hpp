#pragma once
// The small flood scenario the scenario tests share (a ~24 x 18 km piece of the real Grand
// Canyon DEM with a river inflow) and helpers to read what a run writes.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include <strata/gis/dem_io.hpp>
#include <strata/gis/geodesy.hpp>
#include <strata/scenario/run.hpp>
#include <strata/scenario/scenario.hpp>

#include "strata_test.hpp"

namespace strata::scenario::test_support {

// 20 minutes of a 20,000 m3/s river entering a ~24 x 18 km piece of the canyon at ~600 m cells.
inline std::string scenarioText() {
  return "name = \"test flood\"\n"
         "[terrain]\ndem = \"" +
         strata::test::dataPath("grand_canyon/grand_canyon_512.tif") +
         "\"\n"
         "[region]\nbbox_lonlat = [-112.25, 36.02, -112.001, 36.18]\ncell_size = \"600 m\"\n"
         "[model]\nkind = \"flood\"\nmanning_n = 0.04\n"
         "boundary = { west = \"open\", east = \"closed\", south = \"open\", north = \"open\" }\n"
         "[[water.inflow]]\nname = \"Colorado\"\nline_lonlat = [[-112.0225, 36.063], [-112.0225, 36.08]]\n"
         "hydrograph = [[0, 0], [5, 20000], [20, 20000]]\nhydrograph_units = [\"min\", \"m3/s\"]\n"
         "[time]\nduration = \"20 min\"\noutput_interval = \"5 min\"\n"
         "[outputs]\nwet_threshold = \"0.1 m\"\n";
}

// A dam break in a closed ~24 x 18 km piece of the canyon at 600 m cells: a lake 100 m above the
// river held behind a dam in the east, 20 minutes, rows of gauges and sections every minute;
// `outputs` is appended to [outputs] ([[outputs.gauge]] and [[outputs.section]] tables).
inline std::string damBreakText(const std::string& outputs = {}) {
  return "name = \"dam break with a gauge and a section\"\n"
         "[terrain]\ndem = \"" +
         strata::test::dataPath("grand_canyon/grand_canyon_512.tif") +
         "\"\n"
         "[region]\nbbox_lonlat = [-112.25, 36.02, -112.001, 36.18]\ncell_size = \"600 m\"\n"
         "[model]\nkind = \"flood\"\nmanning_n = 0.04\nboundary = \"closed\"\n"
         "[[water.dam_break]]\npolygon_lonlat = [[-112.08, 36.04], [-112.01, 36.04], [-112.01, 36.12], "
         "[-112.08, 36.12]]\nsurface = \"850 m\"\n"
         "[time]\nduration = \"20 min\"\noutput_interval = \"5 min\"\n"
         "[outputs]\nprobe_interval = \"1 min\"\n" +
         outputs;
}

inline scenario::Scenario writeScenario(const std::filesystem::path& dir) {
  const auto file = dir / "flood.toml";
  std::ofstream(file) << scenarioText();
  auto s = strata::scenario::loadScenario(file);
  EXPECT_TRUE(s) << s.message();
  return *s;
}

// A file's bytes ("" when it cannot be read).
inline std::string slurp(const std::filesystem::path& p) {
  std::ifstream f(p, std::ios::binary);
  std::stringstream s;
  s << f.rdbuf();
  return s.str();
}

/// A raster of `width` x `height` cells of `cellM` in UTM zone 12N (EPSG:32612), its north-west
/// corner at (x0, y0), every cell `fill`: the synthetic DEMs and maps of the spatial-input tests.
inline gis::Raster utmRaster(int width, int height, double x0, double y0, double cellM, float fill) {
  auto crs = gis::describeCrs("EPSG:32612");
  EXPECT_TRUE(crs) << crs.message();
  gis::Raster r;
  r.georef = *crs;
  r.georef.width = width;
  r.georef.height = height;
  r.georef.transform = gis::GeoTransform{{x0, cellM, 0, y0, 0, -cellM}};
  r.values = gis::Grid<float>(width, height, fill);
  return r;
}

/// A run into `out` on the CPU backend, without pictures (and without plots unless asked).
inline RunOptions cpuOptions(const std::filesystem::path& out, bool plots = false) {
  RunOptions o;
  o.outDir = out;
  o.backend = Backend::kCpu;
  o.pictures = false;
  o.plots = plots;
  return o;
}

inline gis::ReadOptions allowEmpty() {
  gis::ReadOptions o;
  o.allowAllNoData = true;
  return o;
}

inline std::vector<std::vector<double>> readCsv(const std::filesystem::path& path) {
  std::ifstream f(path);
  std::string line;
  std::getline(f, line);  // header
  std::vector<std::vector<double>> rows;
  while (std::getline(f, line)) {
    std::vector<double> row;
    std::stringstream ss(line);
    std::string cell;
    while (std::getline(ss, cell, ',')) row.push_back(std::stod(cell));
    rows.push_back(row);
  }
  return rows;
}

}  // namespace strata::scenario::test_support
