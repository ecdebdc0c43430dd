#pragma once
// A scenario run spread over the ranks of MPI_COMM_WORLD (`mpirun -np N strata flood SCENARIO`,
// docs/distributed.md, "Scenario runs"). The lead rank (0) builds the domain (the conditioning,
// fill_depressions and breach_inflows, needs the whole region), writes the model's input as
// GeoTIFFs into the run folder (input/) and sends every rank what it needs besides cells (the
// shape, the model, the sources and levels); each rank then reads only its blocks' windows (plus
// halo) of those files. Every rank runs the same loop, and writes its own blocks of the maps
// (pieces.hpp) and its own checkpoint part; only the lead writes the other files.

#include <filesystem>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include <strata/core/result.hpp>
#include <strata/scenario/domain.hpp>
#include <strata/sim/exact_sum.hpp>
#include <strata/sim/region.hpp>

namespace strata::scenario::detail {

/// The ranks a run's loop runs on. A single-process run is one lead rank: nothing is exchanged
/// and MPI is never called.
class Ranks {
 public:
  static Ranks single() { return {}; }
  /// The ranks of MPI_COMM_WORLD (MPI must be initialised: `strata` does it under mpirun).
  static Ranks world();

  bool distributed() const { return distributed_; }
  bool lead() const { return rank_ == 0; }
  int rank() const { return rank_; }
  int size() const { return size_; }

  /// Collective: success on every rank, or the lowest failing rank's failure on every rank.
  Status agree(const Status& local) const;
  /// Collective: whether any rank has been asked to stop (Ctrl-C, SIGTERM).
  bool anyInterrupted() const;
  /// Collective: the lead's `bytes` on every rank.
  std::string fromLead(std::string bytes) const;
  /// Collective: the smallest and largest of `value` over the ranks.
  std::pair<long long, long long> minMax(long long value) const;
  /// Collective: whether `value` holds on every rank.
  bool all(bool value) const;
  /// Collective: `sums` added over the ranks, in place (exact: the same on any number of ranks).
  void sum(std::vector<sim::ExactSum>& sums) const;
  /// Collective: every rank's `values` (the same count on each), in rank order, on every rank.
  std::vector<double> allGather(const std::vector<double>& values) const;
  /// Collective: each of `values` the smallest (largest) over the ranks, in place.
  void min(std::vector<double>& values) const;
  void max(std::vector<double>& values) const;
  /// Collective: every rank's `bytes`, in rank order, on the lead (nothing elsewhere).
  std::vector<std::string> gatherToLead(const std::string& bytes) const;
  /// Collective: every rank's `bytes`, in rank order, on every rank.
  std::vector<std::string> allGatherBytes(const std::string& bytes) const;
  /// Collective: sends `up` to the rank before this one and `down` to the one after it; returns
  /// what they sent (the one before's `down`, the one after's `up`; empty where there is none).
  std::pair<std::string, std::string> swapWithNeighbours(const std::string& up, const std::string& down) const;

 private:
  bool distributed_ = false;
  int rank_ = 0, size_ = 1;
};

/// The run folder's model input files for `layers` layers (relative paths): input/base.tif,
/// input/layer_K.tif (K = 1 the bottom layer), input/water.tif, input/rain.tif.
std::vector<std::string> modelInputFiles(int layers);
/// Layers a distributed run can have (one model input file each).
inline constexpr int kMaxInputLayers = 64;

/// Collective: writes the model input (base, layers, initial water and rain raster when present)
/// as float32 GeoTIFFs in the region's CRS (`georef`, the whole region's) into `runDir`/input:
/// each rank its rows of the region, `d` (its grids' rows from d.firstRow). `layers`, `water` and
/// `rain`: which files the region has (the same on every rank).
Status writeModelInput(const Ranks& ranks, const std::filesystem::path& runDir, const gis::Georef& georef,
                       const ScenarioDomain& d, int layers, bool water, bool rain);

class RowBuilder;
/// A domain built by the ranks: its shape (the same on every rank, with the report's numbers of
/// the build) and this rank's rows of it.
struct RowsBuilt {
  ScenarioDomain shape, rows;
};
/// Collective: the domain built rows by rows over the ranks (domain_rows.hpp): rank r builds rows
/// [r h / N, (r + 1) h / N) from its own windows of the DEM or store, the ranks combine the
/// datum, the totals and the checks, settle at_rest layers against each other's border rows
/// (settle.hpp), flood breach_inflows together (breach.hpp), and fill_depressions runs tile by
/// tile (each rank's rows a tile; the labels' graph is gathered to the lead, solved there and
/// sent back). Writes nothing (a check that fails leaves no file). Needs at least one row per
/// rank (RowBuilder::plan refuses a region with fewer).
Result<RowsBuilt> buildByRows(const RowBuilder& builder, const Scenario& s, const Ranks& ranks);
/// Collective: every rank writes its rows into the model input and, with `elevation`, into
/// maps/elevation.tif.
Status writeRows(const Ranks& ranks, const std::filesystem::path& runDir, const RowsBuilt& built, bool elevation);

/// The region read window by window from those files (`shape`: RowsBuilt::shape): what each
/// rank builds its blocks from.
sim::RegionSource modelInputSource(const std::filesystem::path& runDir, const ScenarioDomain& shape);

/// checkpoint.R-of-N.bin: rank R's part of a run checkpointed on N ranks.
std::string rankCheckpointFile(int rank, int ranks);
/// Whether `name` is such a file (any R and N); sets `ranks` to its N.
bool isRankCheckpointFile(std::string_view name, int* ranks = nullptr);

}  // namespace strata::scenario::detail
