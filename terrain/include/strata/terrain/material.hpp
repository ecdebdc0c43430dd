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
  float erodibility = 1.0f;      ///< scale of the force-based law's erosion (dimensionless, rock < soil < sand)
  float dissolutionRate = 0.0f;  ///< dissolution in slow water (m of material per m of water per s)
  float talusAngleDeg = 35.0f;   ///< steepest stable dry slope; steeper is weathered down (degrees)
  float densityKgM3 = 2650.0f;   ///< bulk density (kg/m^3)
  /// Rate at which material above its talus angle moves down (1/s): an excess relaxes as
  /// exp(-rate t) (docs/sim-erosion.md, E7). Loose sand slides within seconds; bedrock weathers
  /// over days.
  float weatheringRatePerS = 0.1f;
  // The shear-stress law (docs/sim-erosion.md, E1-E3) and bank failure (E8), in SI units.
  float criticalShearPa = 1.0f;      ///< tau_c: bed shear stress below which the flow entrains nothing (Pa)
  float shearErodibility = 2e-7f;    ///< k_d: entrainment per Pa of excess shear, E = k_d (tau - tau_c) (m/(s Pa))
  float settlingVelocityMS = 0.02f;  ///< w_s of its grains in water (m/s): deposits settle at w_s c
  float frictionAngleDeg = 30.0f;    ///< phi': effective friction angle of a wet bank (degrees)
  float cohesionPa = 0.0f;           ///< c': effective cohesion of a wet bank (Pa); 0 for loose grains
};

/// Defaults from the literature (docs/sim-erosion.md, "Materials", cites each): bedrock barely
/// erodes and stands steep; sand moves easily and rests at ~32 degrees (its angle of repose).
std::vector<Material> defaultMaterials();

/// Index of the material named `name` in `table`, or -1.
int findMaterial(const std::vector<Material>& table, const std::string& name);

/// Checks a material read from user data (a store manifest, a scenario): a non-empty name, colour
/// in [0,1], erodibility and dissolution >= 0, talus and friction angles in (0, 90) degrees,
/// density > 0, critical shear, shear erodibility, settling velocity and cohesion >= 0.
Status validateMaterial(const Material& m);

}  // namespace strata::terrain
