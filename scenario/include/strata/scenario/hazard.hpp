#pragma once
// Flood hazard to people: the UK's hazard rating (Defra / Environment Agency R&D report FD2321/TR2,
// "Flood Risks to People Phase 2", 2006, and its supplementary note of 2008):
//   HR = d (v + 0.5) + DF
// with d the depth (m), v the speed (m/s) and DF the debris factor of FD2321's table 3.1 by depth
// and land use. Its classes: below 0.75 "low" (caution), 0.75 to 1.25 "moderate" (danger for
// some), 1.25 to 2.0 "significant" (danger for most), above 2.0 "extreme" (danger for all).
// Strata rates each cell from its largest depth and its largest speed over the run, which may
// come at different times: an upper bound of FD2321's rating at each time (stated in the map's
// band description and the report).

#include <array>
#include <string_view>

namespace strata::scenario {

/// FD2321's land uses for the debris factor.
enum class HazardLandUse { kPasture, kWoodland, kUrban };

/// The debris factor: 0 up to 0.25 m; 0.25 to 0.75 m: pasture 0, woodland 0.5, urban 1; deeper:
/// pasture 0.5, woodland and urban 1.
inline double debrisFactor(double depthM, HazardLandUse use) {
  if (depthM <= 0.25) return 0.0;
  if (depthM <= 0.75) return use == HazardLandUse::kPasture ? 0.0 : use == HazardLandUse::kWoodland ? 0.5 : 1.0;
  return use == HazardLandUse::kPasture ? 0.5 : 1.0;
}

inline double hazardRating(double depthM, double speedMS, HazardLandUse use) {
  return depthM * (speedMS + 0.5) + debrisFactor(depthM, use);
}

inline const char* hazardLandUseName(HazardLandUse use) {
  return use == HazardLandUse::kPasture ? "pasture" : use == HazardLandUse::kWoodland ? "woodland" : "urban";
}

/// The classes' upper bounds (the last is open).
inline constexpr std::array<double, 3> kHazardClassBounds{0.75, 1.25, 2.0};
inline constexpr std::array<std::string_view, 4> kHazardClassNames{
    "low (caution)", "moderate (danger for some)", "significant (danger for most)", "extreme (danger for all)"};

/// 0 (low) .. 3 (extreme).
inline int hazardClass(double rating) {
  int k = 0;
  while (k < 3 && rating >= kHazardClassBounds[size_t(k)]) ++k;
  return k;
}

}  // namespace strata::scenario
