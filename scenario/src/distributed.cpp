#include "distributed.hpp"

#include <mpi.h>

#include <charconv>
#include <climits>
#include <cstdint>

#include <strata/core/bytes.hpp>
#include <strata/core/interrupt.hpp>
#include <strata/gis/dem_io.hpp>
#include <strata/sim/distributed_solver.hpp>

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
void readCells(ByteReader& r, std::vector<std::pair<int, int>>& cells) {
  std::vector<int32_t> flat;
  r.vec(flat);
  cells.clear();
  for (size_t i = 0; i + 1 < flat.size(); i += 2) cells.emplace_back(flat[i], flat[i + 1]);
}
void writeSeries(ByteWriter& w, const TimeSeries& s) { w.vec(s.samples()); }
void readSeries(ByteReader& r, TimeSeries& s) {
  std::vector<TimeSeries::Sample> samples;
  r.vec(samples);
  if (r.ok && !samples.empty()) s = TimeSeries(std::move(samples));
}

// A material's fields in order, for a ByteWriter (M = const Material) or a ByteReader.
template <class IO, class M>
void materialFields(IO& io, M& m) {
  io.str(m.name);
  io.pod(m.colour);
  io.pod(m.erodibility);
  io.pod(m.dissolutionRate);
  io.pod(m.talusAngleDeg);
  io.pod(m.densityKgM3);
  io.pod(m.weatheringRatePerS);
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

std::vector<double> Ranks::allGather(const std::vector<double>& values) const {
  if (!distributed_) return values;
  std::vector<double> all(values.size() * size_t(size_));
  MPI_Allgather(values.data(), int(values.size()), MPI_DOUBLE, all.data(), int(values.size()), MPI_DOUBLE,
                MPI_COMM_WORLD);
  return all;
}

// A georeference's fields in order, for a ByteWriter (G = const Georef) or a ByteReader.
template <class IO, class G>
void georefFields(IO& io, G& g) {
  io.str(g.crsWkt);
  io.str(g.crsName);
  io.pod(g.geographic);
  io.pod(g.transform.c);
  io.pod(g.width);
  io.pod(g.height);
  io.str(g.body.name);
  io.pod(g.body.semiMajorM);
  io.pod(g.body.flattening);
  io.str(g.verticalUnit);
}

// What the report says of the domain's build, for a ByteWriter (D = const ScenarioDomain) or a
// ByteReader.
template <class IO, class D>
void reportFields(IO& io, D& d) {
  for (auto* names : {&d.sourceNames, &d.levelNames}) {
    uint64_t n = names->size();
    io.pod(n);
    if constexpr (!std::is_const_v<D>) names->resize(size_t(std::min<uint64_t>(n, io.left())));
    for (auto& name : *names) io.str(name);
  }
  io.pod(d.damBreakVolumeM3);
  io.pod(d.totalAreaM2);
  io.pod(d.bedRangeM);
  io.pod(d.breach);
  io.pod(d.filled);
  io.pod(d.voidCells);
  io.vec(d.layerCellsTooSteep);
}

std::string encodeDomainShape(const ScenarioDomain& d) {
  ByteWriter w;
  georefFields(w, d.bed.georef);
  w.pod(int32_t(d.bed.georef.epsg.value_or(-1)));
  w.pod(d.params);
  w.vec(d.input.rowDxM);
  w.pod(d.input.dyM);
  w.pod(d.input.datumM);
  w.pod(uint64_t(d.input.materials.size()));
  for (const auto& m : d.input.materials) materialFields(w, m);
  w.pod(uint8_t(d.input.waterDepthM.size() > 0));
  w.pod(uint8_t(d.input.rainMmPerHour.size() > 0));
  w.pod(uint64_t(d.sources.size()));
  for (const auto& s : d.sources) {
    writeCells(w, s.cells);
    writeSeries(w, s.dischargeM3S);
  }
  w.pod(uint64_t(d.levels.size()));
  for (const auto& l : d.levels) {
    writeCells(w, l.cells);
    writeSeries(w, l.stageM);
  }
  w.pod(d.rainMmPerHour);
  w.pod(d.rainStartS);
  w.pod(d.rainEndS);
  reportFields(w, d);
  return w.out;
}

Result<ScenarioDomain> decodeDomainShape(std::string_view bytes) {
  ByteReader r{bytes};
  ScenarioDomain d;
  georefFields(r, d.bed.georef);
  int32_t epsg = -1;
  r.pod(epsg);
  if (epsg >= 0) d.bed.georef.epsg = epsg;
  r.pod(d.params);
  r.vec(d.input.rowDxM);
  r.pod(d.input.dyM);
  r.pod(d.input.datumM);
  uint64_t n = 0;
  r.pod(n);
  for (uint64_t i = 0; r.ok && i < n && i < uint64_t(kMaxInputLayers); ++i)
    materialFields(r, d.input.materials.emplace_back());
  uint8_t water = 0, rain = 0;
  r.pod(water);
  r.pod(rain);
  // A one-cell marker: the lead's domain has these grids (their cells are in input/).
  if (water) d.input.waterDepthM = gis::Grid<float>(1, 1, 0.0f);
  if (rain) d.input.rainMmPerHour = gis::Grid<float>(1, 1, 0.0f);
  r.pod(n);
  for (uint64_t i = 0; r.ok && i < n; ++i) {
    auto& s = d.sources.emplace_back();
    readCells(r, s.cells);
    readSeries(r, s.dischargeM3S);
  }
  r.pod(n);
  for (uint64_t i = 0; r.ok && i < n; ++i) {
    auto& l = d.levels.emplace_back();
    readCells(r, l.cells);
    readSeries(r, l.stageM);
  }
  r.pod(d.rainMmPerHour);
  r.pod(d.rainStartS);
  r.pod(d.rainEndS);
  reportFields(r, d);
  if (!r.ok || r.left() != 0)
    return fail("the domain sent by rank 0 is damaged (" + std::to_string(bytes.size()) + " bytes)");
  return d;
}

std::vector<std::string> modelInputFiles(int layers) {
  std::vector<std::string> files{"input/base.tif", "input/water.tif", "input/rain.tif"};
  for (int k = 1; k <= layers; ++k) files.push_back("input/layer_" + std::to_string(k) + ".tif");
  return files;
}

Status writeModelInput(const fs::path& runDir, const ScenarioDomain& d) {
  const int layers = int(d.input.layersM.size());
  if (layers > kMaxInputLayers) {
    return fail(std::to_string(layers) + " layers: a run over MPI ranks takes at most " +
                std::to_string(kMaxInputLayers));
  }
  std::error_code ec;
  fs::create_directories(runDir / "input", ec);
  if (ec) return fail((runDir / "input").string() + ": cannot create: " + ec.message());
  auto write = [&](const std::string& file, const gis::Grid<float>& values, const std::string& what) -> Status {
    gis::WriteOptions o;
    o.metadata = {{"STRATA_MODEL_INPUT", what}};
    return gis::writeGeoTiff((runDir / file).string(), gis::Raster{d.bed.georef, values}, o);
  };
  STRATA_TRY_STATUS(write("input/base.tif", d.input.baseM, "base elevation (m), conditioned, walls included"));
  if (d.input.waterDepthM.size() > 0)
    STRATA_TRY_STATUS(write("input/water.tif", d.input.waterDepthM, "initial depth (m)"));
  if (d.input.rainMmPerHour.size() > 0) {
    STRATA_TRY_STATUS(write("input/rain.tif", d.input.rainMmPerHour, "rain (mm/h)"));
  }
  for (int k = 0; k < layers; ++k) {
    STRATA_TRY_STATUS(write("input/layer_" + std::to_string(k + 1) + ".tif", d.input.layersM[size_t(k)],
                            "thickness (m) of " + d.input.materials[size_t(k)].name));
  }
  return {};
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
