#pragma once
// [terrain] breach_inflows over the ranks of a run: one process is one rank holding every row
// (docs/scenario.md, "Conditioning"; docs/distributed.md, "Built by the ranks").

#include <string>
#include <vector>

#include <strata/core/result.hpp>
#include <strata/scenario/domain.hpp>
#include <strata/sim/mpi/ranks.hpp>

namespace strata::scenario::detail {

using sim::Ranks;

/// Carves each inflow's path to an open edge (domain.cpp says which path, and how) into d's base
/// and bed, and sets d.breach (the same on every rank).
///
/// `rowStarts`: the first of each rank's own rows, then the region's height (ranks + 1 values; one
/// process: {0, height}). `d` holds rows from d.firstRow: this rank's own, then any after them it
/// keeps for a later step (changed too where a path crosses them, as their owner changes them).
/// `sources` and `names`: the inflows on cells of the region.
///
/// Over several ranks the search is the one process's priority flood, its cells held by their
/// rows' ranks: a rank takes the next cell of its queue only while no other rank holds one that
/// comes first and nothing it sent across its border this round could come back before it (keys
/// ordered by the path's highest cell, its length, its sum of elevations, then the cell). Every
/// cell is then reached from the same neighbour, and the path, its profile and the report's
/// figures are the one process's, bit for bit. In effect the ranks take turns (in a round only
/// the rank holding the first cell of all takes any): the flood is as sequential as in one
/// process, a small part of the build (20 ms of 1.3 s at 5 M cells); what the ranks gain is that
/// none holds more than its own rows.
Status breachInflowPaths(const Scenario& s, const Ranks& ranks, const std::vector<int>& rowStarts,
                         const std::vector<sim::Source>& sources, const std::vector<std::string>& names,
                         ScenarioDomain& d);

}  // namespace strata::scenario::detail
