#include <strata/scenario/run.hpp>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <functional>
#include <memory>
#include <optional>
#include <sstream>

#include <strata/core/file_lock.hpp>
#include <strata/core/files.hpp>
#include <strata/core/interrupt.hpp>
#include <strata/core/log.hpp>
#include <strata/core/progress.hpp>
#include <strata/gis/dem_io.hpp>
#include <strata/gis/fill_depressions.hpp>
#include <strata/gis/geodesy.hpp>
#include <strata/gis/polygons.hpp>
#include <strata/gl/context.hpp>
#include <strata/render/image_io.hpp>
#include <strata/render/terrain_renderer.hpp>
#include <strata/scenario/domain.hpp>
#include <strata/scenario/report.hpp>
#include <strata/sim/cpu_solver.hpp>
#include <strata/sim/gl/gl_solver.hpp>
#include <strata/sim/mpi/distributed_solver.hpp>

#include "build_rows.hpp"
#include "checkpoint.hpp"
#include "domain_rows.hpp"
#include "pieces.hpp"
#include "probes.hpp"
#include "styles.hpp"

namespace strata::scenario {
namespace fs = std::filesystem;
using detail::Ranks;
namespace {

// The net change of material thickness at cell i of a piece (m): the layers summed in float,
// bottom first, now less at the start.
float materialChange(const detail::Piece& p, size_t i) {
  float now = 0, before = 0;
  for (const auto& l : p.layers) now += l.data[i];
  for (const auto& l : p.initialLayers) before += l.data[i];
  return now - before;
}

// The layer_thickness map of layer k (1 = the bottom one).
std::string layerMapFile(int k) { return "maps/layer_" + std::to_string(k) + ".tif"; }
constexpr int kMaxLayerMaps = 64;  // layers beyond this get no map (the report still lists them)

// The files a run writes, relative to its folder: what --overwrite may remove and what makes a
// folder "hold an earlier run".
std::vector<std::string> runFolderFiles() {
  std::vector<std::string> files{"scenario.toml",  "series.csv", "gauges.csv",        "sections.csv",
                                 "checkpoint.bin", "report.md",  "maps/elevation.tif"};
  for (const auto& m : knownOutputMaps()) {
    if (m == "layer_thickness") continue;  // one file per layer, below
    files.push_back("maps/" + m + (m == "flood_outline" ? ".gpkg" : ".tif"));
    files.push_back("plots/" + m + ".png");
  }
  for (int k = 1; k <= kMaxLayerMaps; ++k) files.push_back(layerMapFile(k));
  // QGIS styles beside every map (styles.hpp).
  for (size_t i = 0, n = files.size(); i < n; ++i) {
    if (files[i].starts_with("maps/")) files.push_back(fs::path(files[i]).replace_extension(".qml").string());
  }
  for (const char* p : {"water", "area", "balance", "sediment", "gauges", "sections"})
    files.push_back("plots/" + std::string(p) + ".png");
  for (const char* p : {"before", "peak", "after", "max_depth"}) files.push_back("pictures/" + std::string(p) + ".png");
  for (const auto& f : detail::modelInputFiles(detail::kMaxInputLayers)) files.push_back(f);
  return files;
}

// Whether `name` is a temporary of the run file `file` (a file name): file.tmp-PID-N
// (writeFileAtomic), file.tmp-PID-N.png (pictures), file.tmpPID (GeoTIFFs), stem.tmp.png (plots).
bool isTemporaryOf(const std::string& name, const std::string& file) {
  const std::string stem = fs::path(file).stem().string();
  if (file.ends_with(".png") && name == stem + ".tmp.png") return true;
  if (isTemporaryNameOf(name, file)) return true;
  if (file.ends_with(".png") && name.ends_with(".png") && isTemporaryNameOf(name.substr(0, name.size() - 4), file)) {
    return true;
  }
  // .tmpPID
  const std::string_view rest = std::string_view(name).substr(std::min(name.size(), file.size() + 4));
  return name.starts_with(file + ".tmp") && !rest.empty() &&
         std::all_of(rest.begin(), rest.end(), [](char c) { return c >= '0' && c <= '9'; });
}

// A run's name as progress lines and logs show it: at most 60 characters, no control characters
// (the report holds it whole).
std::string displayName(const std::string& name) {
  std::string out;
  for (char c : name.substr(0, 60)) out += (static_cast<unsigned char>(c) < 0x20 || c == 0x7f) ? ' ' : c;
  if (name.size() > 60) out += "...";
  return out;
}

// Takes the run folder for this run: creates it, locks it (one writer per folder), refuses to mix
// with an earlier run's outputs unless resuming or overwriting (which removes those outputs, and
// nothing else), then removes the temporaries a killed run left.
Result<FileLock> takeRunFolder(const RunOptions& opt) {
  const auto& dir = opt.outDir;
  if (opt.resume && opt.overwrite) return fail(dir.string() + ": resume or overwrite a run folder, not both");
  std::error_code ec;
  fs::create_directories(dir, ec);
  if (ec) return fail(dir.string() + ": cannot create the run folder: " + ec.message());
  auto lock = FileLock::acquire(dir / "run.lock");
  if (!lock) return fail(dir.string() + ": another run is writing into this run folder (" + lock.message() + ")");
  const auto outputs = opt.resume ? std::vector<std::string>() : runFolderOutputs(dir);
  if (!outputs.empty() && !opt.overwrite) {
    std::string list;
    for (size_t i = 0; i < outputs.size() && i < 4; ++i) list += (i ? ", " : "") + outputs[i];
    if (outputs.size() > 4) list += ", ...";
    return fail(dir.string() + ": holds the outputs of an earlier run (" + list +
                "); continue it with --resume or replace them with --overwrite");
  }
  for (const auto& f : outputs) {
    if (!fs::remove(dir / f, ec) && ec) return fail((dir / f).string() + ": cannot remove: " + ec.message());
  }
  for (const auto& t : runFolderTemporaries(dir)) fs::remove(dir / t, ec);
  return lock;
}

// What runs the simulation: a GL context when the GL backend or the pictures need one, and the
// solver (startContext, then startSolver). `auto` takes the GL backend on a hardware GPU and the CPU backend when the
// only GL is a software rasteriser (llvmpipe is slower than the CPU backend) or there is none. Over MPI ranks: every
// rank's blocks run on its own GPU (one per local rank) for GL, `auto` takes GL only when every rank has a hardware
// GPU, and only the lead needs a context for pictures.
struct Engine {
  std::optional<gl::HeadlessContext> context;
  std::unique_ptr<sim::Solver> solver;
  sim::DistributedSolver* distributed = nullptr;  ///< the solver, when it runs over MPI ranks
  bool gpu = false;                               ///< the solver's passes run on the GPU
};

// The GL context, made before anything is built or written, so that a run that cannot have one
// fails leaving the run folder as it was; and whether the blocks run on the GPU.
Result<Engine> startContext(Backend backend, bool pictures, const Ranks& ranks) {
  Engine e;
  Status contextStatus;
  gl::HeadlessOptions glOptions;
  // (collective: every rank asks, whether or not it makes a context)
  if (ranks.distributed()) glOptions.device = sim::rankEglDevice(MPI_COMM_WORLD);
  if (backend != Backend::kCpu || (pictures && ranks.lead())) {
    auto ctx = gl::HeadlessContext::create(glOptions);
    if (ctx) {
      e.context.emplace(std::move(ctx).value());
    } else if (backend == Backend::kGpu) {
      contextStatus = fail("the GPU backend needs a GL 4.5 context: " + ctx.message());
    } else if (pictures && ranks.lead()) {
      contextStatus = fail("pictures need a GL 4.5 context (run with --no-pictures without one): " + ctx.message());
    }
  }
  STRATA_TRY_STATUS(ranks.agree(contextStatus));
  const bool hardware = e.context && !e.context->info().isSoftware();
  e.gpu = backend == Backend::kGpu || (backend == Backend::kAuto && ranks.all(hardware));
  return e;
}

// The solver over the domain (over MPI ranks: each rank its blocks, read from the model input).
Status startSolver(Engine& e, const ScenarioDomain& d, const Ranks& ranks, const fs::path& runDir) {
  if (ranks.distributed()) {
    sim::DistributedOptions o;
    o.comm = MPI_COMM_WORLD;
    // One rank has nothing to deal or exchange: one block, as fast as one process (4 blocks of the
    // 384 x 226 main job took 2x as long: halos are 33% of their cells, and the CPU backend runs a
    // pass over fewer than 16k active cells on one thread). Over several ranks, 4 blocks each to
    // deal by work.
    if (ranks.size() == 1) o.blocksPerRank = 1;
    STRATA_TRY(auto s, sim::DistributedSolver::create(detail::modelInputSource(runDir, d), d.params, o,
                                                      e.gpu ? sim::glSolverFactory() : sim::cpuSolverFactory()));
    auto solver = std::make_unique<sim::DistributedSolver>(std::move(s));
    e.distributed = solver.get();
    e.solver = std::move(solver);
  } else if (e.gpu) {
    STRATA_TRY(auto s, sim::GlSolver::create(d.input, d.params));
    e.solver = std::make_unique<sim::GlSolver>(std::move(s));
  } else {
    STRATA_TRY(auto s, sim::CpuSolver::create(d.input, d.params));
    e.solver = std::make_unique<sim::CpuSolver>(std::move(s));
  }
  for (const auto& src : d.sources) STRATA_TRY_STATUS(e.solver->addSource(src));
  for (const auto& level : d.levels) STRATA_TRY_STATUS(e.solver->addLevel(level));
  return {};
}

// What a picture shows of the solver's state: read on every rank (the reads are collective over
// MPI ranks), drawn by the lead. `surfaceM` and `layers` (the top four) only in erosion runs.
struct PictureState {
  gis::Grid<float> depthM, surfaceM;
  std::vector<gis::Grid<float>> layers;
};

// Oblique pictures of the region with its water, drawn by the concentric-ring renderer: from a
// little behind the first inflow (or the region's centre), looking across the region towards its
// centre, about a quarter of the region's north-south extent above its highest point.
class Pictures {
 public:
  /// `erosion`: draw the solver's current surface and its layers (in their materials' colours),
  /// not the initial bed. Water is drawn only where it is deeper than `wetThresholdM`.
  /// `bed`: the region's bed at every `stride`-th cell (detail::readStrided of the elevation map);
  /// the state drawn comes at the same cells (detail::gatherStrided).
  static Result<Pictures> create(const ScenarioDomain& d, const gis::Raster& bed, int stride, bool erosion,
                                 double wetThresholdM) {
    Pictures p;
    p.stride_ = stride;
    p.erosion_ = erosion;
    p.wetThresholdM_ = float(wetThresholdM);
    p.datumM_ = d.input.datumM;
    const size_t layers = d.input.materials.size();
    for (size_t k = layers > 4 ? layers - 4 : 0, slot = 0; k < layers; ++k, ++slot) {
      const auto& c = d.input.materials[k].colour;
      p.shading_.layerColours[slot] = glm::vec3(c[0], c[1], c[2]);
    }
    const auto& g = bed.georef;
    STRATA_TRY(p.scene_, render::TerrainScene::create(bed));
    STRATA_TRY(p.ring_, render::RingRenderer::create({.circles = 160}));
    STRATA_TRY(p.target_, render::OffscreenTarget::create(kWidth, kHeight));
    const double cx = 0.5 * g.width, cy = 0.5 * g.height;
    double tx = cx, ty = cy;
    if (!d.sources.empty()) {
      tx = (d.sources.front().cells.front().first + 0.5) / stride;
      ty = (d.sources.front().cells.front().second + 0.5) / stride;
    }
    // Cell (column, row) offsets in metres: east, north.
    const double dxM = d.input.rowDxM[d.input.rowDxM.size() / 2] * stride, dyM = d.input.dyM * stride;
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
    p.shading_.waterFadeM = std::max(p.wetThresholdM_, 0.05f);
    return p;
  }

