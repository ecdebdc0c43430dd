// Host side of the GPU simulation: owns the buffers, binds them at the slots declared in
// shaders/common/sim.glsl, and dispatches the passes in the order CpuSimulation::takeStep runs
// them, with a shader-storage barrier between passes.
#include <strata/render/sim/simulation.hpp>

#include <epoxy/gl.h>

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstring>
#include <numeric>
#include <string>

#include <strata/render/gl/objects.hpp>
#include <strata/terrain/sim/sim_host.hpp>

namespace strata::render::sim {

namespace ts = strata::terrain::sim;

namespace {
// Binding slots (shaders/common/sim.glsl and the kernels).
enum Slot : GLuint {
  kParams = 0,
  kMaterials = 1,
  kRowDx = 2,
  kBase = 3,
  kBed = 4,
  kLayers = 5,
  kStateIn = 6,
  kStateOut = 7,
  kStage = 8,
  kFlux = 9,
  kFaceX = 10,
  kFaceY = 11,
  kTilt = 12,
  kAccum = 13,
  kRain = 14,
  kThermal = 15,
  kSources = 16,
  kMaxSpeed = 17,
  kFluxDiag = 18,
  kFloodStats = 19,
  kFvLimit = 20,
};
constexpr size_t kParamsDtOffset = offsetof(ts::SimParams, dtS);

void barrier() { glMemoryBarrier(GL_SHADER_STORAGE_BARRIER_BIT); }
}  // namespace

struct Simulation::Impl {
  ts::SimParams p{};
  double datumM = 0, minCell = 1, timeS = 0, lastDt = 0, rainM3 = 0, inflowM3 = 0, rainRateM3S = 0, maxRainMmH = 0;
  double initialWater = 0, initialMaterial = 0;
  long long steps = 0;
  std::vector<double> rowDxD;
  std::vector<ts::Source> sources;
  std::vector<ts::LevelBoundary> levels;
  std::vector<float> rainRaster;  // host copy, for the rain volume rate after setParams
  size_t n = 0;

  gl::Buffer params, materials, rowDx, base, bed, layers, stateA, stateB, stage, flux, fluxDiag, faceX, faceY, tilt,
      accum, rain, thermal, sourceEntries, maxSpeed, floodStats, fvLimit, levelEntries;
  float wetThresholdM = -1;  // < 0: flood statistics off
  bool aIsCurrent = true;
  gl::Program pSources, pPointSources, pWaveSpeed, pPipeFlux, pPipeUpdate, pFvFace, pFvLimit, pFvUpdate, pErode,
      pThermalFlux, pThermalApply, pFloodStats, pLevel;

  const gl::Buffer& cur() const { return aIsCurrent ? stateA : stateB; }
  const gl::Buffer& next() const { return aIsCurrent ? stateB : stateA; }

  void bindAll() const {
    params.bindBase(GL_SHADER_STORAGE_BUFFER, kParams);
    materials.bindBase(GL_SHADER_STORAGE_BUFFER, kMaterials);
    rowDx.bindBase(GL_SHADER_STORAGE_BUFFER, kRowDx);
    base.bindBase(GL_SHADER_STORAGE_BUFFER, kBase);
    bed.bindBase(GL_SHADER_STORAGE_BUFFER, kBed);
    layers.bindBase(GL_SHADER_STORAGE_BUFFER, kLayers);
    cur().bindBase(GL_SHADER_STORAGE_BUFFER, kStateIn);
    next().bindBase(GL_SHADER_STORAGE_BUFFER, kStateOut);
    stage.bindBase(GL_SHADER_STORAGE_BUFFER, kStage);
    flux.bindBase(GL_SHADER_STORAGE_BUFFER, kFlux);
    fluxDiag.bindBase(GL_SHADER_STORAGE_BUFFER, kFluxDiag);
    faceX.bindBase(GL_SHADER_STORAGE_BUFFER, kFaceX);
    faceY.bindBase(GL_SHADER_STORAGE_BUFFER, kFaceY);
    tilt.bindBase(GL_SHADER_STORAGE_BUFFER, kTilt);
    accum.bindBase(GL_SHADER_STORAGE_BUFFER, kAccum);
    rain.bindBase(GL_SHADER_STORAGE_BUFFER, kRain);
    thermal.bindBase(GL_SHADER_STORAGE_BUFFER, kThermal);
    sourceEntries.bindBase(GL_SHADER_STORAGE_BUFFER, kSources);
    maxSpeed.bindBase(GL_SHADER_STORAGE_BUFFER, kMaxSpeed);
    fvLimit.bindBase(GL_SHADER_STORAGE_BUFFER, kFvLimit);
  }

