#include <strata/render/gl/objects.hpp>

#include <glm/gtc/type_ptr.hpp>

#include <strata/render/gl/shader_source.hpp>

namespace strata::render::gl {

namespace detail {
void deleteBuffer(GLuint id) { glDeleteBuffers(1, &id); }
void deleteTexture(GLuint id) { glDeleteTextures(1, &id); }
void deleteFramebuffer(GLuint id) { glDeleteFramebuffers(1, &id); }
void deleteRenderbuffer(GLuint id) { glDeleteRenderbuffers(1, &id); }
void deleteVertexArray(GLuint id) { glDeleteVertexArrays(1, &id); }
void deleteProgram(GLuint id) { glDeleteProgram(id); }
void deleteShader(GLuint id) { glDeleteShader(id); }
void deleteQuery(GLuint id) { glDeleteQueries(1, &id); }
}  // namespace detail

// ---- Buffer ----------------------------------------------------------------------------------

namespace {
GLuint createBuffer() {
  GLuint id = 0;
  glCreateBuffers(1, &id);
  return id;
}
}  // namespace

Buffer::Buffer(size_t bytes, const void* data, GLbitfield flags) : Object(createBuffer()), bytes_(bytes) {
  STRATA_CHECK(bytes > 0) << "empty buffer";
  glNamedBufferStorage(id(), GLsizeiptr(bytes), data, flags);
}

void Buffer::upload(size_t offset, size_t bytes, const void* data) {
  STRATA_CHECK(offset + bytes <= bytes_) << "upload of " << bytes << " bytes at " << offset << " past " << bytes_;
  glNamedBufferSubData(id(), GLintptr(offset), GLsizeiptr(bytes), data);
}

void Buffer::download(size_t offset, size_t bytes, void* out) const {
  STRATA_CHECK(offset + bytes <= bytes_) << "download of " << bytes << " bytes at " << offset << " past " << bytes_;
  glGetNamedBufferSubData(id(), GLintptr(offset), GLsizeiptr(bytes), out);
}

void Buffer::fill(uint32_t pattern) {
  glClearNamedBufferData(id(), GL_R32UI, GL_RED_INTEGER, GL_UNSIGNED_INT, &pattern);
}

void Buffer::bindBase(GLenum target, GLuint index) const { glBindBufferBase(target, index, id()); }

// ---- Texture ---------------------------------------------------------------------------------

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
  t.target_ = GL_TEXTURE_2D;
  glTextureStorage2D(t.id(), t.levels_, format.internal, width, height);
  t.setFilter(t.levels_ > 1 ? GL_LINEAR_MIPMAP_LINEAR : GL_LINEAR, GL_LINEAR);
  t.setWrap(GL_CLAMP_TO_EDGE);
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
  t.target_ = GL_TEXTURE_2D_ARRAY;
  glTextureStorage3D(t.id(), t.levels_, format.internal, width, height, layers);
  t.setFilter(t.levels_ > 1 ? GL_LINEAR_MIPMAP_LINEAR : GL_LINEAR, GL_LINEAR);
  t.setWrap(GL_CLAMP_TO_EDGE);
  return t;
}

void Texture::upload(const void* data, int level, int x, int y, int w, int h, int layer) {
  if (w < 0) w = std::max(1, width_ >> level);
  if (h < 0) h = std::max(1, height_ >> level);
  glPixelStorei(GL_UNPACK_ALIGNMENT, 1);
  if (target_ == GL_TEXTURE_2D_ARRAY) {
    glTextureSubImage3D(id(), level, x, y, layer, w, h, 1, format_.format, format_.type, data);
  } else {
    glTextureSubImage2D(id(), level, x, y, w, h, format_.format, format_.type, data);
  }
}

void Texture::download(void* out, size_t bytes, int level) const {
  glPixelStorei(GL_PACK_ALIGNMENT, 1);
  glGetTextureImage(id(), level, format_.format, format_.type, GLsizei(bytes), out);
}

void Texture::generateMipmap() { glGenerateTextureMipmap(id()); }

void Texture::setFilter(GLenum minFilter, GLenum magFilter) {
  glTextureParameteri(id(), GL_TEXTURE_MIN_FILTER, GLint(minFilter));
  glTextureParameteri(id(), GL_TEXTURE_MAG_FILTER, GLint(magFilter));
}

void Texture::setWrap(GLenum wrap) {
  glTextureParameteri(id(), GL_TEXTURE_WRAP_S, GLint(wrap));
  glTextureParameteri(id(), GL_TEXTURE_WRAP_T, GLint(wrap));
}