  /// Draws the terrain with the solver's state and writes `file` (PNG).
  Status draw(PictureState state, const fs::path& file) {
    for (float& h : state.depthM.data) h = h > wetThresholdM_ ? h : 0.0f;  // no rain film painted as water
    if (erosion_) {
      // The surface as it is now (bed above the datum, layers included) and the top four layers.
      for (float& z : state.surfaceM.data) z = float(double(z) + datumM_);
      scene_.writeHeights(0, 0, state.surfaceM);
      STRATA_TRY_STATUS(scene_.setMaterialLayers(state.layers));
    }
    STRATA_TRY_STATUS(scene_.setWaterDepth(state.depthM));
    return write(file);
  }

  /// The run's maximum depth draped over the terrain as drawn last (no water drawn), through the
  /// drape's ramp from the wet threshold to the 98th percentile of the wet cells' maxima (shallower
  /// cells not drawn); the last picture of a run (the drape stays on the scene).
  Status drawMaxDepth(const gis::Grid<float>& maxDepthM, const gis::Georef& georef, const fs::path& file) {
    std::vector<float> wet;
    for (float v : maxDepthM.data) {
      if (v > wetThresholdM_) wet.push_back(v);
    }
    render::DrapeOptions o;
    o.transparentBelow = true;
    float top = wetThresholdM_ + 1;
    if (!wet.empty()) {
      auto it = wet.begin() + std::ptrdiff_t(0.98 * double(wet.size() - 1));
      std::nth_element(wet.begin(), it, wet.end());
      top = std::max(*it, top);
    }
    o.range = std::array<double, 2>{std::max(double(wetThresholdM_), 1e-3), double(top)};
    STRATA_TRY(auto image, render::drapeFromGrid(maxDepthM, georef, o, "max_depth"));
    STRATA_TRY_STATUS(scene_.setWaterDepth(gis::Grid<float>(maxDepthM.width, maxDepthM.height, 0.0f)));
    STRATA_TRY_STATUS(scene_.setDrape(image));
    maxDepthRange_ = *o.range;
    return write(file);
  }
  /// The ramp's ends of the max-depth picture (m).
  std::array<double, 2> maxDepthRange() const { return maxDepthRange_; }
  int stride() const { return stride_; }
  const gis::Georef& georef() const { return scene_.georef(); }

 private:
  Status write(const fs::path& file) {
    STRATA_TRY_STATUS(ring_->draw(scene_, camera_, shading_, target_));
    const auto tmp = temporaryPathFor(file).string() + ".png";
    STRATA_TRY_STATUS(render::writeImage8(tmp, kWidth, kHeight, 4, target_.colour()));
    return commitTemporary(tmp, file);
  }

  static constexpr int kWidth = 960, kHeight = 540;
  int stride_ = 1;
  bool erosion_ = false;
  std::array<double, 2> maxDepthRange_{0, 0};
  float wetThresholdM_ = 0;
  double datumM_ = 0;
  render::TerrainScene scene_;
  std::unique_ptr<render::RingRenderer> ring_;
  render::OffscreenTarget target_;
  render::CameraPose camera_;
  render::Shading shading_;
};

// The layer a cell shows: the topmost at least kExposedM thick (a film of a few millimetres that
// the drying rain leaves over everything does not hide what lies under it), else the topmost
// with any material; -1 for none. `thickness(k)` gives layer k's, bottom first.
constexpr float kExposedM = 0.01f;
template <class Thickness>
int exposedLayer(int layers, Thickness&& thickness) {
  int any = -1;
  for (int k = layers - 1; k >= 0; --k) {
    const float t = thickness(k);
    if (t >= kExposedM) return k;
    if (t > 0 && any < 0) any = k;
  }
  return any;
}

// The run in progress: the scenario, its domain, the solver and what has been written so far.
// Over MPI ranks every rank holds one and calls the same methods in the same order (the solver's
// reads are collective); only the lead holds the domain's grids and gets the grids read, and only
// it writes files.
class Run {
 public:
  Run(const Scenario& s, const RunOptions& opt, const Ranks& ranks, ScenarioDomain d, Engine e)
      : s_(s), opt_(opt), ranks_(ranks), d_(std::move(d)), e_(std::move(e)) {
    if (ranks_.distributed()) {
      input_ = detail::modelInputSource(opt_.outDir, d_).read;
    } else {
      input_ = [this](const gis::CellRect& r) { return sim::cutRegion(d_.input, r); };
    }
  }
  Run(const Run&) = delete;  // input_ holds `this`
  Run& operator=(const Run&) = delete;

  sim::Solver& solver() { return *e_.solver; }
  /// The gauges and sections (null when the scenario has none): recording from start(), which a
  /// fresh run calls at t = 0 (after any spin-up), a resumed one with its checkpoint's record.
  detail::Probes* probes() { return probes_ ? &*probes_ : nullptr; }
  Status startProbes(const std::vector<double>* saved) {
    if (d_.gauges.empty() && d_.sections.empty()) return {};
    probes_.emplace(d_, solver().grid(), s_.outputs.probeIntervalS);
    solver().integrateFaces(probes_->faceIndices());  // each step's volume through them (W37)
    if (saved) return probes_->restore(*saved);
    probes_->row(solver());
    return {};
  }
  /// The solver when it runs over MPI ranks (else null).
  sim::DistributedSolver* distributed() { return e_.distributed; }

  /// The state a picture shows at every `stride`-th cell (collective: gathered to the lead).
  PictureState pictureState(const std::vector<detail::Piece>& pieces, int stride) {
    const int w = e_.solver->grid().width, h = e_.solver->grid().height;
    PictureState p;
    p.depthM = detail::gatherStrided(ranks_, pieces, stride, w, h,
                                     [](const detail::Piece& q, size_t i) { return q.depth.data[i]; });
    if (s_.erosion.enabled) {
      p.surfaceM = detail::gatherStrided(ranks_, pieces, stride, w, h,
                                         [](const detail::Piece& q, size_t i) { return q.bed.data[i]; });
      const int L = int(d_.input.materials.size());
      for (int k = std::max(0, L - 4); k < L; ++k) {
        p.layers.push_back(detail::gatherStrided(ranks_, pieces, stride, w, h, [k](const detail::Piece& q, size_t i) {
          return q.layers[size_t(k)].data[i];
        }));
      }
    }
    return p;
  }

  /// The largest depth each cell had, at every `stride`-th cell (collective: on the lead).
  gis::Grid<float> maxDepthStrided(const std::vector<detail::Piece>& pieces, int stride) {
    return detail::gatherStrided(ranks_, pieces, stride, e_.solver->grid().width, e_.solver->grid().height,
                                 [](const detail::Piece& q, size_t i) { return q.flood.maxDepthM.data[i]; });
  }

  // Uniform rain while it falls, [start, end).
  double rainAt(double t) const { return t >= d_.rainStartS && t < d_.rainEndS ? d_.rainMmPerHour : 0.0; }

  // The rain frame falling at t ([water.rain] frames): -1 before the first and from the end on.
  int frameAt(double t) const {
    int k = -1;
    for (size_t i = 0; i < d_.rainFrames.size(); ++i) {
      if (t >= d_.rainFrames[i].startS) k = int(i);
    }
    return t < d_.rainFramesEndS ? k : -1;
  }

  Status setRain(double t) {
    if (!d_.rainFrames.empty()) {
      const int k = frameAt(t);
      if (k == frame_) return {};
      STRATA_TRY_STATUS(solver().setRainRaster(k < 0 ? gis::Grid<float>() : d_.rainFrames[size_t(k)].mmPerHour));
      frame_ = k;
      return {};
    }
    if (float(rainAt(t)) == solver().params().rainMmPerHour) return {};
    auto p = solver().params();
    p.rainMmPerHour = float(rainAt(t));
    return solver().setParams(p);
  }

