#include <strata/gl/state.hpp>

#include <epoxy/gl.h>

namespace strata::gl {

void memoryBarrier(Barrier barrier) {
  static constexpr std::pair<Barrier, GLbitfield> kBits[] = {
      {Barrier::kStorage, GL_SHADER_STORAGE_BARRIER_BIT},
      {Barrier::kBufferUpdate, GL_BUFFER_UPDATE_BARRIER_BIT},
      {Barrier::kTextureUpdate, GL_TEXTURE_UPDATE_BARRIER_BIT},
      {Barrier::kTextureFetch, GL_TEXTURE_FETCH_BARRIER_BIT},
      {Barrier::kImageAccess, GL_SHADER_IMAGE_ACCESS_BARRIER_BIT},
      {Barrier::kPixelBuffer, GL_PIXEL_BUFFER_BARRIER_BIT},
      {Barrier::kUniform, GL_UNIFORM_BARRIER_BIT},
      {Barrier::kVertexAttrib, GL_VERTEX_ATTRIB_ARRAY_BARRIER_BIT | GL_ELEMENT_ARRAY_BARRIER_BIT},
      {Barrier::kCommand, GL_COMMAND_BARRIER_BIT},
  };
  GLbitfield bits = 0;
  for (const auto& [b, gl] : kBits) {
    if (uint32_t(barrier) & uint32_t(b)) bits |= gl;
  }
  glMemoryBarrier(bits);
}

void finish() { glFinish(); }

Viewport viewport() {
  GLint v[4] = {0, 0, 0, 0};
  glGetIntegerv(GL_VIEWPORT, v);
  return {v[0], v[1], v[2], v[3]};
}

void setViewport(const Viewport& v) { glViewport(v.x, v.y, v.width, v.height); }

void setDepthTest(DepthTest test, bool write) {
  if (test == DepthTest::kOff) {
    glDisable(GL_DEPTH_TEST);
    glDepthFunc(GL_LESS);  // GL's default, for code that turns the test on without setting it
  } else {
    glEnable(GL_DEPTH_TEST);
    glDepthFunc(test == DepthTest::kGreater ? GL_GREATER : GL_LESS);
  }
  glDepthMask(write ? GL_TRUE : GL_FALSE);
}

void setClipDepth(ClipDepth range) {
  glClipControl(GL_LOWER_LEFT, range == ClipDepth::kZeroToOne ? GL_ZERO_TO_ONE : GL_NEGATIVE_ONE_TO_ONE);
}

void setCulling(bool cullBackFaces) {
  if (cullBackFaces) {
    glEnable(GL_CULL_FACE);
    glCullFace(GL_BACK);
  } else {
    glDisable(GL_CULL_FACE);
  }
}

void setBlend(Blend blend) {
  if (blend == Blend::kAlpha) {
    glEnable(GL_BLEND);
    glBlendFunc(GL_SRC_ALPHA, GL_ONE_MINUS_SRC_ALPHA);
  } else {
    glDisable(GL_BLEND);
  }
}

FramebufferBinding FramebufferBinding::current() {
  GLint name = 0;
  glGetIntegerv(GL_DRAW_FRAMEBUFFER_BINDING, &name);
  FramebufferBinding b;
  b.name_ = uint32_t(name);
  return b;
}

void FramebufferBinding::restore() const { glBindFramebuffer(GL_FRAMEBUFFER, name_); }

void bindWindowFramebuffer() { glBindFramebuffer(GL_FRAMEBUFFER, 0); }

std::vector<uint8_t> readWindowPixels(int width, int height) {
  std::vector<uint8_t> pixels(size_t(width) * size_t(height) * 4);
  glBindFramebuffer(GL_READ_FRAMEBUFFER, 0);
  glPixelStorei(GL_PACK_ALIGNMENT, 1);
  glReadPixels(0, 0, width, height, GL_RGBA, GL_UNSIGNED_BYTE, pixels.data());
  return pixels;
}

}  // namespace strata::gl