  // W10 with the step's sources (terrain::sim::stepDtWithSources).
  double nextDt() {
    if (p.cflAlpha <= 0) return p.maxDtS;  // no read-back
    return ts::stepDtWithSources(p, maxWaveSpeed(), minCell, maxRainMmH, sources, rowDxD, double(p.dyM), timeS);
  }

  double maxWaveSpeed() {
    if (p.cflAlpha <= 0) return 0.0;  // stepDt ignores it: no read-back
    maxSpeed.fill(0u);
    bindAll();
    pWaveSpeed.dispatchCovering(int(n));
    glMemoryBarrier(GL_BUFFER_UPDATE_BARRIER_BIT);
    uint32_t bits = 0;
    maxSpeed.download(0, 4, &bits);
    float v;
    std::memcpy(&v, &bits, 4);
    return double(v);
  }

  void takeStep(double dtS) {
    const int w = p.width, h = p.height;
    if (float(dtS) != p.dtS) {
      p.dtS = float(dtS);
      params.upload(kParamsDtOffset, sizeof(float), &p.dtS);
    }
    const auto entries = ts::mergeSources(sources, w, timeS, timeS + double(float(dtS)));
    for (const auto& e : entries) inflowM3 += double(e.rateM3S) * double(p.dtS);
    rainM3 += rainRateM3S * double(p.dtS);
    bindAll();
    pSources.dispatchCovering(w, h);
    barrier();
    if (!entries.empty()) {
      const size_t bytes = entries.size() * sizeof(ts::SourceEntry);
      if (sourceEntries.size() < bytes) {
        sourceEntries = gl::Buffer(bytes);
        sourceEntries.bindBase(GL_SHADER_STORAGE_BUFFER, kSources);
      }
      sourceEntries.upload(0, bytes, entries.data());
      pPointSources.set("entryCount", unsigned(entries.size()));
      pPointSources.dispatchCovering(int(entries.size()));
      barrier();
    }
    if (p.waterModel == int32_t(ts::WaterModel::kVirtualPipes)) {
      pPipeFlux.dispatchCovering(w, h);
      barrier();
      pPipeUpdate.dispatchCovering(w, h);
      barrier();
    } else {
      pFvFace.set("average", 0);
      pFvFace.dispatchCovering(w, h);
      barrier();
      pFvUpdate.set("final_", 0);
      pFvUpdate.dispatchCovering(w, h);
      barrier();
      stage.bindBase(GL_SHADER_STORAGE_BUFFER, kStateIn);  // the corrector's faces come from U1
      pFvFace.set("average", 1);
      pFvFace.dispatchCovering(w, h);
      barrier();
      cur().bindBase(GL_SHADER_STORAGE_BUFFER, kStateIn);
      pFvLimit.dispatchCovering(w, h);
      barrier();
      pFvUpdate.set("final_", 1);
      pFvUpdate.dispatchCovering(w, h);
      barrier();
    }
    aIsCurrent = !aIsCurrent;
    cur().bindBase(GL_SHADER_STORAGE_BUFFER, kStateIn);
    next().bindBase(GL_SHADER_STORAGE_BUFFER, kStateOut);
    if (!levels.empty()) levelPass();
    if (p.erosionEnabled) {
      pErode.dispatchCovering(w, h);
      barrier();
    }
    if (p.thermalEnabled) {
      pThermalFlux.dispatchCovering(w, h);
      barrier();
      pThermalApply.dispatchCovering(w, h);
      barrier();
    }
    timeS += double(p.dtS);
    lastDt = double(p.dtS);
    ++steps;
    if (wetThresholdM >= 0) {
      cur().bindBase(GL_SHADER_STORAGE_BUFFER, kStateIn);
      floodStats.bindBase(GL_SHADER_STORAGE_BUFFER, kFloodStats);
      pFloodStats.set("timeS", float(timeS));
      pFloodStats.set("wetThresholdM", wetThresholdM);
      pFloodStats.dispatchCovering(int(n));
      barrier();
    }
  }

