#include "distributed.hpp"

#include <mpi.h>

#include <charconv>
#include <climits>
#include <cstdint>

#include <strata/core/bytes.hpp>
#include <strata/core/interrupt.hpp>
#include <strata/gis/dem_io.hpp>
#include <strata/gis/fill_depressions.hpp>
#include <strata/sim/distributed_solver.hpp>

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

Ranks Ranks::world() {
  Ranks r;
  r.distributed_ = true;
  MPI_Comm_rank(MPI_COMM_WORLD, &r.rank_);
  MPI_Comm_size(MPI_COMM_WORLD, &r.size_);
  return r;
}

Status Ranks::agree(const Status& local) const {
  return distributed_ ? sim::collectiveStatus(local, MPI_COMM_WORLD) : local;
}

bool Ranks::anyInterrupted() const {
  if (!distributed_) return interrupted();
  int mine = interrupted() ? 1 : 0, any = 0;
  MPI_Allreduce(&mine, &any, 1, MPI_INT, MPI_MAX, MPI_COMM_WORLD);
  return any != 0;
}

std::string Ranks::fromLead(std::string bytes) const {
  if (!distributed_) return bytes;
  unsigned long long n = bytes.size();
  MPI_Bcast(&n, 1, MPI_UNSIGNED_LONG_LONG, 0, MPI_COMM_WORLD);
  bytes.resize(size_t(n));
  // In pieces of at most INT_MAX bytes (MPI counts are int).
  for (size_t at = 0; at < bytes.size(); at += size_t(INT_MAX)) {
    MPI_Bcast(bytes.data() + at, int(std::min<size_t>(INT_MAX, bytes.size() - at)), MPI_CHAR, 0, MPI_COMM_WORLD);
  }
  return bytes;
}

std::pair<long long, long long> Ranks::minMax(long long value) const {
  if (!distributed_) return {value, value};
  long long lo = 0, hi = 0;
  MPI_Allreduce(&value, &lo, 1, MPI_LONG_LONG, MPI_MIN, MPI_COMM_WORLD);
  MPI_Allreduce(&value, &hi, 1, MPI_LONG_LONG, MPI_MAX, MPI_COMM_WORLD);
  return {lo, hi};
}

bool Ranks::all(bool value) const { return minMax(value ? 1 : 0).first == 1; }

void Ranks::sum(std::vector<sim::ExactSum>& sums) const {
  if (distributed_) sim::allreduceExact(sums.data(), int(sums.size()), MPI_COMM_WORLD);
}

void Ranks::min(std::vector<double>& values) const {
  if (distributed_) MPI_Allreduce(MPI_IN_PLACE, values.data(), int(values.size()), MPI_DOUBLE, MPI_MIN, MPI_COMM_WORLD);
}

void Ranks::max(std::vector<double>& values) const {
  if (distributed_) MPI_Allreduce(MPI_IN_PLACE, values.data(), int(values.size()), MPI_DOUBLE, MPI_MAX, MPI_COMM_WORLD);
}

namespace {

// Each rank's offset in a gather of `counts` bytes (under 2 GB in all: MPI counts are int).
std::vector<int> offsetsOf(const std::vector<int>& counts) {
  std::vector<int> offsets(counts.size());
  size_t total = 0;
  for (size_t r = 0; r < counts.size(); ++r) {
    offsets[r] = int(total);
    total += size_t(counts[r]);
  }
  STRATA_CHECK(total < size_t(INT_MAX)) << "a gather over the ranks exceeds 2 GB";
  return offsets;
}

// The gathered bytes back as each rank's part.
std::vector<std::string> partsOf(const std::string& all, const std::vector<int>& counts,
                                 const std::vector<int>& offsets) {
  std::vector<std::string> out;
  for (size_t r = 0; r < counts.size(); ++r) out.push_back(all.substr(size_t(offsets[r]), size_t(counts[r])));
  return out;
}

}  // namespace

