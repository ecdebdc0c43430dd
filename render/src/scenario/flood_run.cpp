#include <strata/render/scenario/flood_run.hpp>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <optional>
#include <sstream>

#include <strata/core/files.hpp>
#include <strata/core/interrupt.hpp>
#include <strata/core/log.hpp>
#include <strata/core/progress.hpp>
#include <strata/gis/dem_io.hpp>
#include <strata/gis/geodesy.hpp>
#include <strata/render/gl/context.hpp>
#include <strata/render/image_io.hpp>
#include <strata/render/scenario/report.hpp>
#include <strata/render/sim/simulation.hpp>
#include <strata/render/terrain/terrain_renderer.hpp>
#include <strata/terrain/scenario_domain.hpp>

#ifndef STRATA_TOOLS_DIR
#define STRATA_TOOLS_DIR "tools"
#endif

namespace strata::render::scenario {
namespace fs = std::filesystem;
namespace {

constexpr char kMagic[8] = {'S', 'T', 'R', 'A', 'T', 'A', 'C', '1'};

// FNV-1a of the scenario text: a checkpoint only resumes the scenario that wrote it.
uint64_t hashText(const std::string& text) {
  uint64_t h = 1469598103934665603ull;
  for (unsigned char c : text) h = (h ^ c) * 1099511628211ull;
  return h;
}

std::string slurp(const fs::path& p) {
  std::ifstream f(p, std::ios::binary);
  std::stringstream s;
  s << f.rdbuf();
  return s.str();
}

// Binary checkpoint: header, the series so far, the simulation snapshot.
struct Writer {
  std::string out;
  template <class T>
  void pod(const T& v) {
    out.append(reinterpret_cast<const char*>(&v), sizeof v);
  }
  template <class T>
  void vec(const std::vector<T>& v) {
    pod(uint64_t(v.size()));
    out.append(reinterpret_cast<const char*>(v.data()), v.size() * sizeof(T));
  }
};

struct Reader {
  const std::string& in;
  size_t at = 0;
  bool ok = true;
  template <class T>
  void pod(T& v) {
    if (at + sizeof v > in.size()) {
      ok = false;
      return;
    }
    std::memcpy(&v, in.data() + at, sizeof v);
    at += sizeof v;
  }
  template <class T>
  void vec(std::vector<T>& v) {
    uint64_t n = 0;
    pod(n);
    if (!ok || n > (in.size() - at) / sizeof(T)) {
      ok = false;
      return;
    }
    v.resize(n);
    std::memcpy(v.data(), in.data() + at, n * sizeof(T));
    at += n * sizeof(T);
  }
};

void writeGrid(Writer& w, const gis::Grid<float>& g) {
  w.pod(int32_t(g.width));
  w.pod(int32_t(g.height));
  w.vec(g.data);
}
void readGrid(Reader& r, gis::Grid<float>& g) {
  int32_t wd = 0, ht = 0;
  r.pod(wd);
  r.pod(ht);
  r.vec(g.data);
  g.width = wd;
  g.height = ht;
  if (g.data.size() != size_t(wd) * size_t(ht)) r.ok = false;
}

std::string encodeCheckpoint(uint64_t hash, int interval, const std::vector<SeriesRow>& series,
                             const sim::Simulation::Snapshot& snap) {
  Writer w;
  w.out.append(kMagic, sizeof kMagic);
  w.pod(hash);
  w.pod(int32_t(interval));
  w.vec(series);
  w.pod(snap.counters);
  w.vec(snap.raw.state);
  w.vec(snap.raw.flux);
  w.vec(snap.raw.fluxDiag);
  w.vec(snap.raw.layers);
  w.vec(snap.raw.accum);
  writeGrid(w, snap.flood.maxDepthM);
  writeGrid(w, snap.flood.maxSpeedMS);
  writeGrid(w, snap.flood.arrivalS);
  writeGrid(w, snap.flood.wetDurationS);
  return w.out;
}

Status decodeCheckpoint(const fs::path& path, uint64_t hash, int& interval, std::vector<SeriesRow>& series,
                        sim::Simulation::Snapshot& snap) {
  const std::string data = slurp(path);
  if (data.size() < sizeof kMagic || std::memcmp(data.data(), kMagic, sizeof kMagic) != 0) {
    return fail(path.string() + ": not a Strata checkpoint");
  }
  Reader r{data, sizeof kMagic};
  uint64_t fileHash = 0;
  int32_t iv = 0;
  r.pod(fileHash);
  r.pod(iv);
  if (r.ok && fileHash != hash) return fail(path.string() + ": written by a different scenario (the file changed)");
  r.vec(series);
  r.pod(snap.counters);
  r.vec(snap.raw.state);
  r.vec(snap.raw.flux);
  r.vec(snap.raw.fluxDiag);
  r.vec(snap.raw.layers);
  r.vec(snap.raw.accum);
  readGrid(r, snap.flood.maxDepthM);
  readGrid(r, snap.flood.maxSpeedMS);
  readGrid(r, snap.flood.arrivalS);
  readGrid(r, snap.flood.wetDurationS);
  if (!r.ok || r.at != data.size()) return fail(path.string() + ": truncated or corrupt checkpoint");
  interval = iv;
  return {};
}

// Total material thickness per cell (m), for terrain change.
gis::Grid<float> materialThickness(const std::vector<gis::Grid<float>>& layers) {
  gis::Grid<float> t(layers.front().width, layers.front().height, 0.0f);
  for (const auto& l : layers) {
    for (size_t i = 0; i < t.size(); ++i) t.data[i] += l.data[i];
  }
  return t;
}

// Oblique pictures of the region with its water, drawn by the concentric-ring renderer: from a
// little behind the first inflow (or the region's centre), looking across the region towards its
// centre, about a quarter of the region's north-south extent above its highest point.
class Pictures {
 public:
  static Result<Pictures> create(const strata::terrain::ScenarioDomain& d) {
    Pictures p;
    const auto& g = d.bed.georef;
    STRATA_TRY(p.scene_, terrain::TerrainScene::create(d.bed));
    STRATA_TRY(p.ring_, terrain::RingRenderer::create({.circles = 160}));
    STRATA_TRY(p.target_, terrain::OffscreenTarget::create(kWidth, kHeight));
    const double cx = 0.5 * g.width, cy = 0.5 * g.height;
    double tx = cx, ty = cy;
    if (!d.sources.empty()) {
      tx = d.sources.front().cells.front().first + 0.5;
      ty = d.sources.front().cells.front().second + 0.5;
    }
    // Cell (column, row) offsets in metres: east, north.
    const double dxM = d.input.rowDxM[d.input.rowDxM.size() / 2], dyM = d.input.dyM;
    double east = (cx - tx) * dxM, north = (ty - cy) * dyM;
    if (std::hypot(east, north) < 1) north = 1;  // no inflow: look north from the centre
    const double camX = std::clamp(tx - 0.15 * (cx - tx), 0.5, g.width - 0.5);
    const double camY = std::clamp(ty - 0.15 * (cy - ty), 0.5, g.height - 0.5);
    p.camera_.lon = g.transform.x(camX, camY);
    p.camera_.lat = g.transform.y(camX, camY);
    p.camera_.heightM = p.scene_.maxElevationM() + 0.25 * dyM * g.height;
    p.camera_.headingDeg = std::atan2(east, north) * 180 / M_PI;
    p.camera_.pitchDeg = -40;
    p.camera_.fovYDeg = 50;
    p.shading_.waterDepthScaleM = 15;
    return p;
  }

