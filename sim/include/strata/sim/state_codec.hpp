#pragma once
// A SolverState as bytes and back, walking SolverState::forEachField (the one list of its fields):
// what moves a block's state between the ranks of a distributed run, and what a rank's part of a
// distributed checkpoint is written as. Native byte order (the ranks of one run share it); no
// checksum (a file format adds its own).

#include <string>
#include <string_view>

#include <strata/core/result.hpp>
#include <strata/sim/solver.hpp>

namespace strata::sim {

std::string encodeState(const SolverState& state);
/// Fails if `bytes` is not a whole encoded state (truncated, trailing bytes, sizes out of range).
Result<SolverState> decodeState(std::string_view bytes);

}  // namespace strata::sim
