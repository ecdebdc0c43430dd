// The sliding grid's fixed mesh: exact triangle count, a tiling of its square, and no
// T-junction between levels (checked as edge manifoldness, like the ring mesh).
#include <gtest/gtest.h>

#include <cmath>
#include <map>
#include <set>

#include <strata/render/sliding_grid.hpp>

namespace strata::render {
namespace {

class SlidingGridMeshTest : public ::testing::TestWithParam<std::pair<int, int>> {};

TEST_P(SlidingGridMeshTest, TilesItsSquareWithoutTJunctions) {
  const SlidingGridParams p{.halfCells = GetParam().first, .levels = GetParam().second};
  const auto mesh = SlidingGridMesh::build(p);
  ASSERT_EQ(mesh.triangles.size() % 3, 0u);
  const size_t n = mesh.triangles.size() / 3;
  EXPECT_EQ(n, SlidingGridMesh::triangleCount(p));
  const double half = double(p.halfCells) * double(1 << (p.levels - 1));

  // Counter-clockwise, areas summing to the square's: no overlap and no gap (integer
  // coordinates: the sums are exact in double).
  double area = 0;
  std::set<std::pair<uint32_t, uint32_t>> directed;
  std::map<std::pair<uint32_t, uint32_t>, int> undirected;
  for (size_t t = 0; t < n; ++t) {
    const uint32_t v[3] = {mesh.triangles[3 * t], mesh.triangles[3 * t + 1], mesh.triangles[3 * t + 2]};
    const glm::dvec2 a(mesh.vertices[v[0]]), b(mesh.vertices[v[1]]), c(mesh.vertices[v[2]]);
    const double twice = (b.x - a.x) * (c.y - a.y) - (b.y - a.y) * (c.x - a.x);
    ASSERT_GT(twice, 0) << "triangle " << t << " is clockwise or flat";
    area += 0.5 * twice;
    for (int e = 0; e < 3; ++e) {
      const uint32_t x = v[e], y = v[(e + 1) % 3];
      ASSERT_TRUE(directed.insert({x, y}).second) << "directed edge " << x << "->" << y << " used twice";
      ++undirected[{std::min(x, y), std::max(x, y)}];
    }
  }
  EXPECT_EQ(area, 4 * half * half);

  // Every edge inside the square is shared by exactly two triangles: a T-junction (a vertex of
  // the fine level in the middle of a coarse edge) would leave the coarse edge and the two fine
  // half-edges each used once.
  int rim = 0;
  for (const auto& [edge, count] : undirected) {
    const glm::vec3 a = mesh.vertices[edge.first], b = mesh.vertices[edge.second];
    const bool onRim = (std::abs(a.x) == half && a.x == b.x) || (std::abs(a.y) == half && a.y == b.y);
    if (onRim) {
      ++rim;
      EXPECT_EQ(count, 1);
    } else {
      ASSERT_EQ(count, 2) << "edge (" << a.x << "," << a.y << ")-(" << b.x << "," << b.y << ")";
    }
  }
  EXPECT_EQ(rim, 4 * 2 * p.halfCells);  // the coarsest level's 2M cells on each side
  EXPECT_EQ(long(mesh.vertices.size()) - long(undirected.size()) + long(n), 1);

  // Each vertex samples the MIP level of the coarsest level it belongs to: the smallest l with
  // max(|x|, |y|) <= M 2^l, plus one on a level's outer boundary (shared with the next level).
  for (const auto& v : mesh.vertices) {
    const int r = int(std::max(std::abs(v.x), std::abs(v.y)));
    int l = 0;
    while (r > (p.halfCells << l)) ++l;
    const int expected = (r == (p.halfCells << l) && l < p.levels - 1) ? l + 1 : l;
    EXPECT_EQ(int(v.z), expected) << "vertex (" << v.x << "," << v.y << ")";
  }
}

INSTANTIATE_TEST_SUITE_P(Sizes, SlidingGridMeshTest,
                         ::testing::Values(std::pair{4, 1}, std::pair{4, 2}, std::pair{4, 3}, std::pair{8, 4},
                                           std::pair{64, 4}));

}  // namespace
}  // namespace strata::render
