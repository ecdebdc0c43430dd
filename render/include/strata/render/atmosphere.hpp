#pragma once
// A body's air, for the sky and aerial perspective (docs/render-rings.md, "Sky and air"): two
// exponential layers, molecules (Rayleigh: extinction by colour channel, blue most) and haze
// (grey extinction, scattering its own colour), each with an extinction coefficient at the
// datum and a scale height. Light scattered towards the viewer along a path of optical depth
// tau (per channel) is brightness x (scattering colour) x (1 - exp(-tau)): a blue zenith, a
// whitening horizon, distant terrain fading into the sky's colour, and black space above the
// air seen from orbit, with a bright rim at the limb.

#include <optional>

#include <glm/vec3.hpp>

#include <strata/gis/body.hpp>

namespace strata::render {

struct Atmosphere {
  glm::vec3 rayleighPerM{5.0e-6f, 1.16e-5f, 2.83e-5f};  ///< molecular extinction at the datum (1/m), R G B
  float rayleighScaleM = 8000;                          ///< its scale height (m)
  float hazePerM = 1.0e-5f;                             ///< haze extinction at the datum (1/m), all channels
  float hazeScaleM = 1200;                              ///< its scale height (m)
  glm::vec3 hazeColour{0.95f, 0.95f, 0.95f};            ///< what the haze scatters
  float brightness = 1.0f;                              ///< scattered light at full optical depth, sun overhead
};

/// The Earth's air (Rayleigh at 680/550/440 nm, 8 km; a 1.2 km haze layer, ~40 km visibility at
/// sea level) and Mars's (thin CO2, 11.1 km; well-mixed dust of vertical optical depth 0.3,
/// butterscotch); nothing for the Moon or an unknown body.
std::optional<Atmosphere> atmosphereFor(const gis::Body& body);

}  // namespace strata::render
