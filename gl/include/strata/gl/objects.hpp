#pragma once
// Move-only RAII wrappers over GL objects (direct state access, GL 4.5), with Strata's own small
// enums where GL takes an enum: no GL header here or in any other public header, so only
// gl/src calls GL (docs/architecture.md, "The GL layer"). Pipeline state, barriers and draws that
// belong to no object are in state.hpp.

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <span>
#include <string>
#include <utility>
#include <vector>

#include <glm/glm.hpp>

#include <strata/core/result.hpp>
#include <strata/gl/bindings.hpp>
#include <strata/gl/shader_source.hpp>

namespace strata::gl {

/// Owns one GL object name; `Deleter(name)` frees it. The name is for gl/src.
template <void (*Deleter)(uint32_t)>
class Object {
 public:
  Object() = default;
  explicit Object(uint32_t id) : id_(id) {}
  Object(Object&& o) noexcept : id_(std::exchange(o.id_, 0)) {}
  Object& operator=(Object&& o) noexcept {
    if (this != &o) {
      reset();
      id_ = std::exchange(o.id_, 0);
    }
    return *this;
  }
  Object(const Object&) = delete;
  Object& operator=(const Object&) = delete;
  ~Object() { reset(); }

  uint32_t id() const { return id_; }
  explicit operator bool() const { return id_ != 0; }
  void reset() {
    if (id_) Deleter(id_);
    id_ = 0;
  }

 private:
  uint32_t id_ = 0;
};

namespace detail {
void deleteBuffer(uint32_t id);
void deleteTexture(uint32_t id);
void deleteFramebuffer(uint32_t id);
void deleteVertexArray(uint32_t id);
void deleteProgram(uint32_t id);
void deleteShader(uint32_t id);
void deleteQuery(uint32_t id);
}  // namespace detail

/// What this thread's GL calls asked of the driver so far (gl/src counts them). A read makes the
/// host wait for the GPU to finish the commands before it; a query of a program's state waits
/// for a threaded driver's worker (NVIDIA's "threaded optimisation") to catch up: a loop that
/// only feeds the GPU should make neither (sim::GlSolver's step makes one 4-byte read when its
/// time step is adaptive, none when it is fixed; tests/gl and tests/sim count them).
struct CallCounts {
  uint64_t dispatches = 0;     ///< compute dispatches (Program::dispatchCovering, dispatchIndirect)
  uint64_t hostReads = 0;      ///< Buffer::download and Texture::download / downloadRegion
  uint64_t hostReadBytes = 0;  ///< the bytes those read
  uint64_t queries = 0;        ///< program state asked of GL after linking (an uncached uniform location)
};
/// This thread's counts since it started.
const CallCounts& callCounts();

/// Whether a buffer's contents may change after creation through upload().
enum class BufferStorage {
  kDynamic,    ///< upload() allowed (GL_DYNAMIC_STORAGE_BIT)
  kImmutable,  ///< contents given at creation; GPU writes (shaders, fill, copies) still allowed
  kReadback,   ///< read by the host often (download): kept in host memory (GL_CLIENT_STORAGE_BIT)
};

/// A buffer with immutable storage (glNamedBufferStorage).
class Buffer : public Object<detail::deleteBuffer> {
 public:
  Buffer() = default;
  explicit Buffer(size_t bytes, const void* data = nullptr, BufferStorage storage = BufferStorage::kDynamic);
  template <class T>
  static Buffer from(std::span<const T> values, BufferStorage storage = BufferStorage::kDynamic) {
    return Buffer(values.size_bytes(), values.data(), storage);
  }
  size_t size() const { return bytes_; }
  void upload(size_t offset, size_t bytes, const void* data);
  void download(size_t offset, size_t bytes, void* out) const;
  template <class T>
  std::vector<T> read(size_t offset = 0, size_t count = size_t(-1)) const {
    if (count == size_t(-1)) count = (bytes_ - offset) / sizeof(T);
    std::vector<T> out(count);
    download(offset, count * sizeof(T), out.data());
    return out;
  }
  /// Fills with a repeated 32-bit pattern (e.g. 0 or a float's bits).
  void fill(uint32_t pattern);
  /// Copies `bytes` bytes from this buffer at `offset` into `dst` at `dstOffset`, on the GPU.
  void copyTo(const Buffer& dst, size_t bytes, size_t offset = 0, size_t dstOffset = 0) const;
  /// Binds to shader-storage binding point `unit` (a `buffer` block).
  void bindStorage(int unit) const;
  /// Binds to uniform-buffer binding point `unit` (a `uniform` block).
  void bindUniform(int unit) const;
  /// Binds to a declared slot (storage or uniform, as the slot says).
  void bind(const Binding& slot) const;

