#pragma once
// A synthetic terrain of any size, computed cell by cell (nothing held in memory), for tests and
// benchmarks of the store: square blocks that are flat, gently ramped or rough noise.

#include <cstdint>

#include <strata/terrain/ingest.hpp>

namespace strata::terrain {

/// What a block of the synthetic scene is.
enum class SyntheticBlock { Flat, Ramp, Rough };

/// Parameters of the synthetic scene.
struct SyntheticScene {
  int blockCells = 1024;       ///< block side (cells); align with the store footprint to test the metric
  float rampFraction = 0.3f;   ///< share of blocks that ramp by 30% of the amplitude across the block
  float roughFraction = 0.2f;  ///< share of blocks of white noise over the full amplitude
  float baseM = 100.0f;        ///< elevation of flat blocks (m)
  float amplitudeM = 1000.0f;  ///< noise amplitude (m): rough blocks span [base, base + amplitude)
  uint32_t seed = 1;
};

/// The kind of block (bx, by), a deterministic function of the seed.
SyntheticBlock syntheticBlockKind(const SyntheticScene& s, int bx, int by);
/// Elevation of cell (x, y) (m).
float syntheticElevation(const SyntheticScene& s, int x, int y);
/// A window reader over the scene (for ingest).
WindowReader syntheticReader(const SyntheticScene& s);

}  // namespace strata::terrain
