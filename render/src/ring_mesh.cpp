#include <strata/render/ring_mesh.hpp>

#include <numbers>

#include <strata/core/check.hpp>

namespace strata::render {

size_t RingMesh::vertexCount(int circles) { return 3 * size_t(circles) * size_t(circles + 1) + 1; }

size_t RingMesh::stripIndexCount(int circles) {
  const size_t n = size_t(circles);
  return 6 * n * n + 30 * n - 2;
}

size_t RingMesh::triangleCount(int circles) { return 6 * size_t(circles) * size_t(circles); }

uint32_t RingMesh::vertexIndex(int circle, int k) {
  if (circle == 0) return 0;
  const int count = 6 * circle;
  k = ((k % count) + count) % count;
  return uint32_t(1 + 3 * circle * (circle - 1) + k);
}

RingMesh RingMesh::build(int circles) {
  STRATA_CHECK(circles >= 1) << "ring mesh needs at least one circle, got " << circles;
  RingMesh mesh;
  mesh.circles = circles;
  mesh.vertices.reserve(vertexCount(circles));
  mesh.vertices.emplace_back(0.0f, 0.0f);
  for (int i = 1; i <= circles; ++i) {
    const float radius = float(i) / float(circles);
    for (int k = 0; k < 6 * i; ++k) {
      mesh.vertices.emplace_back(radius, float(2.0 * std::numbers::pi * k / (6.0 * i)));
    }
  }

  // Sector s of annulus i (between circles i-1 and i) has i+1 outer and i inner vertices; the
  // strip o0 i0 o1 i1 ... o(i-1) i(i-1) oi gives its 2i-1 triangles. A triangle that starts at an
  // odd strip position is (i0, o0, o1) after GL's swap, which is counter-clockwise: every sector
  // therefore starts at an odd position. Sector lengths are odd, so each join is the previous
  // sector's last index, the next sector's first index twice (3 indices, all degenerate).
  auto& strip = mesh.strip;
  strip.reserve(stripIndexCount(circles));
  for (int i = 1; i <= circles; ++i) {
    for (int s = 0; s < 6; ++s) {
      const uint32_t first = vertexIndex(i, s * i);
      if (strip.empty()) {
        strip.push_back(first);
      } else {
        const uint32_t last = strip.back();
        strip.push_back(last);
        strip.push_back(first);
        strip.push_back(first);
      }
      STRATA_CHECK(strip.size() % 2 == 1) << "ring strip parity";
      for (int j = 0; j < i; ++j) {
        strip.push_back(vertexIndex(i, s * i + j));
        strip.push_back(vertexIndex(i - 1, s * (i - 1) + j));
      }
      strip.push_back(vertexIndex(i, s * i + i));
    }
  }
  STRATA_CHECK(strip.size() == stripIndexCount(circles)) << "ring strip has " << strip.size() << " indices";
  return mesh;
}

std::vector<glm::uvec3> stripToTriangles(const std::vector<uint32_t>& strip) {
  std::vector<glm::uvec3> tris;
  for (size_t t = 0; t + 2 < strip.size(); ++t) {
    glm::uvec3 tri = (t % 2 == 0) ? glm::uvec3(strip[t], strip[t + 1], strip[t + 2])
                                  : glm::uvec3(strip[t + 1], strip[t], strip[t + 2]);
    if (tri.x == tri.y || tri.y == tri.z || tri.x == tri.z) continue;
    tris.push_back(tri);
  }
  return tris;
}

}  // namespace strata::render
