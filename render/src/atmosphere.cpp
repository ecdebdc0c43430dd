#include <strata/render/atmosphere.hpp>

#include <cmath>

namespace strata::render {

std::optional<Atmosphere> atmosphereFor(const gis::Body& body) {
  if (std::abs(body.semiMajorM - gis::Body::wgs84().semiMajorM) < 10000.0) return Atmosphere{};
  if (body.name == gis::Body::mars().name) {
    Atmosphere mars;
    // Surface pressure ~0.6% of the Earth's, CO2 (scatters ~2.3x air per molecule): ~1/70 of the
    // Earth's molecular extinction; dust mixed through the 11.1 km scale height (vertical
    // optical depth ~0.3, a clear season), absorbing blue: a butterscotch sky.
    mars.rayleighPerM = glm::vec3(5.0e-6f, 1.16e-5f, 2.83e-5f) / 70.0f;
    mars.rayleighScaleM = 11100;
    mars.hazePerM = 0.3f / 11100.0f;
    mars.hazeScaleM = 11100;
    mars.hazeColour = {0.85f, 0.62f, 0.42f};
    mars.brightness = 1.0f;
    return mars;
  }
  return std::nullopt;
}

}  // namespace strata::render