  // Advances to `endS`, step by step, switching rain at its times; false if interrupted (the
  // interval is then abandoned: a resumed run replays it from the last checkpoint, bit for bit).
  // The last step before `endS` (and before a rain edge) is shortened to land on it; the step W10
  // chose is kept apart (chosenDtS), since a shortened one says nothing about the flow.
  // `tick`, when given, runs after every step or run of steps (progress: it must be cheap and not
  // collective).
  Result<bool> advanceTo(double endS, const std::function<void()>& tick = {}) {
    auto& sv = solver();
    // One rule for "t has reached a time": within 1e-9 of it, relative. (The edges were once
    // compared with another tolerance: a step ending within 6e-8 s before a rain edge at 60 s left
    // the outer loop choosing that edge and the inner loop refusing to step, forever.)
    auto before = [](double t, double target) { return t < target - 1e-9 * std::max(1.0, std::abs(target)); };
    while (before(sv.timeS(), endS)) {
      double next = endS;
      for (double edge : {d_.rainStartS, d_.rainEndS, probes_ ? probes_->nextRowS() : endS}) {
        if (before(sv.timeS(), edge) && edge < next) next = edge;
      }
      for (const auto& f : d_.rainFrames) {
        if (before(sv.timeS(), f.startS) && f.startS < next) next = f.startS;
      }
      if (!d_.rainFrames.empty() && before(sv.timeS(), d_.rainFramesEndS) && d_.rainFramesEndS < next) {
        next = d_.rainFramesEndS;
      }
      STRATA_TRY_STATUS(setRain(sv.timeS()));
      // Without gauges or sections to sum after every step, and on one process: runs of steps
      // (advanceBatch; the GL backend chooses and takes them without waiting for the host, W35)
      // of about 0.1-0.4 s of wall time each, so that progress and a Ctrl-C are seen as often.
      while (!probes_ && !ranks_.distributed() && before(sv.timeS(), next)) {
        const auto t0 = std::chrono::steady_clock::now();
        const auto b = sv.advanceBatch(next, batchSteps_);
        if (b.steps == 0) break;  // (not expected) the steps below take it from here
        chosenDtS_ = b.lastChosenDtS;
        minChosenDtS_ = std::min(minChosenDtS_, b.minChosenDtS);
        const double wallS = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
        if (b.steps == batchSteps_ && wallS < 0.1) batchSteps_ = std::min<int64_t>(2 * batchSteps_, int64_t(1) << 20);
        if (wallS > 0.4) batchSteps_ = std::max<int64_t>(1, batchSteps_ / 2);
        if (tick) tick();
        if (ranks_.anyInterrupted()) return false;
      }
      while (before(sv.timeS(), next)) {
        chosenDtS_ = sv.nextDt();
        minChosenDtS_ = std::min(minChosenDtS_, chosenDtS_);
        const double dtS = std::min(chosenDtS_, next - sv.timeS());
        sv.stepWithDt(dtS);
        if (probes_) {
          probes_->afterStep(sv, dtS);
          if (!before(sv.timeS(), probes_->nextRowS())) probes_->row(sv);
        }
        if (tick) tick();
        if (ranks_.anyInterrupted()) return false;
      }
    }
    return true;
  }

  // The spin-up: from -longestS towards 0 with every source and level at its t = 0 value (a
  // series holds its first sample before it) and no rain (it starts at t >= 0); then the budgets
  // and the flood statistics start over, so that every output is of the run from t = 0. Judged
  // every twentieth of longestS over the last tenth (two twentieths): with a tolerance it ends as
  // soon as the stored water changed by less than that fraction of the base flow there, and the
  // clock moves on to 0 (nothing it holds changes with time; Solver::restartAt).
  Result<SpinUpSummary> spinUp(double longestS, double tolerance, const std::string& name) {
    auto& sv = solver();
    SpinUpSummary u;
    u.longestS = longestS;
    u.toleranceRel = tolerance;
    for (const auto& src : d_.sources) u.baseFlowM3S += src.dischargeM3S.at(0.0);
    sv.startClockAt(-longestS);
    Progress progress("spin-up " + name, longestS);
    constexpr int kChecks = 20, kWindow = 2;
    std::vector<sim::SimStats> at{sv.stats()};  // at each check so far
    // Progress at its own pace (every 10 s of wall time in a log), not only at the checks: a
    // twentieth of a long spin-up can take minutes on a slow machine.
    auto tick = [&] {
      if (progress.due()) progress.update(longestS + sv.timeS(), progressNote("t = -" + formatDuration(-sv.timeS())));
    };
    for (int c = 1; c <= kChecks; ++c) {
      STRATA_TRY(const bool done, advanceTo(c == kChecks ? 0.0 : -longestS + longestS * c / kChecks, tick));
      if (!done) return fail("interrupted during the spin-up (before t = 0: nothing to resume from)");
      at.push_back(sv.stats());  // collective over ranks: every rank judges the same numbers
      progress.update(longestS + sv.timeS(), progressNote("t = -" + formatDuration(-sv.timeS())));
      if (c < kWindow) continue;
      const auto& from = at[size_t(c - kWindow)];
      const auto& to = at[size_t(c)];
      u.windowS = to.timeS - from.timeS;
      u.outflowM3S = (to.outflowM3 - from.outflowM3) / u.windowS;
      u.storageRateM3S = (to.storedWaterM3 - from.storedWaterM3) / u.windowS;
      u.steady = tolerance > 0 && std::abs(u.storageRateM3S) < tolerance * u.baseFlowM3S;
      if (u.steady) break;
    }
    u.seconds = longestS + sv.timeS();
    u.storedM3 = at.back().storedWaterM3;
    u.steps = at.back().steps;
    if (tolerance > 0 && !u.steady) {
      log::warn("spin-up") << "after " << formatDuration(longestS) << " the stored water still changes by "
                           << u.storageRateM3S << " m3/s, more than " << tolerance
                           << " of the base flow: the river is not steady at t = 0 (lengthen time.spin_up)";
    }
    progress.finish(std::to_string(u.steps) + " steps" +
                    (u.steady ? ", steady at " + formatDuration(u.seconds) : std::string()));
    sv.restartAt(0.0);
    sv.enableFloodStats(float(s_.outputs.wetThresholdM));
    return u;
  }

  /// The step W10 chose last (before any shortening to land on an output time or a rain edge).
  double chosenDtS() const { return chosenDtS_; }

  /// A progress line's note: the model time given, the steps so far and the step W10 chose.
  std::string progressNote(const std::string& time) {
    char note[128];
    std::snprintf(note, sizeof note, "%s, %lld steps, dt %.2f s", time.c_str(), solver().counterStats().steps,
                  chosenDtS_);
    return note;
  }

  /// This process's pieces of the state (local: nothing is gathered).
  Result<std::vector<detail::Piece>> pieces() const {
    return detail::readPieces(*e_.solver, input_, s_.erosion.enabled);
  }

  // The series row of the interval that just ended (collective: the areas and volumes are exact
  // sums over the ranks, over the model's cell areas).
  SeriesRow row(const std::vector<detail::Piece>& pieces) {
    const auto st = solver().stats();
    SeriesRow r;
    r.timeS = st.timeS;
    r.steps = st.steps;
    // The shortest step W10 chose in the interval (a step shortened to land on the output time
    // or a rain edge says nothing about the flow).
    r.dtS = minChosenDtS_ < 1e300 ? minChosenDtS_ : st.lastDtS;
    minChosenDtS_ = 1e300;
    r.waterM3 = st.storedWaterM3;
    r.inflowM3 = st.inflowM3;
    r.rainM3 = st.rainM3;
    r.outflowM3 = st.outflowM3;
    r.evaporationM3 = st.evaporatedM3;
    r.infiltrationM3 = st.infiltratedM3;
    const double supplied = st.initialWaterM3 + st.rainM3 + st.inflowM3;
    r.balanceErrorRel = supplied > 0 ? st.waterBalanceM3() / supplied : 0.0;
    r.maxDepthM = st.maxDepthM;
    std::vector<sim::ExactSum> sums(3);  // flooded area, eroded, deposited
    forEachCell(pieces, [&](const detail::Piece& p, size_t i, int, int, double area) {
      if (p.inside.data[i] && p.depth.data[i] > s_.outputs.wetThresholdM) sums[0].add(area);
      if (s_.erosion.enabled) {
        const double v = double(materialChange(p, i)) * area;
        sums[v < 0 ? 1 : 2].add(std::abs(v));
      }
    });
    ranks_.sum(sums);
    r.floodedAreaKm2 = sums[0].value() / 1e6;
    r.sedimentM3 = st.suspendedM3;
    r.erodedM3 = sums[1].value();
    r.depositedM3 = sums[2].value();
    return r;
  }

