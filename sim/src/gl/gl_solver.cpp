// Host side of the GL backend: owns the buffers, binds them at the slots declared in
// sim/shaders/sim.glsl, and dispatches the passes in the order CpuSolver::runStep runs them, with
// a shader-storage barrier between passes.
#include <strata/sim/gl/gl_solver.hpp>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstddef>
#include <cstring>
#include <limits>
#include <map>
#include <string>
#include <utility>

#include <strata/gl/context.hpp>
#include <strata/gl/objects.hpp>
#include <strata/gl/state.hpp>
#include <strata/sim/gl/gl_layout.hpp>
#include <strata/sim/gl/shader_slots.hpp>

namespace strata::sim {

namespace {
constexpr size_t kParamsDtOffset = offsetof(GpuSimParams, dtS);
// The accumulators' buffer: AccumOffset's planes, then W12b's plane of the point sources' second
// halves (ACCUM_POUR; GPU-only, 0 between steps, so never moved to or from a CellBlock).
constexpr int kAccumPour = kAccumPerCell;
constexpr int kAccumPlanes = kAccumPour + 1;

void barrier() { gl::memoryBarrier(gl::Barrier::kStorage); }
void readBarrier() { gl::memoryBarrier(gl::Barrier::kBufferUpdate); }
}  // namespace

std::vector<gl::ShaderDefine> slots::kernelDefines() {
  auto d = gl::definesFor(kAll);
  d.insert(d.end(), {{"ACCUM_PER_CELL", kAccumPerCell},
                     {"ACCUM_OUTFLOW", kAccumOutflow},
                     {"ACCUM_EVAPORATED", kAccumEvaporated},
                     {"ACCUM_SEDIMENT_OUT", kAccumSedimentOut},
                     {"ACCUM_LEVEL", kAccumLevel},
                     {"ACCUM_INFILTRATED", kAccumInfiltrated},
                     {"ACCUM_DEPTH_ERROR", kAccumDepthError},
                     {"ACCUM_POUR", kAccumPour}});
  return d;
}

struct GlSolver::Impl {
  GpuSimParams p{};  // the block the kernels read (gpuParams)
  size_t n = 0;
  int layers = 0;

  gl::Buffer params, materials, rowDx, base, bed, layerBuf, stateA, stateB, stage, flux, fluxDiag, faceX, faceY, tilt,
      accum, rain, manning, infiltration, thermal, scour, sourceEntries, maxSpeed, floodStats, fvLimit, levelEntries,
      clock, series, terms;  // W35's clock, the sources' samples and their shares of the entries
  bool aIsCurrent = true;
  bool rasterRain = false;   // the rain raster has a cell that rains
  bool infiltrates = false;  // W11b: the input gave infiltration rates
  gl::Program pSources, pPointSources, pWaveSpeed, pPipeFlux, pPipeUpdate, pFvFace, pFvLimit, pFvUpdate, pInertialFace,
      pInertialLimit, pInertialUpdate, pErode, pThermalFlux, pThermalApply, pFloodStats, pLevel, pCopyRect, pBedRect,
      pClock;
  // W35: a device step's passes dispatch the group counts step_clock.comp leaves in `clock`.
  bool indirect = false;
  // The step W10 chose last on the device (before the last one was shortened to land on a run's
  // end), to size the next run of them.
  double lastDeviceDtS = 0;
  gl::Buffer maxSpeedHost;  // maxSpeed copied to host memory, read every step (maxWaveSpeed)
  gl::Buffer packed;        // copy_rect.comp's side of a rectangle moved to or from the host

  const gl::Buffer& cur() const { return aIsCurrent ? stateA : stateB; }
  const gl::Buffer& next() const { return aIsCurrent ? stateB : stateA; }
  gl::Buffer& curMut() { return aIsCurrent ? stateA : stateB; }

  void bindAll() const {
    params.bind(slots::kParams);
    materials.bind(slots::kMaterials);
    rowDx.bind(slots::kRowDx);
    base.bind(slots::kBase);
    bed.bind(slots::kBed);
    layerBuf.bind(slots::kLayers);
    cur().bind(slots::kStateIn);
    next().bind(slots::kStateOut);
    stage.bind(slots::kStage);
    flux.bind(slots::kFlux);
    fluxDiag.bind(slots::kFluxDiag);
    faceX.bind(slots::kFaceX);
    faceY.bind(slots::kFaceY);
    tilt.bind(slots::kTilt);
    accum.bind(slots::kAccum);
    rain.bind(slots::kRain);
    manning.bind(slots::kManning);
    infiltration.bind(slots::kInfiltration);
    thermal.bind(slots::kThermal);
    scour.bind(slots::kScour);
    sourceEntries.bind(slots::kSources);
    maxSpeed.bind(slots::kMaxSpeed);
    floodStats.bind(slots::kFloodStats);  // W36: a fused update writes them
    fvLimit.bind(slots::kFvLimit);
    clock.bind(slots::kClock);
    series.bind(slots::kSeries);
    terms.bind(slots::kTerms);
  }