std::vector<std::string> Ranks::gatherToLead(const std::string& bytes) const {
  if (!distributed_) return {bytes};
  STRATA_CHECK(bytes.size() < size_t(INT_MAX)) << "a rank's part of a gather exceeds 2 GB";
  int n = int(bytes.size());
  std::vector<int> counts(static_cast<size_t>(size_)), offsets;
  MPI_Gather(&n, 1, MPI_INT, counts.data(), 1, MPI_INT, 0, MPI_COMM_WORLD);
  std::string all;
  if (lead()) {
    offsets = offsetsOf(counts);
    all.resize(size_t(offsets.back()) + size_t(counts.back()));
  }
  MPI_Gatherv(bytes.data(), n, MPI_CHAR, all.data(), counts.data(), offsets.data(), MPI_CHAR, 0, MPI_COMM_WORLD);
  return lead() ? partsOf(all, counts, offsets) : std::vector<std::string>{};
}

std::vector<std::string> Ranks::allGatherBytes(const std::string& bytes) const {
  if (!distributed_) return {bytes};
  STRATA_CHECK(bytes.size() < size_t(INT_MAX)) << "a rank's part of a gather exceeds 2 GB";
  int n = int(bytes.size());
  std::vector<int> counts(static_cast<size_t>(size_));
  MPI_Allgather(&n, 1, MPI_INT, counts.data(), 1, MPI_INT, MPI_COMM_WORLD);
  const std::vector<int> offsets = offsetsOf(counts);
  std::string all(size_t(offsets.back()) + size_t(counts.back()), '\0');
  MPI_Allgatherv(bytes.data(), n, MPI_CHAR, all.data(), counts.data(), offsets.data(), MPI_CHAR, MPI_COMM_WORLD);
  return partsOf(all, counts, offsets);
}

std::pair<std::string, std::string> Ranks::swapWithNeighbours(const std::string& up, const std::string& down) const {
  if (!distributed_) return {};
  const int before = rank_ > 0 ? rank_ - 1 : MPI_PROC_NULL, after = rank_ + 1 < size_ ? rank_ + 1 : MPI_PROC_NULL;
  STRATA_CHECK(up.size() < size_t(INT_MAX) && down.size() < size_t(INT_MAX)) << "a rank's part of a swap exceeds 2 GB";
  int upCount = int(up.size()), downCount = int(down.size()), fromBefore = 0, fromAfter = 0;
  MPI_Sendrecv(&upCount, 1, MPI_INT, before, 0, &fromAfter, 1, MPI_INT, after, 0, MPI_COMM_WORLD, MPI_STATUS_IGNORE);
  MPI_Sendrecv(&downCount, 1, MPI_INT, after, 1, &fromBefore, 1, MPI_INT, before, 1, MPI_COMM_WORLD, MPI_STATUS_IGNORE);
  std::pair<std::string, std::string> got{std::string(size_t(fromBefore), '\0'), std::string(size_t(fromAfter), '\0')};
  MPI_Sendrecv(up.data(), upCount, MPI_CHAR, before, 2, got.second.data(), fromAfter, MPI_CHAR, after, 2,
               MPI_COMM_WORLD, MPI_STATUS_IGNORE);
  MPI_Sendrecv(down.data(), downCount, MPI_CHAR, after, 3, got.first.data(), fromBefore, MPI_CHAR, before, 3,
               MPI_COMM_WORLD, MPI_STATUS_IGNORE);
  return got;
}

std::vector<double> Ranks::allGather(const std::vector<double>& values) const {
  if (!distributed_) return values;
  std::vector<double> all(values.size() * size_t(size_));
  MPI_Allgather(values.data(), int(values.size()), MPI_DOUBLE, all.data(), int(values.size()), MPI_DOUBLE,
                MPI_COMM_WORLD);
  return all;
}

std::vector<std::string> modelInputFiles(int layers) {
  std::vector<std::string> files{"input/base.tif", "input/water.tif", "input/rain.tif"};
  for (int k = 1; k <= layers; ++k) files.push_back("input/layer_" + std::to_string(k) + ".tif");
  return files;
}