  // The maps the scenario asks for, as GeoTIFFs in the region's CRS (collective: each rank
  // writes its pieces).
  Status writeMaps(const std::vector<detail::Piece>& pieces) {
    const auto& maps = s_.outputs.maps;
    const bool layerMaps = std::find(maps.begin(), maps.end(), "layer_thickness") != maps.end();
    // `values` of a piece, no data outside the region and, `wetOnly`, where it never was wet; the
    // band described (gdalinfo and QGIS show it: times are in seconds). GDAL's unit type is set
    // for lengths only: it is a DEM's vertical unit to GDAL and to gis::readDem, which refuse
    // "s" and "m/s", and flood maps are read back as drapes; other units are in the description.
    using Text = std::pair<std::string, std::string>;  // the band's description, its unit
    auto writeMap = [&](const std::string& file, bool asked, bool wetOnly, const Text& text,
                        const std::function<gis::Grid<float>(const detail::Piece&)>& values,
                        const std::vector<std::pair<std::string, std::string>>& metadata = {}) -> Status {
      if (!asked) return {};
      gis::WriteOptions o;
      o.metadata = metadata;
      o.description = text.first;
      o.units = text.second;
      return detail::writeMapFile(ranks_, opt_.outDir / file, d_.bed.georef, o, pieces, [&](const detail::Piece& p) {
        gis::Grid<float> g = values(p);
        for (size_t i = 0; i < g.size(); ++i) {
          if (!p.inside.data[i] || (wetOnly && !(p.flood.maxDepthM.data[i] > s_.outputs.wetThresholdM))) {
            g.data[i] = gis::kNoData;
          }
        }
        return g;
      });
    };
    auto map = [&](const std::string& name, bool wetOnly, const Text& text,
                   const std::function<gis::Grid<float>(const detail::Piece&)>& values,
                   const std::vector<std::pair<std::string, std::string>>& metadata = {}) {
      return writeMap("maps/" + name + ".tif", std::find(maps.begin(), maps.end(), name) != maps.end(), wetOnly, text,
                      values, metadata);
    };
    // The wet threshold in the depth maps' metadata: plots draw depths from it (plot_maps.py).
    char wet[32];
    std::snprintf(wet, sizeof wet, "%.9g", s_.outputs.wetThresholdM);
    const std::vector<std::pair<std::string, std::string>> wetMeta{{"STRATA_WET_THRESHOLD_M", wet}};
    STRATA_TRY_STATUS(map(
        "max_depth", false, {"largest water depth", "m"}, [](const detail::Piece& p) { return p.flood.maxDepthM; },
        wetMeta));
    STRATA_TRY_STATUS(map("max_speed", false, {"largest flow speed (m/s)", ""},
                          [](const detail::Piece& p) { return p.flood.maxSpeedMS; }));
    STRATA_TRY_STATUS(map("arrival_time", true,
                          {"time the water first passed the wet threshold, from the start (s)", ""},
                          [](const detail::Piece& p) { return p.flood.arrivalS; }));
    STRATA_TRY_STATUS(map("inundation_duration", false, {"time spent deeper than the wet threshold (s)", ""},
                          [](const detail::Piece& p) { return p.flood.wetDurationS; }));
    STRATA_TRY_STATUS(map(
        "final_depth", false, {"water depth at the end", "m"}, [](const detail::Piece& p) { return p.depth; },
        wetMeta));
    // FD2321's hazard rating (hazard.hpp) from each cell's largest depth and speed, where wet.
    STRATA_TRY_STATUS(map("hazard_rating", true,
                          {"flood hazard rating HR = d (v + 0.5) + DF (FD2321) from the largest depth and speed, "
                           "classes at 0.75, 1.25, 2",
                           ""},
                          [this](const detail::Piece& p) {
                            gis::Grid<float> g(p.rect.width, p.rect.height, 0.0f);
                            for (size_t i = 0; i < g.size(); ++i) {
                              g.data[i] = float(hazardRating(p.flood.maxDepthM.data[i], p.flood.maxSpeedMS.data[i],
                                                             s_.outputs.hazardLandUse));
                            }
                            return g;
                          },
                          {{"HAZARD_LAND_USE", hazardLandUseName(s_.outputs.hazardLandUse)}}));
    STRATA_TRY_STATUS(writeOutline(pieces));
    if (!s_.erosion.enabled) return {};
    // terrain_change (net cut and fill, m), exposed_material (exposedLayer: bottom = 0; none: no
    // data), suspended_sediment (m of material in the water) and layer_thickness
    // (maps/layer_K.tif, K = 1 the bottom layer, each naming its material).
    STRATA_TRY_STATUS(map("terrain_change", false, {"net change of the surface: cut below 0, fill above", "m"},
                          [](const detail::Piece& p) {
                            gis::Grid<float> g(p.rect.width, p.rect.height);
                            for (size_t i = 0; i < g.size(); ++i) g.data[i] = materialChange(p, i);
                            return g;
                          }));
    const int L = int(d_.input.materials.size());
    // Each value's material and colour (STRATA_MATERIAL_k, STRATA_COLOUR_k "r,g,b"): GIS tools
    // list them, and the plot draws its legend from them.
    std::vector<std::pair<std::string, std::string>> legend;
    for (int l = 0; l < L; ++l) {
      const auto& m = d_.input.materials[size_t(l)];
      char rgb[64];
      std::snprintf(rgb, sizeof rgb, "%.3f,%.3f,%.3f", m.colour[0], m.colour[1], m.colour[2]);
      legend.push_back({"STRATA_MATERIAL_" + std::to_string(l), m.name});
      legend.push_back({"STRATA_COLOUR_" + std::to_string(l), rgb});
    }
    STRATA_TRY_STATUS(map(
        "exposed_material", false, {"topmost layer holding material: layer number - 1, bottom 0", ""},
        [L](const detail::Piece& p) {
          gis::Grid<float> top(p.rect.width, p.rect.height, gis::kNoData);
          for (size_t i = 0; i < top.size(); ++i) {
            const int l = exposedLayer(L, [&](int k) { return p.layers[size_t(k)].data[i]; });
            if (l >= 0) top.data[i] = float(l);
          }
          return top;
        },
        legend));
    STRATA_TRY_STATUS(map("suspended_sediment", false, {"material carried by the water, as a thickness", "m"},
                          [](const detail::Piece& p) { return p.suspended; }));
    for (int l = 0; l < std::min(L, kMaxLayerMaps); ++l) {
      STRATA_TRY_STATUS(writeMap(
          layerMapFile(l + 1), layerMaps, false,
          {"thickness of layer " + std::to_string(l + 1) + " (" + d_.input.materials[size_t(l)].name + ") at the end",
           "m"},
          [l](const detail::Piece& p) { return p.layers[size_t(l)]; },
          {{"STRATA_LAYER", std::to_string(l + 1)},
           {"STRATA_MATERIAL", d_.input.materials[size_t(l)].name},
           {"STRATA_UNITS", "m"}}));
    }
    return {};
  }

  // The flood's extremes and the area ever wet (collective: reduced over the ranks).
  // maps/flood_outline.gpkg: the cells ever deeper than the wet threshold as polygons, one per
  // connected (4-neighbour) wet area, with its area (the model's cell areas, as the report's) and
  // largest depth. The largest depths are gathered to the lead, which traces and writes.
  Status writeOutline(const std::vector<detail::Piece>& pieces) {
    const auto& maps = s_.outputs.maps;
    if (std::find(maps.begin(), maps.end(), "flood_outline") == maps.end()) return {};
    const int w = e_.solver->grid().width, h = e_.solver->grid().height;
    const float wet = float(s_.outputs.wetThresholdM);
    const auto depth = detail::gatherStrided(ranks_, pieces, 1, w, h, [wet](const detail::Piece& p, size_t i) {
      return p.inside.data[i] && p.flood.maxDepthM.data[i] > wet ? p.flood.maxDepthM.data[i] : 0.0f;
    });
    Status status;
    if (ranks_.lead()) {
      gis::Grid<uint8_t> mask(w, h, 0);
      for (size_t i = 0; i < mask.size(); ++i) mask.data[i] = depth.data[i] > 0.0f;
      int32_t count = 0;
      const auto labels = gis::labelComponents(mask, &count);
      gis::PolygonLayer layer{"flood_outline", {"area_m2", "max_depth_m"}, {}};
      std::vector<sim::ExactSum> area(size_t(count) + 1);
      std::vector<double> deepest(size_t(count) + 1, 0.0);
      for (int y = 0; y < h; ++y) {
        for (int x = 0; x < w; ++x) {
          const int32_t k = labels.at(x, y);
          if (k == 0) continue;
          area[size_t(k)].add(e_.solver->grid().area(y));
          deepest[size_t(k)] = std::max(deepest[size_t(k)], double(depth.at(x, y)));
        }
      }
      for (int32_t k = 1; k <= count; ++k) layer.values[k] = {area[size_t(k)].value(), deepest[size_t(k)]};
      status =
          gis::writeLabelPolygons((opt_.outDir / "maps" / "flood_outline.gpkg").string(), d_.bed.georef, labels, layer);
    }
    return ranks_.agree(status);
  }

  // The water at the end that stands in closed depressions of the bed (report.hpp, pondedM3),
  // on the lead: the depth (and, in an erosion run, the bed as it ends) gathered, the bed
  // otherwise the one the model used (maps/elevation.tif), a priority flood from the open edges.
  Status addPonding(const std::vector<detail::Piece>& pieces, FloodSummary& f) {
    const int w = e_.solver->grid().width, h = e_.solver->grid().height;
    const auto depth = detail::gatherStrided(ranks_, pieces, 1, w, h, [](const detail::Piece& p, size_t i) {
      return p.inside.data[i] ? std::max(0.0f, p.depth.data[i]) : 0.0f;
    });
    const auto inside = detail::gatherStrided(ranks_, pieces, 1, w, h,
                                              [](const detail::Piece& p, size_t i) { return float(p.inside.data[i]); });
    gis::Grid<float> bed;
    if (s_.erosion.enabled) {
      bed = detail::gatherStrided(ranks_, pieces, 1, w, h,
                                  [](const detail::Piece& p, size_t i) { return p.bed.data[i]; });
    }
    if (!ranks_.lead()) return {};
    if (!s_.erosion.enabled) {
      STRATA_TRY(auto map, detail::readStrided(opt_.outDir / "maps" / "elevation.tif", 1));
      bed = std::move(map.values);
    }
    if (bed.width != w || bed.height != h)
      return fail(opt_.outDir.string() + "/maps/elevation.tif: not the region's size");
    gis::Grid<uint8_t> in(w, h, 0), drains(w, h, 0);
    const auto& open = s_.model.boundaries;  // W E S N
    for (int y = 0; y < h; ++y) {
      for (int x = 0; x < w; ++x) {
        const bool cell = inside.at(x, y) > 0.5f && std::isfinite(bed.at(x, y));
        in.at(x, y) = cell;
        if (!std::isfinite(bed.at(x, y))) bed.at(x, y) = kWallElevationM;
        const bool edge = (x == 0 && open[0] == Boundary::Open) || (x == w - 1 && open[1] == Boundary::Open) ||
                          (y == h - 1 && open[2] == Boundary::Open) || (y == 0 && open[3] == Boundary::Open);
        drains.at(x, y) = cell && edge;
      }
    }
    gis::FillInput fill;
    fill.elevation = &bed;
    fill.inside = &in;
    fill.drains = &drains;
    const auto filled = gis::fillDepressions(fill, {gis::CellRect{0, 0, w, h}});
    sim::ExactSum ponded, all;
    for (int y = 0; y < h; ++y) {
      const double area = e_.solver->grid().area(y);
      for (int x = 0; x < w; ++x) {
        const double d = depth.at(x, y);
        all.add(d * area);
        const double below = std::min(d, double(filled.at(x, y)) - double(bed.at(x, y)));
        if (!in.at(x, y) || !(below > 0)) continue;
        ponded.add(below * area);
        if (d > f.deepestPonded.value) f.deepestPonded = {d, x, y};
      }
    }
    f.pondedM3 = ponded.value();
    f.waterAtEndM3 = all.value();
    return {};
  }

