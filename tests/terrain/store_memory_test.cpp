// Streaming ingest: memory is bounded by the tile size, not the input size. Its own binary,
// because it replaces the global operator new to count live heap bytes (which, unlike RSS, means
// the same under AddressSanitizer, whose quarantine keeps freed memory resident).
#include <gtest/gtest.h>

#include <malloc.h>

#include <atomic>
#include <cstdlib>
#include <fstream>
#include <new>

#include <strata/terrain/ingest.hpp>
#include <strata/terrain/synthetic.hpp>
#include <strata/terrain/tile_store.hpp>

#include "strata_test.hpp"

namespace {
std::atomic<long> gLiveBytes{0}, gPeakBytes{0};

void* countedAlloc(size_t n) {
  void* p = std::malloc(n ? n : 1);
  if (!p) throw std::bad_alloc();
  const long live = gLiveBytes += long(malloc_usable_size(p));
  long peak = gPeakBytes.load();
  while (live > peak && !gPeakBytes.compare_exchange_weak(peak, live)) {
  }
  return p;
}
void countedFree(void* p) {
  if (!p) return;
  gLiveBytes -= long(malloc_usable_size(p));
  std::free(p);
}
}  // namespace

void* operator new(size_t n) { return countedAlloc(n); }
void* operator new[](size_t n) { return countedAlloc(n); }
void operator delete(void* p) noexcept { countedFree(p); }
void operator delete[](void* p) noexcept { countedFree(p); }
void operator delete(void* p, size_t) noexcept { countedFree(p); }
void operator delete[](void* p, size_t) noexcept { countedFree(p); }

namespace strata::terrain {
namespace {

long rssKb(const char* key) {
  std::ifstream in("/proc/self/status");
  std::string line;
  while (std::getline(in, line)) {
    if (line.rfind(key, 0) == 0) return std::stol(line.substr(std::string(key).size()));
  }
  return -1;
}

TEST(Ingest, PeakMemoryIsBoundedByTheTileNotTheInput) {
  // 4096 x 4096 float32 = 64 MiB of input, tiles of 256 cells (256 KiB per field). The ingest
  // holds a few tiles at a time; bench/bench_store.cpp and `strata ingest` under /usr/bin/time -v
  // check the same at 32768^2 (4 GiB), see docs/benchmarks.md.
  SyntheticScene s;
  s.blockCells = 256;
  gis::Georef g;
  g.width = g.height = 4096;
  const auto dir = test::tempDir("big");
  IngestOptions o;
  o.metric = {3, 8};
  o.cache.prefetch = false;
  malloc_trim(0);                                 // freed heap back to the system: RSS growth is real
  std::ofstream("/proc/self/clear_refs") << "5";  // reset the peak RSS (VmHWM)
  const long rssBefore = rssKb("VmRSS:");
  const long heapBefore = gLiveBytes.load();
  gPeakBytes = heapBefore;
  auto rep = ingest(dir, g, {{{"bedrock", LayerKind::Bedrock, ""}, syntheticReader(s)}}, o);
  ASSERT_TRUE(rep) << rep.message();
  const long heapGrewKb = (gPeakBytes.load() - heapBefore) / 1024;
  const long rssGrewKb = rssKb("VmHWM:") - rssBefore;
  std::cout << "ingest of 64 MiB: peak live heap grew by " << heapGrewKb << " kB, peak RSS by " << rssGrewKb << " kB\n";
  // 1/8 of the input (8 MiB = 32 tiles' worth) is far above what a tile-at-a-time ingest needs
  // (a tile, its box means and mips, its EXR bytes: ~1 MiB) and far below a whole-input copy.
  EXPECT_LT(heapGrewKb, 64 * 1024 / 8);
#ifndef __SANITIZE_ADDRESS__
  EXPECT_LT(rssGrewKb, 64 * 1024 / 8);  // under ASan the quarantine keeps freed blocks resident
#endif
  // Complex tiles read back cell for cell at full resolution.
  auto store = TileStore::open(dir, o.cache);
  ASSERT_TRUE(store);
  int checked = 0;
  for (int by = 0; by < 16 && checked < 4; ++by) {
    for (int bx = 0; bx < 16 && checked < 4; ++bx) {
      if (syntheticBlockKind(s, bx, by) != SyntheticBlock::Rough) continue;
      ASSERT_EQ(store->tile(bx, by).exp, 8);
      auto w = store->readWindow(0, {bx * 256, by * 256, 256, 256}, 0);
      ASSERT_TRUE(w);
      for (int y = 0; y < 256; ++y) {
        for (int x = 0; x < 256; ++x) ASSERT_EQ(w->at(x, y), syntheticElevation(s, bx * 256 + x, by * 256 + y));
      }
      ++checked;
    }
  }
  EXPECT_EQ(checked, 4);
}

}  // namespace
}  // namespace strata::terrain
