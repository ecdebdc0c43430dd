#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <numbers>

#include <strata/gis/dem_io.hpp>
#include <strata/gis/geodesy.hpp>
#include <strata/gl/state.hpp>
#include <strata/render/image_io.hpp>
#include <strata/scenario/domain.hpp>
#include <strata/viewer/viewer.hpp>

namespace strata::viewer {

namespace {

using Clock = std::chrono::steady_clock;
double msSince(Clock::time_point t0) { return std::chrono::duration<double, std::milli>(Clock::now() - t0).count(); }

std::string fmt(const char* format, auto... args) {
  char buf[256];
  std::snprintf(buf, sizeof buf, format, args...);
  return buf;
}

// Tools that change the elevation (the held mouse button keeps applying them).
bool isHeightTool(Tool t) {
  return t == Tool::kRaise || t == Tool::kLower || t == Tool::kSmooth || t == Tool::kFlatten ||
         t == Tool::kAddMaterial || t == Tool::kRemoveMaterial;
}

constexpr const char* kToolKeys[] = {"1", "2", "3", "4", "5", "6", "7", "8", "9"};

}  // namespace

Viewer::Viewer(render::TerrainScene scene, const ViewerOptions& options)
    : scene_(std::move(scene)), options_(options) {}

Result<std::unique_ptr<Viewer>> Viewer::create(const gis::Raster& dem, const ViewerOptions& options) {
  STRATA_TRY(auto scene, render::TerrainScene::create(dem, {.planetary = options.planetary}));
  std::unique_ptr<Viewer> v(new Viewer(std::move(scene), options));
  STRATA_TRY(v->renderer_, render::RingRenderer::create(
                               {.circles = options.circles, .softMinM = options.softMinM, .rangeM = options.rangeM}));
  STRATA_TRY(auto target, render::OffscreenTarget::create(options.width, options.height, options.samples));
  v->target_.emplace(std::move(target));
  STRATA_TRY(auto editor, TerrainEditor::create(v->scene_));
  v->editor_.emplace(std::move(editor));
  STRATA_TRY(auto hud, render::Overlay::create());
  v->hud_.emplace(std::move(hud));
  v->camera_.emplace(v->scene_, options.flight);
  // Start looking at the terrain from above its centre, a sixth of its width away.
  const auto& c = dem.georef.transform.c;
  const double extentM = dem.georef.geographic
                             ? std::abs(c[1]) * dem.values.width * v->scene_.radiusM() * std::numbers::pi / 180.0
                             : std::abs(c[1]) * dem.values.width * v->scene_.metresPerCrsUnit().x;
  auto& pose = v->camera_->pose();
  pose.heightM = options.shading.exaggeration * v->scene_.heightAt(pose.lon, pose.lat) +
                 std::clamp(extentM / 6.0, 200.0, options.planetary ? 1.5 * v->scene_.radiusM() : 5e5);
  pose.pitchDeg = options.planetary ? -90 : -35;
  v->brush_.radiusM = std::max(extentM / 40.0, 1.0);
  return v;
}

Status Viewer::resize(int width, int height) {
  if (width == target_->width() && height == target_->height()) return {};
  STRATA_TRY(auto target, render::OffscreenTarget::create(width, height, options_.samples));
  target_.emplace(std::move(target));
  return {};
}

std::optional<glm::dvec2> Viewer::pick(double x, double y) const {
  const int w = target_->width(), h = target_->height();
  const auto f = render::frameGeometry(scene_, camera_->pose(), options_.shading, w, h);
  const auto at = render::groundEnuAt(f, *target_, int(std::floor(x)), int(std::floor(y)));
  if (!at) return std::nullopt;
  const glm::dvec3 enu = *at;
  const auto& c = scene_.georef().transform.c;
  if (scene_.planetary()) {
    // The frame is east-north-up at the viewer, with up the ellipsoid normal at its nadir
    // (render::positionAt): the point's geodetic lon/lat is the terrain's, as the
    // exaggerated elevation is along the same normal.
    const auto& pose = camera_->pose();
    const gis::LocalFrame frame({pose.lon, pose.lat, pose.heightM}, scene_.georef().body);
    const gis::LonLat p = frame.fromEnu({enu.x, enu.y, enu.z});
    if (!std::isfinite(p.lonDeg) || !std::isfinite(p.latDeg)) return std::nullopt;
    // The longitude in the turn nearest the DEM's centre (a global DEM may run 0..360).
    const double centre = c[0] + 0.5 * c[1] * scene_.width();
    return glm::dvec2(p.lonDeg - 360.0 * std::round((p.lonDeg - centre) / 360.0), p.latDeg);
  }
  const glm::dvec2 uv = f.uvCam + f.uvPerMetre * glm::dvec2(enu.x, enu.y);
  if (!std::isfinite(uv.x) || !std::isfinite(uv.y)) return std::nullopt;
  return glm::dvec2(c[0] + c[1] * uv.x * scene_.width(), c[3] + c[5] * uv.y * scene_.height());
}

Status Viewer::handle(const Command& command) {
  message_.clear();
  const double k = options_.shading.exaggeration;
  return std::visit(
      [&](const auto& c) -> Status {
        using T = std::decay_t<decltype(c)>;
        if constexpr (std::is_same_v<T, KeyCommand>) {
          return key(c);
        } else if constexpr (std::is_same_v<T, MouseMoveCommand>) {
          if (rightDown_ && cursor_.x >= 0) camera_->look(c.x - cursor_.x, c.y - cursor_.y);
          cursor_ = {c.x, c.y};
          return {};
        } else if constexpr (std::is_same_v<T, MouseButtonCommand>) {
          if (c.button == MouseButtonCommand::kRight) {
            rightDown_ = c.down;
            return {};
          }
          leftDown_ = c.down;
          const auto at = pick(cursor_.x, cursor_.y);
          if (brush_.tool == Tool::kRegion) {
            if (!at) return fail("region: the cursor is not over the terrain");
            if (c.down) {
              regionStart_ = *at;
              return {};
            }
            return startRegion(regionStart_.x, regionStart_.y, at->x, at->y);
          }
          if (!c.down) {
            if (editor_->inStroke()) editor_->endStroke();
            return {};
          }
          if (!at) return fail(std::string(toolName(brush_.tool)) + ": the cursor is not over the terrain");
          return applyToolAt(at->x, at->y, true);
        } else if constexpr (std::is_same_v<T, ToolCommand>) {
          const auto t = toolFromName(c.name);
          if (!t)
            return fail("tool '" + c.name + "': unknown (raise lower smooth flatten copy paste water spring region)");
          brush_.tool = *t;
          return {};
        } else if constexpr (std::is_same_v<T, BrushCommand>) {
          brush_.radiusM = c.radiusM;
          brush_.strength = c.strength;
          if (c.layer >= 0) brush_.layer = c.layer;
          return {};
        } else if constexpr (std::is_same_v<T, StrokeCommand>) {
          if (brush_.tool == Tool::kRegion) return fail("stroke: the region tool takes 'region LON0 LAT0 LON1 LAT1'");
          STRATA_TRY_STATUS(applyToolAt(c.lon, c.lat, true));
          if (editor_->inStroke()) editor_->endStroke();
          return {};
        } else if constexpr (std::is_same_v<T, GoToCommand>) {
          return camera_->goTo(c.lon, c.lat, c.aglM, k);
        } else if constexpr (std::is_same_v<T, LookCommand>) {
          camera_->pose().headingDeg = c.headingDeg;
          camera_->pose().pitchDeg = c.pitchDeg;
          return {};
        } else if constexpr (std::is_same_v<T, ExaggerationCommand>) {
          const double agl = camera_->heightAboveGroundM(k);
          options_.shading.exaggeration = float(c.factor);
          camera_->pose().heightM = c.factor * scene_.heightAt(camera_->pose().lon, camera_->pose().lat) + agl;
          return {};
        } else if constexpr (std::is_same_v<T, UndoCommand>) {
          if (!editor_->undo()) message_ = "nothing to undo";
          return region_ ? rebuildSimulation(region_->sim->readWaterDepth()) : Status{};
        } else if constexpr (std::is_same_v<T, RedoCommand>) {
          if (!editor_->redo()) message_ = "nothing to redo";
          return region_ ? rebuildSimulation(region_->sim->readWaterDepth()) : Status{};
        } else if constexpr (std::is_same_v<T, RegionCommand>) {
          return startRegion(c.lon0, c.lat0, c.lon1, c.lat1);
        } else if constexpr (std::is_same_v<T, SimCommand>) {
          if (!region_) return fail("simulation: choose a region first (region tool, or 'region' in a script)");
          switch (c.action) {
            case SimCommand::kPlay: region_->playing = true; break;
            case SimCommand::kPause: region_->playing = false; break;
            case SimCommand::kStep: return stepSimulation(c.count);
            case SimCommand::kSpeed: region_->stepsPerFrame = c.count; break;
            case SimCommand::kErosionOn: return setErosion(true);
            case SimCommand::kErosionOff: return setErosion(false);
          }
          return {};
        } else if constexpr (std::is_same_v<T, StampCommand>) {
          const auto blend = blendFromName(c.blend);
          if (!blend) return fail("stamp: blend '" + c.blend + "': expected add, subtract, multiply or replace");
          gis::Grid<float> t;
          if (auto image = render::readImage8(c.path)) {
            t = gis::Grid<float>(image->width, image->height);
            for (size_t i = 0; i < t.data.size(); ++i)
              t.data[i] = float(image->pixels[i * size_t(image->channels)]) / 255.0f;
          } else {
            auto raster = gis::readDem(c.path);
            if (!raster) return fail("stamp " + c.path + ": " + image.message() + "; " + raster.message());
            t = std::move(raster->values);
          }
          editor_->setStamp(t, *blend);
          brush_.tool = Tool::kStamp;
          return {};
        } else if constexpr (std::is_same_v<T, ScreenshotCommand>) {
          pendingScreenshots_.push_back(c);
          return {};
        } else if constexpr (std::is_same_v<T, SaveCommand>) {
          const std::string path = c.path.empty() ? savePath : c.path;
          if (!saver) return fail("save: this viewer has no way to save");
          STRATA_TRY_STATUS(saver(path));
          editor_->clearDirty();
          message_ = "saved to " + path;
          return {};
        } else {
          static_assert(std::is_same_v<T, QuitCommand>);
          quit_ = true;
          return {};
        }
      },
      command);
}

Status Viewer::key(const KeyCommand& k) {
  auto& keys = camera_->keys;
  const std::string& n = k.name;
  if (n == "W") keys.forward = k.down;
  if (n == "S") keys.back = k.down;
  if (n == "A") keys.left = k.down;
  if (n == "D") keys.right = k.down;
  if (n == "E") keys.up = k.down;
  if (n == "Q") keys.down = k.down;
  if (n == "SHIFT") keys.fast = k.down;
  if (!k.down) return {};
  const double ex = options_.shading.exaggeration;
  if (n == "SPACE")
    return region_ ? handle(SimCommand{region_->playing ? SimCommand::kPause : SimCommand::kPlay})
                   : handle(SimCommand{SimCommand::kPlay});
  if (n == "N") return handle(SimCommand{SimCommand::kStep, 1});
  if (n == "Z") return handle(UndoCommand{});
  if (n == "Y") return handle(RedoCommand{});
  if (n == "H" || n == "F1") showHelp_ = !showHelp_;
  if (n == "F2") options_.showHud = !options_.showHud;
  if (n == "ESCAPE") quit_ = true;
  if (n == "LEFT_BRACKET") brush_.radiusM /= 1.25;
  if (n == "RIGHT_BRACKET") brush_.radiusM *= 1.25;
  if (n == "MINUS") brush_.strength /= 1.25;
  if (n == "EQUAL") brush_.strength *= 1.25;
  if (n == "PAGE_UP") return handle(ExaggerationCommand{ex * 1.25});
  if (n == "PAGE_DOWN") return handle(ExaggerationCommand{ex / 1.25});
  if (n == "COMMA" && region_) region_->stepsPerFrame = std::max(1, region_->stepsPerFrame / 2);
  if (n == "PERIOD" && region_) region_->stepsPerFrame = std::min(4096, region_->stepsPerFrame * 2);
  for (int i = 0; i < int(std::size(kToolKeys)); ++i) {
    if (n == kToolKeys[i]) brush_.tool = Tool(i);
  }
  if (n == "0") {
    if (!editor_->hasStamp()) return fail("stamp: load an image first ('stamp PATH BLEND' in a script)");
    brush_.tool = Tool::kStamp;
  }
  if (n == "G") {  // go to the point under the cursor, keeping the height above ground
    const auto at = pick(cursor_.x, cursor_.y);
    if (!at) return fail("goto: the cursor is not over the terrain");
    return camera_->goTo(at->x, at->y, -1, ex);
  }
  if (n == "X" && region_) return setErosion(!region_->erosion);
  if (n == "R") brush_.tool = Tool::kRain;
  if (n == "M") brush_.tool = Tool::kAddMaterial;
  if (n == "B") brush_.tool = Tool::kRemoveMaterial;
  if (n == "L") brush_.layer = (brush_.layer + 1) % 4;
  return {};
}

Status Viewer::applyToolAt(double lon, double lat, bool newStroke) {
  const glm::dvec2 cell = editor_->cellOf(lon, lat);
  switch (brush_.tool) {
    case Tool::kSpring: {
      if (!region_) return fail("spring: choose a simulation region first");
      const auto& r = region_->rect;
      const int x = int(std::floor(cell.x)) - r.x, y = int(std::floor(cell.y)) - r.y;
      if (x < 0 || y < 0 || x >= r.width || y >= r.height) return fail("spring: outside the simulation region");
      region_->springCells.push_back({x, y});
      region_->springRatesM3S.push_back(brush_.strength);
      return region_->sim->addSource({{{x, y}}, TimeSeries::constant(brush_.strength)});
    }
    case Tool::kWater: {
      if (!region_) return fail("water: choose a simulation region first");
      auto water = region_->sim->readWaterDepth();
      const glm::dvec2 rc = editor_->radiusCells(brush_.radiusM, cell.y);
      const auto& r = region_->rect;
      for (int y = 0; y < r.height; ++y) {
        for (int x = 0; x < r.width; ++x) {
          const glm::dvec2 d = (glm::dvec2(r.x + x + 0.5, r.y + y + 0.5) - cell) / rc;
          const double r2 = glm::dot(d, d);
          if (r2 < 1) water.at(x, y) += float(std::max(brush_.strength, 0.0) * (1 - r2) * (1 - r2));
        }
      }
      STRATA_TRY_STATUS(rebuildSimulation(water));
      return showWater();
    }
    case Tool::kRain: {
      if (!region_) return fail("rain: choose a simulation region first");
      const glm::dvec2 rc = editor_->radiusCells(brush_.radiusM, cell.y);
      const auto& r = region_->rect;
      if (region_->rainMmPerHour.data.empty()) region_->rainMmPerHour = gis::Grid<float>(r.width, r.height, 0.0f);
      for (int y = 0; y < r.height; ++y) {
        for (int x = 0; x < r.width; ++x) {
          const glm::dvec2 d = (glm::dvec2(r.x + x + 0.5, r.y + y + 0.5) - cell) / rc;
          const double r2 = glm::dot(d, d);
          if (r2 < 1) region_->rainMmPerHour.at(x, y) += float(std::max(brush_.strength, 0.0) * (1 - r2) * (1 - r2));
        }
      }
      return rebuildSimulation(region_->sim->readWaterDepth());
    }
    case Tool::kRegion: return fail("region: drag with the left button");
    default: break;
  }
  if (newStroke) {
    if (editor_->inStroke()) editor_->endStroke();
    editor_->beginStroke();
  }
  STRATA_TRY_STATUS(editor_->dab(brush_, cell));
  // The simulation reads the edited bed: rebuild it from the new terrain and the current water.
  if (region_ && (isHeightTool(brush_.tool) || brush_.tool == Tool::kPaste || brush_.tool == Tool::kStamp)) {
    const auto& d = editor_->lastDab();
    const auto& r = region_->rect;
    if (!d.empty() && d.x < r.x + r.width && r.x < d.x + d.width && d.y < r.y + r.height && r.y < d.y + d.height) {
      STRATA_TRY_STATUS(rebuildSimulation(region_->sim->readWaterDepth()));
    }
  }
  return {};
}

Status Viewer::startRegion(double lon0, double lat0, double lon1, double lat1) {
  const glm::dvec2 a = editor_->cellOf(lon0, lat0), b = editor_->cellOf(lon1, lat1);
  const int x0 = std::max(0, int(std::floor(std::min(a.x, b.x)))),
            y0 = std::max(0, int(std::floor(std::min(a.y, b.y))));
  const int x1 = std::min(scene_.width(), int(std::ceil(std::max(a.x, b.x))));
  const int y1 = std::min(scene_.height(), int(std::ceil(std::max(a.y, b.y))));
  if (x1 - x0 < 4 || y1 - y0 < 4) return fail("region: needs at least 4x4 cells inside the terrain");
  region_.emplace();
  region_->rect = {x0, y0, x1 - x0, y1 - y0};
  scene_.clearWaterState();  // the previous region's water
  STRATA_TRY_STATUS(rebuildSimulation(gis::Grid<float>(x1 - x0, y1 - y0, 0.0f)));
  return showWater();
}

Status Viewer::rebuildSimulation(const gis::Grid<float>& waterM) {
  auto& reg = *region_;
  const auto& r = reg.rect;
  if (reg.sim) reg.timeOffsetS += reg.sim->stats().timeS;
  strata::sim::SimInput in;
  in.baseM = gis::Grid<float>(r.width, r.height);
  for (int y = 0; y < r.height; ++y) {
    for (int x = 0; x < r.width; ++x) in.baseM.at(x, y) = scene_.heights().at(r.x + x, r.y + y);
  }
  if (reg.erosion) {
    // The editor's four layers are the sim's (sediment settles on the top one); the base is the
    // surface less their thickness, so the bed is the drawn surface.
    const auto& l = editor_->layers();
    in.layersM.assign(4, gis::Grid<float>(r.width, r.height));
    for (int y = 0; y < r.height; ++y) {
      for (int x = 0; x < r.width; ++x) {
        const size_t i = (size_t(r.y + y) * size_t(scene_.width()) + size_t(r.x + x)) * 4;
        for (int k = 0; k < 4; ++k) {
          in.layersM[size_t(k)].at(x, y) = l[i + size_t(k)];
          in.baseM.at(x, y) -= l[i + size_t(k)];
        }
      }
    }
    in.materials = strata::terrain::defaultMaterials();
  } else {
    in.layersM = {gis::Grid<float>(r.width, r.height, 0.0f)};
    in.materials = {strata::terrain::Material{}};
  }
  in.waterDepthM = waterM;
  in.rainMmPerHour = reg.rainMmPerHour;
  // Cell sizes as a scenario's: geodesic, from the region's own georeference.
  gis::Georef g = scene_.georef();
  g.transform.c[0] = scene_.georef().transform.x(r.x, r.y);
  g.transform.c[3] = scene_.georef().transform.y(r.x, r.y);
  g.width = r.width;
  g.height = r.height;
  STRATA_TRY(auto sizes, scenario::measureCells(g));
  in.dyM = sizes.dyM;
  in.rowDxM = std::move(sizes.rowDxM);
  double lo = in.baseM.data[0];
  for (float v : in.baseM.data) lo = std::min(lo, double(v));
  in.datumM = std::floor(lo);
  // The model as a scenario's [model] and [erosion]: flood mode, open edges; erosion with the
  // viewer's interactive preset (docs/viewer.md): the force-based law of terrain authoring, rates
  // high enough to see channels within seconds of play, and a 1 mm dry depth so films of rain do
  // not erode.
  scenario::Scenario s;
  s.model.manningN = 0.03;
  s.model.maxStepS = 10.0;
  s.erosion.enabled = reg.erosion;
  s.erosion.law = sim::ErosionLaw::kForceBased;
  s.erosion.thermal = false;
  s.erosion.capacity = 0.05;
  s.erosion.erosionRate = 0.5;
  s.erosion.depositionRate = 0.3;
  strata::sim::SimParams p = scenario::modelParams(s);
  if (reg.erosion) {
    p.deepWaterM = 2.0f;
    p.slowWaterMS = 0.05f;
    p.dryDepthM = 1e-3f;
  }
  STRATA_TRY(auto sim, sim::GlSolver::create(in, p));
  reg.sim = std::make_unique<sim::GlSolver>(std::move(sim));
  for (size_t i = 0; i < reg.springCells.size(); ++i) {
    STRATA_TRY_STATUS(reg.sim->addSource({{reg.springCells[i]}, TimeSeries::constant(reg.springRatesM3S[i])}));
  }
  return {};
}

Status Viewer::setErosion(bool on) {
  if (!region_) return fail("erosion: choose a simulation region first");
  if (on == region_->erosion) return {};
  if (on && editor_->layers().empty()) {
    // Four layers (rock, soil, sand, sediment) with 2 m of soil over the region, taken from
    // the surface (which does not move). Starting layers clears the undo history.
    std::vector<gis::Grid<float>> layers(4, gis::Grid<float>(scene_.width(), scene_.height(), 0.0f));
    const auto& r = region_->rect;
    for (int y = r.y; y < r.y + r.height; ++y) {
      for (int x = r.x; x < r.x + r.width; ++x) layers[1].at(x, y) = 2.0f;
    }
    STRATA_TRY_STATUS(editor_->setLayers(layers));
    message_ = "erosion on: 2 m of soil over the region (undo history cleared)";
  }
  region_->erosion = on;
  return rebuildSimulation(region_->sim->readWaterDepth());
}

Status Viewer::stepSimulation(int steps) {
  const auto t0 = Clock::now();
  region_->sim->step(steps);
  if (region_->erosion) {
    // The bed and layers moved: bring them into the scene (elevations, layer colours) and the
    // editor's mirror.
    const auto bed = region_->sim->readBed();
    const auto layers = region_->sim->readLayers();
    const double datum = region_->sim->datumM();
    std::vector<float> heights(bed.data.size()), packed(bed.data.size() * 4);
    for (size_t i = 0; i < bed.data.size(); ++i) {
      heights[i] = float(double(bed.data[i]) + datum);
      for (size_t k = 0; k < 4; ++k) packed[i * 4 + k] = layers[k].data[i];
    }
    editor_->applyExternal(region_->rect, heights, packed);
  }
  STRATA_TRY_STATUS(showWater());
  region_->lastStepMs = msSince(t0);
  return {};
}

Status Viewer::showWater() {
  // A GPU-to-GPU copy of the region's state (h, s, hu, hv) into the scene's water-state texture:
  // the depth is drawn as water, the suspended sediment (non-zero with erosion on) as silt.
  const auto& r = region_->rect;
  scene_.copyWaterState(region_->sim->stateBuffer(), r.x, r.y, r.width, r.height);
  return {};
}

Status Viewer::frame(double dtS) {
  const auto t0 = Clock::now();
  camera_->update(dtS, options_.shading.exaggeration);
  Status status;
  if (leftDown_ && editor_->inStroke() && isHeightTool(brush_.tool)) {
    if (const auto at = pick(cursor_.x, cursor_.y)) status = applyToolAt(at->x, at->y, false);
  }
  if (region_ && region_->playing) {
    if (auto s = stepSimulation(region_->stepsPerFrame); !s) status = s;
  }
  // The draw of two frames ago has finished by now on any GPU that keeps up: reading its timer
  // rarely waits (and flushes where nothing else does, e.g. headless contexts without a swap).
  auto& timer = gpuTimers_[frameIndex_ % 3];
  if (frameIndex_ >= 2) gpuFrameMs_ = gpuTimers_[(frameIndex_ + 1) % 3].milliseconds();
  timer.begin();
  // Shadows follow edits once a stroke ends, and erosion's when the region is paused (casting
  // them takes tens of milliseconds: not every frame of a stroke or a running simulation).
  if (scene_.shadowsStale() && !editor_->inStroke() && !(region_ && region_->playing)) {
    STRATA_TRY_STATUS(scene_.recastShadows());
  }
  STRATA_TRY_STATUS(renderer_->draw(scene_, camera_->pose(), options_.shading, *target_));
  if (options_.scaleBar) hud_->drawScaleBarOver(*target_, scene_, camera_->pose(), options_.shading);
  timer.end();
  ++frameIndex_;
  cpuFrameMs_ = msSince(t0);
  return status;
}

Status Viewer::present(int width, int height) {
  target_->blitColourToWindow(width, height);
  gl::bindWindowFramebuffer();
  auto capture = [&](bool withHud) -> Status {
    for (const auto& shot : pendingScreenshots_) {
      if (shot.withHud != withHud) continue;
      const std::vector<uint8_t> pixels = gl::readWindowPixels(width, height);
      std::vector<uint8_t> flipped(pixels.size());
      const size_t row = size_t(width) * 4;
      for (int y = 0; y < height; ++y) {
        std::copy_n(&pixels[size_t(height - 1 - y) * row], row, &flipped[size_t(y) * row]);
      }
      for (size_t i = 3; i < flipped.size(); i += 4) flipped[i] = 255;
      STRATA_TRY_STATUS(render::writeImage8(shot.path, width, height, 4, flipped));
    }
    return {};
  };
  STRATA_TRY_STATUS(capture(false));
  const int scale = height >= 700 ? 2 : 1;
  if (options_.showHud) hud_->drawText(hudLines(), 0, 0, width, height, scale);
  if (showHelp_) {
    const auto help = helpLines();
    int w = 0, h = 0;
    render::Overlay::measureText(help, scale, w, h);
    hud_->drawText(help, std::max(0, width - w), 0, width, height, scale);
  }
  STRATA_TRY_STATUS(capture(true));
  pendingScreenshots_.clear();
  return {};
}

Viewer::FrameTimes Viewer::times() const {
  return {cpuFrameMs_, gpuFrameMs_, region_ && region_->playing ? region_->lastStepMs : 0.0};
}

std::vector<std::string> Viewer::hudLines() const {
  const double ex = options_.shading.exaggeration;
  const auto& pose = camera_->pose();
  std::vector<std::string> lines;
  lines.push_back(fmt("frame %.1f ms CPU, %.1f ms GPU", cpuFrameMs_, gpuFrameMs_));
  if (region_) {
    lines.push_back(fmt("sim %s x%d%s  %.1f ms/frame  t=%.0f s", region_->playing ? "playing" : "paused",
                        region_->stepsPerFrame, region_->erosion ? " erosion" : "", region_->lastStepMs,
                        region_->timeOffsetS + region_->sim->stats().timeS));
  } else {
    lines.push_back("sim: no region (tool 9, drag)");
  }
  lines.push_back(fmt("above ground %.0f m  speed %.0f m/s  exaggeration %.2f", camera_->heightAboveGroundM(ex),
                      camera_->speedMS(ex), ex));
  lines.push_back(fmt("camera %.5f %.5f  heading %.0f pitch %.0f", pose.lon, pose.lat, pose.headingDeg, pose.pitchDeg));
  if (const auto at = pick(cursor_.x, cursor_.y)) {
    lines.push_back(fmt("cursor %.5f %.5f  elevation %.1f m", at->x, at->y, scene_.heightAt(at->x, at->y)));
  } else {
    lines.push_back("cursor: -");
  }
  lines.push_back(fmt("tool %s  radius %.0f m  strength %.3g  layer %d  undo %zu redo %zu", toolName(brush_.tool),
                      brush_.radiusM, brush_.strength, brush_.layer, editor_->undoDepth(), editor_->redoDepth()));
  lines.push_back(message_.empty() ? "H: help" : message_);
  return lines;
}

std::vector<std::string> Viewer::helpLines() {
  return {"W A S D: fly   Q E: down, up   SHIFT: fast",
          "right mouse drag: look   left mouse: use the tool",
          "1 raise 2 lower 3 smooth 4 flatten 5 copy 6 paste",
          "7 water 8 spring 9 region (drag a rectangle)",
          "0 stamp (image from a script)   R rain",
          "M add, B remove material   L next layer",
          "[ ]: brush radius   - =: strength",
          "Z: undo   Y: redo   PAGE UP/DOWN: exaggeration",
          "SPACE: play/pause   N: step   , .: sim speed",
          "G: go to the point under the cursor   X: erosion on/off",
          "F2: HUD   H or F1: this help   ESC: quit"};
}

}  // namespace strata::viewer
