// GL layer baselines: the device's copy bandwidth (the floor every memory-bound kernel is
// measured against) and a 5-point r32f stencil pass, timed with GPU timer queries.
//   build/bench/strata_bench_gl [--benchmark_filter=...]
#include <benchmark/benchmark.h>

#include "bench_context.hpp"

#include <strata/gl/objects.hpp>
#include <strata/gl/state.hpp>
#include "grid_params.hpp"

namespace {
using namespace strata;

// Device-to-device copy: bytes read + bytes written per second.
void BM_BufferCopy(benchmark::State& state) {
  strata::bench::sharedContext();
  const size_t bytes = size_t(state.range(0)) << 20;
  gl::Buffer a(bytes), b(bytes);
  a.fill(0x3f800000u);
  for (auto _ : state) {
    gl::GpuTimer t;
    t.begin();
    a.copyTo(b, bytes);
    t.end();
    state.SetIterationTime(t.milliseconds() * 1e-3);
  }
  state.SetBytesProcessed(int64_t(state.iterations()) * int64_t(2 * bytes));
}
BENCHMARK(BM_BufferCopy)->Arg(64)->Arg(256)->UseManualTime()->Unit(benchmark::kMillisecond);

void BM_LaplacianStencil(benchmark::State& state) {
  strata::bench::sharedContext();
  const int n = int(state.range(0));
  auto src = gl::Texture::create2D(gl::TextureFormat::kR32F, n, n),
       dst = gl::Texture::create2D(gl::TextureFormat::kR32F, n, n);
  std::vector<float> zeros(size_t(n) * size_t(n), 1.0f);
  src.upload(zeros.data());
  test::GridParams g;
  g.size = {n, n};
  gl::Buffer params(sizeof g, &g);
  auto prog = gl::Program::compute("tests/gl/shaders/laplacian.comp");
  if (!prog) {
    state.SkipWithError(prog.message().c_str());
    return;
  }
  src.bindImage(0, gl::Access::kRead);
  dst.bindImage(1, gl::Access::kWrite);
  params.bindStorage(2);
  for (auto _ : state) {
    gl::GpuTimer t;
    t.begin();
    prog->dispatchCovering(n, n);
    gl::memoryBarrier(gl::Barrier::kImageAccess);
    t.end();
    state.SetIterationTime(t.milliseconds() * 1e-3);
  }
  // Floor: one read and one write of each cell (neighbours come from cache).
  state.SetBytesProcessed(int64_t(state.iterations()) * int64_t(n) * n * 8);
  state.counters["cells/s"] =
      benchmark::Counter(double(n) * n * double(state.iterations()), benchmark::Counter::kIsRate);
}
BENCHMARK(BM_LaplacianStencil)->Arg(256)->Arg(1024)->Arg(2048)->UseManualTime()->Unit(benchmark::kMillisecond);

}  // namespace

int main(int argc, char** argv) { return strata::bench::benchGlMain(argc, argv); }
