#pragma once
// A run's checkpoint (checkpoint.bin): which run it belongs to (the command, the scenario's text,
// the Strata version), the intervals done, the series so far and the solver's state, with a
// checksum over all of it. The solver's state is sim's own encoding (sim/state_codec.hpp, the one
// codec of SolverState, also what moves blocks between MPI ranks).

#include <cstdint>
#include <filesystem>
#include <string>
#include <string_view>
#include <vector>

#include <strata/core/result.hpp>
#include <strata/scenario/run.hpp>
#include <strata/sim/solver.hpp>

namespace strata::scenario {

/// What a checkpoint must match to be resumed.
struct CheckpointOwner {
  std::string command;        ///< "flood" or "erode"
  uint64_t scenarioHash = 0;  ///< of the scenario file's text
};

struct Checkpoint {
  int interval = 0;  ///< output intervals done
  double wallS = 0;  ///< wall time of the run so far (all its sessions, resumed ones included)
  std::vector<SeriesRow> series;
  SpinUpSummary spinUp;        ///< for the report of a resumed run
  std::vector<double> probes;  ///< the gauges' and sections' rows and sums so far (detail::Probes::save)
  sim::SolverState state;
};

/// checkpoint.R-of-N.bin: rank R's part of a run checkpointed on N ranks; with `previous`,
/// checkpoint.R-of-N.previous.bin, its part of the checkpoint before (kept until every rank has
/// written the next, so that a rank killed while the parts are written loses nothing).
std::string rankCheckpointFile(int rank, int ranks, bool previous = false);
/// Whether `name` is such a file, current or previous (any R and N); sets `ranks` to its N.
bool isRankCheckpointFile(std::string_view name, int* ranks = nullptr);

/// FNV-1a (64 bit) of `text`.
uint64_t fnv1a(std::string_view text);

std::string encodeCheckpoint(const CheckpointOwner& owner, const Checkpoint& checkpoint);
/// Reads `path`; fails naming the file if it is not a checkpoint, is damaged (checksum), or
/// belongs to another command, scenario or Strata version.
Result<Checkpoint> decodeCheckpoint(const std::filesystem::path& path, const CheckpointOwner& owner);

}  // namespace strata::scenario
