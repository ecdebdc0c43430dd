// GPU CDF 5/3 transform: per level, a row pass into the scratch texture and a column pass back
// (forward), or the reverse (inverse). Coefficients outside the level's region stay untouched.
#include <strata/render/procgen/wavelet_gpu.hpp>

#include <strata/terrain/procgen/wavelet.hpp>

namespace strata::render::procgen {

Result<WaveletGpu> WaveletGpu::create() {
  STRATA_TRY(auto program, gl::Program::compute("procgen/dwt53.comp"));
  WaveletGpu w;
  w.program_ = std::move(program);
  return w;
}

gl::Texture& WaveletGpu::scratchFor(const gl::Texture& field) {
  if (!scratch_ || scratch_.width() != field.width() || scratch_.height() != field.height()) {
    scratch_ = gl::Texture::create2D(gl::kR32F, field.width(), field.height());
  }
  return scratch_;
}

void WaveletGpu::pass(gl::Texture& from, gl::Texture& to, glm::ivec2 region, int axis, bool inverse) {
  from.bindImage(0, GL_READ_ONLY);
  to.bindImage(1, GL_WRITE_ONLY);
  program_.set("uRegion", region);
  program_.set("uAxis", axis);
  program_.set("uInverse", inverse ? 1 : 0);
  program_.dispatchCovering(region.x, region.y);
  glMemoryBarrier(GL_SHADER_IMAGE_ACCESS_BARRIER_BIT);
}

void WaveletGpu::forward(gl::Texture& field, int levels) {
  STRATA_CHECK(terrain::procgen::validateLevels(field.width(), field.height(), levels).ok())
      << levels << " levels for " << field.width() << "x" << field.height();
  auto& scratch = scratchFor(field);
  const terrain::procgen::PyramidShape shape{field.width(), field.height(), levels};
  program_.use();
  for (int l = 0; l < levels; ++l) {
    const glm::ivec2 region{shape.regionWidth(l), shape.regionHeight(l)};
    pass(field, scratch, region, 0, false);
    pass(scratch, field, region, 1, false);
  }
}

void WaveletGpu::inverse(gl::Texture& field, int levels) {
  STRATA_CHECK(terrain::procgen::validateLevels(field.width(), field.height(), levels).ok())
      << levels << " levels for " << field.width() << "x" << field.height();
  auto& scratch = scratchFor(field);
  const terrain::procgen::PyramidShape shape{field.width(), field.height(), levels};
  program_.use();
  for (int l = levels - 1; l >= 0; --l) {
    const glm::ivec2 region{shape.regionWidth(l), shape.regionHeight(l)};
    pass(field, scratch, region, 1, true);
    pass(scratch, field, region, 0, true);
  }
}

gl::Texture uploadGrid(const gis::Grid<float>& grid) {
  auto t = gl::Texture::create2D(gl::kR32F, grid.width, grid.height);
  t.upload(grid.data.data());
  return t;
}

gis::Grid<float> downloadGrid(const gl::Texture& texture) {
  glMemoryBarrier(GL_TEXTURE_UPDATE_BARRIER_BIT);
  gis::Grid<float> g(texture.width(), texture.height());
  g.data = texture.read<float>();
  return g;
}

}  // namespace strata::render::procgen