  // A pass over `x` x `y` invocations of `shape`: directly, or in a device step as step_clock.comp
  // says (nothing once the clock has reached its end).
  void run(const gl::Program& prog, ClockShape shape, int x, int y = 1) const {
    if (indirect) {
      prog.dispatchIndirect(clock, offsetof(GpuClock, dispatchNow) + 12 * size_t(shape));
    } else {
      prog.dispatchCovering(x, y);
    }
  }

  // W10's wave speed of the current state into maxSpeed (the buffers bound).
  void waveSpeedPass() {
    maxSpeed.fill(0u);
    pWaveSpeed.dispatchCovering(int(n));
    barrier();
  }

  double maxWaveSpeed() {
    bindAll();
    waveSpeedPass();
    readBarrier();
    // Through a host-memory buffer: NVIDIA moved maxSpeed itself between GPU and host memory at
    // every step's read (and warned each time) when it was read directly.
    maxSpeed.copyTo(maxSpeedHost, 4);
    uint32_t bits = 0;
    maxSpeedHost.download(0, 4, &bits);
    float v;
    std::memcpy(&v, &bits, 4);
    return double(v);
  }

  // One step from the host: its length, sources and levels given (StepInputs).
  void takeStep(const StepInputs& step, bool hasLevels, float wetThresholdM) {
    if (step.dtS != p.dtS) {
      p.dtS = step.dtS;
      params.upload(kParamsDtOffset, sizeof(float), &p.dtS);
    }
    bindAll();
    if (!step.sources.empty()) {
      const size_t bytes = step.sources.size() * sizeof(SourceEntry);
      if (sourceEntries.size() < bytes) sourceEntries = gl::Buffer(bytes);
      sourceEntries.bind(slots::kSources);
      sourceEntries.upload(0, bytes, step.sources.data());
      pPointSources.set("entryCount", unsigned(step.sources.size()));
    }
    pFloodStats.set("timeS", float(step.startS + double(step.dtS)));
    passes(step.sources.size(), hasLevels ? &step.levels : nullptr, wetThresholdM);
  }

  // W36: a device step of flood mode whose water update is its last change of the state (no
  // levels: device steps have none; no erosion or thermal weathering) ends that update with the
  // flood statistics and the next step's wave speed (sim_tail.glsl) instead of their own passes.
  bool fusedTail() const {
    return indirect && p.waterModel != int32_t(WaterModel::kVirtualPipes) && p.erosionEnabled == 0 &&
           p.thermalEnabled == 0;
  }

  // The tail's uniforms of an update program (both 0 where it does not end the step).
  static void setTail(const gl::Program& update, bool speed, bool stats, float wetThresholdM) {
    update.set("tailSpeed", speed ? 1u : 0u);
    update.set("tailStats", stats ? 1u : 0u);
    if (stats) update.set("wetThresholdM", wetThresholdM);
  }

  // W11 or W11b can change a cell (the CPU backend's Impl::rainOrLosses): otherwise sources.comp
  // adds 0 to settled depths and is not dispatched, and in a device step step_clock.comp pours the
  // point sources in itself (W36: nothing comes between them).
  bool rainOrLosses() const {
    return p.rainMmPerHour != 0.0f || rasterRain || p.evaporationMmPerHour != 0.0f || infiltrates;
  }
  // W36: the clock pours the point sources in itself where nothing comes between it and them: a
  // step without a rain pass, unless the local-inertial scheme pours after its faces (W38).
  bool clockPours() const {
    return !rainOrLosses() && (p.waterModel == int32_t(WaterModel::kVirtualPipes) ||
                               p.floodScheme != int32_t(FloodScheme::kLocalInertial));
  }

