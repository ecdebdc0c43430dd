#pragma once
// Synthetic DEMs for demos, tests and benchmarks (no file needed): a rough fractal terrain.

#include <cstdint>

#include <strata/gis/raster.hpp>

namespace strata::render {

/// A rough fractal terrain: octaves of smoothed value noise from half the grid's size down to a
/// 2-cell period, each 0.55 of the previous amplitude. `size`^2 cells of `cellM` metres on a
/// projected grid with its top-left corner at easting 500 km, northing 4000 km (realistic CRS
/// magnitudes); elevations around `amplitudeM` (roughly 0 .. 2 * amplitudeM).
gis::Raster syntheticDem(int size, double cellM, double amplitudeM, uint32_t seed);

}  // namespace strata::render
