#pragma once
// Host-side pieces both solvers share, so the CPU reference and the GPU run take the same
// steps: the time step rule (W10), source merging (W12) and the rain volume rate.

#include <cstdint>
#include <vector>

#include <strata/terrain/sim/sim_params.hpp>

namespace strata::terrain::sim {

/// One cell fed by sources this step (std430 mirror of `SourceEntry` in shaders/common/sim.glsl).
struct SourceEntry {
  uint32_t cell = 0;     ///< y * width + x
  float rateM3S = 0.0f;  ///< discharge into that cell (m^3/s)
};
static_assert(sizeof(SourceEntry) == 8);

/// The sources' mean discharges over [t0S, t1S] (exact integrals of the hydrographs), merged
/// per cell (each cell once, sorted by cell index).
std::vector<SourceEntry> mergeSources(const std::vector<Source>& sources, int width, double t0S, double t1S);

/// Step length (W10): maxDtS when cflAlpha <= 0 or the domain is still; otherwise
/// alpha * minCellM / maxWaveSpeedMS, capped by maxDtS. `maxWaveSpeedMS` is max(|u| + sqrt(g h)).
double stepDt(const SimParams& params, double maxWaveSpeedMS, double minCellM);

/// Smallest cell side over all rows (m).
double minCellSize(const std::vector<double>& rowDxM, double dyM);

/// Rain falling on the whole domain (m^3/s): uniform rate plus the raster, times cell areas.
double rainVolumeRate(const SimParams& params, const std::vector<float>& rainRasterMmH,
                      const std::vector<double>& rowDxM, int width);

/// sum over cells of value * cell area (m^3), in double; `values` is row-major width x rows, or
/// several such grids one after another (a layer stack).
double integrate(const std::vector<float>& values, const std::vector<double>& rowDxM, double dyM, int width,
                 size_t offset = 0);

}  // namespace strata::terrain::sim
