// GPU CDF 5/3 transform: per level, a row pass into the scratch texture and a column pass back
// (forward), or the reverse (inverse). Coefficients outside the level's region stay untouched.
#include <strata/procgen/wavelet_gpu.hpp>

#include <strata/gl/state.hpp>
#include <strata/procgen/shader_slots.hpp>
#include <strata/procgen/wavelet.hpp>

namespace strata::procgen {

Result<WaveletGpu> WaveletGpu::create() {
  STRATA_TRY(auto cdf53, gl::Program::compute("procgen/shaders/dwt53.comp", gl::definesFor(slots::kAll)));
  STRATA_TRY(auto cdf97, gl::Program::compute("procgen/shaders/dwt97.comp", gl::definesFor(slots::kAll)));
  WaveletGpu w;
  w.cdf53_ = std::move(cdf53);
  w.cdf97_ = std::move(cdf97);
  return w;
}

const gl::Program& WaveletGpu::programFor(procgen::Wavelet wavelet) const {
  return wavelet == procgen::Wavelet::Cdf97 ? cdf97_ : cdf53_;
}

gl::Texture& WaveletGpu::scratchFor(const gl::Texture& field) {
  if (!scratch_ || scratch_.width() != field.width() || scratch_.height() != field.height()) {
    scratch_ = gl::Texture::create2D(gl::TextureFormat::kR32F, field.width(), field.height());
  }
  return scratch_;
}

void WaveletGpu::pass(const gl::Program& program, gl::Texture& from, gl::Texture& to, glm::ivec2 region, int axis,
                      bool inverse) {
  from.bindImage(slots::kDwtSrc, gl::Access::kRead);
  to.bindImage(slots::kDwtDst, gl::Access::kWrite);
  program.set("uRegion", region);
  program.set("uAxis", axis);
  program.set("uInverse", inverse ? 1 : 0);
  program.dispatchCovering(region.x, region.y);
  gl::memoryBarrier(gl::Barrier::kImageAccess);
}

void WaveletGpu::forward(gl::Texture& field, int levels, procgen::Wavelet wavelet) {
  STRATA_CHECK(procgen::validateLevels(field.width(), field.height(), levels).ok())
      << levels << " levels for " << field.width() << "x" << field.height();
  auto& scratch = scratchFor(field);
  const procgen::PyramidShape shape{field.width(), field.height(), levels};
  const auto& program = programFor(wavelet);
  for (int l = 0; l < levels; ++l) {
    const glm::ivec2 region{shape.regionWidth(l), shape.regionHeight(l)};
    pass(program, field, scratch, region, 0, false);
    pass(program, scratch, field, region, 1, false);
  }
}

void WaveletGpu::inverse(gl::Texture& field, int levels, procgen::Wavelet wavelet) {
  STRATA_CHECK(procgen::validateLevels(field.width(), field.height(), levels).ok())
      << levels << " levels for " << field.width() << "x" << field.height();
  auto& scratch = scratchFor(field);
  const procgen::PyramidShape shape{field.width(), field.height(), levels};
  const auto& program = programFor(wavelet);
  for (int l = levels - 1; l >= 0; --l) {
    const glm::ivec2 region{shape.regionWidth(l), shape.regionHeight(l)};
    pass(program, field, scratch, region, 1, true);
    pass(program, scratch, field, region, 0, true);
  }
}

gl::Texture uploadGrid(const gis::Grid<float>& grid) {
  auto t = gl::Texture::create2D(gl::TextureFormat::kR32F, grid.width, grid.height);
  t.upload(grid.data.data());
  return t;
}

gis::Grid<float> downloadGrid(const gl::Texture& texture) {
  gl::memoryBarrier(gl::Barrier::kTextureUpdate);
  gis::Grid<float> g(texture.width(), texture.height());
  g.data = texture.read<float>();
  return g;
}

}  // namespace strata::procgen
