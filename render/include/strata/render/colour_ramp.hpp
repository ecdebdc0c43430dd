#pragma once
// A user's elevation colour ramp in gdaldem color-relief's text format, so one file colours
// `gdaldem color-relief` output, QGIS and Strata alike: one stop a line, "ELEVATION R G B [A]"
// (spaces, tabs or commas between), ELEVATION a number in metres or a percentage of the
// terrain's range ("50%"), "nv R G B" the no-data colour (read, unused: voids are filled or
// holes), '#' starting a comment. Between stops the colour is interpolated linearly; beyond the
// ends it is the end's colour (gdaldem's default mode).

#include <string>
#include <vector>

#include <glm/vec3.hpp>

#include <strata/core/result.hpp>

namespace strata::render {

struct ColourRamp {
  static constexpr int kMaxStops = 64;  ///< stops the shader holds
  std::vector<float> elevationsM;       ///< ascending
  std::vector<glm::vec3> colours;       ///< 0..1, one per stop
  /// The colour at `elevationM`, as gdaldem color-relief computes it (before rounding to bytes).
  glm::vec3 at(float elevationM) const;
};

/// Reads a gdaldem color-relief file; percentages are of [minM, maxM] (the terrain's range).
/// Errors name the file and line and say what was expected; at most kMaxStops stops.
Result<ColourRamp> loadColourRamp(const std::string& path, float minM, float maxM);

}  // namespace strata::render
