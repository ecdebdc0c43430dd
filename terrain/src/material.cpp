#include <strata/terrain/material.hpp>

namespace strata::terrain {

std::vector<Material> defaultMaterials() {
  return {
      {"rock", {0.45f, 0.36f, 0.30f}, 0.05f, 1e-7f, 70.0f, 2650.0f},
      {"soil", {0.40f, 0.30f, 0.18f}, 0.6f, 5e-6f, 40.0f, 1600.0f},
      {"sand", {0.85f, 0.76f, 0.52f}, 1.0f, 1e-5f, 32.0f, 1550.0f},
      {"sediment", {0.55f, 0.50f, 0.40f}, 1.2f, 2e-5f, 30.0f, 1400.0f},
  };
}

int findMaterial(const std::vector<Material>& table, const std::string& name) {
  for (size_t i = 0; i < table.size(); ++i) {
    if (table[i].name == name) return int(i);
  }
  return -1;
}

}  // namespace strata::terrain
