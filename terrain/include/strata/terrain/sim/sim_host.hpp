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

/// One cell held at a fixed level this step (std430 mirror of `LevelEntry` in shaders/common/sim.glsl).
struct LevelEntry {
  uint32_t cell = 0;    ///< y * width + x
  float stageM = 0.0f;  ///< water surface elevation relative to the datum (m)
};
static_assert(sizeof(LevelEntry) == 8);

/// The levels' stages at `tS` relative to `datumM`, per cell (each cell once, sorted by index; a
/// cell held by several levels takes the highest).
std::vector<LevelEntry> levelEntries(const std::vector<LevelBoundary>& levels, int width, double tS, double datumM);
/// Checks a level's cells against the grid and its stage times (strictly increasing).
Status checkLevel(const LevelBoundary& level, int width, int height);

/// The sources' mean discharges over [t0S, t1S] (exact integrals of the hydrographs), merged
/// per cell (each cell once, sorted by cell index).
std::vector<SourceEntry> mergeSources(const std::vector<Source>& sources, int width, double t0S, double t1S);

/// Step length (W10): maxDtS when cflAlpha <= 0 or the domain is still; otherwise the longest
/// dt <= maxDtS with dt * (S + sqrt(g r dt)) <= alpha * minCellM, S = `maxWaveSpeedMS` =
/// max(|u| + sqrt(g h)) before the step and r = `sourceDepthRateMS`, a bound on the depth per
/// second the step's sources add to any one cell (sourceDepthRate()): the wave speed after they
/// pour in is at most S + sqrt(g r dt), so the step is not too long for the water it adds.
double stepDt(const SimParams& params, double maxWaveSpeedMS, double minCellM, double sourceDepthRateMS = 0.0);

/// Bound on the depth per second (m/s) rain and sources add to any one cell over [t0S, t1S]:
/// max over cells of the uniform rain, plus `maxRainRasterMmH`, plus the sum of the peak
/// discharges over the window of the sources feeding the cell divided by its area. Any step
/// inside the window adds at most this times its length to a cell.
double sourceDepthRate(const SimParams& params, double maxRainRasterMmH, const std::vector<Source>& sources,
                       const std::vector<double>& rowDxM, double dyM, double t0S, double t1S);

/// Both above for the step starting at `timeS`: the sources' window is the step the wave speed
/// alone would allow (the source-aware step is never longer).
double stepDtWithSources(const SimParams& params, double maxWaveSpeedMS, double minCellM, double maxRainRasterMmH,
                         const std::vector<Source>& sources, const std::vector<double>& rowDxM, double dyM,
                         double timeS);

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
