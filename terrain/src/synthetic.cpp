#include <strata/terrain/synthetic.hpp>

namespace strata::terrain {
namespace {

// A 32-bit integer hash (lowbias32, by Chris Wellons): cheap, and good enough for white noise.
uint32_t hash32(uint32_t x) {
  x ^= x >> 16;
  x *= 0x7feb352dU;
  x ^= x >> 15;
  x *= 0x846ca68bU;
  x ^= x >> 16;
  return x;
}

float unit(uint32_t h) { return float(h >> 8) * (1.0f / 16777216.0f); }  // [0, 1), 24 bits

}  // namespace

SyntheticBlock syntheticBlockKind(const SyntheticScene& s, int bx, int by) {
  const float u = unit(hash32(uint32_t(bx) * 0x9e3779b9U ^ hash32(uint32_t(by) + s.seed * 0x85ebca6bU)));
  if (u < s.roughFraction) return SyntheticBlock::Rough;
  if (u < s.roughFraction + s.rampFraction) return SyntheticBlock::Ramp;
  return SyntheticBlock::Flat;
}

float syntheticElevation(const SyntheticScene& s, int x, int y) {
  const int n = s.blockCells;
  switch (syntheticBlockKind(s, x / n, y / n)) {
    case SyntheticBlock::Flat: return s.baseM;
    case SyntheticBlock::Ramp: return s.baseM + 0.3f * s.amplitudeM * float(x % n) / float(n - 1);
    case SyntheticBlock::Rough:
      return s.baseM + s.amplitudeM * unit(hash32(uint32_t(x) ^ hash32(uint32_t(y) ^ s.seed)));
  }
  return s.baseM;
}

WindowReader syntheticReader(const SyntheticScene& s) {
  return [s](int x0, int y0, int w, int h) -> Result<gis::Grid<float>> {
    gis::Grid<float> g(w, h);
    for (int y = 0; y < h; ++y) {
      for (int x = 0; x < w; ++x) g.at(x, y) = syntheticElevation(s, x0 + x, y0 + y);
    }
    return g;
  };
}

}  // namespace strata::terrain
