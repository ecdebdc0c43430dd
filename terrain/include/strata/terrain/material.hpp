#pragma once
// Materials of the layered terrain: what each layer is made of and how it erodes.

#include <array>
#include <string>
#include <vector>

#include <strata/core/result.hpp>

namespace strata::terrain {

struct Material {
  std::string name;
  std::array<float, 3> colour{0.5f, 0.5f, 0.5f};  ///< linear RGB in [0,1], for shading
  float erodibility = 1.0f;                       ///< scale of force-based erosion (dimensionless, rock < soil < sand)
  float dissolutionRate = 0.0f;                   ///< dissolution in slow water (m of material per m of water per s)
  float talusAngleDeg = 35.0f;                    ///< steepest stable slope; steeper is weathered down (degrees)
  float densityKgM3 = 2650.0f;                    ///< bulk density (kg/m^3)
  /// Rate at which material above its talus angle moves down (1/s): the share of the excess
  /// moved in a step of dt is ~ rate * dt (docs/sim-erosion.md, E7). Loose sand slides within
  /// seconds; bedrock weathers over days.
  float weatheringRatePerS = 0.1f;
};

/// Defaults from textbook values: bedrock barely erodes and stands steep; sand moves easily and
/// rests at ~32 degrees (its angle of repose).
std::vector<Material> defaultMaterials();

/// Index of the material named `name` in `table`, or -1.
int findMaterial(const std::vector<Material>& table, const std::string& name);

/// Checks a material read from user data (a store manifest, a scenario): a non-empty name, colour
/// in [0,1], erodibility and dissolution >= 0, talus angle in (0, 90) degrees, density > 0.
Status validateMaterial(const Material& m);

}  // namespace strata::terrain
