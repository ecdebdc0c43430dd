#pragma once
// C++ mirrors of the structs that GLSL reads from buffers (std430). Each is declared once here
// and once in a GLSL include under tests/gl/shaders and sim/shaders; the static_asserts pin the offsets, and
// tests/render checks the GLSL side against them (parsed on the CPU and read back on the GPU).

#include <cstddef>
#include <cstdint>

#include <glm/glm.hpp>

namespace strata::test {

/// tests/gl/shaders/grid.glsl: GridParams.
struct GridParams {
  glm::ivec2 size{0};
  glm::vec2 cellSizeM{1.0f};
  float datumM = 0;
  float noData = -32768.0f;
  uint32_t flags = 0;
  uint32_t pad0 = 0;
  glm::vec4 sun{0, 0, 1, 1};
};
static_assert(sizeof(GridParams) == 48);
static_assert(offsetof(GridParams, size) == 0);
static_assert(offsetof(GridParams, cellSizeM) == 8);
static_assert(offsetof(GridParams, datumM) == 16);
static_assert(offsetof(GridParams, noData) == 20);
static_assert(offsetof(GridParams, flags) == 24);
static_assert(offsetof(GridParams, sun) == 32);

}  // namespace strata::test
