#pragma once
// Private to the terrain renderers: the per-frame GL state and the uniforms every terrain
// shader shares (render/shaders/terrain_common.glsl).

#include <strata/gl/state.hpp>
#include <strata/render/terrain_renderer.hpp>

namespace strata::render::detail {

/// Binds the target and sets the reversed-Z state; on destruction resolves a multisampled
/// target and restores the previous framebuffer and the default depth convention so other GL
/// users are not surprised.
class FrameState {
 public:
  FrameState(const OffscreenTarget& target, const glm::vec4& sky);
  ~FrameState();
  FrameState(const FrameState&) = delete;
  FrameState& operator=(const FrameState&) = delete;

 private:
  gl::FramebufferBinding previous_;
  const OffscreenTarget& target_;
};

/// Sets terrain_common.glsl's and terrain.frag's uniforms and binds the scene's textures; a
/// streamed scene is first moved to the frame's viewer and refilled within its budget.
Status setCommonUniforms(const gl::Program& p, const TerrainScene& scene, const FrameGeometry& frame,
                         const Shading& shading, const glm::dmat4& viewProj);

/// The sky pass (render/shaders/sky.vert, sky.frag): compiled once per renderer.
Result<gl::Program> createSkyProgram();

/// Draws the sky of shading.atmosphere over the whole bound target, before the terrain (colour,
/// and NaN elevation; depth untouched); nothing when there is no atmosphere. `vao` is any
/// vertex array (the pass pulls no attributes).
void drawSky(const gl::Program& sky, const gl::VertexArray& vao, const TerrainScene& scene, const FrameGeometry& frame,
             const Shading& shading, const glm::dmat4& viewProj);

}  // namespace strata::render::detail
