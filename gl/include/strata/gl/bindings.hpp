#pragma once
// Shader binding slots declared once in C++. A library lists its slots in one table of
// `Binding`s; its programs are compiled with the table as #defines (`definesFor`), so GLSL writes
// `layout(binding = SLOT_HEIGHT)` and never a number, and a GPU test compares each linked
// program's blocks, samplers and images (Program::resources) with the table (checkBindings).
// No GL here.

#include <span>
#include <string>
#include <string_view>
#include <vector>

#include <strata/gl/shader_source.hpp>

namespace strata::gl {

/// What sits on a binding point.
enum class ResourceKind {
  kStorageBuffer,  ///< `buffer` block (std430), Buffer::bindStorage
  kUniformBuffer,  ///< `uniform` block (std140), Buffer::bindUniform
  kSampler,        ///< sampler uniform, Texture::bind
  kImage,          ///< image uniform, Texture::bindImage
};

const char* resourceKindName(ResourceKind kind);

/// One binding slot of a library's shaders.
struct Binding {
  std::string_view define;    ///< the name GLSL uses: layout(binding = SLOT_HEIGHT)
  ResourceKind kind;          ///< what C++ binds there
  int unit;                   ///< the binding point
  std::string_view resource;  ///< the GLSL block or uniform name on it (uHeight), for checkBindings
};

/// The table as #defines for Program::compute / graphics / link.
std::vector<ShaderDefine> definesFor(std::span<const Binding> bindings);

/// A buffer block, sampler or image of a linked program and the binding it got.
struct ProgramResource {
  std::string name;
  ResourceKind kind;
  int binding;
};

}  // namespace strata::gl
