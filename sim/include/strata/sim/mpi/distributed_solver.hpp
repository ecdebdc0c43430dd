#pragma once
// A region run as rectangular blocks spread over MPI ranks (docs/distributed.md). Each block is a
// solver (any backend, made by a SolverFactory on the rank that owns it) over its cells plus a
// halo; after every step the halos are refreshed from the blocks that own those cells, with
// non-blocking sends and receives between ranks, so the result is the one-process run's, bit for
// bit, on any number of ranks. All blocks take one step, chosen from the largest wave speed over
// all ranks (MPI_Allreduce). The statistics are sums of per-cell terms rounded to a fixed point
// and added as integers, so they too are the same on any number of ranks.
//
// Work follows the water: a block whose cells and halo are dry and still (and which has no rain,
// source or level, nor thermal weathering) skips its passes, which is exact (a step would change
// none of its values); blocks are dealt to ranks by their work (active blocks cost their cells,
// idle ones `idleWeight` of that) along a Hilbert curve, at creation and every `rebalanceEvery`
// steps or on rebalance(), moving each block whose rank changes (its state, encoded, over MPI).
//
// Everything but the accessors marked "local" is collective: every rank of the communicator
// calls it in the same order with the same arguments (sources, levels, parameters). Readers
// (readWaterDepth, readBlock, readFloodStats, ...) gather to rank 0, the others get empty grids;
// writeBlock writes rank 0's block. saveState/restoreState are per rank: each rank saves and
// restores its own part (its blocks), on the same number of ranks and block grid. The solver must
// be destroyed before MPI_Finalize.

#include <mpi.h>

#include <memory>
#include <string>
#include <vector>

#include <strata/core/result.hpp>
#include <strata/sim/region.hpp>
#include <strata/sim/solver.hpp>

namespace strata::sim {

struct DistributedOptions {
  MPI_Comm comm = MPI_COMM_WORLD;  ///< the ranks of the run (duplicated: the run's messages are its own)
  /// Interior cells per block; 0 = about blocksPerRank blocks per rank, as square as the region allows.
  int blockWidth = 0, blockHeight = 0;
  int blocksPerRank = 4;
  /// Halo width (cells): one step reads at most 7 cells away (TileOptions::halo), so 8.
  int halo = 8;
  /// Blocks whose cells and halo are dry and still skip their passes (exact; off only to compare).
  bool skipIdle = true;
  /// Deal the blocks by work before the first step (else by cells: an even split of the region).
  bool balanceAtStart = true;
  /// Steps between re-balances (0: only when rebalance() is called, e.g. at checkpoints).
  int rebalanceEvery = 0;
  /// Work of an idle block relative to an active one of the same size (its halo exchange and check).
  double idleWeight = 0.05;
  /// A re-balance moves blocks only when the busiest rank has more than this times the mean work.
  double rebalanceAbove = 1.1;
};

/// What a re-balance did and cost (the same on every rank).
struct RebalanceReport {
  double imbalanceBefore = 1, imbalanceAfter = 1;  ///< busiest rank's work over the mean
  int blocksMoved = 0;
  double bytesMoved = 0;  ///< encoded block states sent, over all ranks
  double seconds = 0;     ///< wall time, slowest rank (weights, plan, transfer, rebuilding the moved blocks)
};

/// This rank's counters since creation (local).
struct DistributedCounters {
  long long steps = 0;
  long long activeBlockSteps = 0, idleBlockSteps = 0;  ///< blocks stepped / skipped
  double computedCells = 0;                            ///< cells the stepped blocks computed (interior + halo)
  double interiorCells = 0;                            ///< interior cells of the stepped blocks
  double haloBytesSent = 0;                            ///< to other ranks
  double haloBytesLocal = 0;                           ///< copied between this rank's own blocks
  long long messagesSent = 0;
  double stepSeconds = 0;      ///< in the blocks' passes
  double exchangeSeconds = 0;  ///< packing, sending, waiting, unpacking halos
  double waitSeconds = 0;      ///< of which blocked in MPI_Waitany / MPI_Wait (what overlap did not hide)
  double reduceSeconds = 0;    ///< the step's wave-speed Allreduce
  std::vector<RebalanceReport> rebalances;
};

class DistributedSolver final : public Solver {
 public:
  /// Collective. Each rank reads only its blocks' windows (plus halo) from `region` and makes their
  /// solvers with `makeBlock`; fails on every rank if any rank fails (naming the rank).
  static Result<DistributedSolver> create(const RegionSource& region, const SimParams& params,
                                          const DistributedOptions& options, const SolverFactory& makeBlock);
  /// Collective: the same over an input every rank holds whole (regionSourceOf).
  static Result<DistributedSolver> create(const SimInput& input, const SimParams& params,
                                          const DistributedOptions& options, const SolverFactory& makeBlock);
  DistributedSolver(DistributedSolver&&) noexcept;
  DistributedSolver& operator=(DistributedSolver&&) noexcept;
  ~DistributedSolver() override;

