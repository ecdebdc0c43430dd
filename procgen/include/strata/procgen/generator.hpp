#pragma once
// User generation scripts: a small GLSL function spliced into procgen/shaders/generate.comp,
// compiled at run time, run over the output grid (height form) or over the wavelet pyramid and
// then inverse-transformed (level form). docs/procgen.md describes the forms and built-ins.

#include <cstdint>
#include <string>
#include <vector>

#include <strata/core/result.hpp>
#include <strata/gis/raster.hpp>
#include <strata/gl/shader_source.hpp>
#include <strata/procgen/wavelet.hpp>

namespace strata::procgen {

/// The GLSL of one script and where it came from, so compile errors name the user's file/line.
struct UserScript {
  std::string fileName;  ///< named in compile errors, e.g. "docs/examples/fbm_waves_mountain.toml"
  std::string glsl;      ///< defines `float height(vec2 p)` or `float level(vec2 p, int lvl)`
  int firstLine = 1;     ///< line of `glsl`'s first line in fileName
};

/// Which function a script defines.
enum class ScriptForm { Height, Level };

/// Finds `height(vec2 ...)` or `level(vec2 ..., int ...)` in the script; fails when it has
/// neither or both.
Result<ScriptForm> detectForm(const UserScript& script);

/// The compute shader of a script: the template with the user's text spliced in as its own
/// source string (`#line firstLine N`, files[N] = fileName). No GL: testable anywhere.
Result<gl::ShaderSource> spliceScript(const UserScript& script, ScriptForm form);

/// What to generate.
struct GenerateOptions {
  int width = 256, height = 256;  ///< output grid, cells
  uint32_t seed = 1;              ///< seeds every hash of the built-ins
  int levels = 6;                 ///< wavelet levels; level form: must fit the size (maxLevels)
  /// The pyramid's wavelet (level form; also the transform of the input DEMs).
  procgen::Wavelet wavelet = procgen::Wavelet::Cdf53;
  /// Input DEMs (metres, NaN = no data) read by dem0Level/dem1Level; each is resampled
  /// (bilinear) to width x height and its no data filled with its mean before the transform.
  std::vector<gis::Grid<float>> dems;
  /// Histogram-match each generated detail band to the same band of this DEM (-1: off).
  int matchDem = -1;
  /// Also match the coarse LL band (else it is kept as the script made it).
  bool matchCoarse = false;
};

/// Runs a script on the current GL context and returns the height field (row 0 at the top).
Result<gis::Grid<float>> generate(const UserScript& script, const GenerateOptions& options);

/// Levels actually used for a w x h output when `requested` are asked for (clamped to
/// 1..maxLevels; only the height form, which has no pyramid of its own, relies on the clamp).
int effectiveLevels(int width, int height, int requested);

}  // namespace strata::procgen