  FloodSummary floodSummary(const std::vector<detail::Piece>& pieces) {
    const double wet = s_.outputs.wetThresholdM;
    const auto& g = d_.bed.georef;
    detail::Extreme deep, fast, far, froude;
    std::vector<sim::ExactSum> everWet(6);  // all, then per hazard class, then supercritical
    const double gravity = double(solver().params().gravityMS2);
    sim::ExactSum wetVoid;
    detail::Extreme deepVoid;
    int wetVoidCells = 0;
    // The void mask of the whole region (one process; a rank holds no mask of its own).
    const bool voidsHere = s_.terrain.voids == decltype(s_.terrain)::Voids::kFill && d_.voidCells > 0 &&
                           d_.voids.width == e_.solver->grid().width && d_.voids.height == e_.solver->grid().height;
    std::optional<std::pair<int, int>> c0;
    std::optional<gis::LonLat> from;
    if (!d_.sources.empty()) {
      c0 = d_.sources.front().cells.front();
      auto ll = gis::pixelToLonLat(g, c0->first + 0.5, c0->second + 0.5);
      if (ll) from = *ll;
    }
    forEachCell(pieces, [&](const detail::Piece& p, size_t i, int x, int y, double area) {
      const float depth = p.flood.maxDepthM.data[i], speed = p.flood.maxSpeedMS.data[i];
      if (p.inside.data[i] && std::isfinite(depth) && detail::beats({depth, x, y, 0}, deep)) deep = {depth, x, y, 0};
      if (p.inside.data[i] && std::isfinite(speed) && detail::beats({speed, x, y, 0}, fast)) fast = {speed, x, y, 0};
      const double arrival = p.flood.arrivalS.data[i];
      // How far the water got: the wet cell farthest from the first inflow (the inflow's own cell
      // when none is farther).
      if (c0 && x == c0->first && y == c0->second && detail::beats({0, x, y, arrival}, far)) far = {0, x, y, arrival};
      if (!(depth > wet)) return;
      if (p.inside.data[i]) {
        everWet[0].add(area);
        everWet[1 + size_t(hazardClass(hazardRating(depth, speed, s_.outputs.hazardLandUse)))].add(area);
        const double fr = double(speed) / std::sqrt(gravity * double(depth));
        if (std::isfinite(fr) && detail::beats({fr, x, y, 0}, froude)) froude = {fr, x, y, 0};
        if (fr > 1.0) everWet[5].add(area);
        if (voidsHere && d_.voids.at(x, y)) {
          wetVoid.add(area);
          ++wetVoidCells;
          if (detail::beats({depth, x, y, 0}, deepVoid)) deepVoid = {depth, x, y, 0};
        }
      }
      if (!from) return;
      auto to = gis::pixelToLonLat(g, x + 0.5, y + 0.5);
      const double m = to ? gis::geodesicDistanceM(*from, *to, g.body) : 0;
      if (m > 0 && detail::beats({m, x, y, arrival}, far)) far = {m, x, y, arrival};
    });
    deep = detail::largest(ranks_, deep);
    fast = detail::largest(ranks_, fast);
    far = detail::largest(ranks_, far);
    froude = detail::largest(ranks_, froude);
    ranks_.sum(everWet);
    FloodSummary f;
    f.deepest = {deep.value, deep.x, deep.y};
    f.fastest = {fast.value, fast.x, fast.y};
    f.farthest = {far.value, far.x, far.y};
    f.farthestArrivalS = far.with;
    f.everWetM2 = everWet[0].value();
    for (size_t k = 0; k < f.hazardClassM2.size(); ++k) f.hazardClassM2[k] = everWet[1 + k].value();
    f.wetVoidM2 = wetVoid.value();
    f.wetVoidCells = wetVoidCells;
    f.deepestVoid = {deepVoid.value, deepVoid.x, deepVoid.y};
    f.froude = {froude.value, froude.x, froude.y};
    f.supercriticalM2 = everWet[5].value();
    return f;
  }

  // Where the material went (the report's balance): per layer, and the solver's totals
  // (collective; computed on the lead).
  MaterialBudget materialBudget(const std::vector<detail::Piece>& pieces) {
    MaterialBudget b;
    const auto st = solver().stats();
    const size_t L = d_.input.materials.size();
    // Per layer: at the start, at the end, exposed at the start, at the end; then eroded, deposited.
    std::vector<sim::ExactSum> sums(4 * L + 2);
    forEachCell(pieces, [&](const detail::Piece& p, size_t i, int, int, double area) {
      double change = 0;
      for (size_t l = 0; l < L; ++l) {
        const double before = p.initialLayers[l].data[i], after = p.layers[l].data[i];
        sums[l].add(before * area);
        sums[L + l].add(after * area);
        change += after - before;
      }
      sums[4 * L + (change < 0 ? 0 : 1)].add(std::abs(change) * area);
      const int topBefore = exposedLayer(int(L), [&](int k) { return p.initialLayers[size_t(k)].data[i]; });
      const int topAfter = exposedLayer(int(L), [&](int k) { return p.layers[size_t(k)].data[i]; });
      if (topBefore >= 0) sums[2 * L + size_t(topBefore)].add(area);
      if (topAfter >= 0) sums[3 * L + size_t(topAfter)].add(area);
    });
    ranks_.sum(sums);
    for (size_t l = 0; l < L; ++l) {
      b.layers.push_back(d_.input.materials[l].name);
      b.initialM3.push_back(sums[l].value());
      b.finalM3.push_back(sums[L + l].value());
      b.exposedInitialM2.push_back(sums[2 * L + l].value());
      b.exposedFinalM2.push_back(sums[3 * L + l].value());
    }
    b.erodedM3 = sums[4 * L].value();
    b.depositedM3 = sums[4 * L + 1].value();
    b.suspendedM3 = st.suspendedM3;
    b.outflowM3 = st.sedimentOutflowM3;
    b.initialM3Total = st.initialMaterialM3;
    return b;
  }

  const ScenarioDomain& domain() const { return d_; }
  // The maps the scenario asks for, as written (by this session or, resumed, by an earlier one).
  std::vector<std::string> mapFiles() const {
    std::vector<std::string> files;
    for (const auto& m : s_.outputs.maps) {
      const std::string file = "maps/" + m + (m == "flood_outline" ? ".gpkg" : ".tif");
      if (fs::exists(opt_.outDir / file)) files.push_back(file);
    }
    return files;
  }
  std::string backendName() const { return e_.solver->backendName(); }

 private:
  // f(piece, index in the piece, global column, global row, the model's area of the cell) for
  // every cell of the pieces.
  template <class F>
  void forEachCell(const std::vector<detail::Piece>& pieces, F&& f) const {
    for (const auto& p : pieces) {
      for (int y = 0; y < p.rect.height; ++y) {
        const double area = e_.solver->grid().area(p.rect.y + y);  // as the solver's totals (float32 dy)
        for (int x = 0; x < p.rect.width; ++x) {
          f(p, size_t(y) * size_t(p.rect.width) + size_t(x), p.rect.x + x, p.rect.y + y, area);
        }
      }
    }
  }

