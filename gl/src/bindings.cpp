#include <strata/gl/bindings.hpp>

namespace strata::gl {

const char* resourceKindName(ResourceKind kind) {
  switch (kind) {
    case ResourceKind::kStorageBuffer: return "storage block";
    case ResourceKind::kUniformBuffer: return "uniform block";
    case ResourceKind::kSampler: return "sampler";
    case ResourceKind::kImage: return "image";
  }
  return "resource";
}

std::vector<ShaderDefine> definesFor(std::span<const Binding> bindings) {
  std::vector<ShaderDefine> out;
  out.reserve(bindings.size());
  for (const auto& b : bindings) out.push_back({std::string(b.define), b.unit});
  return out;
}

}  // namespace strata::gl
