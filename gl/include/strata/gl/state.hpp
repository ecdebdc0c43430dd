#pragma once
// GL state that belongs to no object, as small named operations: memory barriers, the
// rasteriser's depth, blend and cull state, the viewport, framebuffer bindings and reads of the
// window's framebuffer. Each acts on the current context. No GL header (docs/architecture.md).

#include <cstdint>
#include <vector>

namespace strata::gl {

/// What a glMemoryBarrier makes visible: the kind of access that follows shader writes.
enum class Barrier : uint32_t {
  kStorage = 1u << 0,        ///< shader-storage buffer reads and writes
  kBufferUpdate = 1u << 1,   ///< Buffer::download, read, copyTo, upload
  kTextureUpdate = 1u << 2,  ///< Texture::download, read, upload, copyTexels
  kTextureFetch = 1u << 3,   ///< sampling a texture in a shader
  kImageAccess = 1u << 4,    ///< image loads and stores
  kPixelBuffer = 1u << 5,    ///< Texture::uploadFrom (a buffer as pixel source)
  kUniform = 1u << 6,        ///< uniform blocks
  kVertexAttrib = 1u << 7,   ///< vertex and index buffers
  kCommand = 1u << 8,        ///< indirect dispatch arguments (Program::dispatchIndirect)
};
constexpr Barrier operator|(Barrier a, Barrier b) { return Barrier(uint32_t(a) | uint32_t(b)); }
void memoryBarrier(Barrier barrier);

/// Waits until every command issued so far has finished (glFinish): for timing only.
void finish();

/// A viewport rectangle in pixels.
struct Viewport {
  int x = 0, y = 0, width = 0, height = 0;
};
Viewport viewport();
void setViewport(const Viewport& v);

/// Depth test: off, or passing fragments nearer by the given convention.
enum class DepthTest { kOff, kLess, kGreater };
/// Sets the depth test and whether depth is written (writes need the test on).
void setDepthTest(DepthTest test, bool write = true);
/// The clip-space depth range: GL's default [-1, 1], or [0, 1] (reversed-Z with a float depth).
enum class ClipDepth { kMinusOneToOne, kZeroToOne };
void setClipDepth(ClipDepth range);
/// Back-face culling on or off.
void setCulling(bool cullBackFaces);
/// Colour blending: off, or source-alpha over what is there.
enum class Blend { kOff, kAlpha };
void setBlend(Blend blend);

/// The draw framebuffer bound when it was taken, to bind again later (e.g. a renderer that
/// draws into its own target restores the caller's binding).
class FramebufferBinding {
 public:
  static FramebufferBinding current();
  void restore() const;

 private:
  uint32_t name_ = 0;
};

/// Binds the window's framebuffer (a WindowContext's; a HeadlessContext has none: use
/// HeadlessContext::bindDefaultFramebuffer).
void bindWindowFramebuffer();
/// Reads the w x h pixels at (0, 0) of the window's framebuffer as RGBA8, bottom row first.
std::vector<uint8_t> readWindowPixels(int width, int height);

}  // namespace strata::gl