 private:
  size_t bytes_ = 0;
};

/// Texel formats Strata uses (internal format plus the matching transfer format and type).
enum class TextureFormat {
  kR32F,      ///< one float
  kRG32F,     ///< two floats
  kRGBA32F,   ///< four floats
  kR32UI,     ///< one uint32 (sample with usampler, nearest filtering)
  kRGBA8,     ///< four unsigned normalised bytes
  kDepth32F,  ///< float depth
};
int bytesPerTexel(TextureFormat format);

/// Texture filtering. kLinear is trilinear on a texture with a mip chain.
enum class Filter { kNearest, kLinear };
/// Addressing outside [0, 1].
enum class Wrap { kClampToEdge, kRepeat };
/// How a compute shader uses an image.
enum class Access { kRead, kWrite, kReadWrite };

/// A 2D texture or 2D array texture with immutable storage. Linear filtering and
/// clamp-to-edge addressing at creation.
class Texture : public Object<detail::deleteTexture> {
 public:
  Texture() = default;
  /// levels = 0: the full mip chain.
  static Texture create2D(TextureFormat format, int width, int height, int levels = 1);
  static Texture create2DArray(TextureFormat format, int width, int height, int layers, int levels = 1);
  /// A multisampled 2D texture (`samples` per texel, fixed sample locations): a render target
  /// to resolve into a plain texture (Framebuffer::resolveTo), not sampled or read directly.
  static Texture create2DMultisample(TextureFormat format, int width, int height, int samples);

  int width() const { return width_; }
  int height() const { return height_; }
  int layers() const { return layers_; }
  int levels() const { return levels_; }
  bool isArray() const { return array_; }
  TextureFormat format() const { return format_; }

  /// Uploads a w x h region at (x,y) of `level` (and `layer` for arrays), tightly packed.
  void upload(const void* data, int level = 0, int x = 0, int y = 0, int w = -1, int h = -1, int layer = 0);
  /// Uploads a w x h region at (x,y) of level 0 from `source` at byte `offset`, tightly packed
  /// texels of this texture's format, on the GPU (a pixel-unpack copy). Writes by shaders to
  /// `source` need memoryBarrier(Barrier::kPixelBuffer) first.
  void uploadFrom(const Buffer& source, size_t offset, int x, int y, int w, int h);
  /// Sets every texel of `level` to zero.
  void clear(int level = 0);
  /// Reads level `level` (all layers) tightly packed.
  void download(void* out, size_t bytes, int level = 0) const;
  template <class T>
  std::vector<T> read(int level = 0) const {
    const int w = std::max(1, width_ >> level), h = std::max(1, height_ >> level);
    std::vector<T> out(size_t(w) * size_t(h) * size_t(layers_) * size_t(bytesPerTexel(format_)) / sizeof(T));
    download(out.data(), out.size() * sizeof(T), level);
    return out;
  }
  /// Reads the w x h region at (x, y) of `level` and `layer` tightly packed.
  void downloadRegion(void* out, size_t bytes, int x, int y, int w, int h, int level = 0, int layer = 0) const;
  template <class T>
  std::vector<T> readRegion(int x, int y, int w, int h, int level = 0, int layer = 0) const {
    std::vector<T> out(size_t(w) * size_t(h) * size_t(bytesPerTexel(format_)) / sizeof(T));
    downloadRegion(out.data(), out.size() * sizeof(T), x, y, w, h, level, layer);
    return out;
  }
  void generateMipmap();
  void setFilter(Filter filter);
  void setWrap(Wrap s, Wrap t);
  void setWrap(Wrap both) { setWrap(both, both); }
  /// Binds to texture unit `unit` (a sampler).
  void bind(int unit) const;
  void bind(const Binding& slot) const;
  /// Binds `level` (all layers of an array) to image unit `unit`.
  void bindImage(int unit, Access access, int level = 0) const;
  void bindImage(const Binding& slot, Access access, int level = 0) const;

 private:
  TextureFormat format_ = TextureFormat::kR32F;
  int width_ = 0, height_ = 0, layers_ = 1, levels_ = 1;
  bool array_ = false;
};

/// A texel position in a texture: mip level, x, y and array layer.
struct TexelAt {
  int level = 0, x = 0, y = 0, layer = 0;
};
/// Copies w x h texels (x `layers` layers) from `src` at `from` to `dst` at `to`, on the GPU;
/// the formats must be compatible (same size per texel). `dst` is written although it is const:
/// as with bindImage, constness is the C++ handle's, not the texels'.
void copyTexels(const Texture& src, TexelAt from, const Texture& dst, TexelAt to, int w, int h, int layers = 1);

/// A framebuffer object. Every colour attachment is drawn to: fragment output `location = i`
/// goes to colour attachment i.
class Framebuffer : public Object<detail::deleteFramebuffer> {
 public:
  static Framebuffer create();
  void attachColour(int index, const Texture& texture, int level = 0);
  void attachDepth(const Texture& texture, int level = 0);
  /// Fails naming the GL status when the framebuffer is incomplete.
  Status check() const;
  void bind() const;
  /// Clears colour attachment `index` (a float or normalised format) to `value`.
  void clearColour(int index, const glm::vec4& value) const;
  void clearDepth(float value) const;
  /// Copies colour attachment `index` (`from` pixels) to the window's framebuffer, scaled to
  /// `to` pixels with `filter`.
  void blitColourToWindow(int index, glm::ivec2 from, glm::ivec2 to, Filter filter) const;
  /// Resolves this (multisampled) framebuffer into `dst` of the same size: each colour
  /// attachment i into dst's attachment i (colours averaged over the samples) and the depth
  /// (one sample).
  void resolveTo(const Framebuffer& dst, glm::ivec2 size) const;