  const Scenario& s_;
  const RunOptions& opt_;
  const Ranks& ranks_;
  ScenarioDomain d_;
  Engine e_;
  detail::InputWindow input_;  // the model input of a window: what the solver started from
  std::optional<detail::Probes> probes_;
  double chosenDtS_ = 0, minChosenDtS_ = 1e300;
  int64_t batchSteps_ = 16;  // what advanceTo asks of advanceBatch at a time (sized by its wall time)
  int frame_ = -2;           // the rain frame the solver has (setRain); -2: none set yet (a new or resumed run)
};

}  // namespace

std::vector<std::string> runFolderOutputs(const fs::path& runDir) {
  std::vector<std::string> out;
  for (const auto& f : runFolderFiles()) {
    if (fs::exists(runDir / f)) out.push_back(f);
  }
  // The ranks' checkpoint parts of a run over MPI (checkpoint.R-of-N.bin).
  std::error_code ec;
  std::vector<std::string> parts;
  for (const auto& e : fs::directory_iterator(runDir, ec)) {
    const std::string name = e.path().filename().string();
    if (isRankCheckpointFile(name)) parts.push_back(name);
  }
  std::sort(parts.begin(), parts.end());
  out.insert(out.end(), parts.begin(), parts.end());
  return out;
}

std::vector<std::string> runFolderTemporaries(const fs::path& runDir) {
  std::vector<std::string> out;
  const auto files = runFolderFiles();
  for (const char* sub : {"", "maps", "plots", "pictures", "input"}) {
    std::error_code ec;
    for (const auto& e : fs::directory_iterator(runDir / sub, ec)) {
      const std::string name = e.path().filename().string();
      const std::string rel = std::string(sub) + (*sub ? "/" : "");
      const auto tmp = name.find(".tmp");
      const bool rankPart = !*sub && tmp != std::string::npos && isRankCheckpointFile(name.substr(0, tmp)) &&
                            isTemporaryOf(name, name.substr(0, tmp));
      const bool ours =
          rankPart || std::any_of(files.begin(), files.end(), [&](const std::string& f) {
            return fs::path(f).parent_path().string() == sub && isTemporaryOf(name, fs::path(f).filename().string());
          });
      if (ours && e.is_regular_file(ec)) out.push_back(rel + name);
    }
  }
  std::sort(out.begin(), out.end());
  return out;
}

Result<std::map<std::string, std::vector<double>>> readSeriesCsv(const fs::path& file) {
  STRATA_TRY_STATUS(requireRegularFile(file, "a run's series"));
  std::ifstream in(file);
  std::string line;
  std::vector<std::string> header;
  if (!std::getline(in, line)) return fail(file.string() + ": empty");
  std::stringstream hs(line);
  for (std::string h; std::getline(hs, h, ',');) header.push_back(h);
  std::map<std::string, std::vector<double>> cols;
  int row = 1;
  while (std::getline(in, line)) {
    ++row;
    std::stringstream ls(line);
    size_t k = 0;
    for (std::string v; std::getline(ls, v, ',') && k < header.size(); ++k) {
      char* end = nullptr;
      const double x = std::strtod(v.c_str(), &end);
      if (end == v.c_str()) return fail(file.string() + ":" + std::to_string(row) + ": not a number: " + v);
      cols[header[k]].push_back(x);
    }
  }
  if (cols.empty() || cols.begin()->second.empty())
    return fail(file.string() + ": no rows (the run has no output yet)");
  return cols;
}

std::string seriesCsv(const std::vector<SeriesRow>& rows) {
  std::string out =
      "time_s,steps,dt_s,water_volume_m3,flooded_area_km2,inflow_m3,rain_m3,outflow_m3,evaporation_m3,"
      "infiltration_m3,balance_error_rel,max_depth_m,sediment_m3,eroded_m3,deposited_m3\n";
  char buf[512];
  for (const auto& r : rows) {
    std::snprintf(buf, sizeof buf, "%.3f,%lld,%.6g,%.9g,%.9g,%.9g,%.9g,%.9g,%.9g,%.9g,%.6g,%.6g,%.9g,%.9g,%.9g\n",
                  r.timeS, r.steps, r.dtS, r.waterM3, r.floodedAreaKm2, r.inflowM3, r.rainM3, r.outflowM3,
                  r.evaporationM3, r.infiltrationM3, r.balanceErrorRel, r.maxDepthM, r.sedimentM3, r.erodedM3,
                  r.depositedM3);
    out += buf;
  }
  return out;
}

namespace {

// Why a checkpoint to resume from is missing, when the folder says: a run checkpointed on another
// number of ranks (or by one process).
std::string checkpointHint(const fs::path& dir, const Ranks& ranks) {
  std::error_code ec;
  for (const auto& e : fs::directory_iterator(dir, ec)) {
    int n = 0;
    if (isRankCheckpointFile(e.path().filename().string(), &n) && n != ranks.size()) {
      return " (the run was checkpointed on " + std::to_string(n) + " MPI ranks: resume it with mpirun -np " +
             std::to_string(n) + ")";
    }
  }
  if (ranks.distributed() && fs::exists(dir / "checkpoint.bin")) {
    return " (the run was checkpointed by one process: resume it without mpirun)";
  }
  return "";
}

// One run of a scenario, as runScenario's named steps. Every step is collective over the ranks:
// each rank takes it, and a failure on any rank fails it on all (Ranks::agree).
class Session {
 public:
  Session(const Scenario& s, const RunOptions& opt)
      : s_(s), opt_(opt), ranks_(opt.distributed ? Ranks::world() : Ranks::single()), name_(displayName(s.name)) {}

  // Derived sizes first: the interval count (64-bit, bounded; the parser checked it for files, a
  // scenario built in code is checked here) and, in the domain build, the grid against memory.
  Status countIntervals() {
    const double count = std::ceil(s_.durationS / s_.outputIntervalS - 1e-9);
    if (!(s_.durationS > 0 && count >= 1 && count <= double(kMaxOutputIntervals))) {
      char msg[160];
      std::snprintf(msg, sizeof msg, "%.3g output intervals over the duration (1 to %lld)", count, kMaxOutputIntervals);
      return fail(s_.at("time.output_interval") + msg);
    }
    intervals_ = int(count);
    return {};
  }

  // The GL context (before anything is written), the domain and the run folder. In one process
  // the domain is built whole. Over MPI ranks each rank builds its own rows from its windows of
  // the DEM or store (build_rows.hpp; the region needs a row per rank), writes them into input/
  // (the model input the run's blocks read) and runs on the domain's shape.
  Status buildDomain() {
    if (ranks_.distributed() && (!s_.outputs.gauges.empty() || !s_.outputs.sections.empty())) {
      return fail(s_.at(s_.outputs.gauges.empty() ? "outputs.section" : "outputs.gauge") +
                  "gauges and sections are not recorded over MPI ranks yet: run this scenario in one process");
    }
    if (ranks_.distributed() && s_.water.rain && !s_.water.rain->frames.empty()) {
      return fail(s_.at("water.rain.frames") +
                  "rain frames do not reach MPI ranks yet (each rank's blocks would need their windows of every "
                  "frame): run this scenario in one process");
    }
    // Local time steps run on the CPU backend in one process: `auto` takes it.
    Backend backend = opt_.backend.value_or(s_.model.backend);
    if (s_.model.localSteps && (backend == Backend::kGpu || ranks_.distributed())) {
      return fail(s_.at("model.local_steps") +
                  "local time steps run on the CPU backend in one process (the GPU backend and MPI ranks take one "
                  "step for the whole grid): leave them out or run with the CPU backend in one process");
    }
    if (s_.model.localSteps) backend = Backend::kCpu;
    STRATA_TRY(engine_, startContext(backend, opt_.pictures, ranks_));
    std::optional<detail::RowsBuilt> rows;
    if (ranks_.distributed()) {
      auto planned =
          detail::RowBuilder::plan(s_, opt_.memoryBudgetBytes, ranks_.size(), opt_.pictures, ranks_.onThisMachine());
      STRATA_TRY_STATUS(ranks_.agree(statusOf(planned)));
      STRATA_TRY(rows, detail::buildByRows(*planned, s_, ranks_));
    } else {
      STRATA_TRY(domain_, scenario::buildDomain(s_, opt_.memoryBudgetBytes));
    }
    STRATA_TRY_STATUS(takeFolder());
    scenarioText_ = ranks_.fromLead(ranks_.lead() ? s_.text : std::string());
    // The bed the model uses (conditioned), written once the domain is built: a map for the GIS
    // user, and what pictures and plots draw.
    if (rows) {
      STRATA_TRY_STATUS(detail::writeRows(ranks_, opt_.outDir, *rows));
      domain_ = std::move(rows->shape);  // this rank's rows: read back from input/ by its blocks
    } else {
      STRATA_TRY_STATUS(detail::writeRaster(ranks_, opt_.outDir / "maps" / "elevation.tif", domain_.bed.georef,
                                            detail::elevationMapOptions(), {{0, 0, domain_.bed.values}}));
      if (domain_.conditioningM.size() > 0) {
        STRATA_TRY_STATUS(detail::writeRaster(ranks_, opt_.outDir / "maps" / "conditioning.tif", domain_.bed.georef,
                                              detail::conditioningMapOptions(), {{0, 0, domain_.conditioningM}}));
      }
    }
    if (ranks_.lead()) {
      const auto& g = domain_.bed.georef;
      log::info(opt_.command) << name_ << ": " << g.width << " x " << g.height << " cells, "
                              << domain_.totalAreaM2 / 1e6 << " km^2, " << domain_.sources.size() << " inflow(s), "
                              << domain_.levels.size() << " fixed level(s), " << formatDuration(s_.durationS)
                              << " simulated"
                              << (ranks_.distributed()
                                      ? ", built by the " + std::to_string(ranks_.size()) + " ranks row by row"
                                      : std::string());
    }
    return {};
  }

  // The solver on the built domain, with its flood statistics (a fresh run with a spin-up starts
  // them at its end, Run::spinUp: kept through it they would be reset unread, 3 % of its time).
  Status startSolver() {
    STRATA_TRY_STATUS(scenario::startSolver(engine_, domain_, ranks_, opt_.outDir));
    if (!(s_.spinUpS > 0 && !opt_.resume)) engine_.solver->enableFloodStats(float(s_.outputs.wetThresholdM));
    run_.emplace(s_, opt_, ranks_, std::move(domain_), std::move(engine_));
    installInterruptHandler();  // before "running on": from that line on a Ctrl-C stops the run cleanly
    log::info(opt_.command) << "running on " << run_->backendName();
    return {};
  }

  // The spin-up (a fresh run only: a resumed run's is in its checkpoint).
  Status spinUp() {
    if (s_.spinUpS > 0 && !opt_.resume) {
      STRATA_TRY(spinUp_, run_->spinUp(s_.spinUpS, s_.spinUpTolerance, name_));
    }
    return {};
  }

