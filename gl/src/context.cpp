#include <strata/gl/context.hpp>

#include <epoxy/egl.h>
#include <epoxy/gl.h>
#define GLFW_INCLUDE_NONE
#include <GLFW/glfw3.h>

#include <dlfcn.h>

#include <charconv>
#include <cstdlib>
#include <cstring>
#include <mutex>
#include <vector>

#include <strata/core/log.hpp>

namespace strata::gl {
namespace {

thread_local long tErrorCount = 0;

bool hasExtension(const char* list, const char* name) {
  if (!list) return false;
  const size_t n = std::strlen(name);
  for (const char* p = list; (p = std::strstr(p, name)); p += n) {
    if ((p == list || p[-1] == ' ') && (p[n] == ' ' || p[n] == '\0')) return true;
  }
  return false;
}

const char* str(const char* s) { return s ? s : ""; }

void GLAPIENTRY debugCallback(GLenum source, GLenum type, GLuint id, GLenum severity, GLsizei length,
                              const GLchar* message, const void*) {
  const std::string_view msg(message, length < 0 ? std::strlen(message) : size_t(length));
  if (source == GL_DEBUG_SOURCE_SHADER_COMPILER) {
    // Compile errors come back through Program's Result, with file names mapped: not counted.
    log::debug("gl") << msg;
  } else if (type == GL_DEBUG_TYPE_ERROR) {
    ++tErrorCount;
    log::error("gl") << msg << " (id " << id << ")";
  } else if (type == GL_DEBUG_TYPE_PERFORMANCE) {
    // Driver advice for developers (NVIDIA's "buffer moved to host memory", "shader recompiled
    // based on GL state"): nothing a user can act on, and some come once per step.
    log::debug("gl") << msg;
  } else if (severity == GL_DEBUG_SEVERITY_HIGH || severity == GL_DEBUG_SEVERITY_MEDIUM) {
    log::warn("gl") << msg;
  } else {
    log::debug("gl") << msg;
  }
}

void installDebugOutput() {
  if (!epoxy_has_gl_extension("GL_KHR_debug") && epoxy_gl_version() < 43) return;
  glEnable(GL_DEBUG_OUTPUT);
  glEnable(GL_DEBUG_OUTPUT_SYNCHRONOUS);
  glDebugMessageCallback(debugCallback, nullptr);
  glDebugMessageControl(GL_DONT_CARE, GL_DONT_CARE, GL_DONT_CARE, 0, nullptr, GL_TRUE);
}

std::string eglErrorString(EGLint e) {
  switch (e) {
    case EGL_NOT_INITIALIZED: return "EGL_NOT_INITIALIZED";
    case EGL_BAD_ACCESS: return "EGL_BAD_ACCESS";
    case EGL_BAD_ALLOC: return "EGL_BAD_ALLOC";
    case EGL_BAD_ATTRIBUTE: return "EGL_BAD_ATTRIBUTE";
    case EGL_BAD_CONFIG: return "EGL_BAD_CONFIG";
    case EGL_BAD_CONTEXT: return "EGL_BAD_CONTEXT";
    case EGL_BAD_DISPLAY: return "EGL_BAD_DISPLAY";
    case EGL_BAD_MATCH: return "EGL_BAD_MATCH";
    case EGL_BAD_PARAMETER: return "EGL_BAD_PARAMETER";
    default: return "EGL error " + std::to_string(e);
  }
}

// Chooses the EGL display: an NVIDIA device if asked for (or "auto" and one exists), else Mesa
// surfaceless. Returns EGL_NO_DISPLAY with `why` set when nothing fits.
EGLDisplay chooseDisplay(const std::string& want, ContextInfo& info, std::string& why) {
  const char* clientExts = eglQueryString(EGL_NO_DISPLAY, EGL_EXTENSIONS);
  if (!clientExts) {
    why = "EGL has no client extensions (is libEGL from glvnd/Mesa installed?)";
    return EGL_NO_DISPLAY;
  }
  const bool canEnumerate =
      hasExtension(clientExts, "EGL_EXT_device_enumeration") || hasExtension(clientExts, "EGL_EXT_device_base");
  // "gpu:K" falls back to Mesa surfaceless like "auto" where there is no NVIDIA device.
  const bool deviceIndex = want != "auto" && want != "surfaceless" && want.rfind("gpu:", 0) != 0;
  if (deviceIndex && !(canEnumerate && hasExtension(clientExts, "EGL_EXT_platform_device"))) {
    why = "EGL device " + want +
          " asked for, but this EGL cannot enumerate devices (no EGL_EXT_device_enumeration and "
          "EGL_EXT_platform_device)";
    return EGL_NO_DISPLAY;
  }
  if (want != "surfaceless" && canEnumerate && hasExtension(clientExts, "EGL_EXT_platform_device")) {
    EGLint n = 0;
    eglQueryDevicesEXT(0, nullptr, &n);
    std::vector<EGLDeviceEXT> devices(size_t(std::max(n, 0)));
    if (n > 0) eglQueryDevicesEXT(n, devices.data(), &n);
    int chosen = -1;
    const bool gpuK = want.rfind("gpu:", 0) == 0;
    if (want != "auto" && !gpuK) {
      chosen = std::atoi(want.c_str());
      if (chosen < 0 || chosen >= n) {
        why = "EGL device " + want + " asked for, but there " + (n == 1 ? "is 1" : "are " + std::to_string(n));
        return EGL_NO_DISPLAY;
      }
    } else {
      // "auto": the first NVIDIA device; "gpu:K": the K-th of them, wrapping (one per local MPI
      // rank: sim::rankEglDevice); none: Mesa surfaceless below.
      std::vector<int> gpus;
      for (int i = 0; i < n; ++i) {
        if (hasExtension(eglQueryDeviceStringEXT(devices[size_t(i)], EGL_EXTENSIONS), "EGL_NV_device_cuda")) {
          gpus.push_back(i);
        }
      }
      const std::string k = gpuK ? want.substr(4) : "0";
      if (k.empty() || k.find_first_not_of("0123456789") != std::string::npos || k.size() > 6) {
        why = "EGL device '" + want + "': expected auto, surfaceless, an index or gpu:<k>";
        return EGL_NO_DISPLAY;
      }
      if (!gpus.empty()) chosen = gpus[size_t(std::stoi(k)) % gpus.size()];
    }
    if (chosen >= 0) {
      EGLDeviceEXT dev = devices[size_t(chosen)];
      const char* exts = eglQueryDeviceStringEXT(dev, EGL_EXTENSIONS);
      const char* drm =
          hasExtension(exts, "EGL_EXT_device_drm") ? eglQueryDeviceStringEXT(dev, EGL_DRM_DEVICE_FILE_EXT) : nullptr;
      info.platform = "EGL device";
      info.eglDevice = "device " + std::to_string(chosen) + " of " + std::to_string(n) +
                       (drm ? std::string(" (") + drm + ")" : "") + ": " + str(exts);
      EGLDisplay dpy = eglGetPlatformDisplayEXT(EGL_PLATFORM_DEVICE_EXT, dev, nullptr);
      if (dpy != EGL_NO_DISPLAY) return dpy;
      why = "eglGetPlatformDisplayEXT(EGL_PLATFORM_DEVICE_EXT) failed: " + eglErrorString(eglGetError());
    }
  }
  if (hasExtension(clientExts, "EGL_MESA_platform_surfaceless")) {
    info.platform = "EGL surfaceless (Mesa)";
    info.eglDevice.clear();
    EGLDisplay dpy = eglGetPlatformDisplayEXT(EGL_PLATFORM_SURFACELESS_MESA, EGL_DEFAULT_DISPLAY, nullptr);
    if (dpy != EGL_NO_DISPLAY) return dpy;
    why = "eglGetPlatformDisplayEXT(EGL_PLATFORM_SURFACELESS_MESA) failed: " + eglErrorString(eglGetError());
  } else if (why.empty()) {
    why =
        "no EGL device with EGL_NV_device_cuda and no EGL_MESA_platform_surfaceless "
        "(install libegl-mesa0 and libgl1-mesa-dri for llvmpipe)";
  }
  return EGL_NO_DISPLAY;
}

}  // namespace

bool ContextInfo::isSoftware() const {
  return renderer.find("llvmpipe") != std::string::npos || renderer.find("softpipe") != std::string::npos;
}

ContextInfo queryContextInfo() {
  ContextInfo info;
  info.vendor = str(reinterpret_cast<const char*>(glGetString(GL_VENDOR)));
  info.renderer = str(reinterpret_cast<const char*>(glGetString(GL_RENDERER)));
  info.version = str(reinterpret_cast<const char*>(glGetString(GL_VERSION)));
  info.glsl = str(reinterpret_cast<const char*>(glGetString(GL_SHADING_LANGUAGE_VERSION)));
  return info;
}

ContextLimits queryContextLimits() {
  ContextLimits l;
  glGetIntegerv(GL_MAX_TEXTURE_SIZE, &l.maxTextureSize);
  glGetIntegerv(GL_MAX_ARRAY_TEXTURE_LAYERS, &l.maxArrayTextureLayers);
  glGetIntegerv(GL_MAX_3D_TEXTURE_SIZE, &l.max3dTextureSize);
  for (GLuint i = 0; i < 3; ++i) {
    glGetIntegeri_v(GL_MAX_COMPUTE_WORK_GROUP_COUNT, i, &l.maxComputeWorkGroupCount[i]);
    glGetIntegeri_v(GL_MAX_COMPUTE_WORK_GROUP_SIZE, i, &l.maxComputeWorkGroupSize[i]);
  }
  glGetIntegerv(GL_MAX_COMPUTE_WORK_GROUP_INVOCATIONS, &l.maxComputeWorkGroupInvocations);
  glGetIntegerv(GL_MAX_COMPUTE_SHARED_MEMORY_SIZE, &l.maxComputeSharedMemorySize);
  GLint64 ssbo = 0;
  glGetInteger64v(GL_MAX_SHADER_STORAGE_BLOCK_SIZE, &ssbo);
  l.maxShaderStorageBlockSize = ssbo;
  glGetIntegerv(GL_MAX_SHADER_STORAGE_BUFFER_BINDINGS, &l.maxShaderStorageBufferBindings);
  glGetIntegerv(GL_MAX_IMAGE_UNITS, &l.maxImageUnits);
  glGetIntegerv(GL_MAX_UNIFORM_BLOCK_SIZE, &l.maxUniformBlockSize);
  glGetIntegerv(GL_MAX_SAMPLES, &l.maxSamples);
  GLint bits = 0;
  glGetQueryiv(GL_TIME_ELAPSED, GL_QUERY_COUNTER_BITS, &bits);
  l.timerQuery = bits > 0;
  return l;
}

long errorCount() { return tErrorCount; }

// ---------------------------------------------------------------------------------------------
// Headless (EGL)

struct HeadlessContext::Impl {
  EGLDisplay display = EGL_NO_DISPLAY;
  EGLContext context = EGL_NO_CONTEXT;
  EGLSurface surface = EGL_NO_SURFACE;  // a 1x1 pbuffer only where surfaceless contexts are missing
  GLuint fbo = 0;
  ContextInfo info;