 private:
  uint32_t colourMask_ = 0;  // attached colour attachments
};

/// Primitives of a draw call.
enum class Primitive { kPoints, kLines, kTriangles, kTriangleStrip };

class VertexArray : public Object<detail::deleteVertexArray> {
 public:
  static VertexArray create();
  /// A mesh: attribute 0 = `floatsPerVertex` tightly packed floats from `vertices`, indexed by
  /// the uint32 `indices`. The buffers must outlive the vertex array.
  static VertexArray forMesh(const Buffer& vertices, int floatsPerVertex, const Buffer& indices);
  /// Sets the uint32 index buffer; it must outlive the vertex array.
  void setIndices(const Buffer& indices);
  void bind() const;
  /// Draws `count` vertices from `first` with the program in use (no index buffer needed).
  void drawArrays(Primitive primitive, int first, int count) const;
  /// Draws `count` uint32 indices of the index buffer with the program in use.
  void drawElements(Primitive primitive, int count) const;
};

/// Shader stages.
enum class ShaderStage { kVertex, kFragment, kGeometry, kCompute };

/// A linked program. Created from shaders under <library>/shaders/ (embedded, or STRATA_SHADER_DIR)
/// or from sources; compile errors name the real file:line. `defines` are inserted after each
/// stage's #version line (insertDefines): a library's binding slots reach GLSL this way.
class Program : public Object<detail::deleteProgram> {
 public:
  Program() = default;
  static Result<Program> compute(const std::string& name, std::span<const ShaderDefine> defines = {});
  static Result<Program> graphics(const std::string& vertexName, const std::string& fragmentName,
                                  std::span<const ShaderDefine> defines = {});
  /// From already-preprocessed sources (stage, source) pairs; `label` names it in errors.
  struct Stage {
    ShaderStage stage;
    std::string text;
    std::vector<std::string> files;
  };
  static Result<Program> link(const std::vector<Stage>& stages, const std::string& label,
                              std::span<const ShaderDefine> defines = {});

  void use() const;
  int location(const char* name) const;
  void set(const char* name, float v) const;
  void set(const char* name, int v) const;
  void set(const char* name, unsigned v) const;
  void set(const char* name, glm::vec2 v) const;
  void set(const char* name, glm::vec3 v) const;
  void set(const char* name, glm::vec4 v) const;
  void set(const char* name, glm::ivec2 v) const;
  void set(const char* name, const glm::mat3& v) const;
  void set(const char* name, const glm::mat4& v) const;
  /// The local work-group size declared in a compute shader.
  glm::ivec3 workGroupSize() const;
  /// Dispatches enough groups to cover (x, y, z) invocations (compute programs).
  void dispatchCovering(int x, int y = 1, int z = 1) const;
  /// Dispatches the group counts (3 uint32) that `args` holds at `offset` (a multiple of 4),
  /// written there on the GPU (a compute shader before it, then Barrier::kCommand): 0 groups
  /// run nothing.
  void dispatchIndirect(const Buffer& args, size_t offset) const;
  /// The active buffer blocks, samplers and images with their bindings (program interface
  /// query), in GL's order.
  std::vector<ProgramResource> resources() const;

 private:
  // Asked of GL once, at link, so that dispatches and uniform updates query nothing: the
  // work-group size (compute programs) and the active uniforms' locations by name (an array's
  // as "a" and "a[0]"; a name not among them is asked of GL once and remembered).
  glm::ivec3 groupSize_{1, 1, 1};
  mutable std::vector<std::pair<std::string, int>> locations_;
};

/// Checks a linked program against a library's binding table: every active block, sampler and
/// image must be declared (same kind, same GLSL name) and bound where the table says. Fails
/// naming `label`, the resource and both bindings.
Status checkBindings(const Program& program, std::span<const Binding> bindings, const std::string& label);

/// GPU time of a span of commands (a GL_TIME_ELAPSED query). Results are read without stalling
/// when available; `milliseconds()` waits.
class GpuTimer {
 public:
  GpuTimer();
  void begin();
  void end();
  bool ready() const;
  double milliseconds() const;

 private:
  Object<detail::deleteQuery> query_;
  bool pending_ = false;
};

}  // namespace strata::gl
