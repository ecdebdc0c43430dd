#pragma once
// The "sliding sampling grid": a fixed index grid of nested square levels (a restricted quadtree:
// level l has cells of 2^l texels, neighbouring cells differ by one level at most), built once and
// slid under the viewer in steps of the coarsest cells, so that every vertex always samples the
// same lattice of texels. Between levels, the fine level's odd boundary vertices are folded onto
// their even neighbours, so the two levels share every boundary vertex: no T-junction, no crack.
// For comparison with the ring renderer (docs/render-rings.md).

#include <cstddef>
#include <cstdint>
#include <memory>
#include <vector>

#include <glm/glm.hpp>

#include <strata/render/terrain_renderer.hpp>

namespace strata::render {

struct SlidingGridParams {
  int halfCells = 64;  ///< M: level 0 spans [-M, M]^2 texels; level l spans [-M 2^l, M 2^l]^2 (M even, >= 4)
  int levels = 4;      ///< L nested levels
};

struct SlidingGridMesh {
  std::vector<glm::vec3> vertices;  ///< (x, y) lattice position in level-0 texels, z = MIP level to sample
  std::vector<uint32_t> triangles;  ///< GL_TRIANGLES, counter-clockwise seen from +z
  /// Builds the mesh; `params` must have an even halfCells >= 4 and 1..16 levels.
  static SlidingGridMesh build(const SlidingGridParams& params);
  /// 2 (2M)^2 + (L - 1) 2 ((2M)^2 - M^2) minus two per folded boundary pair: the exact count.
  static size_t triangleCount(const SlidingGridParams& params);
};

/// Draws a SlidingGridMesh slid under the viewer (planar scenes).
class SlidingGridRenderer final : public TerrainRenderer {
 public:
  static Result<std::unique_ptr<SlidingGridRenderer>> create(const SlidingGridParams& params = {});
  std::string name() const override { return "sliding-grid"; }
  Status draw(const TerrainScene& scene, const CameraPose& camera, const Shading& shading,
              const OffscreenTarget& target, const glm::dmat4* observer = nullptr) override;
  size_t trianglesPerFrame(const TerrainScene&) const override { return size_t(indexCount_) / 3; }

 private:
  SlidingGridParams params_;
  gl::Program program_, sky_;
  gl::VertexArray vao_;
  gl::Buffer vertices_, indices_;
  int indexCount_ = 0;
};

}  // namespace strata::render
