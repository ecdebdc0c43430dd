#include "build_rows.hpp"

#include <mpi.h>

#include <climits>
#include <cstdint>

#include <strata/core/bytes.hpp>
#include <strata/core/interrupt.hpp>
#include <strata/gis/dem_io.hpp>
#include <strata/gis/fill_depressions.hpp>
#include <strata/sim/mpi/distributed_solver.hpp>

#include "breach.hpp"
#include "domain_rows.hpp"
#include "pieces.hpp"
#include "settle.hpp"

namespace strata::scenario::detail {
namespace fs = std::filesystem;
namespace {

// A cell list as flat (x, y) ints (std::pair is not trivially copyable).
void writeCells(ByteWriter& w, const std::vector<std::pair<int, int>>& cells) {
  std::vector<int32_t> flat;
  flat.reserve(cells.size() * 2);
  for (const auto& [x, y] : cells) {
    flat.push_back(x);
    flat.push_back(y);
  }
  w.vec(flat);
}
std::string cellBytes(const std::vector<std::pair<int, int>>& cells) {
  ByteWriter w;
  writeCells(w, cells);
  return w.out;
}
void readCells(ByteReader& r, std::vector<std::pair<int, int>>& cells) {
  std::vector<int32_t> flat;
  r.vec(flat);
  cells.clear();
  for (size_t i = 0; i + 1 < flat.size(); i += 2) cells.emplace_back(flat[i], flat[i + 1]);
}
// One window of one model input file.
Result<gis::Grid<float>> readInputWindow(const fs::path& file, const gis::CellRect& window) {
  gis::ReadOptions o;
  o.window = window;
  o.allowAllNoData = true;  // the files hold no nodata; a window of it is then found below
  STRATA_TRY(auto r, gis::readDem(file.string(), o));
  for (float v : r.values.data) {
    if (v != v) return fail(file.string() + ": a cell without data in the model input (written damaged?)");
  }
  return std::move(r.values);
}

}  // namespace

std::vector<std::string> modelInputFiles(int layers) {
  std::vector<std::string> files{"input/base.tif"};
  for (const auto& o : kOptionalInputs) files.push_back(o.file);
  for (int k = 1; k <= layers; ++k) files.push_back("input/layer_" + std::to_string(k) + ".tif");
  return files;
}

Status writeModelInput(const Ranks& ranks, const fs::path& runDir, const gis::Georef& georef, const ScenarioDomain& d,
                       const ScenarioDomain& shape) {
  const int layers = int(shape.input.materials.size());
  if (layers > kMaxInputLayers) {
    return fail(std::to_string(layers) + " layers: a run over MPI ranks takes at most " +
                std::to_string(kMaxInputLayers));
  }
  std::error_code ec;
  if (ranks.lead()) fs::create_directories(runDir / "input", ec);
  STRATA_TRY_STATUS(
      ranks.agree(ec ? fail((runDir / "input").string() + ": cannot create: " + ec.message()) : Status{}));
  const bool mine = d.input.baseM.size() > 0;
  auto write = [&](const std::string& file, const gis::Grid<float>* values, const std::string& what) -> Status {
    gis::WriteOptions o;
    o.metadata = {{"STRATA_MODEL_INPUT", what}};
    std::vector<gis::GridWindow> windows;
    if (mine) windows.push_back({0, d.firstRow, *values});
    return writeRaster(ranks, runDir / file, georef, o, windows);
  };
  STRATA_TRY_STATUS(write("input/base.tif", &d.input.baseM, "base elevation (m), conditioned, walls included"));
  for (const auto& o : kOptionalInputs) {
    if ((shape.input.*o.grid).size() > 0) STRATA_TRY_STATUS(write(o.file, &(d.input.*o.grid), o.what));
  }
  for (int k = 0; k < layers; ++k) {
    const std::string material = d.input.materials.empty() ? std::string() : d.input.materials[size_t(k)].name;
    STRATA_TRY_STATUS(write("input/layer_" + std::to_string(k + 1) + ".tif",
                            mine ? &d.input.layersM[size_t(k)] : nullptr, "thickness (m) of " + material));
  }
  return {};
}

namespace {

// The first `rows` rows of a rows' build (the row below, read for fill_depressions, dropped).
void keepRows(ScenarioDomain& d, int rows) {
  auto crop = [rows](auto& g) {
    if (g.height > rows) {
      g.data.resize(size_t(rows) * size_t(g.width));
      g.height = rows;
    }
  };
  crop(d.bed.values);
  d.bed.georef.height = rows;
  crop(d.inside);
  crop(d.voids);
  crop(d.cellAreaM2);
  crop(d.input.baseM);
  for (auto& l : d.input.layersM) crop(l);
  for (const auto& o : kOptionalInputs) crop(d.input.*o.grid);
  d.input.rowDxM.resize(std::min(d.input.rowDxM.size(), size_t(rows)));
}

// fill_depressions over the ranks' rows, each a tile (gis::fillDepressions' phases): `d` holds
// the rank's rows and the row below.
Status fillOverRanks(const RowBuilder& b, const Ranks& ranks, const std::vector<gis::CellRect>& tiles, int own,
                     ScenarioDomain& d, sim::ExactSum& volume) {
  const auto drains = b.drains(d);
  bool anyDrain = false;
  for (size_t i = 0; i < size_t(own) * size_t(drains.width); ++i) anyDrain |= drains.data[i] != 0;
  if (!ranks.minMax(anyDrain ? 1 : 0).second) return b.refuseNothingDrains();
  const gis::FillInput in{&d.input.baseM,
                          &d.inside,
                          &drains,
                          {0, d.firstRow, d.input.baseM.width, d.input.baseM.height},
                          d.input.baseM.width};
  const gis::TileFlood flood = gis::floodTile(in, tiles[size_t(ranks.rank())]);
  auto edges = gis::borderEdges(in, tiles);
  edges.insert(edges.end(), flood.edges.begin(), flood.edges.end());
  // The labels' graph to the lead, their spill levels back.
  ByteWriter w;
  w.vec(edges);
  const auto parts = ranks.gatherToLead(w.out);
  std::string solved;
  if (ranks.lead()) {
    std::vector<gis::SpillEdge> all;
    for (const auto& part : parts) {
      ByteReader r{part};
      std::vector<gis::SpillEdge> some;
      r.vec(some);
      all.insert(all.end(), some.begin(), some.end());
    }
    std::vector<int64_t> labels;
    std::vector<float> levels;
    for (const auto& [label, level] : gis::spillLevels(all)) labels.push_back(label), levels.push_back(level);
    ByteWriter out;
    out.vec(labels);
    out.vec(levels);
    solved = std::move(out.out);
  }
  solved = ranks.fromLead(std::move(solved));
  ByteReader r{solved};
  std::vector<int64_t> labels;
  std::vector<float> levels;
  r.vec(labels);
  r.vec(levels);
  if (!r.ok || labels.size() != levels.size())
    return fail("fill_depressions: the spill levels sent by rank 0 are damaged");
  std::vector<std::pair<int64_t, float>> spill;
  spill.reserve(labels.size());
  for (size_t i = 0; i < labels.size(); ++i) spill.push_back({labels[i], levels[i]});
  volume = b.raiseTo(gis::finishTile(in, flood, spill), own, d);
  return {};
}

}  // namespace

Result<RowsBuilt> buildByRows(const RowBuilder& b, const Scenario& s, const Ranks& ranks) {
  ScenarioDomain shape = b.shape();
  const gis::Georef grid = shape.bed.georef;
  const int w = grid.width, h = grid.height, n = ranks.size();
  auto firstRowOf = [&](int k) { return int((long long)h * k / n); };
  std::vector<gis::CellRect> tiles;
  for (int k = 0; k < n; ++k) tiles.push_back({0, firstRowOf(k), w, firstRowOf(k + 1) - firstRowOf(k)});
  const int y0 = firstRowOf(ranks.rank()), own = firstRowOf(ranks.rank() + 1) - y0;
  STRATA_CHECK(own > 0) << "buildByRows needs a row per rank";
  // The row below too, for fill_depressions' joins across the border with the next rank's rows
  // (its base: at_rest leaves the layers of rows not this rank's as they are).
  const int end = s.terrain.fillDepressions ? std::min(h, y0 + own + 1) : y0 + own;
  auto built = b.rows(y0, end);
  STRATA_TRY_STATUS(ranks.agree(statusOf(built)));
  ScenarioDomain d = std::move(built).value();
  settleAtRest(s, ranks, h, own, d);
  std::vector<sim::ExactSum> tooSteep(d.layerCellsTooSteep.size());
  for (size_t l = 0; l < tooSteep.size(); ++l) tooSteep[l].add(d.layerCellsTooSteep[l]);
  ranks.sum(tooSteep);
  shape.layerCellsTooSteep.clear();
  for (const auto& count : tooSteep) shape.layerCellsTooSteep.push_back(int(count.value()));

  // What needs every row, over this rank's own rows: voids, the lowest bed (the datum), the area,
  // loose material.
  const size_t cells = size_t(own) * size_t(w);
  std::vector<sim::ExactSum> sums(2);  // voids, area
  std::vector<double> low{1e300};
  bool loose = false;
  for (size_t i = 0; i < cells; ++i) {
    if (d.voids.data[i]) sums[0].add(1);
    if (!d.inside.data[i]) continue;
    sums[1].add(d.cellAreaM2.data[i]);
    low[0] = std::min(low[0], double(d.bed.values.data[i]));
    for (const auto& l : d.input.layersM) loose |= l.data[i] > 0;
  }
  ranks.sum(sums);
  ranks.min(low);
  const long long voids = (long long)sums[0].value();
  if (voids > 0 && s.terrain.voids == decltype(s.terrain)::Voids::kRefuse) return b.refuseVoids(voids);
  shape.voidCells = int(voids);
  if (s.erosion.enabled && !ranks.minMax(loose ? 1 : 0).second) return b.refuseNoLooseMaterial();
  shape.input.datumM = std::floor(low[0]);
  shape.totalAreaM2 = sums[1].value();
  d.input.datumM = shape.input.datumM;

  std::vector<int> rowStarts;
  for (int k = 0; k <= n; ++k) rowStarts.push_back(firstRowOf(k));
  // The bed before conditioning, for the map of what breach_inflows and fill_depressions changed.
  const bool conditioned = s.terrain.breachInflows || s.terrain.fillDepressions;
  gis::Grid<float> raw = conditioned ? d.bed.values : gis::Grid<float>();
  STRATA_TRY_STATUS(breachInflowPaths(s, ranks, rowStarts, shape.sources, shape.sourceNames, d));
  shape.breach = d.breach;
  if (s.terrain.fillDepressions) {
    std::vector<sim::ExactSum> filled(2);  // cells, volume
    STRATA_TRY_STATUS(fillOverRanks(b, ranks, tiles, own, d, filled[1]));
    filled[0].add(d.filled.cells);
    ranks.sum(filled);
    std::vector<double> deepest{d.filled.maxM};
    ranks.max(deepest);
    shape.filled.cells = int(filled[0].value());
    shape.filled.volumeM3 = filled[1].value();
    shape.filled.maxM = deepest[0];
  }
  keepRows(d, own);
  if (conditioned) {
    d.conditioningM = gis::Grid<float>(w, own, 0.0f);
    for (size_t i = 0; i < d.conditioningM.size(); ++i) {
      d.conditioningM.data[i] = d.inside.data[i] ? d.bed.values.data[i] - raw.data[i] : gis::kNoData;
    }
  }

  // The levels' stages against their lowest bed, and the bed's range, over all rows.
  std::vector<double> levelBeds = b.lowestLevelBeds(d);
  ranks.min(levelBeds);
  STRATA_TRY_STATUS(b.checkLevelStages(levelBeds));
  // voids = "walls": no place on one, in any rank's rows (the first such place, as one process).
  const int wall = b.firstPlaceOnWalls(d, own);
  if (const long long first = ranks.minMax(wall < 0 ? LLONG_MAX : wall).first; first != LLONG_MAX) {
    return b.refusePlaceOnWalls(int(first));
  }
  // voids = "holes": one level that drains every rank's holes (all of them on every rank).
  std::vector<std::pair<int, int>> holes;
  for (const std::string& bytes : ranks.allGatherBytes(cellBytes(b.voidHoleCells(d, own)))) {
    ByteReader in{bytes};
    std::vector<std::pair<int, int>> theirs;
    readCells(in, theirs);
    STRATA_CHECK(in.ok) << "buildByRows: a rank's holes did not decode";
    holes.insert(holes.end(), theirs.begin(), theirs.end());
  }
  b.addVoidHoles(std::move(holes), shape);
  std::vector<double> damBeds = b.placeDamBreaks(d);
  ranks.min(damBeds);
  STRATA_TRY_STATUS(b.checkDamBreaks(damBeds));
  std::vector<sim::ExactSum> damVolume(1);  // over the cells: the same sum as one process's
  for (size_t i = 0; i < d.input.waterDepthM.size(); ++i) {
    damVolume[0].add(double(d.input.waterDepthM.data[i]) * d.cellAreaM2.data[i]);
  }
  ranks.sum(damVolume);
  shape.damBreakVolumeM3 = damVolume[0].value();
  const auto range = b.bedRange(d, own);
  std::vector<double> lo{range[0]}, hi{range[1]};
  ranks.min(lo);
  ranks.max(hi);
  shape.bedRangeM = {float(lo[0]), float(hi[0])};

  return RowsBuilt{std::move(shape), std::move(d)};
}

Status writeRows(const Ranks& ranks, const fs::path& runDir, const RowsBuilt& built) {
  const auto& shape = built.shape;
  const auto& d = built.rows;
  STRATA_TRY_STATUS(writeModelInput(ranks, runDir, shape.bed.georef, d, shape));
  STRATA_TRY_STATUS(writeRaster(ranks, runDir / "maps" / "elevation.tif", shape.bed.georef, elevationMapOptions(),
                                {{0, d.firstRow, d.bed.values}}));
  if (d.conditioningM.size() == 0) return {};
  return writeRaster(ranks, runDir / "maps" / "conditioning.tif", shape.bed.georef, conditioningMapOptions(),
                     {{0, d.firstRow, d.conditioningM}});
}
sim::RegionSource modelInputSource(const fs::path& runDir, const ScenarioDomain& shape) {
  sim::RegionSource region;
  region.width = shape.bed.georef.width;
  region.height = shape.bed.georef.height;
  region.materials = shape.input.materials;
  region.rowDxM = shape.input.rowDxM;
  region.dyM = shape.input.dyM;
  region.datumM = shape.input.datumM;
  std::vector<OptionalInput> optional;
  for (const auto& o : kOptionalInputs) {
    if ((shape.input.*o.grid).size() > 0) optional.push_back(o);
  }
  const int layers = int(shape.input.materials.size());
  region.read = [runDir, rowDxM = shape.input.rowDxM, materials = shape.input.materials, dy = shape.input.dyM,
                 datum = shape.input.datumM, optional, layers](const gis::CellRect& w) -> Result<sim::SimInput> {
    sim::SimInput in;
    STRATA_TRY(in.baseM, readInputWindow(runDir / "input/base.tif", w));
    for (int k = 1; k <= layers; ++k) {
      STRATA_TRY(auto l, readInputWindow(runDir / ("input/layer_" + std::to_string(k) + ".tif"), w));
      in.layersM.push_back(std::move(l));
    }
    for (const auto& o : optional) {
      STRATA_TRY(in.*o.grid, readInputWindow(runDir / o.file, w));
    }
    in.materials = materials;
    if (rowDxM.size() == 1) {
      in.rowDxM = rowDxM;
    } else {
      in.rowDxM.assign(rowDxM.begin() + w.y, rowDxM.begin() + w.y + w.height);
    }
    in.dyM = dy;
    in.datumM = datum;
    return in;
  };
  return region;
}

}  // namespace strata::scenario::detail

