#pragma once
// The concentric-ring mesh: a fixed disc of n circles around the viewer, built once on the CPU
// and displaced in the vertex shader (docs/render-rings.md). Vertices are polar: (normalised
// radius i/n, angle). Circle 0 is the centre vertex, circle i has 6i vertices, so n circles hold
// 3n(n+1)+1 vertices. The index array is ONE triangle strip: each annulus is cut into six
// sectors, each sector is a strip, and the strips are joined by degenerate triangles, with the
// joins padded so that every real triangle is counter-clockwise seen from +z.

#include <cstddef>
#include <cstdint>
#include <vector>

#include <glm/glm.hpp>

namespace strata::render {

struct RingMesh {
  int circles = 0;                  ///< n: circles around the centre vertex
  std::vector<glm::vec2> vertices;  ///< (normalised radius in [0, 1], angle in radians from +x towards +y)
  std::vector<uint32_t> strip;      ///< one GL_TRIANGLE_STRIP with degenerate joins

  /// Builds the mesh of `circles` >= 1 circles.
  static RingMesh build(int circles);
  /// 3n(n+1)+1 vertices.
  static size_t vertexCount(int circles);
  /// 6n^2 + 30n - 2 strip indices (sector strips of 2i+1, three-index joins, one leading pad).
  static size_t stripIndexCount(int circles);
  /// 6n^2 non-degenerate triangles.
  static size_t triangleCount(int circles);
  /// Index of vertex k (taken modulo 6i) of circle i.
  static uint32_t vertexIndex(int circle, int k);
};

/// The triangles a GL_TRIANGLE_STRIP yields, with GL's winding rule (odd triangles swapped),
/// degenerate ones (a repeated index) dropped. For tests and the CPU reference.
std::vector<glm::uvec3> stripToTriangles(const std::vector<uint32_t>& strip);

}  // namespace strata::render
