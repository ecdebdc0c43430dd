#pragma once
// Move-only RAII wrappers over GL objects (direct state access, GL 4.5). The raw names are
// for code inside strata_render only; nothing outside render/ sees a GL header.

#include <epoxy/gl.h>

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <span>
#include <string>
#include <utility>
#include <vector>

#include <glm/glm.hpp>

#include <strata/core/result.hpp>

namespace strata::render::gl {

/// Owns one GL name; `Deleter(GLuint)` frees it.
template <void (*Deleter)(GLuint)>
class Object {
 public:
  Object() = default;
  explicit Object(GLuint id) : id_(id) {}
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

  GLuint id() const { return id_; }
  explicit operator bool() const { return id_ != 0; }
  void reset() {
    if (id_) Deleter(id_);
    id_ = 0;
  }

 private:
  GLuint id_ = 0;
};

namespace detail {
void deleteBuffer(GLuint id);
void deleteTexture(GLuint id);
void deleteFramebuffer(GLuint id);
void deleteRenderbuffer(GLuint id);
void deleteVertexArray(GLuint id);
void deleteProgram(GLuint id);
void deleteShader(GLuint id);
void deleteQuery(GLuint id);
}  // namespace detail

/// A buffer with immutable storage (glNamedBufferStorage).
class Buffer : public Object<detail::deleteBuffer> {
 public:
  Buffer() = default;
  /// `flags`: GL_DYNAMIC_STORAGE_BIT (default) so upload() works; add map bits as needed.
  Buffer(size_t bytes, const void* data = nullptr, GLbitfield flags = GL_DYNAMIC_STORAGE_BIT);
  template <class T>
  static Buffer from(std::span<const T> values, GLbitfield flags = GL_DYNAMIC_STORAGE_BIT) {
    return Buffer(values.size_bytes(), values.data(), flags);
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
  /// Binds to an indexed target (GL_SHADER_STORAGE_BUFFER, GL_UNIFORM_BUFFER).
  void bindBase(GLenum target, GLuint index) const;

 private:
  size_t bytes_ = 0;
};

/// Texel format: internal format plus the matching external format/type for transfers.
struct TextureFormat {
  GLenum internal;  ///< e.g. GL_R32F
  GLenum format;    ///< e.g. GL_RED
  GLenum type;      ///< e.g. GL_FLOAT
  int bytesPerTexel;
};
inline constexpr TextureFormat kR32F{GL_R32F, GL_RED, GL_FLOAT, 4};
inline constexpr TextureFormat kRG32F{GL_RG32F, GL_RG, GL_FLOAT, 8};
inline constexpr TextureFormat kRGBA32F{GL_RGBA32F, GL_RGBA, GL_FLOAT, 16};
inline constexpr TextureFormat kR32UI{GL_R32UI, GL_RED_INTEGER, GL_UNSIGNED_INT, 4};
inline constexpr TextureFormat kRGBA8{GL_RGBA8, GL_RGBA, GL_UNSIGNED_BYTE, 4};
inline constexpr TextureFormat kDepth32F{GL_DEPTH_COMPONENT32F, GL_DEPTH_COMPONENT, GL_FLOAT, 4};

/// A 2D texture or 2D array texture with immutable storage.
class Texture : public Object<detail::deleteTexture> {
 public:
  Texture() = default;
  /// levels = 0: the full mip chain.
  static Texture create2D(TextureFormat format, int width, int height, int levels = 1);
  static Texture create2DArray(TextureFormat format, int width, int height, int layers, int levels = 1);

  int width() const { return width_; }
  int height() const { return height_; }
  int layers() const { return layers_; }
  int levels() const { return levels_; }
  const TextureFormat& format() const { return format_; }

  /// Uploads a w x h region at (x,y) of `level` (and `layer` for arrays), tightly packed.
  void upload(const void* data, int level = 0, int x = 0, int y = 0, int w = -1, int h = -1, int layer = 0);
  /// Reads level `level` (all layers) tightly packed.
  void download(void* out, size_t bytes, int level = 0) const;
  template <class T>
  std::vector<T> read(int level = 0) const {
    const int w = std::max(1, width_ >> level), h = std::max(1, height_ >> level);
    std::vector<T> out(size_t(w) * size_t(h) * size_t(layers_) * size_t(format_.bytesPerTexel) / sizeof(T));
    download(out.data(), out.size() * sizeof(T), level);
    return out;
  }
  void generateMipmap();
  void setFilter(GLenum minFilter, GLenum magFilter);
  void setWrap(GLenum wrap);
  void bind(GLuint unit) const;
  void bindImage(GLuint unit, GLenum access, int level = 0) const;

 private:
  TextureFormat format_{};
  int width_ = 0, height_ = 0, layers_ = 1, levels_ = 1;
  GLenum target_ = GL_TEXTURE_2D;
};

class Renderbuffer : public Object<detail::deleteRenderbuffer> {
 public:
  Renderbuffer() = default;
  Renderbuffer(GLenum internalFormat, int width, int height);
};

/// A framebuffer object; check() reports an incomplete one.
class Framebuffer : public Object<detail::deleteFramebuffer> {
 public:
  static Framebuffer create();
  void attach(GLenum attachment, const Texture& texture, int level = 0);
  void attach(GLenum attachment, const Renderbuffer& rb);
  Status check() const;
  void bind() const;
};

class VertexArray : public Object<detail::deleteVertexArray> {
 public:
  static VertexArray create();
  /// A mesh: attribute 0 = `floatsPerVertex` tightly packed floats from `vertices`, indexed by
  /// the uint32 `indices`. The buffers must outlive the vertex array.
  static VertexArray forMesh(const Buffer& vertices, int floatsPerVertex, const Buffer& indices);
  void bind() const;
};

/// A linked program. Created from shaders under shaders/ (embedded, or STRATA_SHADER_DIR)
/// or from sources; compile errors name the real file:line.
class Program : public Object<detail::deleteProgram> {
 public:
  Program() = default;
  static Result<Program> compute(const std::string& name);
  static Result<Program> graphics(const std::string& vertexName, const std::string& fragmentName);
  /// From already-preprocessed sources (stage, source) pairs; `label` names it in errors.
  struct Stage {
    GLenum type;
    std::string text;
    std::vector<std::string> files;
  };
  static Result<Program> link(const std::vector<Stage>& stages, const std::string& label);

  void use() const;
  GLint location(const char* name) const;
  void set(const char* name, float v) const;
  void set(const char* name, int v) const;
  void set(const char* name, unsigned v) const;
  void set(const char* name, glm::vec2 v) const;
  void set(const char* name, glm::vec3 v) const;
  void set(const char* name, glm::vec4 v) const;
  void set(const char* name, glm::ivec2 v) const;
  void set(const char* name, const glm::mat4& v) const;
  /// The local work-group size declared in a compute shader.
  glm::ivec3 workGroupSize() const;
  /// Dispatches enough groups to cover (x, y, z) invocations (compute programs).
  void dispatchCovering(int x, int y = 1, int z = 1) const;
};

/// GPU time of a span of commands (GL_TIME_ELAPSED). Results are read without stalling when
/// available; `milliseconds()` waits.
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

}  // namespace strata::render::gl