namespace strata::scenario {

// One process builds the domain as one rank holding every row: one order of steps for both.
Result<ScenarioDomain> buildDomain(const Scenario& s, uint64_t memoryBudgetBytes) {
  STRATA_TRY(auto builder, detail::RowBuilder::plan(s, memoryBudgetBytes, 1, true));
  STRATA_TRY(auto built, detail::buildByRows(builder, s, sim::Ranks::single()));
  // The rows are the whole region; the shape holds what is not cells.
  ScenarioDomain d = std::move(built.rows);
  ScenarioDomain& shape = built.shape;
  d.input.materials = shape.input.materials;
  d.input.rowDxM = shape.input.rowDxM;
  d.input.dyM = shape.input.dyM;
  d.input.datumM = shape.input.datumM;
  d.params = shape.params;
  d.sources = std::move(shape.sources);
  d.sourceNames = std::move(shape.sourceNames);
  d.levels = std::move(shape.levels);
  d.levelNames = std::move(shape.levelNames);
  d.gauges = std::move(shape.gauges);
  d.sections = std::move(shape.sections);
  d.rainMmPerHour = shape.rainMmPerHour;
  d.rainStartS = shape.rainStartS;
  d.rainEndS = shape.rainEndS;
  d.damBreakVolumeM3 = shape.damBreakVolumeM3;
  d.totalAreaM2 = shape.totalAreaM2;
  d.bedRangeM = shape.bedRangeM;
  d.breach = shape.breach;
  d.voidCells = shape.voidCells;
  d.layerCellsTooSteep = std::move(shape.layerCellsTooSteep);
  d.filled = shape.filled;
  return d;
}

}  // namespace strata::scenario
