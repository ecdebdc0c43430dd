#pragma once
// The headless GL context every GPU benchmark program shares: created once, on first use, with
// GL debug output off (it costs time on every call); a program that cannot get one exits with the
// reason. benchGlMain() is the main() of those programs: it records the renderer and GL version
// in the benchmark's JSON context so figures say what they were measured on.

#include <benchmark/benchmark.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <optional>
#include <string_view>

#include <strata/gl/context.hpp>
#include <strata/gl/objects.hpp>
#include <strata/gl/state.hpp>

namespace strata::bench {

// The slot benchGlMain empties before returning: NVIDIA's EGL crashed destroying a context from a
// static destructor after main.
inline std::optional<gl::HeadlessContext>& contextSlot() {
  static std::optional<gl::HeadlessContext> c;
  return c;
}

inline gl::HeadlessContext& sharedContext() {
  auto& c = contextSlot();
  if (!c) {
    auto r = gl::HeadlessContext::create({.debugOutput = false});
    if (!r) {
      std::fprintf(stderr, "%s\n", r.message().c_str());
      std::exit(1);
    }
    c.emplace(std::move(r).value());
  }
  return *c;
}

// The GL device's memory bandwidth as its shader cores see it: bytes read + written per second by
// tests/gl/shaders/stream_copy.comp copying a 256 MiB buffer, four copies per timing (so launch
// latency stays small beside them), best of 5 timings, wall time to glFinish. `groupX` 0: 16-byte
// elements in 1-D groups, the best case; else 4-byte floats of an 8192-wide grid in groupX x
// (256 / groupX) groups, as the simulation's kernels read their grids. 0 when the shader cannot
// be built.
// (glCopyBufferSubData is no floor: NVIDIA runs it on a copy engine, at a tenth of this.)
inline double shaderCopyGBs(int groupX, size_t bytes = size_t(256) << 20) {
  const bool vec4 = groupX == 0;
  const gl::ShaderDefine defines[] = {{"VEC4", vec4 ? 1 : 0}, {"GROUP_X", vec4 ? 16 : groupX}};
  auto prog = gl::Program::compute("tests/gl/shaders/stream_copy.comp", defines);
  if (!prog) return 0;
  gl::Buffer a(bytes), b(bytes);
  a.fill(0x3f800000u);
  b.fill(0u);
  a.bindStorage(0);
  b.bindStorage(1);
  const int width = 8192, height = int(bytes / 4 / size_t(width));
  if (vec4) {
    prog->set("uCount", unsigned(bytes / 16));
  } else {
    prog->set("uWidth", width);
    prog->set("uHeight", height);
  }
  auto copy = [&] {
    if (vec4) {
      prog->dispatchCovering(8192 * 256);
    } else {
      prog->dispatchCovering(width, height);
    }
    gl::memoryBarrier(gl::Barrier::kStorage);
  };
  copy();  // first touch, compilation
  gl::finish();
  double best = 1e30;
  for (int r = 0; r < 5; ++r) {
    const auto t0 = std::chrono::steady_clock::now();
    for (int k = 0; k < 4; ++k) copy();
    gl::finish();
    best = std::min(best, std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count() / 4);
  }
  return 2.0 * double(bytes) / best / 1e9;
}

// The bandwidth is measured only for a run (not to list the benchmarks), and on a software
// renderer (llvmpipe: "device" memory is the host's) with one 64 MiB copy: the four 256 MiB
// copies took about 5 minutes there before any benchmark ran.
inline int benchGlMain(int argc, char** argv) {
  bool listing = false;
  for (int k = 1; k < argc; ++k) listing |= std::string_view(argv[k]).starts_with("--benchmark_list_tests");
  benchmark::Initialize(&argc, argv);
  const auto& i = sharedContext().info();
  benchmark::AddCustomContext("gl_renderer", i.renderer);
  benchmark::AddCustomContext("gl_version", i.version);
  if (!listing) {
    char text[200];
    if (i.renderer.find("llvmpipe") != std::string::npos) {
      std::snprintf(text, sizeof text, "%.1f GB/s (vec4, 64 MiB; software renderer)",
                    shaderCopyGBs(0, size_t(64) << 20));
    } else {
      std::snprintf(text, sizeof text,
                    "%.1f GB/s (vec4); floats in groups of 16 x 16: %.1f, 32 x 8: %.1f, 64 x 4: %.1f GB/s",
                    shaderCopyGBs(0), shaderCopyGBs(16), shaderCopyGBs(32), shaderCopyGBs(64));
    }
    benchmark::AddCustomContext("gl_shader_copy", text);
  }
  benchmark::RunSpecifiedBenchmarks();
  benchmark::Shutdown();
  contextSlot().reset();
  return 0;
}

}  // namespace strata::bench