Status writeModelInput(const Ranks& ranks, const fs::path& runDir, const gis::Georef& georef, const ScenarioDomain& d,
                       int layers, bool water, bool rain) {
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
  if (water) STRATA_TRY_STATUS(write("input/water.tif", &d.input.waterDepthM, "initial depth (m)"));
  if (rain) STRATA_TRY_STATUS(write("input/rain.tif", &d.input.rainMmPerHour, "rain (mm/h)"));
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
  crop(d.input.rainMmPerHour);
  crop(d.input.waterDepthM);
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

Status writeRows(const Ranks& ranks, const fs::path& runDir, const RowsBuilt& built, bool elevation) {
  const auto& shape = built.shape;
  const auto& d = built.rows;
  STRATA_TRY_STATUS(writeModelInput(ranks, runDir, shape.bed.georef, d, int(shape.input.materials.size()),
                                    shape.input.waterDepthM.size() > 0, shape.input.rainMmPerHour.size() > 0));
  if (!elevation) return {};
  return writeRaster(ranks, runDir / "maps" / "elevation.tif", shape.bed.georef, {}, {{0, d.firstRow, d.bed.values}});
}
sim::RegionSource modelInputSource(const fs::path& runDir, const ScenarioDomain& shape) {
  sim::RegionSource region;
  region.width = shape.bed.georef.width;
  region.height = shape.bed.georef.height;
  region.materials = shape.input.materials;
  region.rowDxM = shape.input.rowDxM;
  region.dyM = shape.input.dyM;
  region.datumM = shape.input.datumM;
  const bool water = shape.input.waterDepthM.size() > 0, rain = shape.input.rainMmPerHour.size() > 0;
  const int layers = int(shape.input.materials.size());
  region.read = [runDir, rowDxM = shape.input.rowDxM, materials = shape.input.materials, dy = shape.input.dyM,
                 datum = shape.input.datumM, water, rain, layers](const gis::CellRect& w) -> Result<sim::SimInput> {
    sim::SimInput in;
    STRATA_TRY(in.baseM, readInputWindow(runDir / "input/base.tif", w));
    for (int k = 1; k <= layers; ++k) {
      STRATA_TRY(auto l, readInputWindow(runDir / ("input/layer_" + std::to_string(k) + ".tif"), w));
      in.layersM.push_back(std::move(l));
    }
    if (water) {
      STRATA_TRY(in.waterDepthM, readInputWindow(runDir / "input/water.tif", w));
    }
    if (rain) {
      STRATA_TRY(in.rainMmPerHour, readInputWindow(runDir / "input/rain.tif", w));
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

std::string rankCheckpointFile(int rank, int ranks) {
  return "checkpoint." + std::to_string(rank) + "-of-" + std::to_string(ranks) + ".bin";
}

bool isRankCheckpointFile(std::string_view name, int* ranks) {
  // "checkpoint." + at least "0-of-1" + ".bin" (checkpoint.bin, the one process's, is not one).
  if (name.size() < 21 || !name.starts_with("checkpoint.") || !name.ends_with(".bin")) return false;
  name.remove_prefix(11);
  name.remove_suffix(4);
  const auto of = name.find("-of-");
  if (of == std::string_view::npos) return false;
  int r = -1, n = 0;
  const auto a = name.substr(0, of), b = name.substr(of + 4);
  const auto ra = std::from_chars(a.data(), a.data() + a.size(), r);
  const auto rb = std::from_chars(b.data(), b.data() + b.size(), n);
  if (ra.ec != std::errc() || ra.ptr != a.data() + a.size() || rb.ec != std::errc() || rb.ptr != b.data() + b.size())
    return false;
  if (!(r >= 0 && n >= 1 && r < n) ||
      rankCheckpointFile(r, n) != std::string("checkpoint.") + std::string(name) + ".bin")
    return false;
  if (ranks) *ranks = n;
  return true;
}

}  // namespace strata::scenario::detail
