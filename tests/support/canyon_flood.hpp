#pragma once
// A flood on a window of the real Grand Canyon DEM (grand_canyon_512.tif: EPSG:4326, 1/512 deg,
// ~217 m x ~175 m cells): a spring in the main canyon, flood mode with Manning friction, open
// edges. Shared by the adaptive-tile test (tests/render) and benchmark (bench/).
#include <cmath>
#include <numbers>
#include <string>

#include <strata/core/result.hpp>
#include <strata/gis/dem_io.hpp>
#include <strata/sim/input.hpp>
#include <strata/terrain/material.hpp>

namespace strata::test {

struct CanyonFlood {
  sim::SimInput input;
  sim::SimParams params;
  sim::Source spring;
};

/// `n` x `n` cells of the DEM from pixel (x0, y0), per-row dx from the latitude (spherical
/// Earth, R = 6371 km); a spring of `springM3S` at DEM pixel (springX, springY).
inline Result<CanyonFlood> canyonFlood(const std::string& demPath, int x0, int y0, int n, int springX, int springY,
                                       double springM3S) {
  STRATA_TRY(auto dem, gis::readDem(demPath));
  if (x0 + n > dem.values.width || y0 + n > dem.values.height) return fail(demPath + ": the window is outside the DEM");
  CanyonFlood c;
  auto& in = c.input;
  in.baseM = gis::Grid<float>(n, n);
  const auto& t = dem.georef.transform;
  const double rad = std::numbers::pi / 180.0, r = 6371000.0;
  in.dyM = std::abs(t.c[5]) * rad * r;
  float lo = 1e30f;
  for (int y = 0; y < n; ++y) {
    const double lat = t.y(0, y0 + y + 0.5);
    in.rowDxM.push_back(std::abs(t.c[1]) * rad * r * std::cos(lat * rad));
    for (int x = 0; x < n; ++x) {
      in.baseM.at(x, y) = dem.values.at(x0 + x, y0 + y);
      lo = std::min(lo, in.baseM.at(x, y));
    }
  }
  in.datumM = std::floor(double(lo));
  in.materials = {terrain::defaultMaterials()[0]};
  in.layersM = {gis::Grid<float>(n, n, 0.0f)};
  auto& p = c.params;
  p.waterModel = sim::WaterModel::kFiniteVolume;
  p.cflAlpha = 0.45f;
  p.maxDtS = 30.0f;
  p.manningN = 0.04f;  // bedrock channel with boulders, as the scenario
  p.openEdges = sim::kEdgeWest | sim::kEdgeEast | sim::kEdgeNorth | sim::kEdgeSouth;
  c.spring.cells = {{springX - x0, springY - y0}};
  c.spring.dischargeM3S = TimeSeries({{0.0, springM3S}, {1e9, springM3S}});
  return c;
}

}  // namespace strata::test