  // W26: the fixed levels at the end of the step (shaders/sim/level_boundary.comp).
  void levelPass() {
    const auto entries = ts::levelEntries(levels, p.width, timeS + double(p.dtS), datumM);
    if (entries.empty()) return;
    const size_t bytes = entries.size() * sizeof(ts::LevelEntry);
    if (levelEntries.size() < bytes) levelEntries = gl::Buffer(bytes);
    levelEntries.upload(0, bytes, entries.data());
    levelEntries.bindBase(GL_SHADER_STORAGE_BUFFER, kSources);
    pLevel.set("entryCount", unsigned(entries.size()));
    pLevel.dispatchCovering(int(entries.size()));
    barrier();
    sourceEntries.bindBase(GL_SHADER_STORAGE_BUFFER, kSources);
  }

  std::vector<float> readState() const {
    glMemoryBarrier(GL_BUFFER_UPDATE_BARRIER_BIT);
    return cur().read<float>();
  }
};

Result<Simulation> Simulation::create(const SimInput& input, const SimParams& params) {
  STRATA_TRY_STATUS(ts::validate(input, params));
  auto impl = std::make_unique<Impl>();
  Impl& s = *impl;
  s.p = params;
  const int w = input.baseM.width, h = input.baseM.height, L = int(input.layersM.size());
  s.p.width = w;
  s.p.height = h;
  s.p.layerCount = L;
  s.p.dyM = float(input.dyM);
  s.p.dtS = 0.0f;
  s.datumM = input.datumM;
  s.n = size_t(w) * size_t(h);
  const size_t n = s.n;

  struct Kernel {
    gl::Program* program;
    const char* name;
  };
  for (auto [program, name] :
       {Kernel{&s.pSources, "sim/sources.comp"}, Kernel{&s.pPointSources, "sim/point_sources.comp"},
        Kernel{&s.pWaveSpeed, "sim/wave_speed.comp"}, Kernel{&s.pPipeFlux, "sim/pipe_flux.comp"},
        Kernel{&s.pPipeUpdate, "sim/pipe_update.comp"}, Kernel{&s.pFvFace, "sim/fv_face.comp"},
        Kernel{&s.pFvLimit, "sim/fv_limit.comp"}, Kernel{&s.pFvUpdate, "sim/fv_update.comp"},
        Kernel{&s.pErode, "sim/erode.comp"}, Kernel{&s.pThermalFlux, "sim/thermal_flux.comp"},
        Kernel{&s.pThermalApply, "sim/thermal_apply.comp"}, Kernel{&s.pFloodStats, "sim/flood_stats.comp"},
        Kernel{&s.pLevel, "sim/level_boundary.comp"}}) {
    auto prog = gl::Program::compute(name);
    if (!prog) return fail("sim: " + prog.message());
    *program = std::move(prog).value();
  }

  std::vector<ts::SimMaterial> mats;
  for (const auto& m : input.materials) mats.push_back(ts::toSimMaterial(m));
  std::vector<float> rowDxF;
  for (int y = 0; y < h; ++y) {
    s.rowDxD.push_back(ts::rowDx(input, y));
    rowDxF.push_back(float(s.rowDxD.back()));
  }
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
  s.rainRateM3S = ts::rainVolumeRate(s.p, rain, s.rowDxD, w);
  s.rainRaster = rain;
  s.maxRainMmH = double(*std::max_element(rain.begin(), rain.end()));
  s.minCell = ts::minCellSize(s.rowDxD, input.dyM);

  const GLbitfield dyn = GL_DYNAMIC_STORAGE_BIT;
  s.params = gl::Buffer(sizeof(ts::SimParams), &s.p, dyn);
  s.materials = gl::Buffer::from(std::span<const ts::SimMaterial>(mats));
  s.rowDx = gl::Buffer::from(std::span<const float>(rowDxF));
  s.base = gl::Buffer::from(std::span<const float>(base));
  s.bed = gl::Buffer::from(std::span<const float>(bed));
  s.layers = gl::Buffer::from(std::span<const float>(layers));
  s.stateA = gl::Buffer::from(std::span<const float>(state));
  s.stateB = gl::Buffer::from(std::span<const float>(state));
  s.stage = gl::Buffer::from(std::span<const float>(state));
  s.flux = gl::Buffer(16 * n);
  s.flux.fill(0u);
  s.fluxDiag = gl::Buffer(s.p.diagonalPipes ? 16 * n : 16);
  s.fluxDiag.fill(0u);
  const bool flood = s.p.waterModel == int32_t(ts::WaterModel::kFiniteVolume);
  s.faceX = gl::Buffer(flood ? 16 * size_t(w + 1) * size_t(h) : 16);
  s.faceX.fill(0u);
  s.faceY = gl::Buffer(flood ? 16 * size_t(w) * size_t(h + 1) : 16);
  s.faceY.fill(0u);
  s.fvLimit = gl::Buffer(flood ? 4 * n : 16);
  s.fvLimit.fill(0u);
  s.tilt = gl::Buffer(4 * n);
  s.tilt.fill(0u);
  s.accum = gl::Buffer(32 * n);
  s.accum.fill(0u);
  s.rain = gl::Buffer::from(std::span<const float>(rain));
  s.thermal = gl::Buffer(16 * n);
  s.thermal.fill(0u);
  s.sourceEntries = gl::Buffer(sizeof(ts::SourceEntry) * 16);
  s.maxSpeed = gl::Buffer(4);
  s.floodStats = gl::Buffer(16 * n);

  Simulation sim(std::move(impl));
  const auto st = sim.stats();
  sim.impl_->initialWater = st.storedWaterM3;
  sim.impl_->initialMaterial = st.materialM3;
  return sim;
}

Simulation::Simulation(std::unique_ptr<Impl> impl) : impl_(std::move(impl)) {}
Simulation::Simulation(Simulation&&) noexcept = default;
Simulation& Simulation::operator=(Simulation&&) noexcept = default;
Simulation::~Simulation() = default;

Status Simulation::addSource(const Source& source) {
  const auto& p = impl_->p;
  for (auto [x, y] : source.cells) {
    if (x < 0 || y < 0 || x >= p.width || y >= p.height) {
      return fail("sim source: cell (" + std::to_string(x) + ", " + std::to_string(y) + ") is outside the " +
                  std::to_string(p.width) + "x" + std::to_string(p.height) + " grid");
    }
  }
  for (size_t i = 1; i < source.hydrographM3S.size(); ++i) {
    if (!(source.hydrographM3S[i].first > source.hydrographM3S[i - 1].first)) {
      return fail("sim source: hydrograph times must increase (sample " + std::to_string(i) + ")");
    }
  }
  impl_->sources.push_back(source);
  return {};
}

Status Simulation::addLevel(const LevelBoundary& level) {
  STRATA_TRY_STATUS(ts::checkLevel(level, impl_->p.width, impl_->p.height));
  impl_->levels.push_back(level);
  return {};
}

Status Simulation::setParams(const SimParams& params) {
  Impl& s = *impl_;
  const SimParams next = ts::runtimeParams(s.p, params);
  STRATA_TRY_STATUS(ts::validateParams(next));
  s.p = next;
  s.params.upload(0, sizeof(ts::SimParams), &s.p);
  s.rainRateM3S = ts::rainVolumeRate(s.p, s.rainRaster, s.rowDxD, s.p.width);
  return {};
}

void Simulation::step(int n) {
  for (int k = 0; k < n; ++k) impl_->takeStep(impl_->nextDt());
}

void Simulation::advance(double seconds) {
  Impl& s = *impl_;
  const double end = s.timeS + seconds;
  while (s.timeS < end - 1e-9 * std::max(1.0, end)) {
    s.takeStep(std::min(s.nextDt(), end - s.timeS));
  }
}

gis::Grid<float> Simulation::readWaterDepth() const {
  const auto st = impl_->readState();
  gis::Grid<float> g(impl_->p.width, impl_->p.height);
  for (size_t i = 0; i < g.size(); ++i) g.data[i] = st[4 * i];
  return g;
}

VelocityField Simulation::readVelocity() const {
  const auto st = impl_->readState();
  const float dry = impl_->p.dryDepthM;
  VelocityField v{gis::Grid<float>(impl_->p.width, impl_->p.height), gis::Grid<float>(impl_->p.width, impl_->p.height)};
  for (size_t i = 0; i < v.uMS.size(); ++i) {
    const float h = st[4 * i];
    v.uMS.data[i] = h > dry ? st[4 * i + 2] / h : 0.0f;
    v.vMS.data[i] = h > dry ? st[4 * i + 3] / h : 0.0f;
  }
  return v;
}

std::vector<gis::Grid<float>> Simulation::readLayers() const {
  glMemoryBarrier(GL_BUFFER_UPDATE_BARRIER_BIT);
  const auto all = impl_->layers.read<float>();
  const size_t n = impl_->n;
  std::vector<gis::Grid<float>> out;
  for (int l = 0; l < impl_->p.layerCount; ++l) {
    gis::Grid<float> g(impl_->p.width, impl_->p.height);
    std::copy(all.begin() + ptrdiff_t(size_t(l) * n), all.begin() + ptrdiff_t(size_t(l + 1) * n), g.data.begin());
    out.push_back(std::move(g));
  }
  return out;
}

const gl::Buffer& Simulation::stateBuffer() const { return impl_->cur(); }

gis::Grid<float> Simulation::readSuspended() const {
  const auto st = impl_->readState();
  gis::Grid<float> g(impl_->p.width, impl_->p.height);
  for (size_t i = 0; i < g.size(); ++i) g.data[i] = st[4 * i + 1];
  return g;
}

gis::Grid<float> Simulation::readBed() const {
  glMemoryBarrier(GL_BUFFER_UPDATE_BARRIER_BIT);
  gis::Grid<float> g(impl_->p.width, impl_->p.height);
  g.data = impl_->bed.read<float>();
  return g;
}

double Simulation::datumM() const { return impl_->datumM; }
const SimParams& Simulation::params() const { return impl_->p; }

size_t Simulation::gpuBytes() const {
  const Impl& s = *impl_;
  size_t total = 0;
  for (const gl::Buffer* b :
       {&s.params, &s.materials, &s.rowDx,   &s.base,          &s.bed,      &s.layers,    &s.stateA,
        &s.stateB, &s.stage,     &s.flux,    &s.fluxDiag,      &s.faceX,    &s.faceY,     &s.tilt,
        &s.accum,  &s.rain,      &s.thermal, &s.sourceEntries, &s.maxSpeed, &s.floodStats}) {
    total += b->size();
  }
  return total;
}

Simulation::RawState Simulation::readRaw() const {
  const Impl& s = *impl_;
  glMemoryBarrier(GL_BUFFER_UPDATE_BARRIER_BIT);
  return {s.cur().read<float>(), s.flux.read<float>(), s.fluxDiag.read<float>(), s.layers.read<float>(),
          s.accum.read<float>()};
}

void Simulation::writeRaw(const RawState& raw) {
  Impl& s = *impl_;
  STRATA_CHECK(raw.state.size() == 4 * s.n && raw.flux.size() == 4 * s.n &&
               raw.layers.size() == size_t(s.p.layerCount) * s.n)
      << "writeRaw: sizes do not match the grid";
  glMemoryBarrier(GL_BUFFER_UPDATE_BARRIER_BIT);
  (s.aIsCurrent ? s.stateA : s.stateB).upload(0, raw.state.size() * 4, raw.state.data());
  s.flux.upload(0, raw.flux.size() * 4, raw.flux.data());
  s.fluxDiag.upload(0, raw.fluxDiag.size() * 4, raw.fluxDiag.data());
  s.layers.upload(0, raw.layers.size() * 4, raw.layers.data());
  const auto base = s.base.read<float>();
  std::vector<float> bed(s.n);
  for (size_t i = 0; i < s.n; ++i) {
    float b = base[i];
    for (int l = 0; l < s.p.layerCount; ++l) b += raw.layers[size_t(l) * s.n + i];
    bed[i] = b;
  }
  s.bed.upload(0, bed.size() * 4, bed.data());
}

namespace {
// Flood statistics start as: no depth, no speed, never arrived, never wet.
std::vector<float> initialFloodStats(size_t n) {
  std::vector<float> v(4 * n, 0.0f);
  for (size_t i = 0; i < n; ++i) v[4 * i + 2] = -1.0f;
  return v;
}
}  // namespace

void Simulation::enableFloodStats(float wetThresholdM) {
  STRATA_CHECK(wetThresholdM >= 0) << "wet threshold " << wetThresholdM;
  impl_->wetThresholdM = wetThresholdM;
  const auto init = initialFloodStats(impl_->n);
  impl_->floodStats.upload(0, init.size() * 4, init.data());
}

FloodStats Simulation::readFloodStats() const {
  const Impl& s = *impl_;
  glMemoryBarrier(GL_BUFFER_UPDATE_BARRIER_BIT);
  const auto v = s.wetThresholdM >= 0 ? s.floodStats.read<float>() : initialFloodStats(s.n);
  FloodStats f;
  gis::Grid<float>* grids[4] = {&f.maxDepthM, &f.maxSpeedMS, &f.arrivalS, &f.wetDurationS};
  for (int k = 0; k < 4; ++k) {
    *grids[k] = gis::Grid<float>(s.p.width, s.p.height);
    for (size_t i = 0; i < s.n; ++i) grids[k]->data[i] = v[4 * i + size_t(k)];
  }
  return f;
}

Simulation::Snapshot Simulation::snapshot() const {
  const Impl& s = *impl_;
  Snapshot snap;
  snap.counters = {s.timeS, s.lastDt, s.rainM3, s.inflowM3, s.initialWater, s.initialMaterial, s.steps, s.p.dtS};
  snap.raw = readRaw();
  snap.flood = readFloodStats();
  return snap;
}

Status Simulation::restore(const Snapshot& snap) {
  Impl& s = *impl_;
  const size_t n = s.n;
  if (snap.raw.state.size() != 4 * n || snap.raw.flux.size() != 4 * n ||
      snap.raw.layers.size() != size_t(s.p.layerCount) * n || snap.raw.accum.size() != 8 * n ||
      snap.flood.maxDepthM.size() != n) {
    return fail("sim: the snapshot is of a different grid (" + std::to_string(snap.raw.state.size() / 4) +
                " cells, this simulation has " + std::to_string(n) + ")");
  }
  writeRaw(snap.raw);
  s.accum.upload(0, snap.raw.accum.size() * 4, snap.raw.accum.data());
  std::vector<float> f(4 * n);
  for (size_t i = 0; i < n; ++i) {
    f[4 * i] = snap.flood.maxDepthM.data[i];
    f[4 * i + 1] = snap.flood.maxSpeedMS.data[i];
    f[4 * i + 2] = snap.flood.arrivalS.data[i];
    f[4 * i + 3] = snap.flood.wetDurationS.data[i];
  }
  s.floodStats.upload(0, f.size() * 4, f.data());
  const auto& c = snap.counters;
  s.timeS = c.timeS;
  s.lastDt = c.lastDtS;
  s.rainM3 = c.rainM3;
  s.inflowM3 = c.inflowM3;
  s.initialWater = c.initialWaterM3;
  s.initialMaterial = c.initialMaterialM3;
  s.steps = c.steps;
  s.p.dtS = c.dtS;
  s.params.upload(kParamsDtOffset, sizeof(float), &s.p.dtS);
  return {};
}

double Simulation::maxWaveSpeedMS() {
  const float alpha = impl_->p.cflAlpha;
  impl_->p.cflAlpha = 1.0f;  // force the reduction even for a fixed-step run
  const double v = impl_->maxWaveSpeed();
  impl_->p.cflAlpha = alpha;
  return v;
}

void Simulation::stepWithDt(double dtS) { impl_->takeStep(dtS); }

std::vector<float> Simulation::readStateRaw() const { return impl_->readState(); }

void Simulation::writeStateRaw(const std::vector<float>& state) {
  Impl& s = *impl_;
  STRATA_CHECK(state.size() == 4 * s.n) << "writeStateRaw: " << state.size() / 4 << " cells, grid has " << s.n;
  glMemoryBarrier(GL_BUFFER_UPDATE_BARRIER_BIT);
  (s.aIsCurrent ? s.stateA : s.stateB).upload(0, state.size() * 4, state.data());
}

std::vector<float> Simulation::readFaceMassFlux() const {
  const Impl& s = *impl_;
  STRATA_CHECK(s.p.waterModel == int32_t(ts::WaterModel::kFiniteVolume)) << "face fluxes exist in flood mode only";
  glMemoryBarrier(GL_BUFFER_UPDATE_BARRIER_BIT);
  const auto fx = s.faceX.read<float>(), fy = s.faceY.read<float>();
  const auto limit = s.fvLimit.read<float>();
  const int w = s.p.width, h = s.p.height;
  // The flux the last corrector applied: scaled by its upwind cell's W25 limit (fv_update.comp).
  auto limited = [&](float f, int upX, int upY) {
    const bool inside = upX >= 0 && upY >= 0 && upX < w && upY < h;
    return inside ? f * limit[size_t(upY) * size_t(w) + size_t(upX)] : f;
  };
  std::vector<float> out;
  out.reserve(fx.size() / 4 + fy.size() / 4);
  for (int y = 0; y < h; ++y) {
    for (int x = 0; x <= w; ++x) {
      const float f = fx[4 * (size_t(y) * size_t(w + 1) + size_t(x))];
      out.push_back(f > 0 ? limited(f, x - 1, y) : limited(f, x, y));
    }
  }
  for (int y = 0; y <= h; ++y) {
    for (int x = 0; x < w; ++x) {
      const float f = fy[4 * (size_t(y) * size_t(w) + size_t(x))];
      out.push_back(f > 0 ? limited(f, x, y - 1) : limited(f, x, y));
    }
  }
  return out;
}

double Simulation::sourceDepthRateMS(double t1S) const {
  const Impl& s = *impl_;
  return ts::sourceDepthRate(s.p, s.maxRainMmH, s.sources, s.rowDxD, double(s.p.dyM), s.timeS, t1S);
}

SimStats Simulation::stats() const {
  const Impl& s = *impl_;
  const auto st = s.readState();
  const auto acc = s.accum.read<float>();
  const auto layers = s.layers.read<float>();
  const size_t n = s.n;
  std::vector<float> h(n), sus(n);
  float hmax = 0.0f;
  SimStats out;
  double levelIn = 0, levelOut = 0;
  for (size_t i = 0; i < n; ++i) {
    h[i] = st[4 * i];
    sus[i] = st[4 * i + 1];
    hmax = std::max(hmax, h[i]);
    out.outflowM3 += double(acc[8 * i]);
    out.evaporatedM3 += double(acc[8 * i + 2]);
    out.sedimentOutflowM3 += double(acc[8 * i + 4]);
    (acc[8 * i + 6] > 0 ? levelIn : levelOut) += double(acc[8 * i + 6]);
  }
  const double dy = double(s.p.dyM);
  out.timeS = s.timeS;
  out.steps = s.steps;
  out.lastDtS = s.lastDt;
  out.storedWaterM3 = ts::integrate(h, s.rowDxD, dy, s.p.width);
  out.initialWaterM3 = s.initialWater;
  out.rainM3 = s.rainM3;
  out.inflowM3 = s.inflowM3 + levelIn;  // W26: level cells that gained water on balance
  out.outflowM3 -= levelOut;            // and those that lost
  out.suspendedM3 = ts::integrate(sus, s.rowDxD, dy, s.p.width);
  out.materialM3 = out.suspendedM3 + ts::integrate(layers, s.rowDxD, dy, s.p.width);
  out.initialMaterialM3 = s.initialMaterial;
  out.maxDepthM = hmax;
  return out;
}

}  // namespace strata::render::sim