  // Pictures: the state read on every rank at every `stride_`-th cell, drawn by the lead; the
  // "before" picture of a fresh run.
  Status openPictures() {
    if (!opt_.pictures) return {};
    stride_ = detail::pictureStride(run_->solver().grid().width, run_->solver().grid().height, opt_.pictureCells);
    Status status;
    if (ranks_.lead()) {
      std::error_code ec;
      fs::create_directories(opt_.outDir / "pictures", ec);
      auto bed = detail::readStrided(opt_.outDir / "maps" / "elevation.tif", stride_);
      status = statusOf(bed);
      if (bed) {
        auto p = Pictures::create(run_->domain(), *bed, stride_, s_.erosion.enabled, s_.outputs.wetThresholdM);
        if (p) pictures_.emplace(std::move(p).value());
        status = statusOf(p);
      }
    }
    STRATA_TRY_STATUS(ranks_.agree(status));
    if (opt_.resume) return {};
    auto pieces = run_->pieces();
    STRATA_TRY_STATUS(ranks_.agree(statusOf(pieces)));
    return drawPicture(*pieces, "before.png");
  }

  // A resumed run continues from its checkpoint (each rank its own part, all of the same
  // interval); a fresh one records its scenario. Over MPI ranks each rank holds its parts of the
  // last two checkpoints, and the run resumes from the newest interval every rank has: a rank
  // killed while the parts were written leaves the others one interval ahead, not a lost run.
  Status resumeOrBegin() {
    summary_.backend = run_->backendName();
    summary_.ranks = ranks_.size();
    if (!opt_.resume) {
      STRATA_TRY_STATUS(run_->startProbes(nullptr));
      STRATA_TRY_STATUS(
          ranks_.agree(ranks_.lead() ? writeFileAtomic(opt_.outDir / "scenario.toml", scenarioText_) : Status{}));
      // The state at t = 0 (after any spin-up): a run stopped before its first output interval
      // ends can be resumed too.
      return writeCheckpoint(Checkpoint{0,
                                        wallSoFar(),
                                        {},
                                        spinUp_,
                                        run_->probes() ? run_->probes()->save() : std::vector<double>{},
                                        run_->solver().saveState()});
    }
    std::optional<Checkpoint> current, previous;
    Status status;
    // This rank's part (`previous`: the one before), if it has one; a part that does not decode
    // (damaged, or of another scenario) fails the resume.
    auto readPart = [&](bool isPrevious, std::optional<Checkpoint>& into) {
      if (!status.ok() || !fs::exists(checkpointPath(isPrevious))) return;
      auto decoded = decodeCheckpoint(checkpointPath(isPrevious), owner());
      if (decoded) into = std::move(decoded).value();
      status = statusOf(decoded);
    };
    readPart(false, current);
    if (ranks_.distributed()) readPart(true, previous);
    if (status.ok() && !current && !previous) {
      status = fail(checkpointPath().string() + ": no checkpoint to resume from" + checkpointHint(opt_.outDir, ranks_));
    }
    STRATA_TRY_STATUS(ranks_.agree(status));
    const int newest = std::max(current ? current->interval : -1, previous ? previous->interval : -1);
    const int target = ranks_.minMax(newest).first;
    const bool fromPrevious = !(current && current->interval == target);
    if (fromPrevious && !(previous && previous->interval == target)) {
      status = fail(opt_.outDir.string() + ": rank " + std::to_string(ranks_.rank()) +
                    " has no checkpoint part of interval " + std::to_string(target) + " (its newest is " +
                    std::to_string(newest) + "): the parts are not of one run");
    } else if (fromPrevious) {
      // The newer part of this rank is dropped: its files again say where the run stands.
      std::error_code ec;
      fs::rename(checkpointPath(true), checkpointPath(), ec);
      if (ec) status = fail(checkpointPath(true).string() + ": cannot restore it: " + ec.message());
    }
    STRATA_TRY_STATUS(ranks_.agree(status));
    if (fromPrevious)
      log::warn(opt_.command)
          << "resuming from the checkpoint before the last: the ranks were stopped while writing it";
    Checkpoint c = std::move(fromPrevious ? *previous : *current);
    if (c.interval > intervals_) return fail(checkpointPath().string() + ": more intervals than the scenario has");
    STRATA_TRY_STATUS(run_->solver().restoreState(c.state));
    STRATA_TRY_STATUS(run_->setRain(c.state.counters.timeS));
    if (auto st = run_->startProbes(&c.probes); !st.ok()) return fail(checkpointPath().string() + ": " + st.message());
    interval_ = c.interval;
    earlierWallS_ = c.wallS;
    spinUp_ = c.spinUp;
    summary_.series = std::move(c.series);
    log::info(opt_.command) << "resuming at " << formatDuration(run_->solver().timeS()) << " (interval " << interval_
                            << ")";
    return {};
  }

  // The output intervals: each advanced to its end with progress, then closed (its row, maps,
  // pictures and checkpoint). Stops early when interrupted or asked to.
  Status runIntervals() {
    // Resumed at a peak so far (the run may have been killed before it drew it): keep its state.
    if (opt_.pictures && opt_.resume && !summary_.series.empty() && isPeak(summary_.series.back())) {
      auto pieces = run_->pieces();
      STRATA_TRY_STATUS(ranks_.agree(statusOf(pieces)));
      peakPicture_ = run_->pictureState(*pieces, stride_);
    }
    Progress progress(opt_.command + " " + name_, s_.durationS);
    // RunOptions::onProgress at most every 0.2 s; a false answer stops the run as a Ctrl-C does.
    auto nextCallback = std::chrono::steady_clock::now();
    auto tellProgress = [&] {
      nextCallback = std::chrono::steady_clock::now() + std::chrono::milliseconds(200);
      if (!opt_.onProgress(run_->solver().timeS(), s_.durationS)) setInterrupted(true);
    };
    auto note = [&] { return run_->progressNote("t = " + formatDuration(run_->solver().timeS())); };
    while (interval_ < intervals_) {
      const double t1 = std::min(s_.durationS, (interval_ + 1) * s_.outputIntervalS);
      // Progress whenever it is due (a bar on a terminal, a log line every 10 s of wall time
      // otherwise), step by step, and at the end of the interval.
      auto tick = [&] {
        if (progress.due()) progress.update(run_->solver().timeS(), note());
        if (opt_.onProgress && std::chrono::steady_clock::now() >= nextCallback) tellProgress();
      };
      STRATA_TRY(const bool done, run_->advanceTo(t1, tick));
      progress.update(run_->solver().timeS(), note());
      if (opt_.onProgress && done) tellProgress();
      if (!done) break;
      STRATA_TRY_STATUS(closeInterval());
      if (opt_.stopAfterIntervals >= 0 && interval_ >= opt_.stopAfterIntervals && interval_ < intervals_) break;
    }
    // A run that stops early draws the peak it has kept (resumed at that interval, a run keeps
    // its state again: the start of this function).
    STRATA_TRY_STATUS(drawPeakPicture());
    summary_.completed = interval_ >= intervals_;
    if (summary_.completed) {
      progress.finish(std::to_string(run_->solver().stats().steps) + " steps");
    } else if (summary_.series.empty()) {
      log::warn(opt_.command)
          << "stopped before the first output interval ended: no outputs yet; --resume continues from t = 0";
    } else {
      log::warn(opt_.command) << "stopped at " << formatDuration(summary_.series.back().timeS)
                              << "; outputs are those of that interval; continue with --resume";
    }
    return {};
  }

  // The summary, the files written, the budgets, and (by the lead) the plots and the report.
  Result<RunSummary> finish() {
    const auto st = run_->solver().stats();
    summary_.simulatedS = st.timeS;
    summary_.steps = st.steps - spinUp_.steps;  // the run's own: the solver counts the spin-up's too
    summary_.wallS = wallSoFar();
    summary_.spinUp = spinUp_;
    summary_.files = {"scenario.toml", "series.csv"};
    if (const auto* p = run_->probes()) {
      summary_.gauges = p->gaugeSummaries();
      summary_.sections = p->sectionSummaries();
      for (const char* f : {"gauges.csv", "sections.csv"}) {
        if (fs::exists(opt_.outDir / f)) summary_.files.push_back(f);
      }
    }
    if (ranks_.distributed()) {
      for (int r = 0; r < ranks_.size(); ++r) {
        summary_.files.push_back(rankCheckpointFile(r, ranks_.size()));
        if (fs::exists(opt_.outDir / rankCheckpointFile(r, ranks_.size(), true))) {
          summary_.files.push_back(rankCheckpointFile(r, ranks_.size(), true));
        }
      }
      for (const auto& f : detail::modelInputFiles(int(run_->domain().input.materials.size()))) {
        if (fs::exists(opt_.outDir / f)) summary_.files.push_back(f);
      }
    } else {
      summary_.files.push_back("checkpoint.bin");
    }
    for (const char* f : {"maps/elevation.tif", "maps/conditioning.tif"}) {
      if (fs::exists(opt_.outDir / f)) summary_.files.push_back(f);
    }
    const auto maps = run_->mapFiles();
    summary_.files.insert(summary_.files.end(), maps.begin(), maps.end());
    std::vector<std::string> pictureFiles;
    for (const char* p : {"pictures/before.png", "pictures/peak.png", "pictures/after.png", "pictures/max_depth.png"}) {
      if (fs::exists(opt_.outDir / p)) pictureFiles.push_back(p);
    }
    summary_.files.insert(summary_.files.end(), pictureFiles.begin(), pictureFiles.end());
    auto pieces = run_->pieces();
    STRATA_TRY_STATUS(ranks_.agree(statusOf(pieces)));
    if (s_.erosion.enabled) {
      summary_.material = run_->materialBudget(*pieces);
      for (int k = 1; k <= kMaxLayerMaps; ++k) {
        if (fs::exists(opt_.outDir / layerMapFile(k))) summary_.files.push_back(layerMapFile(k));
      }
    }
    FloodSummary flood = run_->floodSummary(*pieces);
    STRATA_TRY_STATUS(ranks_.agree(run_->addPonding(*pieces, flood)));
    if (!ranks_.lead()) return summary_;  // the lead writes the styles, plots and the report
    std::vector<std::string> written;     // the maps
    for (const auto& f : summary_.files) {
      if (f.starts_with("maps/")) written.push_back(f);
    }
    STRATA_TRY(auto styles, detail::writeMapStyles(opt_.outDir, written, s_.outputs.wetThresholdM));
    summary_.files.insert(summary_.files.end(), styles.begin(), styles.end());
    // The report before the slow parts (plots, the maps' COG copies): the ranks of a run that
    // mpirun stops are killed about a second after they are told to stop (Open MPI sends SIGTERM,
    // then SIGKILL), and the report says where the run stands. Written again with the plots.
    const ReportInput report{s_, run_->domain(), summary_, flood, run_->backendName(), pictureFiles, maxDepthLegend()};
    for (const auto& w : runWarnings(report)) log::warn(opt_.command) << w;
    STRATA_TRY_STATUS(writeReport(opt_.outDir, report));
    if (opt_.plots) {
      STRATA_TRY(auto plots, writePlots(opt_.outDir, !summary_.series.empty()));
      summary_.files.insert(summary_.files.end(), plots.begin(), plots.end());
      STRATA_TRY_STATUS(writeReport(opt_.outDir, report));
    }
    // The run's maps as Cloud Optimized GeoTIFFs (overviews: a GIS pans a large one quickly);
    // written window by window during the run, rewritten once here.
    for (const auto& f : written) {
      if (f.ends_with(".tif")) STRATA_TRY_STATUS(gis::rewriteAsCog((opt_.outDir / f).string()));
    }
    summary_.files.push_back("report.md");
    return summary_;
  }