  // The passes of a step after its sources' entries are in place (docs/sim-water.md, "One step").
  void passes(size_t sourceEntryCount, const std::vector<LevelEntry>* levels, float wetThresholdM) {
    const int w = p.width, h = p.height;
    const bool fused = fusedTail() && levels == nullptr;
    const bool tailSpeed = fused && p.cflAlpha > 0, tailStats = fused && wetThresholdM >= 0;
    auto pour = [&] {  // W11, W11b, W12
      if (rainOrLosses()) {
        run(pSources, kShapeGrid, w, h);
        barrier();
      }
      if (sourceEntryCount > 0 && (!indirect || !clockPours())) {  // else the clock poured them in
        run(pPointSources, kShapeEntries, int(sourceEntryCount));
        barrier();
      }
    };
    if (p.waterModel == int32_t(WaterModel::kVirtualPipes)) {
      pour();
      run(pPipeFlux, kShapeGrid, w, h);
      barrier();
      run(pPipeUpdate, kShapeGrid, w, h);
      barrier();
    } else if (p.floodScheme == int32_t(FloodScheme::kLocalInertial)) {
      run(pInertialFace, kShapeGrid, w, h);
      barrier();
      pour();  // W38: the faces from the depths before the step's sources
      run(pInertialLimit, kShapeGrid, w, h);
      barrier();
      setTail(pInertialUpdate, tailSpeed, tailStats, wetThresholdM);
      run(pInertialUpdate, kShapeGrid, w, h);
      barrier();
    } else {
      pour();
      pFvFace.set("average", 0);
      run(pFvFace, kShapeGrid, w, h);
      barrier();
      pFvUpdate.set("final_", 0);
      setTail(pFvUpdate, false, false, wetThresholdM);
      run(pFvUpdate, kShapeGrid, w, h);
      barrier();
      stage.bind(slots::kStateIn);  // the corrector's faces come from U1
      pFvFace.set("average", 1);
      run(pFvFace, kShapeGrid, w, h);
      barrier();
      cur().bind(slots::kStateIn);
      run(pFvLimit, kShapeGrid, w, h);
      barrier();
      pFvUpdate.set("final_", 1);
      pFvUpdate.set("pours", sourceEntryCount > 0 ? 1u : 0u);  // W12b
      setTail(pFvUpdate, tailSpeed, tailStats, wetThresholdM);
      run(pFvUpdate, kShapeGrid, w, h);
      barrier();
    }
    aIsCurrent = !aIsCurrent;
    cur().bind(slots::kStateIn);
    next().bind(slots::kStateOut);
    if (levels) levelPass(*levels);
    if (p.erosionEnabled) {
      run(pErode, kShapeGrid, w, h);
      barrier();
    }
    if (p.thermalEnabled) {
      run(pThermalFlux, kShapeGrid, w, h);
      barrier();
      run(pThermalApply, kShapeGrid, w, h);
      barrier();
    }
    if (wetThresholdM >= 0 && !tailStats) {
      cur().bind(slots::kStateIn);
      floodStats.bind(slots::kFloodStats);
      pFloodStats.set("wetThresholdM", wetThresholdM);
      run(pFloodStats, kShapeCells, int(n));
      barrier();
    }
  }

  // W35: steps chosen and taken on the GPU towards r.endS, at most r.maxSteps, in runs of steps
  // queued without reading anything back; one read of the clock after each run. The runs are
  // sized from the last step (a run that overshoots the end dispatches no groups after it).
  DeviceRun deviceRun(const DeviceRequest& r, const std::vector<Source>& sourceList, const SimParams& sp,
                      const CellGrid& grid, float wetThresholdM) {
    const auto [entryCount, termCount] = uploadSourceTables(sourceList, grid);
    GpuClock c;
    c.timeS = r.timeS;
    c.endS = r.endS;
    c.minChosenDtS = std::numeric_limits<double>::infinity();
    c.maxDtS = double(sp.maxDtS);
    c.reachM = double(sp.cflAlpha) * grid.minCellM;
    c.gravityMS2 = double(sp.gravityMS2);
    c.rainRateMS = r.rainRateMS;
    c.adaptive = sp.cflAlpha > 0 ? 1u : 0u;
    c.inertial = sp.floodScheme == FloodScheme::kLocalInertial ? 1u : 0u;
    c.pointSources = clockPours() ? 1u : 0u;
    c.termCount = uint32_t(termCount);
    auto groups = [](size_t cells, int per) { return uint32_t((cells + size_t(per) - 1) / size_t(per)); };
    const uint32_t full[3 * kClockShapes] = {groups(size_t(p.width), 16),
                                             groups(size_t(p.height), 16),
                                             1,
                                             groups(n, 256),
                                             1,
                                             1,
                                             groups(entryCount, 64),
                                             1,
                                             1};
    std::copy(std::begin(full), std::end(full), c.dispatchFull);
    clock.upload(0, sizeof(GpuClock), &c);
    pPointSources.set("entryCount", unsigned(entryCount));
    pFloodStats.set("timeFromClock", 1u);
    DeviceRun out;
    out.timeS = r.timeS;
    indirect = true;
    // The state ping-pongs at every step queued; the steps queued after the clock reached its
    // end run nothing, so the current buffer is the one of the last step that ran.
    const bool startA = aIsCurrent;
    if (p.cflAlpha > 0 && fusedTail()) {  // W36: the first step's wave speed; each update leaves the next's
      bindAll();
      waveSpeedPass();
    }
    bool done = false;
    while (!done && out.steps < r.maxSteps) {
      // Enough steps to reach the end at the last step's length, and a few more: a step queued
      // past the end costs its dispatches (of no groups), a run too short another read.
      const double left = r.endS - out.timeS;
      const double estimate = lastDeviceDtS > 0 ? left / lastDeviceDtS * 1.02 + 2.0 : 16.0;
      const int64_t queued =
          std::max<int64_t>(1, std::min<int64_t>(r.maxSteps - out.steps, int64_t(std::min(estimate, 65536.0))));
      for (int64_t k = 0; k < queued; ++k) deviceStep(entryCount, wetThresholdM);
      readBarrier();
      clock.download(0, offsetof(GpuClock, dispatchNow), &c);
      out.steps = int64_t(c.steps);
      out.timeS = c.timeS;
      done = c.done != 0 || Solver::reached(c.timeS, r.endS);
      aIsCurrent = c.steps % 2 == 0 ? startA : !startA;
      if (c.steps > 0) lastDeviceDtS = c.lastChosenDtS;
    }
    indirect = false;
    p.dtS = -1.0f;  // the GPU's P.dtS is the last device step's: the next host step uploads its own
    pFloodStats.set("timeFromClock", 0u);
    out.inflowM3 = c.inflowM3;
    out.lastDtS = double(c.lastDtS);
    out.minChosenDtS = c.steps > 0 ? c.minChosenDtS : 0.0;
    out.lastChosenDtS = c.lastChosenDtS;
    return out;
  }