  // Collective readers: the whole grid on rank 0, empty grids elsewhere.
  gis::Grid<float> readWaterDepth() const override;
  VelocityField readVelocity() const override;
  std::vector<gis::Grid<float>> readLayers() const override;
  gis::Grid<float> readSuspended() const override;
  gis::Grid<float> readBed() const override;
  FloodStats readFloodStats() const override;
  /// Collective: exact sums over all ranks (the same value on every rank).
  SimStats stats() const override;
  std::string backendName() const override;
  /// Collective: the largest over all ranks.
  double maxWaveSpeedMS() const override;
  /// Collective: the rectangle on rank 0 (the other ranks get it with no data).
  CellBlock readBlock(int x0, int y0, int width, int height, unsigned parts = kBlockAll) const override;
  /// Collective: rank 0's block is written (the others' argument is ignored).
  void writeBlock(const CellBlock& block) override;
  /// Collective: on rank 0, empty elsewhere.
  std::vector<float> readFaceMassFlux() const override;

  /// Collective: deals the blocks to ranks by their current work and moves those whose rank
  /// changes (nothing moves when the busiest rank is within rebalanceAbove of the mean). Fails on
  /// every rank if a moved block cannot be rebuilt on its new rank (its window unreadable there).
  Result<RebalanceReport> rebalance();

  int rank() const;   ///< local
  int ranks() const;  ///< local
  int blockCount() const;
  /// This rank's blocks: their interiors (global cells), what outputs are written from per rank.
  std::vector<CellRect> localRects() const override;
  CellBlock readLocal(const CellRect& rect, unsigned parts) const override;
  FloodStats readLocalFloodStats(const CellRect& rect) const override;
  gis::Grid<float> readLocalBed(const CellRect& rect) const override;
  /// The rank of every block (local: every rank holds the same).
  const std::vector<int>& owners() const;
  const DistributedCounters& counters() const;  ///< local

 private:
  struct Impl;
  DistributedSolver(const CellGrid& grid, const SimParams& params, std::unique_ptr<Impl> impl);
  void runStep(const StepInputs& step) override;
  void onParamsChanged() override;
  Status onSourceAdded(const Source& source) override;
  void forEachPart(const std::function<void(Solver&)>& f) override;
  Status onLevelAdded(const LevelBoundary& level) override;
  RainTotals rainTotals() const override;
  bool keepsFloodStats() const override { return true; }
  bool floodStatsInParts() const override { return true; }
  void resetFloodStats() override;
  void saveCells(SolverState& out) const override;
  Status restoreCells(const SolverState& in) override;

  std::unique_ptr<Impl> impl_;
};

/// Collective: the rank of this process among the ranks of `comm` on the same node
/// (MPI_COMM_TYPE_SHARED).
int localRank(MPI_Comm comm);
/// Collective (localRank): the EGL device for this rank's GL context (gl::HeadlessOptions::device): "gpu:<local rank>",
/// the node's GPUs dealt one per local rank (wrapping when there are more ranks than GPUs; Mesa's
/// surfaceless platform where there is none). STRATA_EGL_DEVICE, if set, still overrides it.
std::string rankEglDevice(MPI_Comm comm);

}  // namespace strata::sim
