#pragma once
// [[terrain.layer]] at_rest over the ranks of a run: one process is one rank holding every row
// (docs/scenario.md, "Layers"; docs/distributed.md, "Built by the ranks").

#include <strata/scenario/domain.hpp>
#include <strata/sim/mpi/ranks.hpp>

namespace strata::scenario::detail {

using sim::Ranks;

/// Leaves each at_rest layer off the cells where it could not rest (domain.cpp says when), and
/// sets d.layerCellsTooSteep to this rank's counts (add them over the ranks).
///
/// `d` holds rows from d.firstRow of a region `height` rows high: this rank's `own` rows, then any
/// after them it keeps for a later step that reads only their base (left as they are). The ranks
/// before and after this one hold the rows above and below.
///
/// Leaving a layer off only lowers a cell, which only steepens its neighbours' drops: a cell that
/// would shed still would after anything its neighbours do, so what is left off does not depend
/// on the order the cells are tested in. Each rank settles its rows against its neighbours' last
/// border rows until no rank changes anything, and the layers are the one process's, bit for bit.
void settleAtRest(const Scenario& s, const Ranks& ranks, int height, int own, ScenarioDomain& d);

}  // namespace strata::scenario::detail
