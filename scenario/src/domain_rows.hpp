#pragma once
// The domain built rows by rows: every MPI rank of a run builds its own rows of the model input,
// reading only its rows' windows of the DEM (docs/distributed.md, "Built by the ranks"). Each
// rows' build has the bits the whole build (buildDomain) has there; what needs every row (the
// datum, the totals, fill_depressions tile by tile, the checks on levels, voids and loose
// material) the caller combines over the ranks (detail::buildByRows).

#include <array>
#include <memory>
#include <string>
#include <vector>

#include <strata/core/result.hpp>
#include <strata/scenario/domain.hpp>
#include <strata/sim/exact_sum.hpp>

namespace strata::scenario::detail {

class RowBuilder {
 public:
  /// Plans the build (reads no cell; every rank makes the same): the region's grid, per-row cell
  /// sizes, materials, the model, inflows and levels on cells, the rain. The memory check is a
  /// rank's share of a run over `ranks` (with the pictures' gather on the lead when `pictures`)
  /// against its share of the machine's memory (or of `memoryBudgetBytes`), which `ranksOnNode`
  /// ranks share. `s` must outlive the builder.
  static Result<RowBuilder> plan(const Scenario& s, uint64_t memoryBudgetBytes, int ranks, bool pictures,
                                 int ranksOnNode = 1);
  RowBuilder(RowBuilder&&) noexcept;
  ~RowBuilder();

  /// The domain without cells: bed.georef the region's grid, per-row cell sizes, materials, the
  /// model, sources, levels, the rain (1 x 1 markers: rainMmPerHour for a rain raster,
  /// waterDepthM for dam breaks).
  const ScenarioDomain& shape() const;
  /// Rows [y0, y1) of the region (firstRow y0): bed (voids filled as the whole region's fill
  /// fills them, unless voids = "refuse"), voids, mask, cell areas and their total, base (walls),
  /// layers, the rain raster. No datum (the lowest bed over all rows,
  /// floored), nothing filled, no check that needs every row.
  Result<ScenarioDomain> rows(int y0, int y1) const;

  // What buildDomain does over the whole region, for the caller to do over the rows.
  Error refuseVoids(long long count) const;
  /// voids = "walls": the first place (inflows, levels, dam breaks in order) with a cell on a
  /// void of the first `count` rows of `rows` (-1: none), and its refusal.
  int firstPlaceOnWalls(const ScenarioDomain& rows, int count) const;
  Error refusePlaceOnWalls(int index) const;
  /// voids = "holes": the void cells of the first `rows` rows of `rows` that are holes (on the
  /// region's rows), and the level that drains them added to the shape (all ranks' cells, in
  /// row-major order).
  std::vector<std::pair<int, int>> voidHoleCells(const ScenarioDomain& rows, int count) const;
  void addVoidHoles(std::vector<std::pair<int, int>> cells, ScenarioDomain& shape) const;
  bool hasLooseMaterial(const ScenarioDomain& rows) const;
  Error refuseNoLooseMaterial() const;
  gis::Grid<uint8_t> drains(const ScenarioDomain& rows) const;  ///< fill_depressions' open-edge cells
  Error refuseNothingDrains() const;
  /// Raises the first `count` rows of `rows` to `filled` where higher, counting it in rows.filled;
  /// returns the volume raised (an exact sum, to add over the ranks).
  sim::ExactSum raiseTo(const gis::Grid<float>& filled, int count, ScenarioDomain& rows) const;
  std::vector<double> lowestLevelBeds(const ScenarioDomain& rows) const;
  Status checkLevelStages(const std::vector<double>& lowestBed) const;
  /// The dam breaks' initial water on the rows (and its volume in rows.damBreakVolumeM3); each
  /// dam's lowest bed there.
  std::vector<double> placeDamBreaks(ScenarioDomain& rows) const;
  Status checkDamBreaks(const std::vector<double>& lowestBed) const;
  std::array<float, 2> bedRange(const ScenarioDomain& rows, int count) const;

 private:
  struct Impl;
  explicit RowBuilder(std::unique_ptr<Impl> impl);
  std::unique_ptr<Impl> impl_;
};

}  // namespace strata::scenario::detail
