#pragma once
// The CDF 5/3 and 9/7 wavelet transforms on the GPU (procgen/shaders/dwt53.comp, dwt97.comp):
// the same formulas as the CPU reference procgen::forwardTransform / inverseTransform,
// one compute pass per axis and level, in place on an r32f texture (Mallat layout).

#include <strata/core/result.hpp>
#include <strata/gis/raster.hpp>
#include <strata/gl/objects.hpp>
#include <strata/procgen/wavelet.hpp>

namespace strata::procgen {

/// Forward and inverse multi-level transforms of r32f textures.
class WaveletGpu {
 public:
  /// Compiles the transform programs; needs a current GL 4.5 context.
  static Result<WaveletGpu> create();

  /// Replaces the heights in `field` (r32f) by their `levels`-level transform.
  /// Precondition: procgen::validateLevels(w, h, levels) passes.
  void forward(gl::Texture& field, int levels, procgen::Wavelet wavelet = procgen::Wavelet::Cdf53);
  /// Replaces the coefficients in `field` by the heights they encode.
  void inverse(gl::Texture& field, int levels, procgen::Wavelet wavelet = procgen::Wavelet::Cdf53);

 private:
  void pass(const gl::Program& program, gl::Texture& from, gl::Texture& to, glm::ivec2 region, int axis, bool inverse);
  gl::Texture& scratchFor(const gl::Texture& field);
  const gl::Program& programFor(procgen::Wavelet wavelet) const;

  gl::Program cdf53_, cdf97_;
  gl::Texture scratch_;
};

/// An r32f texture holding `grid`.
gl::Texture uploadGrid(const gis::Grid<float>& grid);
/// Level 0 of an r32f texture as a grid.
gis::Grid<float> downloadGrid(const gl::Texture& texture);

}  // namespace strata::procgen
