#pragma once
// One way to get an OpenGL 4.5 core context:
//  - HeadlessContext: EGL with no window. Picks an NVIDIA GPU through EGL_EXT_platform_device
//    when there is one, else Mesa's surfaceless platform (llvmpipe on machines without a GPU).
//    A surfaceless context has no default framebuffer, so the context owns an FBO with no
//    attachments and keeps it bound: draws never hit the undefined framebuffer 0.
//  - WindowContext: a GLFW window (X11 on Debian; Xvfb in tests).
// Both route GL debug output to the logger (category "gl") and count GL errors.

#include <memory>
#include <string>

#include <strata/core/result.hpp>

struct GLFWwindow;

namespace strata::gl {

/// What a context runs on, for `strata gpu-info`, logs and test reports.
struct ContextInfo {
  std::string platform;   ///< "EGL device", "EGL surfaceless (Mesa)", "GLFW window"
  std::string eglDevice;  ///< EGL device description (extensions / DRM node), if any
  std::string eglVendor, eglVersion;
  std::string vendor, renderer, version, glsl;
  bool isSoftware() const;  ///< llvmpipe / softpipe
};

/// Limits that matter to Strata's kernels and renderers.
struct ContextLimits {
  int maxTextureSize = 0, maxArrayTextureLayers = 0, max3dTextureSize = 0;
  int maxComputeWorkGroupCount[3] = {0, 0, 0};
  int maxComputeWorkGroupSize[3] = {0, 0, 0};
  int maxComputeWorkGroupInvocations = 0, maxComputeSharedMemorySize = 0;
  long long maxShaderStorageBlockSize = 0;
  int maxShaderStorageBufferBindings = 0, maxImageUnits = 0, maxUniformBlockSize = 0;
  int maxSamples = 0;
  bool timerQuery = false;
};

ContextInfo queryContextInfo();
ContextLimits queryContextLimits();

/// Number of GL errors reported through debug output on this thread's contexts so far.
long errorCount();

struct HeadlessOptions {
  /// "auto" (NVIDIA device if present, else surfaceless), "surfaceless", a device index, or
  /// "gpu:K" (the K-th NVIDIA device, wrapping; surfaceless if none: one GPU per local MPI rank).
  /// Overridden by the environment variable STRATA_EGL_DEVICE.
  std::string device = "auto";
  bool debugOutput = true;  ///< GL_KHR_debug messages to the logger (synchronous)
};

class HeadlessContext {
 public:
  static Result<HeadlessContext> create(const HeadlessOptions& options = {});
  HeadlessContext(HeadlessContext&&) noexcept;
  HeadlessContext& operator=(HeadlessContext&&) noexcept;
  ~HeadlessContext();

  void makeCurrent();
  const ContextInfo& info() const;
  /// Binds the context's own attachment-less FBO (the stand-in for framebuffer 0).
  void bindDefaultFramebuffer();

 private:
  struct Impl;
  explicit HeadlessContext(std::unique_ptr<Impl> impl);
  std::unique_ptr<Impl> impl_;
};

struct WindowOptions {
  int width = 1280, height = 720;
  std::string title = "Strata";
  bool visible = true;
  bool vsync = true;
  bool debugOutput = true;
};

class WindowContext {
 public:
  static Result<WindowContext> create(const WindowOptions& options = {});
  WindowContext(WindowContext&&) noexcept;
  WindowContext& operator=(WindowContext&&) noexcept;
  ~WindowContext();

  void makeCurrent();
  const ContextInfo& info() const;
  GLFWwindow* window() const;
  bool shouldClose() const;
  void swapBuffers();
  void pollEvents();
  /// Framebuffer size in pixels.
  void framebufferSize(int& width, int& height) const;

 private:
  struct Impl;
  explicit WindowContext(std::unique_ptr<Impl> impl);
  std::unique_ptr<Impl> impl_;
};

}  // namespace strata::gl