 private:
  // The run folder, taken by the lead for the whole run (its lock), with its maps/ folder.
  Status takeFolder() {
    Status status;
    if (ranks_.lead()) {
      auto taken = takeRunFolder(opt_);
      status = statusOf(taken);
      if (taken) {
        lock_.emplace(std::move(taken).value());
        std::error_code ec;
        fs::create_directories(opt_.outDir / "maps", ec);
        if (ec) status = fail(opt_.outDir.string() + ": cannot create the run folder: " + ec.message());
      }
    }
    return ranks_.agree(status);
  }

  // A complete interval: its row, maps, pictures and checkpoint. The stored water, and so which
  // interval is the peak, is the same exact sum on every rank. Each rank reads its own pieces of
  // the state; only pictures gather the depth to the lead.
  Status closeInterval() {
    auto pieces = run_->pieces();
    STRATA_TRY_STATUS(ranks_.agree(statusOf(pieces)));
    const SeriesRow row = run_->row(*pieces);
    summary_.series.push_back(row);
    ++interval_;
    if (opt_.pictures) {
      // The peak picture is of the last interval at which the stored water reached a new high:
      // its state is kept, and drawn once the water has fallen from it (or the run ends or
      // stops), not at every new high (a rising flood drew it at every interval: all 12 of the
      // main job's, 2-3 s each on llvmpipe).
      if (isPeak(row)) {
        peakPicture_ = run_->pictureState(*pieces, stride_);
      } else {
        STRATA_TRY_STATUS(drawPeakPicture());
      }
      if (interval_ == intervals_) {
        // A peak at the last interval is the "after" picture itself: drawn once, copied.
        const bool peakIsLast = peakPicture_ && isPeak(row);
        if (peakIsLast) peakPicture_.reset();
        STRATA_TRY_STATUS(drawPeakPicture());
        STRATA_TRY_STATUS(drawPicture(*pieces, "after.png"));
        if (peakIsLast) STRATA_TRY_STATUS(copyPicture("after.png", "peak.png"));
        const auto maxDepth = run_->maxDepthStrided(*pieces, stride_);
        STRATA_TRY_STATUS(ranks_.agree(pictures_ ? pictures_->drawMaxDepth(maxDepth, pictures_->georef(),
                                                                           opt_.outDir / "pictures" / "max_depth.png")
                                                 : Status{}));
      }
    }
    Status status = run_->writeMaps(*pieces);
    if (status.ok() && ranks_.lead()) status = writeFileAtomic(opt_.outDir / "series.csv", seriesCsv(summary_.series));
    if (const auto* p = run_->probes(); p && status.ok()) {
      if (!p->gaugeSummaries().empty()) status = writeFileAtomic(opt_.outDir / "gauges.csv", p->gaugesCsv());
      if (status.ok() && !p->sectionSummaries().empty())
        status = writeFileAtomic(opt_.outDir / "sections.csv", p->sectionsCsv());
    }
    STRATA_TRY_STATUS(ranks_.agree(status));
    // Over MPI ranks the blocks are dealt again by their work before each checkpoint.
    if (auto* d = run_->distributed()) {
      STRATA_TRY(const auto moved, d->rebalance());
      if (moved.blocksMoved > 0) {
        log::info(opt_.command) << "re-balanced: " << moved.blocksMoved << " blocks moved, busiest rank "
                                << moved.imbalanceBefore << " -> " << moved.imbalanceAfter << " x the mean, "
                                << moved.seconds << " s";
      }
    }
    const Checkpoint c{interval_,
                       wallSoFar(),
                       summary_.series,
                       spinUp_,
                       run_->probes() ? run_->probes()->save() : std::vector<double>{},
                       run_->solver().saveState()};
    return writeCheckpoint(c);
  }

  Status drawPicture(const std::vector<detail::Piece>& pieces, const char* file) {
    auto state = run_->pictureState(pieces, stride_);
    return ranks_.agree(pictures_ ? pictures_->draw(std::move(state), opt_.outDir / "pictures" / file) : Status{});
  }

  // pictures/`to` as a copy of pictures/`from` (written atomically, by the lead).
  Status copyPicture(const char* from, const char* to) {
    Status status;
    if (pictures_) {
      const fs::path dir = opt_.outDir / "pictures";
      const fs::path tmp = temporaryPathFor(dir / to);
      std::error_code ec;
      fs::copy_file(dir / from, tmp, ec);
      status = ec ? fail((dir / to).string() + ": cannot write it: " + ec.message()) : commitTemporary(tmp, dir / to);
    }
    return ranks_.agree(status);
  }

  // Whether `row` (the last of the series) holds as much water as any interval before it.
  bool isPeak(const SeriesRow& row) const {
    return std::all_of(summary_.series.begin(), summary_.series.end(),
                       [&](const SeriesRow& r) { return r.waterM3 <= row.waterM3; });
  }

  // peak.png from the kept state, if there is one not drawn yet.
  Status drawPeakPicture() {
    if (!peakPicture_) return {};
    PictureState state = std::move(*peakPicture_);
    peakPicture_.reset();
    return ranks_.agree(pictures_ ? pictures_->draw(std::move(state), opt_.outDir / "pictures" / "peak.png")
                                  : Status{});
  }

  std::string maxDepthLegend() const {
    if (!pictures_ || !summary_.completed) return {};
    char text[200];
    const auto r = pictures_->maxDepthRange();
    std::snprintf(text, sizeof text,
                  "`max_depth.png`: the largest depth each cell had, from %.2f m (dark purple; shallower cells "
                  "not drawn) to %.1f m and more (yellow).",
                  r[0], r[1]);
    return text;
  }

  // Over MPI ranks this rank's last part becomes its previous one before the new part is written,
  // and the write is complete on every rank before any goes on (agree): the ranks' parts are then
  // never more than one interval apart, and each holds the older of any two (resumeOrBegin).
  Status writeCheckpoint(const Checkpoint& c) {
    Status status;
    if (ranks_.distributed() && fs::exists(checkpointPath())) {
      std::error_code ec;
      fs::rename(checkpointPath(), checkpointPath(true), ec);
      if (ec) status = fail(checkpointPath().string() + ": cannot keep it as the previous part: " + ec.message());
    }
    if (status.ok()) status = writeFileAtomic(checkpointPath(), encodeCheckpoint(owner(), c));
    return ranks_.agree(status);
  }

  CheckpointOwner owner() const { return {opt_.command, fnv1a(scenarioText_)}; }
  fs::path checkpointPath(bool previous = false) const {
    return opt_.outDir / (ranks_.distributed() ? rankCheckpointFile(ranks_.rank(), ranks_.size(), previous)
                                               : std::string("checkpoint.bin"));
  }
  double wallSoFar() const {
    return earlierWallS_ + std::chrono::duration<double>(std::chrono::steady_clock::now() - wallStart_).count();
  }

  const Scenario& s_;
  const RunOptions& opt_;
  const Ranks ranks_;
  const std::string name_;
  const std::chrono::steady_clock::time_point wallStart_ = std::chrono::steady_clock::now();
  int intervals_ = 0;
  Engine engine_;                 // until the run takes it
  ScenarioDomain domain_;         // until the run takes it
  std::optional<FileLock> lock_;  // held by the lead for the whole run
  std::string scenarioText_;
  std::optional<Run> run_;
  std::optional<Pictures> pictures_;
  std::optional<PictureState> peakPicture_;  // the last new high's, not drawn yet
  int stride_ = 1;
  SpinUpSummary spinUp_;
  RunSummary summary_;
  int interval_ = 0;
  double earlierWallS_ = 0;  // of the sessions before a resume
};

}  // namespace

Result<RunSummary> runScenario(const Scenario& s, const RunOptions& opt) {
  Session run(s, opt);
  STRATA_TRY_STATUS(run.countIntervals());
  STRATA_TRY_STATUS(run.buildDomain());
  STRATA_TRY_STATUS(run.startSolver());
  STRATA_TRY_STATUS(run.spinUp());
  STRATA_TRY_STATUS(run.openPictures());
  STRATA_TRY_STATUS(run.resumeOrBegin());
  STRATA_TRY_STATUS(run.runIntervals());
  return run.finish();
}

}  // namespace strata::scenario