  ~Impl() {
    if (context != EGL_NO_CONTEXT) {
      eglMakeCurrent(display, surface, surface, context);
      if (fbo) glDeleteFramebuffers(1, &fbo);
      eglMakeCurrent(display, EGL_NO_SURFACE, EGL_NO_SURFACE, EGL_NO_CONTEXT);
      if (surface != EGL_NO_SURFACE) eglDestroySurface(display, surface);
      eglDestroyContext(display, context);
    }
    // The display is shared per device by EGL and may serve other contexts: not terminated.
  }
};

HeadlessContext::HeadlessContext(std::unique_ptr<Impl> impl) : impl_(std::move(impl)) {}
HeadlessContext::HeadlessContext(HeadlessContext&&) noexcept = default;
HeadlessContext& HeadlessContext::operator=(HeadlessContext&&) noexcept = default;
HeadlessContext::~HeadlessContext() = default;

Result<HeadlessContext> HeadlessContext::create(const HeadlessOptions& options) {
  auto impl = std::make_unique<Impl>();
  std::string want = options.device;
  std::string source = "device '" + want + "'";
  if (const char* env = std::getenv("STRATA_EGL_DEVICE"); env && *env) {
    want = env;
    source = std::string("STRATA_EGL_DEVICE=") + env;
  }
  // "auto", "surfaceless", a device number or gpu:K (the K-th NVIDIA device, one per MPI rank):
  // anything else was once taken as device 0.
  auto number = [](std::string_view text) {
    int v = 0;
    const auto [end, ec] = std::from_chars(text.data(), text.data() + text.size(), v);
    return ec == std::errc() && end == text.data() + text.size() && v >= 0 && text.size() <= 6;
  };
  const bool gpuK = want.rfind("gpu:", 0) == 0 && number(std::string_view(want).substr(4));
  if (want != "auto" && want != "surfaceless" && !gpuK && !number(want)) {
    return fail("egl: " + source + ": expected auto, surfaceless, an EGL device number or gpu:<k>");
  }
  // libepoxy loads libEGL on the first EGL call and aborts the process when it cannot: try first.
  if (!::dlopen("libEGL.so.1", RTLD_LAZY | RTLD_LOCAL)) {
    const char* err = ::dlerror();
    return fail(std::string("egl: cannot load libEGL.so.1 (") + (err ? err : "not found") +
                "); install libegl1, and libegl-mesa0 with libgl1-mesa-dri for llvmpipe");
  }
  std::string why;
  impl->display = chooseDisplay(want, impl->info, why);
  if (impl->display == EGL_NO_DISPLAY) return fail("egl: " + source + ": " + why);
  EGLint major = 0, minor = 0;
  if (!eglInitialize(impl->display, &major, &minor)) {
    return fail("egl: eglInitialize failed on " + impl->info.platform + ": " + eglErrorString(eglGetError()));
  }
  impl->info.eglVendor = str(eglQueryString(impl->display, EGL_VENDOR));
  impl->info.eglVersion = str(eglQueryString(impl->display, EGL_VERSION));
  if (!eglBindAPI(EGL_OPENGL_API))
    return fail("egl: eglBindAPI(EGL_OPENGL_API) failed: " + eglErrorString(eglGetError()));

  const char* dpyExts = eglQueryString(impl->display, EGL_EXTENSIONS);
  EGLConfig config = EGL_NO_CONFIG_KHR;
  const bool noConfig = hasExtension(dpyExts, "EGL_KHR_no_config_context");
  const bool surfaceless = hasExtension(dpyExts, "EGL_KHR_surfaceless_context");
  if (!noConfig || !surfaceless) {
    const EGLint cfgAttribs[] = {EGL_SURFACE_TYPE, EGL_PBUFFER_BIT, EGL_RENDERABLE_TYPE, EGL_OPENGL_BIT, EGL_NONE};
    EGLint count = 0;
    if (!eglChooseConfig(impl->display, cfgAttribs, &config, 1, &count) || count < 1) {
      return fail("egl: no EGL config for desktop OpenGL on " + impl->info.platform);
    }
  }
  const EGLint ctxAttribs[] = {EGL_CONTEXT_MAJOR_VERSION,
                               4,
                               EGL_CONTEXT_MINOR_VERSION,
                               5,
                               EGL_CONTEXT_OPENGL_PROFILE_MASK,
                               EGL_CONTEXT_OPENGL_CORE_PROFILE_BIT,
                               EGL_CONTEXT_OPENGL_DEBUG,
                               options.debugOutput ? EGL_TRUE : EGL_FALSE,
                               EGL_NONE};
  impl->context = eglCreateContext(impl->display, config, EGL_NO_CONTEXT, ctxAttribs);
  if (impl->context == EGL_NO_CONTEXT) {
    return fail("egl: cannot create an OpenGL 4.5 core context on " + impl->info.platform + ": " +
                eglErrorString(eglGetError()));
  }
  if (!surfaceless) {
    const EGLint pb[] = {EGL_WIDTH, 1, EGL_HEIGHT, 1, EGL_NONE};
    impl->surface = eglCreatePbufferSurface(impl->display, config, pb);
  }
  if (!eglMakeCurrent(impl->display, impl->surface, impl->surface, impl->context)) {
    return fail("egl: eglMakeCurrent failed: " + eglErrorString(eglGetError()));
  }
  if (epoxy_gl_version() < 45)
    return fail("egl: the context is not OpenGL 4.5 (got " + std::to_string(epoxy_gl_version()) + ")");
  if (options.debugOutput) installDebugOutput();

  // Stand-in for framebuffer 0: no attachments, so any draw has a complete framebuffer.
  glCreateFramebuffers(1, &impl->fbo);
  glNamedFramebufferParameteri(impl->fbo, GL_FRAMEBUFFER_DEFAULT_WIDTH, 1);
  glNamedFramebufferParameteri(impl->fbo, GL_FRAMEBUFFER_DEFAULT_HEIGHT, 1);
  glBindFramebuffer(GL_FRAMEBUFFER, impl->fbo);

  const std::string platform = impl->info.platform, device = impl->info.eglDevice, ev = impl->info.eglVendor,
                    evv = impl->info.eglVersion;
  impl->info = queryContextInfo();
  impl->info.platform = platform;
  impl->info.eglDevice = device;
  impl->info.eglVendor = ev;
  impl->info.eglVersion = evv;
  log::debug("gl") << "headless context: " << impl->info.renderer << ", " << impl->info.version << " via "
                   << impl->info.platform;
  return HeadlessContext(std::move(impl));
}

void HeadlessContext::makeCurrent() {
  eglMakeCurrent(impl_->display, impl_->surface, impl_->surface, impl_->context);
  glBindFramebuffer(GL_FRAMEBUFFER, impl_->fbo);
}

const ContextInfo& HeadlessContext::info() const { return impl_->info; }

void HeadlessContext::bindDefaultFramebuffer() { glBindFramebuffer(GL_FRAMEBUFFER, impl_->fbo); }

// ---------------------------------------------------------------------------------------------
// Window (GLFW)

namespace {
std::mutex gGlfwMutex;
int gGlfwUsers = 0;
void glfwErrorCallback(int code, const char* description) { log::error("glfw") << description << " (" << code << ")"; }
}  // namespace

struct WindowContext::Impl {
  GLFWwindow* window = nullptr;
  ContextInfo info;
  ~Impl() {
    if (window) glfwDestroyWindow(window);
    std::lock_guard lock(gGlfwMutex);
    if (--gGlfwUsers == 0) glfwTerminate();
  }
};

WindowContext::WindowContext(std::unique_ptr<Impl> impl) : impl_(std::move(impl)) {}
WindowContext::WindowContext(WindowContext&&) noexcept = default;
WindowContext& WindowContext::operator=(WindowContext&&) noexcept = default;
WindowContext::~WindowContext() = default;

Result<WindowContext> WindowContext::create(const WindowOptions& options) {
  {
    std::lock_guard lock(gGlfwMutex);
    glfwSetErrorCallback(glfwErrorCallback);
    if (gGlfwUsers == 0 && !glfwInit()) {
      return fail("glfw: cannot initialise (GLFW 3.3 on Debian needs an X server: is DISPLAY set? Xvfb works)");
    }
    ++gGlfwUsers;
  }
  auto impl = std::make_unique<Impl>();
  glfwDefaultWindowHints();
  glfwWindowHint(GLFW_CONTEXT_VERSION_MAJOR, 4);
  glfwWindowHint(GLFW_CONTEXT_VERSION_MINOR, 5);
  glfwWindowHint(GLFW_OPENGL_PROFILE, GLFW_OPENGL_CORE_PROFILE);
  glfwWindowHint(GLFW_OPENGL_FORWARD_COMPAT, GLFW_TRUE);
  glfwWindowHint(GLFW_OPENGL_DEBUG_CONTEXT, options.debugOutput ? GLFW_TRUE : GLFW_FALSE);
  glfwWindowHint(GLFW_VISIBLE, options.visible ? GLFW_TRUE : GLFW_FALSE);
  impl->window = glfwCreateWindow(options.width, options.height, options.title.c_str(), nullptr, nullptr);
  if (!impl->window) return fail("glfw: cannot create an OpenGL 4.5 core window");
  glfwMakeContextCurrent(impl->window);
  glfwSwapInterval(options.vsync ? 1 : 0);
  if (options.debugOutput) installDebugOutput();
  impl->info = queryContextInfo();
  impl->info.platform = "GLFW window";
  return WindowContext(std::move(impl));
}

void WindowContext::makeCurrent() { glfwMakeContextCurrent(impl_->window); }
const ContextInfo& WindowContext::info() const { return impl_->info; }
GLFWwindow* WindowContext::window() const { return impl_->window; }
bool WindowContext::shouldClose() const { return glfwWindowShouldClose(impl_->window); }
void WindowContext::swapBuffers() { glfwSwapBuffers(impl_->window); }
void WindowContext::pollEvents() { glfwPollEvents(); }
void WindowContext::framebufferSize(int& width, int& height) const {
  glfwGetFramebufferSize(impl_->window, &width, &height);
}

}  // namespace strata::gl
