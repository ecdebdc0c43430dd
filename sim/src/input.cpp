#include <strata/sim/input.hpp>

#include <algorithm>
#include <cmath>
#include <numbers>
#include <string>

namespace strata::sim {
namespace {

Status checkGrid(const gis::Grid<float>& g, int w, int h, const std::string& field, bool nonNegative) {
  if (g.width != w || g.height != h) {
    return fail("sim input: " + field + " is " + std::to_string(g.width) + "x" + std::to_string(g.height) +
                ", expected " + std::to_string(w) + "x" + std::to_string(h));
  }
  for (size_t i = 0; i < g.size(); ++i) {
    const float v = g.data[i];
    if (!std::isfinite(v) || (nonNegative && v < 0.0f)) {
      return fail("sim input: " + field + " has " + (std::isfinite(v) ? "a negative" : "a non-finite") +
                  " value at cell (" + std::to_string(i % size_t(w)) + ", " + std::to_string(i / size_t(w)) + ")");
    }
  }
  return {};
}

}  // namespace

MaterialConstants materialConstants(const terrain::Material& m) {
  MaterialConstants c;
  c.erodibility = m.erodibility;
  c.dissolutionRate = m.dissolutionRate;
  c.tanTalus = float(std::tan(double(m.talusAngleDeg) * std::numbers::pi / 180.0));
  c.weatheringRatePerS = m.weatheringRatePerS;
  c.criticalShearPa = m.criticalShearPa;
  c.shearErodibility = m.shearErodibility;
  c.settlingVelocityMS = m.settlingVelocityMS;
  const double phi = double(m.frictionAngleDeg) * std::numbers::pi / 180.0;
  c.tanFriction = float(std::tan(phi));
  c.sinFriction = float(std::sin(phi));
  c.cosFriction = float(std::cos(phi));
  // Culmann's planar failure: a bank of unit weight gamma = density g fails above the height
  // (4 c' / gamma) sin(beta) cos(phi') / (1 - cos(beta - phi')) (e.g. Lohnes and Handy 1968).
  c.cohesionHeightM = float(4.0 * double(m.cohesionPa) / (double(m.densityKgM3) * 9.81));
  return c;
}

Status validate(const SimInput& input, const SimParams& params) {
  const int w = input.baseM.width, h = input.baseM.height;
  if (w < 2 || h < 2) return fail("sim input: baseM must be at least 2x2 cells");
  STRATA_TRY_STATUS(checkGrid(input.baseM, w, h, "baseM", false));
  if (input.layersM.empty()) return fail("sim input: layersM is empty (need at least one material layer)");
  if (input.materials.size() != input.layersM.size()) {
    return fail("sim input: " + std::to_string(input.materials.size()) + " materials for " +
                std::to_string(input.layersM.size()) + " layers");
  }
  for (size_t l = 0; l < input.layersM.size(); ++l) {
    STRATA_TRY_STATUS(checkGrid(input.layersM[l], w, h, "layersM[" + std::to_string(l) + "]", true));
  }
  if (input.waterDepthM.size() > 0) STRATA_TRY_STATUS(checkGrid(input.waterDepthM, w, h, "waterDepthM", true));
  if (input.rainMmPerHour.size() > 0) STRATA_TRY_STATUS(checkGrid(input.rainMmPerHour, w, h, "rainMmPerHour", true));
  if (input.manningN.size() > 0) STRATA_TRY_STATUS(checkGrid(input.manningN, w, h, "manningN", true));
  if (input.infiltrationMmPerHour.size() > 0) {
    STRATA_TRY_STATUS(checkGrid(input.infiltrationMmPerHour, w, h, "infiltrationMmPerHour", true));
  }
  if (input.infiltrationSuctionM.size() > 0) {
    if (input.infiltrationMmPerHour.size() == 0) return fail("sim input: infiltrationSuctionM without a rate");
    STRATA_TRY_STATUS(checkGrid(input.infiltrationSuctionM, w, h, "infiltrationSuctionM", true));
  }
  if (input.rowDxM.size() != 1 && input.rowDxM.size() != size_t(h)) {
    return fail("sim input: rowDxM has " + std::to_string(input.rowDxM.size()) + " values, expected 1 or " +
                std::to_string(h) + " (one per row)");
  }
  for (double dx : input.rowDxM) {
    if (!(dx > 0) || !std::isfinite(dx)) return fail("sim input: rowDxM has a cell size " + std::to_string(dx));
  }
  if (!(input.dyM > 0) || !std::isfinite(input.dyM)) {
    return fail("sim input: dyM must be positive, got " + std::to_string(input.dyM));
  }
  if (!std::isfinite(input.datumM)) return fail("sim input: datumM is not finite");
  return validateParams(params);
}

CellGrid CellGrid::of(const SimInput& input) {
  return of(input.baseM.width, input.baseM.height, int(input.layersM.size()), input.rowDxM, input.dyM, input.datumM);
}

CellGrid CellGrid::of(int width, int height, int layers, const std::vector<double>& rowDxM, double dyM, double datumM) {
  CellGrid g;
  g.width = width;
  g.height = height;
  g.layers = layers;
  g.rowDxM.resize(size_t(g.height));
  for (int y = 0; y < g.height; ++y) g.rowDxM[size_t(y)] = rowDxM.size() == 1 ? rowDxM[0] : rowDxM[size_t(y)];
  g.dyM = double(float(dyM));
  g.datumM = datumM;
  g.minCellM = dyM;
  for (double dx : g.rowDxM) g.minCellM = std::min(g.minCellM, dx);
  return g;
}

}  // namespace strata::sim