  // One device step: the wave speed (unless the last step's update left it, W36), step_clock.comp,
  // then the passes as it says.
  void deviceStep(size_t entryCount, float wetThresholdM) {
    bindAll();
    if (p.cflAlpha > 0 && !fusedTail()) waveSpeedPass();
    pClock.dispatchCovering(1);
    gl::memoryBarrier(gl::Barrier::kStorage | gl::Barrier::kCommand);
    passes(entryCount, nullptr, wetThresholdM);
  }

  // W35: the sources' samples and their shares of the point-source entries (one per cell, in
  // cell order, as mergeSources lists them), for step_clock.comp: the entries and the terms.
  std::pair<size_t, size_t> uploadSourceTables(const std::vector<Source>& sourceList, const CellGrid& grid) {
    std::map<uint32_t, uint32_t> entryOf;  // cell -> entry, in cell order
    for (const auto& src : sourceList) {
      for (auto [x, y] : src.cells) entryOf.emplace(uint32_t(y) * uint32_t(p.width) + uint32_t(x), 0u);
    }
    std::vector<SourceEntry> entries;
    for (auto& [cell, index] : entryOf) {
      index = uint32_t(entries.size());
      entries.push_back({cell, 0.0f});
    }
    std::vector<double> samples;  // (t, q) pairs
    std::vector<GpuTerm> termList;
    for (const auto& src : sourceList) {
      if (src.cells.empty()) continue;
      const auto first = uint32_t(samples.size() / 2);
      for (const auto& sample : src.dischargeM3S.samples()) samples.insert(samples.end(), {sample[0], sample[1]});
      const auto count = uint32_t(samples.size() / 2) - first;
      for (auto [x, y] : src.cells) {
        const uint32_t cell = uint32_t(y) * uint32_t(p.width) + uint32_t(x);
        termList.push_back({entryOf[cell], first, count, 0, double(src.cells.size()), grid.area(y)});
      }
    }
    // Each entry's shares in the sources' order (mergeSources adds them in that order).
    std::stable_sort(termList.begin(), termList.end(),
                     [](const GpuTerm& a, const GpuTerm& b) { return a.entry < b.entry; });
    auto put = [](gl::Buffer& buf, const void* data, size_t bytes) {
      if (buf.size() < std::max<size_t>(bytes, 16)) buf = gl::Buffer(std::max<size_t>(bytes, 16));
      if (bytes > 0) buf.upload(0, bytes, data);
    };
    put(sourceEntries, entries.data(), entries.size() * sizeof(SourceEntry));
    put(series, samples.data(), samples.size() * sizeof(double));
    put(terms, termList.data(), termList.size() * sizeof(GpuTerm));
    return {entries.size(), termList.size()};
  }

  // W26: the fixed levels at the end of the step (sim/shaders/level_boundary.comp).
  void levelPass(const std::vector<LevelEntry>& entries) {
    if (entries.empty()) return;
    const size_t bytes = entries.size() * sizeof(LevelEntry);
    if (levelEntries.size() < bytes) levelEntries = gl::Buffer(bytes);
    levelEntries.upload(0, bytes, entries.data());
    levelEntries.bind(slots::kLevels);
    pLevel.set("entryCount", unsigned(entries.size()));
    pLevel.dispatchCovering(int(entries.size()));
    barrier();
  }

  std::vector<float> readState() const {
    readBarrier();
    return cur().read<float>();
  }