void Texture::bind(GLuint unit) const { glBindTextureUnit(unit, id()); }

void Texture::bindImage(GLuint unit, GLenum access, int level) const {
  glBindImageTexture(unit, id(), level, target_ == GL_TEXTURE_2D_ARRAY ? GL_TRUE : GL_FALSE, 0, access,
                     format_.internal);
}

// ---- Framebuffer, Renderbuffer, VertexArray ---------------------------------------------------

Renderbuffer::Renderbuffer(GLenum internalFormat, int width, int height) {
  GLuint rid = 0;
  glCreateRenderbuffers(1, &rid);
  static_cast<Object&>(*this) = Object(rid);
  glNamedRenderbufferStorage(rid, internalFormat, width, height);
}

Framebuffer Framebuffer::create() {
  GLuint fid = 0;
  glCreateFramebuffers(1, &fid);
  Framebuffer f;
  static_cast<Object&>(f) = Object(fid);
  return f;
}

void Framebuffer::attach(GLenum attachment, const Texture& texture, int level) {
  glNamedFramebufferTexture(id(), attachment, texture.id(), level);
}

void Framebuffer::attach(GLenum attachment, const Renderbuffer& rb) {
  glNamedFramebufferRenderbuffer(id(), attachment, GL_RENDERBUFFER, rb.id());
}

Status Framebuffer::check() const {
  const GLenum s = glCheckNamedFramebufferStatus(id(), GL_FRAMEBUFFER);
  if (s == GL_FRAMEBUFFER_COMPLETE) return {};
  return fail("gl: framebuffer incomplete (status 0x" + [&] {
    char b[16];
    std::snprintf(b, sizeof b, "%04X", s);
    return std::string(b);
  }() + ")");
}

void Framebuffer::bind() const { glBindFramebuffer(GL_FRAMEBUFFER, id()); }

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
  glVertexArrayElementBuffer(v.id(), indices.id());
  return v;
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

const char* stageName(GLenum type) {
  switch (type) {
    case GL_VERTEX_SHADER: return "vertex";
    case GL_FRAGMENT_SHADER: return "fragment";
    case GL_COMPUTE_SHADER: return "compute";
    case GL_GEOMETRY_SHADER: return "geometry";
    default: return "shader";
  }
}

Result<Program::Stage> loadStage(GLenum type, const std::string& name) {
  STRATA_TRY(auto src, loadShader(name));
  return Program::Stage{type, std::move(src.text), std::move(src.files)};
}

}  // namespace

Result<Program> Program::link(const std::vector<Stage>& stages, const std::string& label) {
  std::vector<Object<detail::deleteShader>> shaders;
  for (const auto& stage : stages) {
    Object<detail::deleteShader> shader(glCreateShader(stage.type));
    const char* text = stage.text.c_str();
    glShaderSource(shader.id(), 1, &text, nullptr);
    glCompileShader(shader.id());
    GLint ok = 0;
    glGetShaderiv(shader.id(), GL_COMPILE_STATUS, &ok);
    if (!ok) {
      return fail("gl: " + std::string(stageName(stage.type)) + " shader of '" + label + "' does not compile:\n" +
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
  return p;
}

Result<Program> Program::compute(const std::string& name) {
  STRATA_TRY(auto stage, loadStage(GL_COMPUTE_SHADER, name));
  return link({std::move(stage)}, name);
}

Result<Program> Program::graphics(const std::string& vertexName, const std::string& fragmentName) {
  STRATA_TRY(auto vs, loadStage(GL_VERTEX_SHADER, vertexName));
  STRATA_TRY(auto fs, loadStage(GL_FRAGMENT_SHADER, fragmentName));
  return link({std::move(vs), std::move(fs)}, vertexName + "+" + fragmentName);
}

void Program::use() const { glUseProgram(id()); }
GLint Program::location(const char* name) const { return glGetUniformLocation(id(), name); }
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
void Program::set(const char* name, const glm::mat4& v) const {
  glProgramUniformMatrix4fv(id(), location(name), 1, GL_FALSE, glm::value_ptr(v));
}

glm::ivec3 Program::workGroupSize() const {
  GLint s[3] = {1, 1, 1};
  glGetProgramiv(id(), GL_COMPUTE_WORK_GROUP_SIZE, s);
  return {s[0], s[1], s[2]};
}

void Program::dispatchCovering(int x, int y, int z) const {
  const glm::ivec3 g = workGroupSize();
  use();
  glDispatchCompute(GLuint((x + g.x - 1) / g.x), GLuint((y + g.y - 1) / g.y), GLuint((z + g.z - 1) / g.z));
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

}  // namespace strata::render::gl
