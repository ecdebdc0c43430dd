#include <strata/terrain/material.hpp>

#include <cmath>
#include <utility>

namespace strata::terrain {

// Where the numbers come from (docs/sim-erosion.md, "Materials", has the derivations):
// - critical shear: sand and sediment from Shields' criterion for their grain size (0.5 and
//   0.2 mm) with Soulsby and Whitehouse's (1997) fit; soil and weathered rock from the ranges of
//   jet tests on cohesive beds (Hanson and Simon 2001, Hydrological Processes 15).
// - shear erodibility: Hanson and Simon's fit k_d = 0.2 tau_c^-0.5 cm^3/(N s) for every material.
// - settling velocity: Ferguson and Church (2004, J. Sedimentary Research 74) for rock fragments
//   of 10 mm, silt of 0.03 mm (soil), sand of 0.5 mm and fine sand of 0.2 mm (sediment).
// - friction angle and cohesion of wet banks: loose sand and fresh deposits at their submerged
//   angle of repose without cohesion; soil as bank soils (Simon et al. 2000, Geomorphology 35:
//   c' 0-20 kPa); weathered rock as a rock mass (Hoek, Carranza-Torres and Corkum 2002: c' of
//   0.1-10 MPa).
std::vector<Material> defaultMaterials() {
  auto m = [](const char* name, std::array<float, 3> colour, float erodibility, float dissolution, float talus,
              float density, float weathering, float tauC, float settling, float friction, float cohesion) {
    Material r;
    r.name = name;
    r.colour = colour;
    r.erodibility = erodibility;
    r.dissolutionRate = dissolution;
    r.talusAngleDeg = talus;
    r.densityKgM3 = density;
    r.weatheringRatePerS = weathering;
    r.criticalShearPa = tauC;
    r.shearErodibility = float(0.2e-6 / std::sqrt(double(tauC)));  // Hanson and Simon 2001, cm^3 -> m^3
    r.settlingVelocityMS = settling;
    r.frictionAngleDeg = friction;
    r.cohesionPa = cohesion;
    return r;
  };
  return {
      m("rock", {0.45f, 0.36f, 0.30f}, 0.05f, 1e-7f, 70.0f, 2650.0f, 1e-5f, 150.0f, 0.46f, 40.0f, 1e6f),
      m("soil", {0.40f, 0.30f, 0.18f}, 0.6f, 5e-6f, 40.0f, 1600.0f, 0.01f, 5.0f, 7.8e-4f, 30.0f, 5e3f),
      m("sand", {0.85f, 0.76f, 0.52f}, 1.0f, 1e-5f, 32.0f, 1550.0f, 0.1f, 0.25f, 0.071f, 30.0f, 0.0f),
      m("sediment", {0.55f, 0.50f, 0.40f}, 1.2f, 2e-5f, 30.0f, 1400.0f, 0.1f, 0.15f, 0.023f, 28.0f, 0.0f),
  };
}

int findMaterial(const std::vector<Material>& table, const std::string& name) {
  for (size_t i = 0; i < table.size(); ++i) {
    if (table[i].name == name) return int(i);
  }
  return -1;
}

Status validateMaterial(const Material& m) {
  const std::string what = "material '" + m.name + "'";
  if (m.name.empty()) return fail("material: empty name");
  for (float c : m.colour) {
    if (!(c >= 0 && c <= 1)) return fail(what + ": colour component " + std::to_string(c) + " outside [0,1]");
  }
  if (!(m.erodibility >= 0)) return fail(what + ": erodibility " + std::to_string(m.erodibility) + " < 0");
  if (!(m.dissolutionRate >= 0)) return fail(what + ": dissolution_rate " + std::to_string(m.dissolutionRate) + " < 0");
  if (!(m.talusAngleDeg > 0 && m.talusAngleDeg < 90)) {
    return fail(what + ": talus_angle_deg " + std::to_string(m.talusAngleDeg) + " outside (0, 90)");
  }
  if (!(m.weatheringRatePerS >= 0 && m.weatheringRatePerS <= 1e3)) {
    return fail(what + ": weathering_rate " + std::to_string(m.weatheringRatePerS) + " outside [0, 1000] per second");
  }
  if (!(m.densityKgM3 > 0)) return fail(what + ": density_kg_m3 " + std::to_string(m.densityKgM3) + " <= 0");
  const std::pair<const char*, float> nonNegative[] = {{"critical_shear_pa", m.criticalShearPa},
                                                       {"shear_erodibility", m.shearErodibility},
                                                       {"settling_velocity", m.settlingVelocityMS},
                                                       {"cohesion_pa", m.cohesionPa}};
  for (const auto& [key, v] : nonNegative) {
    if (!(v >= 0 && v < 1e30f))
      return fail(what + ": " + key + " " + std::to_string(v) + " is not a finite number >= 0");
  }
  if (!(m.frictionAngleDeg > 0 && m.frictionAngleDeg < 90)) {
    return fail(what + ": friction_angle_deg " + std::to_string(m.frictionAngleDeg) + " outside (0, 90)");
  }
  return {};
}

}  // namespace strata::terrain
