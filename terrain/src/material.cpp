#include <strata/terrain/material.hpp>

namespace strata::terrain {

std::vector<Material> defaultMaterials() {
  return {
      {"rock", {0.45f, 0.36f, 0.30f}, 0.05f, 1e-7f, 70.0f, 2650.0f, 1e-5f},
      {"soil", {0.40f, 0.30f, 0.18f}, 0.6f, 5e-6f, 40.0f, 1600.0f, 0.01f},
      {"sand", {0.85f, 0.76f, 0.52f}, 1.0f, 1e-5f, 32.0f, 1550.0f, 0.1f},
      {"sediment", {0.55f, 0.50f, 0.40f}, 1.2f, 2e-5f, 30.0f, 1400.0f, 0.1f},
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
  return {};
}

}  // namespace strata::terrain
