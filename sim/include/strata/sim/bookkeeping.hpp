#pragma once
// The host-side bookkeeping every solver shares, so all backends and runners take the same
// steps: the time step rule (W10), sources merged per cell (W12), fixed levels per cell (W26),
// rain volumes and integrals over the grid.

#include <cstdint>
#include <vector>

#include <strata/sim/input.hpp>

namespace strata::sim {

/// One cell fed by sources this step (also the std430 `SourceEntry` of sim/shaders/sim.glsl).
struct SourceEntry {
  uint32_t cell = 0;     ///< y * width + x
  float rateM3S = 0.0f;  ///< discharge into that cell (m^3/s)
};
static_assert(sizeof(SourceEntry) == 8);

/// One cell held at a fixed level this step (also the std430 `LevelEntry` of sim/shaders/sim.glsl).
struct LevelEntry {
  uint32_t cell = 0;    ///< y * width + x
  float stageM = 0.0f;  ///< water surface elevation relative to the datum (m)
};
static_assert(sizeof(LevelEntry) == 8);

/// Checks a source's cells against a width x height grid and that it has a hydrograph.
Status checkSource(const Source& source, int width, int height);
/// Checks a level's cells against the grid and that it has a stage.
Status checkLevel(const LevelBoundary& level, int width, int height);

/// The levels' stages at `tS` relative to `datumM`, per cell (each cell once, sorted by index; a
/// cell held by several levels takes the highest).
std::vector<LevelEntry> levelEntries(const std::vector<LevelBoundary>& levels, int width, double tS, double datumM);

/// The sources' mean discharges over [t0S, t1S] (exact integrals of the hydrographs), merged
/// per cell (each cell once, sorted by cell index).
std::vector<SourceEntry> mergeSources(const std::vector<Source>& sources, int width, double t0S, double t1S);

/// Step length (W10): maxDtS when cflAlpha <= 0 or the domain is still; otherwise the longest
/// dt <= maxDtS with dt * (S + sqrt(g r dt)) <= alpha * minCellM, S = `maxWaveSpeedMS` =
/// max(|u| + sqrt(g h)) before the step and r = `sourceDepthRateMS`, a bound on the depth per
/// second the step's sources add to any one cell (sourceDepthRate()): the wave speed after they
/// pour in is at most S + sqrt(g r dt), so the step is not too long for the water it adds. The
/// local-inertial scheme's S is max sqrt(g h) (W33), and sqrt(g (h + r dt)) <= sqrt(S^2 + g r dt):
/// its step is the longest with dt * sqrt(S^2 + g r dt) <= alpha * minCellM.
double stepDt(const SimParams& params, double maxWaveSpeedMS, double minCellM, double sourceDepthRateMS = 0.0);

/// How far (m) W10's (W33's) bound lets a wave travel in a step of dtS: stepDt's longest step is
/// the one where this reaches alpha * minCellM. Local time steps (W37) test each block's with it.
double stepTravelM(const SimParams& params, double maxWaveSpeedMS, double sourceDepthRateMS, double dtS);

/// Bound on the depth per second (m/s) rain and sources add to any one cell over [t0S, t1S]:
/// max over cells of the uniform rain, plus `maxRainRasterMmH`, plus the sum of the peak
/// discharges over the window of the sources feeding the cell divided by its area. Any step
/// inside the window adds at most this times its length to a cell.
double sourceDepthRate(const SimParams& params, double maxRainRasterMmH, const std::vector<Source>& sources,
                       const CellGrid& grid, double t0S, double t1S);

/// Both above for the step starting at `timeS`: the sources' window is the step the wave speed
/// alone would allow (the source-aware step is never longer).
double stepDtWithSources(const SimParams& params, double maxWaveSpeedMS, double maxRainRasterMmH,
                         const std::vector<Source>& sources, const CellGrid& grid, double timeS);

/// Rain falling on the whole grid (m^3/s): uniform rate plus the raster (mm/h, empty = none),
/// times cell areas, summed as the kernels add it (float per cell).
double rainVolumeRate(const SimParams& params, const std::vector<float>& rainRasterMmH, const CellGrid& grid);

/// Sum over cells of value * cell area (m^3), in double; `values` is row-major width x height, or
/// several such grids one after another (a layer stack).
double integrate(const std::vector<float>& values, const CellGrid& grid);

}  // namespace strata::sim
