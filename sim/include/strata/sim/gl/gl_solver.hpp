#pragma once
// The GL backend of the water and erosion model: GL 4.5 compute kernels (sim/shaders/*.comp), the
// same passes as CpuSolver, which tests compare it with. All state lives in GPU buffers; a step
// reads nothing back unless the time step is adaptive (cflAlpha > 0: one 4-byte read of the max
// wave speed per step). Needs a current GL 4.5 context (gl::HeadlessContext or a window) for its
// whole life.

#include <memory>
#include <string>
#include <vector>

#include <strata/core/result.hpp>
#include <strata/gl/objects.hpp>
#include <strata/sim/solver.hpp>

namespace strata::sim {

class GlSolver final : public Solver {
 public:
  /// Validates the input, compiles the kernels and uploads the state.
  static Result<GlSolver> create(const SimInput& input, const SimParams& params);
  GlSolver(GlSolver&&) noexcept;
  GlSolver& operator=(GlSolver&&) noexcept;
  ~GlSolver() override;

  gis::Grid<float> readBed() const override;
  std::string backendName() const override;
  double maxWaveSpeedMS() const override;
  CellBlock readBlock(int x0, int y0, int width, int height, unsigned parts = kBlockAll) const override;
  void writeBlock(const CellBlock& block) override;
  std::vector<float> readFaceMassFlux() const override;

  /// The current state on the GPU: 4 floats per cell (h, s, hu, hv), row-major. Valid until the
  /// next step (the state ping-pongs); for GPU-side copies such as drawing the water.
  const gl::Buffer& stateBuffer() const;
  /// Bytes of GPU buffers this solver holds.
  size_t gpuBytes() const;

 private:
  struct Impl;
  GlSolver(const SimInput& input, const SimParams& params, std::unique_ptr<Impl> impl);
  void runStep(const StepInputs& step) override;
  std::optional<DeviceRun> runOnDevice(const DeviceRequest& request) override;
  void onParamsChanged() override;
  Status onRainRasterChanged(const gis::Grid<float>& mmPerHour) override;
  bool keepsFloodStats() const override { return true; }
  void resetFloodStats() override;
  std::vector<float> floodStatsCells() const override;
  void setFloodStatsCells(const std::vector<float>& cells) override;

  std::unique_ptr<Impl> impl_;
};

/// Makes GlSolvers (for runners; the context must be current when they are made and used).
SolverFactory glSolverFactory();

}  // namespace strata::sim
