#pragma once
// The headless GL context every GPU benchmark program shares: created once, on first use, with
// GL debug output off (it costs time on every call); a program that cannot get one exits with the
// reason. benchGlMain() is the main() of those programs: it records the renderer and GL version
// in the benchmark's JSON context so figures say what they were measured on.

#include <benchmark/benchmark.h>

#include <cstdio>
#include <cstdlib>
#include <optional>

#include <strata/gl/context.hpp>

namespace strata::bench {

inline gl::HeadlessContext& sharedContext() {
  static std::optional<gl::HeadlessContext> c = [] {
    auto r = gl::HeadlessContext::create({.debugOutput = false});
    if (!r) {
      std::fprintf(stderr, "%s\n", r.message().c_str());
      std::exit(1);
    }
    return std::optional<gl::HeadlessContext>(std::move(r).value());
  }();
  return *c;
}

inline int benchGlMain(int argc, char** argv) {
  benchmark::Initialize(&argc, argv);
  const auto& i = sharedContext().info();
  benchmark::AddCustomContext("gl_renderer", i.renderer);
  benchmark::AddCustomContext("gl_version", i.version);
  benchmark::RunSpecifiedBenchmarks();
  benchmark::Shutdown();
  return 0;
}

}  // namespace strata::bench
