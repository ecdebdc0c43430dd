#include <strata/gl/objects.hpp>

#include <epoxy/gl.h>

#include <cstdio>
#include <string_view>
#include <type_traits>

#include <glm/gtc/type_ptr.hpp>

#include "gl_enums.hpp"

namespace strata::gl {

static_assert(std::is_same_v<GLuint, uint32_t>, "GL names are held as uint32_t");

namespace detail {
void deleteBuffer(uint32_t id) { glDeleteBuffers(1, &id); }
void deleteTexture(uint32_t id) { glDeleteTextures(1, &id); }
void deleteFramebuffer(uint32_t id) { glDeleteFramebuffers(1, &id); }
void deleteVertexArray(uint32_t id) { glDeleteVertexArrays(1, &id); }
void deleteProgram(uint32_t id) { glDeleteProgram(id); }
void deleteShader(uint32_t id) { glDeleteShader(id); }
void deleteQuery(uint32_t id) { glDeleteQueries(1, &id); }
}  // namespace detail

namespace {
thread_local CallCounts tCounts;
}  // namespace

const CallCounts& callCounts() { return tCounts; }

// ---- Buffer ----------------------------------------------------------------------------------

namespace {
GLuint createBuffer() {
  GLuint id = 0;
  glCreateBuffers(1, &id);
  return id;
}
}  // namespace

Buffer::Buffer(size_t bytes, const void* data, BufferStorage storage) : Object(createBuffer()), bytes_(bytes) {
  STRATA_CHECK(bytes > 0) << "empty buffer";
  GLbitfield flags = 0;
  switch (storage) {
    case BufferStorage::kDynamic: flags = GL_DYNAMIC_STORAGE_BIT; break;
    case BufferStorage::kImmutable: break;
    case BufferStorage::kReadback: flags = GL_DYNAMIC_STORAGE_BIT | GL_MAP_READ_BIT | GL_CLIENT_STORAGE_BIT; break;
  }
  glNamedBufferStorage(id(), GLsizeiptr(bytes), data, flags);
}

void Buffer::upload(size_t offset, size_t bytes, const void* data) {
  STRATA_CHECK(offset + bytes <= bytes_) << "upload of " << bytes << " bytes at " << offset << " past " << bytes_;
  glNamedBufferSubData(id(), GLintptr(offset), GLsizeiptr(bytes), data);
}

void Buffer::download(size_t offset, size_t bytes, void* out) const {
  STRATA_CHECK(offset + bytes <= bytes_) << "download of " << bytes << " bytes at " << offset << " past " << bytes_;
  ++tCounts.hostReads;
  tCounts.hostReadBytes += bytes;
  glGetNamedBufferSubData(id(), GLintptr(offset), GLsizeiptr(bytes), out);
}

void Buffer::fill(uint32_t pattern) {
  glClearNamedBufferData(id(), GL_R32UI, GL_RED_INTEGER, GL_UNSIGNED_INT, &pattern);
}

void Buffer::copyTo(const Buffer& dst, size_t bytes, size_t offset, size_t dstOffset) const {
  STRATA_CHECK(offset + bytes <= bytes_ && dstOffset + bytes <= dst.bytes_)
      << "copy of " << bytes << " bytes from " << offset << " (of " << bytes_ << ") to " << dstOffset << " (of "
      << dst.bytes_ << ")";
  glCopyNamedBufferSubData(id(), dst.id(), GLintptr(offset), GLintptr(dstOffset), GLsizeiptr(bytes));
}

void Buffer::bindStorage(int unit) const {
  STRATA_CHECK(unit >= 0) << "storage binding " << unit;
  glBindBufferBase(GL_SHADER_STORAGE_BUFFER, GLuint(unit), id());
}

void Buffer::bindUniform(int unit) const {
  STRATA_CHECK(unit >= 0) << "uniform binding " << unit;
  glBindBufferBase(GL_UNIFORM_BUFFER, GLuint(unit), id());
}

void Buffer::bind(const Binding& slot) const {
  STRATA_CHECK(slot.kind == ResourceKind::kStorageBuffer || slot.kind == ResourceKind::kUniformBuffer)
      << "a buffer bound to " << slot.define << ", a " << resourceKindName(slot.kind) << " slot";
  if (slot.kind == ResourceKind::kStorageBuffer) {
    bindStorage(slot.unit);
  } else {
    bindUniform(slot.unit);
  }
}

// ---- Texture ---------------------------------------------------------------------------------

int bytesPerTexel(TextureFormat format) { return detail::glFormat(format).bytesPerTexel; }

namespace {
int fullMipCount(int w, int h) {
  int levels = 1;
  while ((w | h) >> levels) ++levels;
  return levels;
}
GLuint createTexture(GLenum target) {
  GLuint id = 0;
  glCreateTextures(target, 1, &id);
  return id;
}
}  // namespace

Texture Texture::create2D(TextureFormat format, int width, int height, int levels) {
  STRATA_CHECK(width > 0 && height > 0) << "texture " << width << "x" << height;
  Texture t;
  static_cast<Object&>(t) = Object(createTexture(GL_TEXTURE_2D));
  t.format_ = format;
  t.width_ = width;
  t.height_ = height;
  t.levels_ = levels > 0 ? levels : fullMipCount(width, height);
  glTextureStorage2D(t.id(), t.levels_, detail::glFormat(format).internal, width, height);
  t.setFilter(Filter::kLinear);
  t.setWrap(Wrap::kClampToEdge);
  return t;
}

Texture Texture::create2DMultisample(TextureFormat format, int width, int height, int samples) {
  STRATA_CHECK(width > 0 && height > 0 && samples >= 1)
      << "multisample texture " << width << "x" << height << " x" << samples;
  Texture t;
  static_cast<Object&>(t) = Object(createTexture(GL_TEXTURE_2D_MULTISAMPLE));
  t.format_ = format;
  t.width_ = width;
  t.height_ = height;
  t.levels_ = 1;
  glTextureStorage2DMultisample(t.id(), samples, detail::glFormat(format).internal, width, height, GL_TRUE);
  return t;
}

Texture Texture::create2DArray(TextureFormat format, int width, int height, int layers, int levels) {
  STRATA_CHECK(width > 0 && height > 0 && layers > 0) << "texture array " << width << "x" << height << "x" << layers;
  Texture t;
  static_cast<Object&>(t) = Object(createTexture(GL_TEXTURE_2D_ARRAY));
  t.format_ = format;
  t.width_ = width;
  t.height_ = height;
  t.layers_ = layers;
  t.levels_ = levels > 0 ? levels : fullMipCount(width, height);
  t.array_ = true;
  glTextureStorage3D(t.id(), t.levels_, detail::glFormat(format).internal, width, height, layers);
  t.setFilter(Filter::kLinear);
  t.setWrap(Wrap::kClampToEdge);
  return t;
}

void Texture::upload(const void* data, int level, int x, int y, int w, int h, int layer) {
  if (w < 0) w = std::max(1, width_ >> level);
  if (h < 0) h = std::max(1, height_ >> level);
  const auto f = detail::glFormat(format_);
  glPixelStorei(GL_UNPACK_ALIGNMENT, 1);
  if (array_) {
    glTextureSubImage3D(id(), level, x, y, layer, w, h, 1, f.format, f.type, data);
  } else {
    glTextureSubImage2D(id(), level, x, y, w, h, f.format, f.type, data);
  }
}

void Texture::uploadFrom(const Buffer& source, size_t offset, int x, int y, int w, int h) {
  STRATA_CHECK(!array_ && x >= 0 && y >= 0 && w > 0 && h > 0 && x + w <= width_ && y + h <= height_ &&
               offset + size_t(w) * size_t(h) * size_t(bytesPerTexel(format_)) <= source.size())
      << "uploadFrom: an array texture, a window outside the texture, or a buffer too small";
  const auto f = detail::glFormat(format_);
  glBindBuffer(GL_PIXEL_UNPACK_BUFFER, source.id());
  glPixelStorei(GL_UNPACK_ALIGNMENT, 4);
  glPixelStorei(GL_UNPACK_ROW_LENGTH, 0);
  glTextureSubImage2D(id(), 0, x, y, w, h, f.format, f.type, reinterpret_cast<const void*>(offset));
  glBindBuffer(GL_PIXEL_UNPACK_BUFFER, 0);
}

void Texture::clear(int level) {
  const auto f = detail::glFormat(format_);
  glClearTexImage(id(), level, f.format, f.type, nullptr);  // null data: zero
}

void Texture::download(void* out, size_t bytes, int level) const {
  const auto f = detail::glFormat(format_);
  glPixelStorei(GL_PACK_ALIGNMENT, 1);
  ++tCounts.hostReads;
  tCounts.hostReadBytes += bytes;
  glGetTextureImage(id(), level, f.format, f.type, GLsizei(bytes), out);
}

void Texture::downloadRegion(void* out, size_t bytes, int x, int y, int w, int h, int level, int layer) const {
  const auto f = detail::glFormat(format_);
  glPixelStorei(GL_PACK_ALIGNMENT, 1);
  ++tCounts.hostReads;
  tCounts.hostReadBytes += bytes;
  glGetTextureSubImage(id(), level, x, y, layer, w, h, 1, f.format, f.type, GLsizei(bytes), out);
}

void Texture::generateMipmap() { glGenerateTextureMipmap(id()); }

void Texture::setFilter(Filter filter) {
  const bool linear = filter == Filter::kLinear;
  const GLenum minFilter = linear ? (levels_ > 1 ? GL_LINEAR_MIPMAP_LINEAR : GL_LINEAR) : GL_NEAREST;
  glTextureParameteri(id(), GL_TEXTURE_MIN_FILTER, GLint(minFilter));
  glTextureParameteri(id(), GL_TEXTURE_MAG_FILTER, GLint(linear ? GL_LINEAR : GL_NEAREST));
}

void Texture::setWrap(Wrap s, Wrap t) {
  auto gl = [](Wrap w) { return GLint(w == Wrap::kRepeat ? GL_REPEAT : GL_CLAMP_TO_EDGE); };
  glTextureParameteri(id(), GL_TEXTURE_WRAP_S, gl(s));
  glTextureParameteri(id(), GL_TEXTURE_WRAP_T, gl(t));
}

void Texture::bind(int unit) const {
  STRATA_CHECK(unit >= 0) << "texture unit " << unit;
  glBindTextureUnit(GLuint(unit), id());
}

void Texture::bind(const Binding& slot) const {
  STRATA_CHECK(slot.kind == ResourceKind::kSampler)
      << "a texture bound as a sampler to " << slot.define << ", a " << resourceKindName(slot.kind) << " slot";
  bind(slot.unit);
}

void Texture::bindImage(int unit, Access access, int level) const {
  STRATA_CHECK(unit >= 0) << "image unit " << unit;
  const GLenum a = access == Access::kRead ? GL_READ_ONLY : access == Access::kWrite ? GL_WRITE_ONLY : GL_READ_WRITE;
  glBindImageTexture(GLuint(unit), id(), level, array_ ? GL_TRUE : GL_FALSE, 0, a, detail::glFormat(format_).internal);
}

void Texture::bindImage(const Binding& slot, Access access, int level) const {
  STRATA_CHECK(slot.kind == ResourceKind::kImage)
      << "a texture bound as an image to " << slot.define << ", a " << resourceKindName(slot.kind) << " slot";
  bindImage(slot.unit, access, level);
}

void copyTexels(const Texture& src, TexelAt from, const Texture& dst, TexelAt to, int w, int h, int layers) {
  STRATA_CHECK(bytesPerTexel(src.format()) == bytesPerTexel(dst.format()))
      << "copyTexels between formats of different texel sizes";
  const GLenum srcTarget = src.isArray() ? GL_TEXTURE_2D_ARRAY : GL_TEXTURE_2D;
  const GLenum dstTarget = dst.isArray() ? GL_TEXTURE_2D_ARRAY : GL_TEXTURE_2D;
  glCopyImageSubData(src.id(), srcTarget, from.level, from.x, from.y, from.layer, dst.id(), dstTarget, to.level, to.x,
                     to.y, to.layer, w, h, layers);
}

// ---- Framebuffer, VertexArray ----------------------------------------------------------------

Framebuffer Framebuffer::create() {
  GLuint fid = 0;
  glCreateFramebuffers(1, &fid);
  Framebuffer f;
  static_cast<Object&>(f) = Object(fid);
  return f;
}

void Framebuffer::attachColour(int index, const Texture& texture, int level) {
  STRATA_CHECK(index >= 0 && index < 8) << "colour attachment " << index;
  glNamedFramebufferTexture(id(), GLenum(GL_COLOR_ATTACHMENT0 + index), texture.id(), level);
  colourMask_ |= 1u << index;
  GLenum buffers[8];
  int count = 0;
  for (int i = 0; i < 8 && (colourMask_ >> i); ++i) {
    buffers[count++] = (colourMask_ >> i) & 1u ? GLenum(GL_COLOR_ATTACHMENT0 + i) : GLenum(GL_NONE);
  }
  glNamedFramebufferDrawBuffers(id(), count, buffers);
}

void Framebuffer::attachDepth(const Texture& texture, int level) {
  glNamedFramebufferTexture(id(), GL_DEPTH_ATTACHMENT, texture.id(), level);
}

Status Framebuffer::check() const {
  const GLenum s = glCheckNamedFramebufferStatus(id(), GL_FRAMEBUFFER);
  if (s == GL_FRAMEBUFFER_COMPLETE) return {};
  char b[16];
  std::snprintf(b, sizeof b, "%04X", s);
  return fail("gl: framebuffer incomplete (status 0x" + std::string(b) + ")");
}

void Framebuffer::bind() const { glBindFramebuffer(GL_FRAMEBUFFER, id()); }

void Framebuffer::clearColour(int index, const glm::vec4& value) const {
  glClearNamedFramebufferfv(id(), GL_COLOR, index, glm::value_ptr(value));
}

void Framebuffer::clearDepth(float value) const { glClearNamedFramebufferfv(id(), GL_DEPTH, 0, &value); }

void Framebuffer::blitColourToWindow(int index, glm::ivec2 from, glm::ivec2 to, Filter filter) const {
  glNamedFramebufferReadBuffer(id(), GLenum(GL_COLOR_ATTACHMENT0 + index));
  glBlitNamedFramebuffer(id(), 0, 0, 0, from.x, from.y, 0, 0, to.x, to.y, GL_COLOR_BUFFER_BIT,
                         filter == Filter::kNearest ? GL_NEAREST : GL_LINEAR);
}

void Framebuffer::resolveTo(const Framebuffer& dst, glm::ivec2 size) const {
  // A blit writes every draw buffer of the destination: one attachment at a time, then the
  // destination's draw buffers as attachColour set them.
  for (int i = 0; i < 8; ++i) {
    if (!((colourMask_ >> i) & 1u) || !((dst.colourMask_ >> i) & 1u)) continue;
    glNamedFramebufferReadBuffer(id(), GLenum(GL_COLOR_ATTACHMENT0 + i));
    glNamedFramebufferDrawBuffer(dst.id(), GLenum(GL_COLOR_ATTACHMENT0 + i));
    glBlitNamedFramebuffer(id(), dst.id(), 0, 0, size.x, size.y, 0, 0, size.x, size.y, GL_COLOR_BUFFER_BIT, GL_NEAREST);
  }
  glBlitNamedFramebuffer(id(), dst.id(), 0, 0, size.x, size.y, 0, 0, size.x, size.y, GL_DEPTH_BUFFER_BIT, GL_NEAREST);
  GLenum buffers[8];
  int count = 0;
  for (int i = 0; i < 8 && (dst.colourMask_ >> i); ++i) {
    buffers[count++] = (dst.colourMask_ >> i) & 1u ? GLenum(GL_COLOR_ATTACHMENT0 + i) : GLenum(GL_NONE);
  }
  glNamedFramebufferDrawBuffers(dst.id(), count, buffers);
}

VertexArray VertexArray::create() {
  GLuint vid = 0;
  glCreateVertexArrays(1, &vid);
  VertexArray v;
  static_cast<Object&>(v) = Object(vid);
  return v;
}

void VertexArray::bind() const { glBindVertexArray(id()); }

VertexArray VertexArray::forMesh(const Buffer& vertices, int floatsPerVertex, const Buffer& indices) {
  VertexArray v = create();
  glVertexArrayVertexBuffer(v.id(), 0, vertices.id(), 0, GLsizei(floatsPerVertex * sizeof(float)));
  glVertexArrayAttribFormat(v.id(), 0, floatsPerVertex, GL_FLOAT, GL_FALSE, 0);
  glVertexArrayAttribBinding(v.id(), 0, 0);
  glEnableVertexArrayAttrib(v.id(), 0);
  v.setIndices(indices);
  return v;
}

void VertexArray::setIndices(const Buffer& indices) { glVertexArrayElementBuffer(id(), indices.id()); }

void VertexArray::drawArrays(Primitive primitive, int first, int count) const {
  bind();
  glDrawArrays(detail::glPrimitive(primitive), first, count);
  glBindVertexArray(0);
}

void VertexArray::drawElements(Primitive primitive, int count) const {
  bind();
  glDrawElements(detail::glPrimitive(primitive), count, GL_UNSIGNED_INT, nullptr);
  glBindVertexArray(0);
}

// ---- Program ---------------------------------------------------------------------------------

namespace {

std::string infoLog(GLuint object, bool program) {
  GLint len = 0;
  if (program) {
    glGetProgramiv(object, GL_INFO_LOG_LENGTH, &len);
  } else {
    glGetShaderiv(object, GL_INFO_LOG_LENGTH, &len);
  }
  std::string log(size_t(std::max(len, 1)), '\0');
  if (program) {
    glGetProgramInfoLog(object, len, nullptr, log.data());
  } else {
    glGetShaderInfoLog(object, len, nullptr, log.data());
  }
  while (!log.empty() && (log.back() == '\0' || log.back() == '\n')) log.pop_back();
  return log;
}

GLenum glStage(ShaderStage stage) {
  switch (stage) {
    case ShaderStage::kVertex: return GL_VERTEX_SHADER;
    case ShaderStage::kFragment: return GL_FRAGMENT_SHADER;
    case ShaderStage::kGeometry: return GL_GEOMETRY_SHADER;
    case ShaderStage::kCompute: return GL_COMPUTE_SHADER;
  }
  return GL_COMPUTE_SHADER;
}

const char* stageName(ShaderStage stage) {
  switch (stage) {
    case ShaderStage::kVertex: return "vertex";
    case ShaderStage::kFragment: return "fragment";
    case ShaderStage::kGeometry: return "geometry";
    case ShaderStage::kCompute: return "compute";
  }
  return "shader";
}

Result<Program::Stage> loadStage(ShaderStage stage, const std::string& name) {
  STRATA_TRY(auto src, loadShader(name));
  return Program::Stage{stage, std::move(src.text), std::move(src.files)};
}

}  // namespace

namespace {
// The name of a program's active resource (program interface query).
std::string resourceName(GLuint program, GLenum interface, GLuint index) {
  GLint length = 0;
  const GLenum prop = GL_NAME_LENGTH;
  glGetProgramResourceiv(program, interface, index, 1, &prop, 1, nullptr, &length);
  std::string s(size_t(std::max(length, 1)), '\0');
  glGetProgramResourceName(program, interface, index, GLsizei(s.size()), nullptr, s.data());
  while (!s.empty() && s.back() == '\0') s.pop_back();
  return s;
}
}  // namespace

Result<Program> Program::link(const std::vector<Stage>& stages, const std::string& label,
                              std::span<const ShaderDefine> defines) {
  std::vector<Object<detail::deleteShader>> shaders;
  for (const auto& stage : stages) {
    Object<detail::deleteShader> shader(glCreateShader(glStage(stage.stage)));
    const std::string source = insertDefines(stage.text, defines);
    const char* text = source.c_str();
    glShaderSource(shader.id(), 1, &text, nullptr);
    glCompileShader(shader.id());
    GLint ok = 0;
    glGetShaderiv(shader.id(), GL_COMPILE_STATUS, &ok);
    if (!ok) {
      return fail("gl: " + std::string(stageName(stage.stage)) + " shader of '" + label + "' does not compile:\n" +
                  mapInfoLog(infoLog(shader.id(), false), stage.files));
    }
    shaders.push_back(std::move(shader));
  }
  Program p;
  static_cast<Object&>(p) = Object(glCreateProgram());
  for (const auto& s : shaders) glAttachShader(p.id(), s.id());
  glLinkProgram(p.id());
  for (const auto& s : shaders) glDetachShader(p.id(), s.id());
  GLint ok = 0;
  glGetProgramiv(p.id(), GL_LINK_STATUS, &ok);
  if (!ok) return fail("gl: program '" + label + "' does not link:\n" + infoLog(p.id(), true));
  glObjectLabel(GL_PROGRAM, p.id(), GLsizei(label.size()), label.c_str());
  const bool compute =
      std::any_of(stages.begin(), stages.end(), [](const Stage& s) { return s.stage == ShaderStage::kCompute; });
  if (compute) {
    GLint g[3] = {1, 1, 1};
    glGetProgramiv(p.id(), GL_COMPUTE_WORK_GROUP_SIZE, g);
    p.groupSize_ = {g[0], g[1], g[2]};
  }
  GLint count = 0;
  glGetProgramInterfaceiv(p.id(), GL_UNIFORM, GL_ACTIVE_RESOURCES, &count);
  for (GLint i = 0; i < count; ++i) {
    const GLenum prop = GL_LOCATION;
    GLint loc = -1;
    glGetProgramResourceiv(p.id(), GL_UNIFORM, GLuint(i), 1, &prop, 1, nullptr, &loc);
    if (loc < 0) continue;  // in a uniform block
    std::string name = resourceName(p.id(), GL_UNIFORM, GLuint(i));
    if (name.size() > 3 && name.ends_with("[0]")) p.locations_.emplace_back(name.substr(0, name.size() - 3), loc);
    p.locations_.emplace_back(std::move(name), loc);
  }
  return p;
}

Result<Program> Program::compute(const std::string& name, std::span<const ShaderDefine> defines) {
  STRATA_TRY(auto stage, loadStage(ShaderStage::kCompute, name));
  return link({std::move(stage)}, name, defines);
}

Result<Program> Program::graphics(const std::string& vertexName, const std::string& fragmentName,
                                  std::span<const ShaderDefine> defines) {
  STRATA_TRY(auto vs, loadStage(ShaderStage::kVertex, vertexName));
  STRATA_TRY(auto fs, loadStage(ShaderStage::kFragment, fragmentName));
  return link({std::move(vs), std::move(fs)}, vertexName + "+" + fragmentName, defines);
}

void Program::use() const { glUseProgram(id()); }
int Program::location(const char* name) const {
  const std::string_view key(name);
  for (const auto& [n, loc] : locations_) {
    if (n == key) return loc;
  }
  ++tCounts.queries;
  const int loc = glGetUniformLocation(id(), name);
  locations_.emplace_back(name, loc);
  return loc;
}
void Program::set(const char* name, float v) const { glProgramUniform1f(id(), location(name), v); }
void Program::set(const char* name, int v) const { glProgramUniform1i(id(), location(name), v); }
void Program::set(const char* name, unsigned v) const { glProgramUniform1ui(id(), location(name), v); }
void Program::set(const char* name, glm::vec2 v) const {
  glProgramUniform2fv(id(), location(name), 1, glm::value_ptr(v));
}
void Program::set(const char* name, glm::vec3 v) const {
  glProgramUniform3fv(id(), location(name), 1, glm::value_ptr(v));
}
void Program::set(const char* name, glm::vec4 v) const {
  glProgramUniform4fv(id(), location(name), 1, glm::value_ptr(v));
}
void Program::set(const char* name, glm::ivec2 v) const {
  glProgramUniform2iv(id(), location(name), 1, glm::value_ptr(v));
}
void Program::set(const char* name, const glm::mat3& v) const {
  glProgramUniformMatrix3fv(id(), location(name), 1, GL_FALSE, glm::value_ptr(v));
}
void Program::set(const char* name, const glm::mat4& v) const {
  glProgramUniformMatrix4fv(id(), location(name), 1, GL_FALSE, glm::value_ptr(v));
}

glm::ivec3 Program::workGroupSize() const { return groupSize_; }

void Program::dispatchCovering(int x, int y, int z) const {
  const glm::ivec3 g = groupSize_;
  use();
  ++tCounts.dispatches;
  glDispatchCompute(GLuint((x + g.x - 1) / g.x), GLuint((y + g.y - 1) / g.y), GLuint((z + g.z - 1) / g.z));
}

void Program::dispatchIndirect(const Buffer& args, size_t offset) const {
  STRATA_CHECK(offset % 4 == 0 && offset + 12 <= args.size()) << "indirect arguments at " << offset;
  use();
  ++tCounts.dispatches;
  glBindBuffer(GL_DISPATCH_INDIRECT_BUFFER, args.id());
  glDispatchComputeIndirect(GLintptr(offset));
}

std::vector<ProgramResource> Program::resources() const {
  std::vector<ProgramResource> out;
  auto name = [&](GLenum interface, GLuint index) { return resourceName(id(), interface, index); };
  // Buffer blocks carry their binding; samplers and images hold theirs as the uniform's value.
  for (const auto& [interface, kind] : {std::pair{GLenum(GL_SHADER_STORAGE_BLOCK), ResourceKind::kStorageBuffer},
                                        std::pair{GLenum(GL_UNIFORM_BLOCK), ResourceKind::kUniformBuffer}}) {
    GLint count = 0;
    glGetProgramInterfaceiv(id(), interface, GL_ACTIVE_RESOURCES, &count);
    for (GLint i = 0; i < count; ++i) {
      GLint binding = -1;
      const GLenum prop = GL_BUFFER_BINDING;
      glGetProgramResourceiv(id(), interface, GLuint(i), 1, &prop, 1, nullptr, &binding);
      out.push_back({name(interface, GLuint(i)), kind, binding});
    }
  }
  GLint count = 0;
  glGetProgramInterfaceiv(id(), GL_UNIFORM, GL_ACTIVE_RESOURCES, &count);
  for (GLint i = 0; i < count; ++i) {
    const GLenum props[3] = {GL_TYPE, GL_LOCATION, GL_BLOCK_INDEX};
    GLint values[3] = {0, -1, -1};
    glGetProgramResourceiv(id(), GL_UNIFORM, GLuint(i), 3, props, 3, nullptr, values);
    const auto kind = detail::opaqueKind(GLenum(values[0]));
    if (!kind || values[1] < 0) continue;
    GLint unit = -1;
    glGetUniformiv(id(), values[1], &unit);
    out.push_back({name(GL_UNIFORM, GLuint(i)), *kind, unit});
  }
  return out;
}

Status checkBindings(const Program& program, std::span<const Binding> bindings, const std::string& label) {
  for (const auto& r : program.resources()) {
    const auto it = std::find_if(bindings.begin(), bindings.end(),
                                 [&](const Binding& b) { return b.kind == r.kind && b.resource == r.name; });
    if (it == bindings.end()) {
      return fail(label + ": " + resourceKindName(r.kind) + " '" + r.name + "' (binding " + std::to_string(r.binding) +
                  ") is not in the C++ binding table");
    }
    if (it->unit != r.binding) {
      return fail(label + ": " + resourceKindName(r.kind) + " '" + r.name + "' is on binding " +
                  std::to_string(r.binding) + ", the C++ table declares " + std::string(it->define) + " = " +
                  std::to_string(it->unit));
    }
  }
  return {};
}

// ---- GpuTimer --------------------------------------------------------------------------------

GpuTimer::GpuTimer() {
  GLuint q = 0;
  glCreateQueries(GL_TIME_ELAPSED, 1, &q);
  query_ = Object<detail::deleteQuery>(q);
}

void GpuTimer::begin() { glBeginQuery(GL_TIME_ELAPSED, query_.id()); }

void GpuTimer::end() {
  glEndQuery(GL_TIME_ELAPSED);
  pending_ = true;
}

bool GpuTimer::ready() const {
  GLint available = 0;
  glGetQueryObjectiv(query_.id(), GL_QUERY_RESULT_AVAILABLE, &available);
  return available != 0;
}

double GpuTimer::milliseconds() const {
  STRATA_CHECK(pending_) << "GpuTimer::milliseconds() before begin()/end()";
  GLuint64 ns = 0;
  glGetQueryObjectui64v(query_.id(), GL_QUERY_RESULT, &ns);
  return double(ns) * 1e-6;
}

}  // namespace strata::gl