  // The cells [x0, x0 + width) x [y0, y0 + height) of `buf` (`planes` planes of n cells, `perCell`
  // floats each) to or from the host, packed as CellBlock holds them, in one transfer: whole rows
  // of one plane directly, anything else through `packed` with copy_rect.comp (a halo strip is
  // thousands of rows; a transfer per row costs a driver round trip each).
  struct Rect {
    size_t perCell, planes;
    int x0, y0, width, height;
    size_t firstPlane = 0;  // of the buffer's planes
    size_t floats() const { return perCell * planes * size_t(width) * size_t(height); }
    bool wholeRows(int gridWidth) const { return planes == 1 && firstPlane == 0 && x0 == 0 && width == gridWidth; }
    size_t offset() const { return 4 * perCell * size_t(y0) * size_t(width); }  // bytes, whole rows
  };
  void copyRect(const gl::Buffer& buf, const Rect& r, bool scatter) {
    if (packed.size() < 4 * r.floats()) packed = gl::Buffer(4 * r.floats());
    buf.bind(slots::kCopyGrid);
    packed.bind(slots::kCopyPacked);
    pCopyRect.set("gridWidth", unsigned(p.width));
    pCopyRect.set("gridCells", unsigned(n));
    pCopyRect.set("x0", unsigned(r.x0));
    pCopyRect.set("y0", unsigned(r.y0));
    pCopyRect.set("width", unsigned(r.width));
    pCopyRect.set("height", unsigned(r.height));
    pCopyRect.set("perCell", unsigned(r.perCell));
    pCopyRect.set("planes", unsigned(r.planes));
    pCopyRect.set("firstPlane", unsigned(r.firstPlane));
    pCopyRect.set("scatter", scatter ? 1u : 0u);
    pCopyRect.dispatchCovering(int(r.perCell) * r.width, int(r.planes) * r.height);
  }
  void downloadRect(const gl::Buffer& buf, const Rect& r, float* out) {
    if (r.floats() == 0) return;
    if (r.wholeRows(p.width)) return buf.download(r.offset(), 4 * r.floats(), out);
    copyRect(buf, r, false);
    readBarrier();
    packed.download(0, 4 * r.floats(), out);
  }
  void uploadRect(gl::Buffer& buf, const Rect& r, const float* in) {
    if (r.floats() == 0) return;
    if (r.wholeRows(p.width)) return buf.upload(r.offset(), 4 * r.floats(), in);
    if (packed.size() < 4 * r.floats()) packed = gl::Buffer(4 * r.floats());
    packed.upload(0, 4 * r.floats(), in);
    copyRect(buf, r, true);
    barrier();
  }

