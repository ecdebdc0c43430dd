#pragma once
// The CPU backend of the water and erosion model (docs/sim-water.md, docs/sim-erosion.md): the
// same passes, in the same order and in float32, as the GL kernels under sim/shaders/, so the two
// agree to rounding. Multi-threaded with OpenMP over rows of 16 x 16-cell blocks, structure of
// arrays with aligned rows, and blocks where a step provably changes nothing (dry, with dry
// neighbours, no rain, source or level, no material sliding) are skipped. Results are the same
// bits whatever the thread count and with or without the skipping (docs/sim-water.md, "The CPU
// backend").

#include <memory>
#include <string>
#include <vector>

#include <strata/core/result.hpp>
#include <strata/sim/solver.hpp>

namespace strata::sim {

/// How a CpuSolver runs; neither choice changes a bit of its results.
struct CpuOptions {
  int threads = 0;              ///< OpenMP threads; 0 = OpenMP's default (OMP_NUM_THREADS, else the cores)
  bool skipQuietBlocks = true;  ///< skip the blocks where a step changes nothing (false: every cell, every step)
};

class CpuSolver final : public Solver {
 public:
  /// Validates and copies the input.
  static Result<CpuSolver> create(const SimInput& input, const SimParams& params, const CpuOptions& options = {});
  CpuSolver(CpuSolver&&) noexcept;
  CpuSolver& operator=(CpuSolver&&) noexcept;
  ~CpuSolver() override;

  gis::Grid<float> readWaterDepth() const override;
  VelocityField readVelocity() const override;
  std::vector<gis::Grid<float>> readLayers() const override;
  gis::Grid<float> readSuspended() const override;
  gis::Grid<float> readBed() const override;
  /// "CPU, N OpenMP threads".
  std::string backendName() const override;
  double maxWaveSpeedMS() const override;
  CellBlock readBlock(int x0, int y0, int width, int height, unsigned parts = kBlockAll) const override;
  void writeBlock(const CellBlock& block) override;
  std::vector<float> readFaceMassFlux() const override;
  std::vector<float> readFaceMassFluxAt(const std::vector<size_t>& faces) const override;
  void integrateFaces(const std::vector<size_t>& faces) override;

  /// The OpenMP threads the passes run on.
  int threads() const;
  /// Cells the water passes updated since the start, summed over steps (all cells every step
  /// without skipping): what the skipping saves.
  long long cellUpdates() const;

 private:
  struct Impl;
  CpuSolver(const SimInput& input, const SimParams& params, const CpuOptions& options);
  void runStep(const StepInputs& step) override;
  void onParamsChanged() override;
  Totals totals() const override;
  Status onRainRasterChanged(const gis::Grid<float>& mmPerHour) override;
  bool keepsFloodStats() const override { return true; }
  void resetFloodStats() override;
  std::vector<float> floodStatsCells() const override;
  void setFloodStatsCells(const std::vector<float>& cells) override;
  void saveCells(SolverState& out) const override;
  Status restoreCells(const SolverState& in) override;

  std::unique_ptr<Impl> impl_;
};

/// Makes CpuSolvers (for runners).
SolverFactory cpuSolverFactory(const CpuOptions& options = {});

}  // namespace strata::sim
