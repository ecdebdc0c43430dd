#include <strata/render/sliding_grid.hpp>

#include <strata/render/shader_slots.hpp>

#include <algorithm>
#include <cmath>
#include <map>
#include <utility>

#include "frame_state.hpp"

namespace strata::render {

size_t SlidingGridMesh::triangleCount(const SlidingGridParams& p) {
  const size_t m = size_t(p.halfCells), rings = size_t(p.levels - 1);
  // Level 0: (2M)^2 cells; each further level: (2M)^2 - M^2 cells; two triangles a cell; one
  // triangle lost per folded vertex (4M odd vertices on each inner level's outer boundary).
  return 2 * 4 * m * m + rings * (6 * m * m - 4 * m);
}

SlidingGridMesh SlidingGridMesh::build(const SlidingGridParams& params) {
  const int m = params.halfCells, levels = params.levels;
  STRATA_CHECK(m >= 4 && m % 2 == 0 && levels >= 1 && levels <= 16)
      << "sliding grid: halfCells " << m << " (even, >= 4), levels " << levels << " (1..16)";
  SlidingGridMesh mesh;
  std::map<std::pair<int, int>, uint32_t> index;
  // An odd vertex on the outer boundary of level l (< L-1) lies mid-edge of a level l+1 cell:
  // fold it onto its even neighbour (towards -x or -y) so that both levels share the boundary.
  auto fold = [&](int x, int y, int l) {
    if (l < levels - 1) {
      const int b = m << l, d = 1 << l;
      if (std::abs(x) == b && ((y >> l) & 1)) {
        y -= d;
      } else if (std::abs(y) == b && ((x >> l) & 1)) {
        x -= d;
      }
    }
    return std::pair<int, int>(x, y);
  };
  auto vertex = [&](int x, int y, int l) {
    const auto key = fold(x, y, l);
    auto [it, added] = index.try_emplace(key, uint32_t(mesh.vertices.size()));
    if (added) {
      mesh.vertices.emplace_back(float(key.first), float(key.second), float(l));
    } else {
      auto& v = mesh.vertices[it->second];
      v.z = std::max(v.z, float(l));  // shared with the coarser level: sample as it does
    }
    return it->second;
  };
  for (int l = 0; l < levels; ++l) {
    const int d = 1 << l, outer = m * d, inner = l == 0 ? 0 : m * d / 2;
    for (int cy = -outer; cy < outer; cy += d) {
      for (int cx = -outer; cx < outer; cx += d) {
        if (l > 0 && cx >= -inner && cx + d <= inner && cy >= -inner && cy + d <= inner) continue;
        const uint32_t a = vertex(cx, cy, l), b = vertex(cx + d, cy, l), c = vertex(cx + d, cy + d, l),
                       e = vertex(cx, cy + d, l);
        for (const auto& t : {glm::uvec3(a, b, c), glm::uvec3(a, c, e)}) {
          if (t.x == t.y || t.y == t.z || t.x == t.z) continue;
          mesh.triangles.insert(mesh.triangles.end(), {t.x, t.y, t.z});
        }
      }
    }
  }
  STRATA_CHECK(mesh.triangles.size() == 3 * triangleCount(params))
      << "sliding grid has " << mesh.triangles.size() / 3 << " triangles";
  return mesh;
}

Result<std::unique_ptr<SlidingGridRenderer>> SlidingGridRenderer::create(const SlidingGridParams& params) {
  if (params.halfCells < 4 || params.halfCells % 2 != 0 || params.halfCells > 4096) {
    return fail("render: sliding grid halfCells " + std::to_string(params.halfCells) + " must be even, 4..4096");
  }
  if (params.levels < 1 || params.levels > 16) {
    return fail("render: sliding grid levels " + std::to_string(params.levels) + " out of range 1..16");
  }
  STRATA_TRY(auto program, gl::Program::graphics("render/shaders/sliding.vert", "render/shaders/terrain.frag",
                                                 gl::definesFor(slots::kAll)));
  auto r = std::make_unique<SlidingGridRenderer>();
  r->params_ = params;
  r->program_ = std::move(program);
  STRATA_TRY(r->sky_, detail::createSkyProgram());
  const auto mesh = SlidingGridMesh::build(params);
  r->vertices_ = gl::Buffer::from(std::span<const glm::vec3>(mesh.vertices), gl::BufferStorage::kImmutable);
  r->indices_ = gl::Buffer::from(std::span<const uint32_t>(mesh.triangles), gl::BufferStorage::kImmutable);
  r->indexCount_ = int(mesh.triangles.size());
  r->vao_ = gl::VertexArray::forMesh(r->vertices_, 3, r->indices_);
  return r;
}

Status SlidingGridRenderer::draw(const TerrainScene& scene, const CameraPose& camera, const Shading& shading,
                                 const OffscreenTarget& target, const glm::dmat4* observer) {
  if (scene.planetary()) return fail("render: the sliding grid renderer draws planar scenes only");
  const FrameGeometry frame = frameGeometry(scene, camera, shading, target.width(), target.height());
  // The viewer in lattice coordinates (lattice point t is the centre of texel t), and the
  // grid's origin snapped to the coarsest level's cells.
  const glm::dvec2 size(scene.width(), scene.height());
  const glm::dvec2 tCam = frame.uvCam * size - 0.5;
  const double step = double(1 << (params_.levels - 1));
  const glm::dvec2 origin = glm::round(tCam / step) * step;
  detail::FrameState state(target, shading.sky);
  detail::drawSky(sky_, vao_, scene, frame, shading, observer ? *observer : frame.viewProj());
  STRATA_TRY_STATUS(
      detail::setCommonUniforms(program_, scene, frame, shading, observer ? *observer : frame.viewProj()));
  program_.set("uOriginFromViewer", glm::vec2(origin - tCam));
  program_.use();
  vao_.drawElements(gl::Primitive::kTriangles, indexCount_);
  return {};
}

}  // namespace strata::render
