#pragma once
// The table written at build time by strata_shader_embed (see cmake/StrataShaders.cmake).
#include <cstddef>

namespace strata::gl::detail {

struct EmbeddedShader {
  const char* name;
  const char* text;
  const char* const* files;
  int fileCount;
};

extern const EmbeddedShader kEmbeddedShaders[];
extern const std::size_t kEmbeddedShaderCount;

}  // namespace strata::gl::detail
