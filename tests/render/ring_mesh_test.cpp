// The ring mesh's topology, checked exhaustively on the CPU for several sizes.
#include <gtest/gtest.h>

#include <cmath>
#include <map>
#include <numbers>
#include <set>

#include <strata/render/ring_mesh.hpp>

namespace strata::render {
namespace {

glm::dvec2 cartesian(const glm::vec2& polar) {
  return {double(polar.x) * std::cos(double(polar.y)), double(polar.x) * std::sin(double(polar.y))};
}

double signedArea(const RingMesh& m, const glm::uvec3& t) {
  const glm::dvec2 a = cartesian(m.vertices[t.x]), b = cartesian(m.vertices[t.y]), c = cartesian(m.vertices[t.z]);
  return 0.5 * ((b.x - a.x) * (c.y - a.y) - (b.y - a.y) * (c.x - a.x));
}

class RingMeshTest : public ::testing::TestWithParam<int> {};

TEST_P(RingMeshTest, VerticesArePolarCirclesOfSixI) {
  const int n = GetParam();
  const auto mesh = RingMesh::build(n);
  ASSERT_EQ(mesh.vertices.size(), size_t(3 * n * (n + 1) + 1));
  EXPECT_EQ(mesh.vertices[0], glm::vec2(0, 0));
  for (int i = 1; i <= n; ++i) {
    for (int k = 0; k < 6 * i; ++k) {
      const auto v = mesh.vertices[RingMesh::vertexIndex(i, k)];
      EXPECT_FLOAT_EQ(v.x, float(i) / float(n));
      EXPECT_FLOAT_EQ(v.y, float(2 * std::numbers::pi * k / (6.0 * i)));
    }
  }
}

TEST_P(RingMeshTest, StripHasClosedFormCountAndSixNSquaredTriangles) {
  const int n = GetParam();
  const auto mesh = RingMesh::build(n);
  EXPECT_EQ(mesh.strip.size(), size_t(6 * n * n + 30 * n - 2));
  for (uint32_t idx : mesh.strip) ASSERT_LT(idx, mesh.vertices.size());
  const auto tris = stripToTriangles(mesh.strip);
  EXPECT_EQ(tris.size(), size_t(6 * n * n));
  EXPECT_EQ(tris.size(), RingMesh::triangleCount(n));
}

TEST_P(RingMeshTest, EveryTriangleIsCounterClockwiseAndTheyTileTheDisc) {
  const int n = GetParam();
  const auto mesh = RingMesh::build(n);
  const auto tris = stripToTriangles(mesh.strip);
  double area = 0;
  for (const auto& t : tris) {
    const double a = signedArea(mesh, t);
    ASSERT_GT(a, 0) << "triangle " << t.x << " " << t.y << " " << t.z << " is clockwise or flat";
    area += a;
  }
  // All triangles positive and summing to the outer 6n-gon's area: no overlap and no gap.
  // 1e-9 relative: double rounding over at most 6*64^2 triangles.
  const double polygon = 0.5 * 6 * n * std::sin(2 * std::numbers::pi / (6.0 * n));
  EXPECT_NEAR(area, polygon, 1e-9 * polygon);
}

TEST_P(RingMeshTest, EdgesAreManifoldWithConsistentOrientation) {
  // No crack or T-junction in the index topology: every directed edge occurs once, every edge
  // inside the disc is shared by exactly two triangles (in opposite directions), the edges on
  // circle n by one, and V - E + F = 1 (a disc).
  const int n = GetParam();
  const auto mesh = RingMesh::build(n);
  const auto tris = stripToTriangles(mesh.strip);
  std::set<std::pair<uint32_t, uint32_t>> directed;
  std::map<std::pair<uint32_t, uint32_t>, int> undirected;
  for (const auto& t : tris) {
    const uint32_t v[3] = {t.x, t.y, t.z};
    for (int e = 0; e < 3; ++e) {
      const uint32_t a = v[e], b = v[(e + 1) % 3];
      ASSERT_TRUE(directed.insert({a, b}).second) << "directed edge " << a << "->" << b << " used twice";
      ++undirected[{std::min(a, b), std::max(a, b)}];
    }
  }
  const uint32_t firstOuter = RingMesh::vertexIndex(n, 0);
  int boundary = 0;
  for (const auto& [edge, count] : undirected) {
    const bool onRim = edge.first >= firstOuter && edge.second >= firstOuter;
    if (onRim && count == 1) {
      ++boundary;
    } else {
      ASSERT_EQ(count, 2) << "edge " << edge.first << "-" << edge.second;
    }
  }
  EXPECT_EQ(boundary, 6 * n);
  const long vertices = long(mesh.vertices.size()), edges = long(undirected.size()), faces = long(tris.size());
  EXPECT_EQ(vertices - edges + faces, 1);
  // Every vertex is used.
  std::set<uint32_t> used(mesh.strip.begin(), mesh.strip.end());
  EXPECT_EQ(used.size(), mesh.vertices.size());
}

INSTANTIATE_TEST_SUITE_P(Sizes, RingMeshTest, ::testing::Values(1, 2, 3, 7, 16, 64));

}  // namespace
}  // namespace strata::render
