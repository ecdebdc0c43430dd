#pragma once
// The domain built by the ranks of a run, rows by rows (`mpirun -np N strata flood SCENARIO`,
// docs/distributed.md, "Built by the ranks"): each rank builds its own rows from its windows of
// the DEM or store (domain_rows.hpp's RowBuilder), the ranks combine what needs every row, each
// rank writes its rows of the model input (input/) and reads its blocks back from there. One
// process is the one-rank case: buildDomain (domain.hpp) is this build over Ranks::single().

#include <filesystem>
#include <string>
#include <utility>
#include <vector>

#include <strata/core/result.hpp>
#include <strata/scenario/domain.hpp>
#include <strata/sim/exact_sum.hpp>
#include <strata/sim/mpi/ranks.hpp>
#include <strata/sim/region.hpp>

namespace strata::scenario::detail {

using sim::Ranks;

/// The run folder's model input files for `layers` layers (relative paths): input/base.tif,
/// input/layer_K.tif (K = 1 the bottom layer) and those of kOptionalInputs.
std::vector<std::string> modelInputFiles(int layers);
/// The per-cell inputs a region may have, each a file of input/ when it does (a shape marks the
/// ones its rows have with a 1 x 1 grid).
struct OptionalInput {
  const char* file;
  gis::Grid<float> sim::SimInput::*grid;
  const char* what;  ///< the file's STRATA_MODEL_INPUT metadata
};
inline constexpr OptionalInput kOptionalInputs[] = {
    {"input/water.tif", &sim::SimInput::waterDepthM, "initial depth (m)"},
    {"input/rain.tif", &sim::SimInput::rainMmPerHour, "rain (mm/h)"},
    {"input/manning.tif", &sim::SimInput::manningN, "Manning's n (s/m^(1/3))"},
    {"input/infiltration_rate.tif", &sim::SimInput::infiltrationMmPerHour, "infiltration rate or Ks (mm/h)"},
    {"input/infiltration_suction.tif", &sim::SimInput::infiltrationSuctionM,
     "Green-Ampt suction head x moisture deficit (m)"},
};
/// Layers a distributed run can have (one model input file each).
inline constexpr int kMaxInputLayers = 64;

/// Collective: writes the model input (base, layers and the optional inputs `shape` marks) as
/// float32 GeoTIFFs in the region's CRS (`georef`, the whole region's) into `runDir`/input: each
/// rank its rows of the region, `d` (its grids' rows from d.firstRow).
Status writeModelInput(const Ranks& ranks, const std::filesystem::path& runDir, const gis::Georef& georef,
                       const ScenarioDomain& d, const ScenarioDomain& shape);

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
/// Collective: every rank writes its rows into the model input and into maps/elevation.tif.
Status writeRows(const Ranks& ranks, const std::filesystem::path& runDir, const RowsBuilt& built);

/// The region read window by window from those files (`shape`: RowsBuilt::shape): what each
/// rank builds its blocks from.
sim::RegionSource modelInputSource(const std::filesystem::path& runDir, const ScenarioDomain& shape);

}  // namespace strata::scenario::detail
