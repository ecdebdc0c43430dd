// strata gpu-info: which GPU (or llvmpipe) Strata's headless context runs on, and its limits.
#include <cstdio>

#include <strata/gl/context.hpp>

#include "commands.hpp"

namespace strata::app {

void addGpuInfoCommand(CLI::App& app) {
  auto* cmd = app.add_subcommand("gpu-info", "Print the EGL device, GL renderer and the limits that matter");
  auto device = std::make_shared<std::string>("auto");
  cmd->add_option("--device", *device, "EGL device: auto, surfaceless, or an index (env STRATA_EGL_DEVICE)");
  cmd->callback([device] {
    auto ctx = gl::HeadlessContext::create({.device = *device, .debugOutput = false});
    if (!ctx) {
      exitCommand("gpu-info", ctx.message());
    }
    const auto& i = ctx->info();
    const auto l = gl::queryContextLimits();
    std::printf("EGL platform        %s\n", i.platform.c_str());
    if (!i.eglDevice.empty()) std::printf("EGL device          %s\n", i.eglDevice.c_str());
    std::printf("EGL vendor/version  %s / %s\n", i.eglVendor.c_str(), i.eglVersion.c_str());
    std::printf("GL vendor           %s\n", i.vendor.c_str());
    std::printf("GL renderer         %s%s\n", i.renderer.c_str(), i.isSoftware() ? "  (software rasteriser)" : "");
    std::printf("GL version          %s\n", i.version.c_str());
    std::printf("GLSL version        %s\n", i.glsl.c_str());
    std::printf("max texture size    %d (array layers %d, 3D %d)\n", l.maxTextureSize, l.maxArrayTextureLayers,
                l.max3dTextureSize);
    std::printf("compute group size  %d x %d x %d (%d invocations, %d B shared)\n", l.maxComputeWorkGroupSize[0],
                l.maxComputeWorkGroupSize[1], l.maxComputeWorkGroupSize[2], l.maxComputeWorkGroupInvocations,
                l.maxComputeSharedMemorySize);
    std::printf("compute group count %d x %d x %d\n", l.maxComputeWorkGroupCount[0], l.maxComputeWorkGroupCount[1],
                l.maxComputeWorkGroupCount[2]);
    std::printf("SSBO                %lld MiB max block, %d bindings\n", l.maxShaderStorageBlockSize >> 20,
                l.maxShaderStorageBufferBindings);
    std::printf("image units         %d\n", l.maxImageUnits);
    std::printf("uniform block       %d B\n", l.maxUniformBlockSize);
    std::printf("timer queries       %s\n", l.timerQuery ? "yes" : "no");
  });
}

}  // namespace strata::app