  /// Draws the terrain with `depthM` of water and writes `file` (PNG).
  Status draw(const gis::Grid<float>& depthM, const fs::path& file) {
    STRATA_TRY_STATUS(scene_.setWaterDepth(depthM));
    STRATA_TRY_STATUS(ring_->draw(scene_, camera_, shading_, target_));
    const auto tmp = temporaryPathFor(file).string() + ".png";
    STRATA_TRY_STATUS(writeImage8(tmp, kWidth, kHeight, 4, target_.colour()));
    return commitTemporary(tmp, file);
  }

 private:
  static constexpr int kWidth = 960, kHeight = 540;
  terrain::TerrainScene scene_;
  std::unique_ptr<terrain::RingRenderer> ring_;
  terrain::OffscreenTarget target_;
  terrain::CameraPose camera_;
  terrain::Shading shading_;
};

}  // namespace

std::string seriesCsv(const std::vector<SeriesRow>& rows) {
  std::string out =
      "time_s,steps,dt_s,water_volume_m3,flooded_area_km2,inflow_m3,rain_m3,outflow_m3,evaporation_m3,"
      "balance_error_rel,max_depth_m,sediment_m3,eroded_m3,deposited_m3\n";
  char buf[512];
  for (const auto& r : rows) {
    std::snprintf(buf, sizeof buf, "%.3f,%lld,%.6g,%.9g,%.9g,%.9g,%.9g,%.9g,%.9g,%.6g,%.6g,%.9g,%.9g,%.9g\n", r.timeS,
                  r.steps, r.dtS, r.waterM3, r.floodedAreaKm2, r.inflowM3, r.rainM3, r.outflowM3, r.evaporationM3,
                  r.balanceErrorRel, r.maxDepthM, r.sedimentM3, r.erodedM3, r.depositedM3);
    out += buf;
  }
  return out;
}

Result<RunSummary> runScenario(const strata::terrain::Scenario& s, const RunOptions& opt) {
  const auto wallStart = std::chrono::steady_clock::now();
  STRATA_TRY(auto domain, strata::terrain::buildDomain(s));
  const auto& g = domain.bed.georef;
  const int w = g.width, h = g.height;
  log::info("flood") << s.name << ": " << w << " x " << h << " cells, " << domain.totalAreaM2 / 1e6 << " km^2, "
                     << domain.sources.size() << " inflow(s), " << domain.levels.size() << " fixed level(s), "
                     << formatDuration(s.durationS) << " simulated";

  std::error_code ec;
  fs::create_directories(opt.outDir / "maps", ec);
  if (ec) return fail(opt.outDir.string() + ": cannot create the run folder: " + ec.message());
  const std::string scenarioText = slurp(s.file);
  const uint64_t hash = hashText(scenarioText);
  const fs::path checkpointPath = opt.outDir / "checkpoint.bin";

  STRATA_TRY(auto ctx, gl::HeadlessContext::create());
  STRATA_TRY(auto sim, sim::Simulation::create(domain.input, domain.params));
  for (const auto& src : domain.sources) STRATA_TRY_STATUS(sim.addSource(src));
  for (const auto& level : domain.levels) STRATA_TRY_STATUS(sim.addLevel(level));
  sim.enableFloodStats(float(s.outputs.wetThresholdM));

  std::optional<Pictures> pictures;
  if (opt.pictures) {
    fs::create_directories(opt.outDir / "pictures", ec);
    STRATA_TRY(auto p, Pictures::create(domain));
    pictures.emplace(std::move(p));
    if (!opt.resume) STRATA_TRY_STATUS(pictures->draw(sim.readWaterDepth(), opt.outDir / "pictures" / "before.png"));
  }

  const auto initialLayers = sim.readLayers();
  const gis::Grid<float> initialMaterial = materialThickness(initialLayers);

  auto rainAt = [&](double t) { return t >= domain.rainStartS && t < domain.rainEndS ? domain.rainMmPerHour : 0.0; };
  RunSummary summary;
  int interval = 0;
  if (opt.resume) {
    if (!fs::exists(checkpointPath)) return fail(checkpointPath.string() + ": no checkpoint to resume from");
    sim::Simulation::Snapshot snap;
    STRATA_TRY_STATUS(decodeCheckpoint(checkpointPath, hash, interval, summary.series, snap));
    STRATA_TRY_STATUS(sim.restore(snap));
    auto p = sim.params();
    p.rainMmPerHour = float(rainAt(snap.counters.timeS));
    STRATA_TRY_STATUS(sim.setParams(p));
    log::info("flood") << "resuming at " << formatDuration(sim.stats().timeS) << " (interval " << interval << ")";
  } else {
    STRATA_TRY_STATUS(writeFileAtomic(opt.outDir / "scenario.toml", scenarioText));
  }

  const int intervals = int(std::ceil(s.durationS / s.outputIntervalS - 1e-9));
  // Each interval advances in fixed chunks, so a resumed run takes the same steps.
  constexpr int kChunks = 20;
  Progress progress("flood " + s.name, s.durationS);
  installInterruptHandler();

  std::vector<std::string> mapFiles;
  while (interval < intervals) {
    const double t0 = interval * s.outputIntervalS, t1 = std::min(s.durationS, (interval + 1) * s.outputIntervalS);
    bool stopped = false;
    for (int c = 0; c < kChunks; ++c) {
      const double a = t0 + (t1 - t0) * c / kChunks, b = t0 + (t1 - t0) * (c + 1) / kChunks;
      // Rain switches on and off at its times: split the chunk there.
      double t = a;
      while (t < b - 1e-9) {
        double next = b;
        for (double edge : {domain.rainStartS, domain.rainEndS}) {
          if (edge > t + 1e-9 && edge < next) next = edge;
        }
        if (float(rainAt(t)) != sim.params().rainMmPerHour) {
          auto p = sim.params();
          p.rainMmPerHour = float(rainAt(t));
          STRATA_TRY_STATUS(sim.setParams(p));
        }
        sim.advance(next - sim.stats().timeS);
        t = next;
      }
      const auto st = sim.stats();
      char note[96];
      std::snprintf(note, sizeof note, "t = %s, %lld steps, dt %.2f s", formatDuration(st.timeS).c_str(), st.steps,
                    st.lastDtS);
      progress.update(st.timeS, note);
      if (interrupted()) {
        stopped = true;
        break;
      }
    }
    if (stopped) break;

    // The interval is complete: its row, maps and checkpoint.
    const auto st = sim.stats();
    const auto depth = sim.readWaterDepth();
    SeriesRow row;
    row.timeS = st.timeS;
    row.steps = st.steps;
    row.dtS = st.lastDtS;
    row.waterM3 = st.storedWaterM3;
    row.inflowM3 = st.inflowM3;
    row.rainM3 = st.rainM3;
    row.outflowM3 = st.outflowM3;
    row.evaporationM3 = st.evaporatedM3;
    const double supplied = st.initialWaterM3 + st.rainM3 + st.inflowM3;
    row.balanceErrorRel = supplied > 0 ? st.waterBalanceM3() / supplied : 0.0;
    row.maxDepthM = st.maxDepthM;
    double area = 0;
    for (size_t i = 0; i < depth.size(); ++i) {
      if (domain.inside.data[i] && depth.data[i] > s.outputs.wetThresholdM) area += domain.cellAreaM2.data[i];
    }
    row.floodedAreaKm2 = area / 1e6;
    row.sedimentM3 = st.suspendedM3;
    gis::Grid<float> change;
    if (s.erosion.enabled) {
      change = materialThickness(sim.readLayers());
      for (size_t i = 0; i < change.size(); ++i) {
        change.data[i] -= initialMaterial.data[i];
        const double v = double(change.data[i]) * domain.cellAreaM2.data[i];
        (v < 0 ? row.erodedM3 : row.depositedM3) += std::abs(v);
      }
    }
    summary.series.push_back(row);
    ++interval;
    if (pictures) {
      // The peak picture is redrawn whenever the stored water reaches a new high at an interval.
      const bool peak = std::all_of(summary.series.begin(), summary.series.end(),
                                    [&](const SeriesRow& r) { return r.waterM3 <= row.waterM3; });
      if (peak) {
        STRATA_TRY_STATUS(pictures->draw(depth, opt.outDir / "pictures" / "peak.png"));
      }
      if (interval == intervals) STRATA_TRY_STATUS(pictures->draw(depth, opt.outDir / "pictures" / "after.png"));
    }

    STRATA_TRY_STATUS(writeFileAtomic(opt.outDir / "series.csv", seriesCsv(summary.series)));
    const auto flood = sim.readFloodStats();
    auto writeMap = [&](const std::string& name, const gis::Grid<float>& values, bool wetOnly) -> Status {
      if (std::find(s.outputs.maps.begin(), s.outputs.maps.end(), name) == s.outputs.maps.end()) return {};
      gis::Raster r{g, values};
      for (size_t i = 0; i < r.values.size(); ++i) {
        if (!domain.inside.data[i] || (wetOnly && !(flood.maxDepthM.data[i] > s.outputs.wetThresholdM))) {
          r.values.data[i] = gis::kNoData;
        }
      }
      const std::string file = "maps/" + name + ".tif";
      STRATA_TRY_STATUS(gis::writeGeoTiff((opt.outDir / file).string(), r));
      if (std::find(mapFiles.begin(), mapFiles.end(), file) == mapFiles.end()) mapFiles.push_back(file);
      return {};
    };
    STRATA_TRY_STATUS(writeMap("max_depth", flood.maxDepthM, false));
    STRATA_TRY_STATUS(writeMap("max_speed", flood.maxSpeedMS, false));
    STRATA_TRY_STATUS(writeMap("arrival_time", flood.arrivalS, true));
    STRATA_TRY_STATUS(writeMap("inundation_duration", flood.wetDurationS, false));
    STRATA_TRY_STATUS(writeMap("final_depth", depth, false));
    if (s.erosion.enabled) STRATA_TRY_STATUS(writeMap("terrain_change", change, false));
    STRATA_TRY_STATUS(
        writeFileAtomic(checkpointPath, encodeCheckpoint(hash, interval, summary.series, sim.snapshot())));
    if (opt.stopAfterIntervals >= 0 && interval >= opt.stopAfterIntervals && interval < intervals) break;
  }
  const auto st = sim.stats();
  summary.completed = interval >= intervals;
  summary.simulatedS = st.timeS;
  summary.steps = st.steps;
  summary.wallS = std::chrono::duration<double>(std::chrono::steady_clock::now() - wallStart).count();
  if (summary.completed) {
    progress.finish(std::to_string(st.steps) + " steps");
  } else {
    log::warn("flood") << "stopped at " << formatDuration(summary.series.empty() ? 0 : summary.series.back().timeS)
                       << "; outputs are those of that interval; continue with --resume";
  }
  summary.files = {"scenario.toml", "series.csv", "checkpoint.bin"};
  summary.files.insert(summary.files.end(), mapFiles.begin(), mapFiles.end());
  std::vector<std::string> pictureFiles;
  for (const char* p : {"pictures/before.png", "pictures/peak.png", "pictures/after.png"}) {
    if (fs::exists(opt.outDir / p)) pictureFiles.push_back(p);
  }
  summary.files.insert(summary.files.end(), pictureFiles.begin(), pictureFiles.end());

  if (opt.plots) {
    STRATA_TRY(auto plots, writePlots(opt.outDir, domain.bed, summary.completed));
    summary.files.insert(summary.files.end(), plots.begin(), plots.end());
  }
  STRATA_TRY_STATUS(
      writeReport(opt.outDir, ReportInput{s, domain, summary, sim.readFloodStats(), ctx.info().renderer}));
  summary.files.push_back("report.md");
  return summary;
}

}  // namespace strata::render::scenario
