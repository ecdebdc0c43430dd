// The GL tests' C++ mirror of GridParams agrees with the GLSL declarations: the GLSL struct is parsed
// and laid out by the std430 rules, and compared with the C++ offsets field by field.
#include <gtest/gtest.h>

#include "glsl_layout.hpp"
#include "grid_params.hpp"

namespace strata::test {
namespace {

TEST(GpuLayouts, GridParamsMatchesGlsl) {
  size_t size = 0;
  const auto fields = glslLayout(std::string(STRATA_SOURCE_DIR) + "/tests/gl/shaders/grid.glsl", "GridParams", size);
  const std::vector<Field> cpp = {
      {"size", offsetof(GridParams, size)},     {"cellSizeM", offsetof(GridParams, cellSizeM)},
      {"datumM", offsetof(GridParams, datumM)}, {"noData", offsetof(GridParams, noData)},
      {"flags", offsetof(GridParams, flags)},   {"pad0", offsetof(GridParams, pad0)},
      {"sun", offsetof(GridParams, sun)}};
  ASSERT_EQ(fields.size(), cpp.size());
  for (size_t i = 0; i < cpp.size(); ++i) {
    EXPECT_EQ(fields[i].name, cpp[i].name);
    EXPECT_EQ(fields[i].offset, cpp[i].offset) << cpp[i].name;
  }
  EXPECT_EQ(size, sizeof(GridParams));
}

}  // namespace
}  // namespace strata::test
