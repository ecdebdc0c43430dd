// The runtime shader loader: embedded copies, or STRATA_SHADER_DIR for live editing.
#include <strata/gl/shader_source.hpp>

#include <cstdlib>

#include "embedded_shaders.hpp"

namespace strata::gl {

Result<ShaderSource> loadShader(const std::string& name) {
  if (const char* dir = std::getenv("STRATA_SHADER_DIR"); dir && *dir) {
    return preprocessShader(name, directoryReader(dir));
  }
  for (size_t i = 0; i < detail::kEmbeddedShaderCount; ++i) {
    const auto& s = detail::kEmbeddedShaders[i];
    if (name == s.name) {
      ShaderSource out{s.name, s.text, {}};
      for (int f = 0; f < s.fileCount; ++f) out.files.emplace_back(s.files[f]);
      return out;
    }
  }
  return fail("shader '" + name + "' is not embedded in this binary (is it under a <library>/shaders folder?)");
}

std::vector<std::string> embeddedShaderNames() {
  std::vector<std::string> names;
  for (size_t i = 0; i < detail::kEmbeddedShaderCount; ++i) names.emplace_back(detail::kEmbeddedShaders[i].name);
  return names;
}

}  // namespace strata::gl