  // The bed of a rectangle from base + layers (after its layers were written): bed_rect.comp.
  void recomputeBed(int x0, int y0, int width, int height) {
    bindAll();
    pBedRect.set("gridWidth", unsigned(p.width));
    pBedRect.set("gridCells", unsigned(n));
    pBedRect.set("layerCount", unsigned(layers));
    pBedRect.set("x0", unsigned(x0));
    pBedRect.set("y0", unsigned(y0));
    pBedRect.set("width", unsigned(width));
    pBedRect.set("height", unsigned(height));
    pBedRect.dispatchCovering(width, height);
    barrier();
  }
};

GlSolver::GlSolver(const SimInput& input, const SimParams& params, std::unique_ptr<Impl> impl)
    : Solver(input, params), impl_(std::move(impl)) {}
GlSolver::GlSolver(GlSolver&&) noexcept = default;
GlSolver& GlSolver::operator=(GlSolver&&) noexcept = default;
GlSolver::~GlSolver() = default;

Result<GlSolver> GlSolver::create(const SimInput& input, const SimParams& params) {
  STRATA_TRY_STATUS(validate(input, params));
  if (params.localStepLevels > 0) return fail(kLocalStepsOnTheCpuOnly);
  auto impl = std::make_unique<Impl>();
  Impl& s = *impl;
  const CellGrid grid = CellGrid::of(input);
  s.p = gpuParams(params, grid, 0.0f);
  const int w = grid.width, h = grid.height, L = grid.layers;
  s.n = grid.cells();
  s.layers = L;
  const size_t n = s.n;

  struct Kernel {
    gl::Program* program;
    const char* name;
  };
  for (auto [program, name] :
       {Kernel{&s.pSources, "sim/shaders/sources.comp"}, Kernel{&s.pPointSources, "sim/shaders/point_sources.comp"},
        Kernel{&s.pWaveSpeed, "sim/shaders/wave_speed.comp"}, Kernel{&s.pPipeFlux, "sim/shaders/pipe_flux.comp"},
        Kernel{&s.pPipeUpdate, "sim/shaders/pipe_update.comp"}, Kernel{&s.pFvFace, "sim/shaders/fv_face.comp"},
        Kernel{&s.pFvLimit, "sim/shaders/fv_limit.comp"}, Kernel{&s.pFvUpdate, "sim/shaders/fv_update.comp"},
        Kernel{&s.pInertialFace, "sim/shaders/inertial_face.comp"},
        Kernel{&s.pInertialLimit, "sim/shaders/inertial_limit.comp"},
        Kernel{&s.pInertialUpdate, "sim/shaders/inertial_update.comp"}, Kernel{&s.pErode, "sim/shaders/erode.comp"},
        Kernel{&s.pThermalFlux, "sim/shaders/thermal_flux.comp"},
        Kernel{&s.pThermalApply, "sim/shaders/thermal_apply.comp"},
        Kernel{&s.pFloodStats, "sim/shaders/flood_stats.comp"}, Kernel{&s.pLevel, "sim/shaders/level_boundary.comp"},
        Kernel{&s.pCopyRect, "sim/shaders/copy_rect.comp"}, Kernel{&s.pBedRect, "sim/shaders/bed_rect.comp"},
        Kernel{&s.pClock, "sim/shaders/step_clock.comp"}}) {
    auto prog = gl::Program::compute(name, slots::kernelDefines());
    if (!prog) return fail("sim: " + prog.message());
    *program = std::move(prog).value();
  }

  std::vector<GpuMaterial> mats;
  for (const auto& m : input.materials) mats.push_back(gpuMaterial(materialConstants(m)));
  std::vector<float> rowDxF;
  for (int y = 0; y < h; ++y) rowDxF.push_back(float(grid.rowDxM[size_t(y)]));
  std::vector<float> base(n), layers(n * size_t(L)), bed(n), state(4 * n, 0.0f);
  for (size_t i = 0; i < n; ++i) base[i] = float(double(input.baseM.data[i]) - input.datumM);
  for (int l = 0; l < L; ++l) {
    std::copy(input.layersM[size_t(l)].data.begin(), input.layersM[size_t(l)].data.end(),
              layers.begin() + ptrdiff_t(size_t(l) * n));
  }
  for (size_t i = 0; i < n; ++i) {
    float b = base[i];
    for (int l = 0; l < L; ++l) b += layers[size_t(l) * n + i];
    bed[i] = b;
    if (input.waterDepthM.size() > 0) state[4 * i] = input.waterDepthM.data[i];
  }
  const std::vector<float> rain =
      input.rainMmPerHour.size() > 0 ? input.rainMmPerHour.data : std::vector<float>(n, 0.0f);

  s.params = gl::Buffer(sizeof(GpuSimParams), &s.p);
  s.materials = gl::Buffer::from(std::span<const GpuMaterial>(mats));
  s.rowDx = gl::Buffer::from(std::span<const float>(rowDxF));
  s.base = gl::Buffer::from(std::span<const float>(base));
  s.bed = gl::Buffer::from(std::span<const float>(bed));
  s.layerBuf = gl::Buffer::from(std::span<const float>(layers));
  s.stateA = gl::Buffer::from(std::span<const float>(state));
  s.stateB = gl::Buffer::from(std::span<const float>(state));
  s.stage = gl::Buffer::from(std::span<const float>(state));
  s.flux = gl::Buffer(16 * n);
  s.flux.fill(0u);
  s.fluxDiag = gl::Buffer(params.diagonalPipes ? 16 * n : 16);
  s.fluxDiag.fill(0u);
  const bool flood = params.waterModel == WaterModel::kFiniteVolume;
  s.faceX = gl::Buffer(flood ? 16 * size_t(w + 1) * size_t(h) : 16);
  s.faceX.fill(0u);
  s.faceY = gl::Buffer(flood ? 16 * size_t(w) * size_t(h + 1) : 16);
  s.faceY.fill(0u);
  s.fvLimit = gl::Buffer(flood ? 4 * n : 16);
  s.fvLimit.fill(0u);
  s.tilt = gl::Buffer(4 * n);
  s.tilt.fill(0u);
  s.accum = gl::Buffer(sizeof(float) * kAccumPlanes * n);
  s.accum.fill(0u);
  s.rain = gl::Buffer::from(std::span<const float>(rain));
  s.rasterRain = std::any_of(rain.begin(), rain.end(), [](float r) { return r != 0.0f; });
  s.infiltrates = input.infiltrationMmPerHour.size() > 0;
  // n^2 per cell of a roughness map; -1 (the uniform P.manningN, which setParams may change) without.
  std::vector<float> manningN2(n, -1.0f);
  for (size_t i = 0; i < input.manningN.size(); ++i) manningN2[i] = input.manningN.data[i] * input.manningN.data[i];
  s.manning = gl::Buffer::from(std::span<const float>(manningN2));
  // W11b: (Ks m/s, psi * dtheta m) per cell; one (0, 0), which every cell reads, without.
  std::vector<float> infiltration(input.infiltrationMmPerHour.size() > 0 ? 2 * n : 2, 0.0f);
  for (size_t i = 0; i < input.infiltrationMmPerHour.size(); ++i) {
    infiltration[2 * i] = input.infiltrationMmPerHour.data[i] * (1.0f / 3.6e6f);  // as the CPU backend
    if (input.infiltrationSuctionM.size() > 0) infiltration[2 * i + 1] = input.infiltrationSuctionM.data[i];
  }
  s.infiltration = gl::Buffer::from(std::span<const float>(infiltration));
  s.thermal = gl::Buffer(16 * n);
  s.thermal.fill(0u);
  s.scour = gl::Buffer(4 * n);
  s.scour.fill(0u);
  s.sourceEntries = gl::Buffer(sizeof(SourceEntry) * 16);
  s.maxSpeed = gl::Buffer(4);
  s.maxSpeedHost = gl::Buffer(4, nullptr, gl::BufferStorage::kReadback);
  s.floodStats = gl::Buffer(16 * n);
  s.clock = gl::Buffer(sizeof(GpuClock));
  s.clock.fill(0u);
  s.series = gl::Buffer(16);
  s.terms = gl::Buffer(sizeof(GpuTerm));

  GlSolver solver(input, params, std::move(impl));
  solver.recordInitialTotals();
  return solver;
}

std::string GlSolver::backendName() const {
  const std::string renderer = gl::queryContextInfo().renderer;
  return "GL on " + (renderer.empty() ? std::string("an unknown device") : renderer);
}

void GlSolver::runStep(const StepInputs& step) { impl_->takeStep(step, !levels().empty(), floodThresholdM()); }

std::optional<Solver::DeviceRun> GlSolver::runOnDevice(const DeviceRequest& request) {
  // W26's fixed levels at each step's end are the host's (levelEntries): those runs step from it.
  if (!levels().empty()) return std::nullopt;
  return impl_->deviceRun(request, sources(), params(), grid(), floodThresholdM());
}

Status GlSolver::onRainRasterChanged(const gis::Grid<float>& mmPerHour) {
  Impl& s = *impl_;
  if (mmPerHour.size() > 0) {
    s.rain.upload(0, s.rain.size(), mmPerHour.data.data());
  } else {
    s.rain.fill(0u);
  }
  s.rasterRain = std::any_of(mmPerHour.data.begin(), mmPerHour.data.end(), [](float r) { return r != 0.0f; });
  return {};
}

void GlSolver::onParamsChanged() {
  Impl& s = *impl_;
  s.p = gpuParams(params(), grid(), s.p.dtS);
  s.params.upload(0, sizeof(GpuSimParams), &s.p);
  // No erosion, no toe scour (E8): what the last erosion pass left must not bring banks down.
  if (!params().erosionEnabled) s.scour.fill(0u);
}

double GlSolver::maxWaveSpeedMS() const { return impl_->maxWaveSpeed(); }

const gl::Buffer& GlSolver::stateBuffer() const { return impl_->cur(); }

gis::Grid<float> GlSolver::readBed() const {
  readBarrier();
  gis::Grid<float> g(grid().width, grid().height);
  g.data = impl_->bed.read<float>();
  return g;
}

size_t GlSolver::gpuBytes() const {
  const Impl& s = *impl_;
  size_t total = 0;
  for (const gl::Buffer* b :
       {&s.params,   &s.materials,  &s.rowDx,   &s.base,         &s.bed,     &s.layerBuf, &s.stateA,
        &s.stateB,   &s.stage,      &s.flux,    &s.fluxDiag,     &s.faceX,   &s.faceY,    &s.tilt,
        &s.accum,    &s.rain,       &s.manning, &s.infiltration, &s.thermal, &s.scour,    &s.sourceEntries,
        &s.maxSpeed, &s.floodStats, &s.fvLimit, &s.clock,        &s.series,  &s.terms}) {
    total += b->size();
  }
  return total;
}

// The buffer of each part of a CellBlock, in CellBlock::forEachPart's order (the diagonal pipes'
// only with them; the carried accumulators are the last planes of the accumulators' buffer).
namespace {
template <class Impl>
std::array<gl::Buffer*, 6> partBuffers(Impl& s, bool diag) {
  return {&s.curMut(), &s.flux, diag ? &s.fluxDiag : nullptr, &s.layerBuf, &s.accum, &s.accum};
}

// `per` accumulators of `cells` cells between the GPU's plane-major order (sim_accum.glsl) and
// CellBlock's cell-major one: toCells from planes to cells, else back.
void transposeAccum(const std::vector<float>& from, std::vector<float>& to, size_t cells, size_t per, bool toCells) {
  for (size_t c = 0; c < cells; ++c) {
    for (size_t k = 0; k < per; ++k) {
      const size_t planar = k * cells + c, cellMajor = c * per + k;
      to[toCells ? cellMajor : planar] = from[toCells ? planar : cellMajor];
    }
  }
}
// The accumulator planes a part holds: all of them, or the carried ones (kBlockCarried).
size_t firstAccumPlane(unsigned bit) { return bit == kBlockCarried ? size_t(kAccumCarriedFrom) : 0; }
}  // namespace

CellBlock GlSolver::readBlock(int x0, int y0, int width, int height, unsigned parts) const {
  const int w = grid().width, L = grid().layers;
  CellBlock b{.rect = {x0, y0, width, height}};
  STRATA_CHECK(blockFits(b, w, grid().height, L))
      << "readBlock (" << x0 << ", " << y0 << ") " << width << "x" << height << " outside the grid";
  Impl& s = *impl_;
  readBarrier();
  // One transfer per part (whole rows, or packed on the GPU first).
  const auto buffers = partBuffers(s, params().diagonalPipes);
  size_t k = 0;
  CellBlock::forEachPart(b, L, [&](unsigned bit, std::vector<float>& out, size_t per, size_t planes) {
    gl::Buffer* buf = buffers[k++];
    if (!(parts & bit) || !buf) return;
    out.resize(per * planes * b.cells());
    if (buf == &s.accum) {  // plane-major on the GPU (sim_accum.glsl), cell-major in the block
      std::vector<float> planar(out.size());
      s.downloadRect(*buf, Impl::Rect{1, per, x0, y0, width, height, firstAccumPlane(bit)}, planar.data());
      transposeAccum(planar, out, b.cells(), per, true);
      return;
    }
    s.downloadRect(*buf, Impl::Rect{per, planes, x0, y0, width, height}, out.data());
  });
  return b;
}

void GlSolver::writeBlock(const CellBlock& b) {
  const int w = grid().width, L = grid().layers;
  STRATA_CHECK(blockFits(b, w, grid().height, L)) << "writeBlock: sizes do not match the block or the grid";
  Impl& s = *impl_;
  readBarrier();
  const auto buffers = partBuffers(s, params().diagonalPipes);
  const gis::CellRect& r = b.rect;
  size_t k = 0;
  CellBlock::forEachPart(b, L, [&](unsigned bit, const std::vector<float>& in, size_t per, size_t planes) {
    gl::Buffer* buf = buffers[k++];
    if (in.empty() || !buf) return;
    if (buf == &s.accum) {  // cell-major in the block, plane-major on the GPU
      std::vector<float> planar(in.size());
      transposeAccum(in, planar, b.cells(), per, false);
      s.uploadRect(*buf, Impl::Rect{1, per, r.x, r.y, r.width, r.height, firstAccumPlane(bit)}, planar.data());
      return;
    }
    s.uploadRect(*buf, Impl::Rect{per, planes, r.x, r.y, r.width, r.height}, in.data());
  });
  if (!b.layers.empty()) s.recomputeBed(r.x, r.y, r.width, r.height);
}

SolverFactory glSolverFactory() {
  return [](const SimInput& input, const SimParams& params) -> Result<std::unique_ptr<Solver>> {
    STRATA_TRY(auto s, GlSolver::create(input, params));
    return std::unique_ptr<Solver>(std::make_unique<GlSolver>(std::move(s)));
  };
}

void GlSolver::resetFloodStats() {
  const auto init = initialFloodStatsCells(impl_->n);
  impl_->floodStats.upload(0, init.size() * 4, init.data());
}

std::vector<float> GlSolver::floodStatsCells() const {
  readBarrier();
  return impl_->floodStats.read<float>();
}

void GlSolver::setFloodStatsCells(const std::vector<float>& cells) {
  STRATA_CHECK(cells.size() == 4 * impl_->n) << "flood statistics of " << cells.size() / 4 << " cells";
  impl_->floodStats.upload(0, cells.size() * 4, cells.data());
}

std::vector<float> GlSolver::readFaceMassFlux() const {
  const Impl& s = *impl_;
  STRATA_CHECK(params().waterModel == WaterModel::kFiniteVolume) << "face fluxes exist in flood mode only";
  readBarrier();
  const auto fx = s.faceX.read<float>(), fy = s.faceY.read<float>();
  // The finite-volume scheme's faces are vec4s (the mass flux first); the local-inertial
  // scheme's one float each (W36).
  const size_t stride = params().floodScheme == FloodScheme::kLocalInertial ? 1 : 4;
  const auto limit = s.fvLimit.read<float>();
  const int w = grid().width, h = grid().height;
  // The flux the last corrector applied: scaled by its upwind cell's W25 limit (fv_update.comp).
  auto limited = [&](float f, int upX, int upY) {
    const bool inside = upX >= 0 && upY >= 0 && upX < w && upY < h;
    return inside ? f * limit[size_t(upY) * size_t(w) + size_t(upX)] : f;
  };
  std::vector<float> out;
  out.reserve(size_t(w + 1) * size_t(h) + size_t(w) * size_t(h + 1));
  for (int y = 0; y < h; ++y) {
    for (int x = 0; x <= w; ++x) {
      const float f = fx[stride * (size_t(y) * size_t(w + 1) + size_t(x))];
      out.push_back(f > 0 ? limited(f, x - 1, y) : limited(f, x, y));
    }
  }
  for (int y = 0; y <= h; ++y) {
    for (int x = 0; x < w; ++x) {
      const float f = fy[stride * (size_t(y) * size_t(w) + size_t(x))];
      out.push_back(f > 0 ? limited(f, x, y - 1) : limited(f, x, y));
    }
  }
  return out;
}

}  // namespace strata::sim
