#pragma once
// Degrees to radians, one constant for every library (they share translation units in unity builds).
#include <numbers>

namespace strata {

/// Radians in a degree.
inline constexpr double kDeg = std::numbers::pi / 180.0;

}  // namespace strata
