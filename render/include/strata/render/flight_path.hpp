#pragma once
// A camera flight path: keyframes interpolated piecewise linearly, for rendering numbered
// frames (`strata render --path`).

#include <string>
#include <vector>

#include <strata/core/result.hpp>
#include <strata/render/terrain_renderer.hpp>

namespace strata::render {

struct FlightPath {
  std::vector<CameraPose> keys;  ///< at least two

  /// Parses keyframes, one per line: `lon lat heightM headingDeg pitchDeg [fovYDeg]` (lon/lat
  /// as in CameraPose); blank lines and lines starting with # are skipped. `source` names the
  /// text in error messages.
  static Result<FlightPath> parse(const std::string& text, const std::string& source);
  /// Reads and parses a keyframe file.
  static Result<FlightPath> load(const std::string& path);
  /// The pose at t in [0, 1] (keys evenly spaced in t; heading along the shorter arc).
  CameraPose at(double t) const;
};

}  // namespace strata::render
