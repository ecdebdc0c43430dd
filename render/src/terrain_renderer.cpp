#include <strata/core/angles.hpp>
#include <strata/render/terrain_renderer.hpp>

#include <algorithm>
#include <bit>
#include <cmath>
#include <limits>
#include <numbers>

#include <glm/gtc/matrix_transform.hpp>

#include <strata/gis/fill_nodata.hpp>
#include <strata/gis/geodesy.hpp>
#include <strata/gl/state.hpp>
#include <strata/render/shader_slots.hpp>
#include <strata/terrain/tile_store.hpp>

#include "frame_state.hpp"

namespace strata::render {
namespace {

constexpr double kPi = std::numbers::pi;
constexpr int kMaxLevels = 32;  // terrain_common.glsl's per-level arrays

glm::mat4 toFloat(const glm::dmat4& m) { return glm::mat4(m); }

bool isGlobalInLongitude(const gis::Georef& g) {
  // Within a tenth of a pixel of 360 degrees (products converted from metres are not exact).
  return g.geographic && std::abs(std::abs(g.transform.c[1]) * g.width - 360.0) < 0.1 * std::abs(g.transform.c[1]);
}

}  // namespace

namespace detail {

FrameState::FrameState(const OffscreenTarget& target, const glm::vec4& sky)
    : previous_(gl::FramebufferBinding::current()), target_(target) {
  target.bind();
  gl::setViewport({0, 0, target.width(), target.height()});
  gl::setClipDepth(gl::ClipDepth::kZeroToOne);
  gl::setDepthTest(gl::DepthTest::kGreater, true);
  gl::setCulling(false);
  target.clear(sky);
}

FrameState::~FrameState() {
  target_.resolve();
  gl::setClipDepth(gl::ClipDepth::kMinusOneToOne);
  gl::setDepthTest(gl::DepthTest::kOff);
  previous_.restore();
}

}  // namespace detail

Palette paletteFor(const gis::Body& body) {
  if (body.name == gis::Body::moon().name) return Palette::Grey;
  if (body.name == gis::Body::mars().name) return Palette::Rust;
  return Palette::Hypsometric;
}

namespace detail {

namespace {
// Towards the sun in the viewer's frame: Shading::sunDir, or from the subsolar point at the
// viewer's place (a projected DEM's centre).
glm::vec3 sunInViewerFrame(const TerrainScene& scene, const FrameGeometry& frame, const Shading& shading) {
  glm::vec3 sun = glm::normalize(shading.sunDir);
  if (shading.subsolarLonLat) {
    const glm::dvec2 place =
        scene.georef().geographic ? glm::dvec2(frame.lonRad / kDeg, frame.latRad / kDeg) : scene.centreLonLat();
    if (std::isfinite(place.x) && std::isfinite(place.y)) {
      sun = glm::vec3(sunDirectionEnu(*shading.subsolarLonLat, place.x, place.y));
    }
  }
  return sun;
}

// atmosphere.glsl's uniforms.
void setAirUniforms(const gl::Program& p, const TerrainScene& scene, const Shading& shading, const glm::vec3& sun) {
  p.set("uHasAir", shading.atmosphere ? 1 : 0);
  if (!shading.atmosphere) return;
  const Atmosphere& a = *shading.atmosphere;
  p.set("uAirRayleigh", a.rayleighPerM);
  p.set("uAirRayleighScaleM", a.rayleighScaleM);
  p.set("uAirHaze", a.hazePerM);
  p.set("uAirHazeScaleM", a.hazeScaleM);
  p.set("uAirHazeColour", a.hazeColour);
  p.set("uAirBrightness", a.brightness);
  p.set("uAirRadius", float(scene.radiusM()));
  p.set("uAirSunDir", sun);
  // Sunlight on the air at the viewer, as atmosphere.glsl's airSunAt.
  const float s = std::clamp((sun.z + 0.1f) / 0.24f, 0.0f, 1.0f);
  p.set("uAirSun", s * s * (3 - 2 * s));
}
}  // namespace

Result<gl::Program> createSkyProgram() {
  return gl::Program::graphics("render/shaders/sky.vert", "render/shaders/sky.frag", gl::definesFor(slots::kAll));
}

void drawSky(const gl::Program& sky, const gl::VertexArray& vao, const TerrainScene& scene, const FrameGeometry& frame,
             const Shading& shading, const glm::dmat4& viewProj) {
  if (!shading.atmosphere) return;
  sky.use();
  sky.set("uInvViewProj", toFloat(glm::inverse(viewProj)));
  sky.set("uSkyAltM", float(frame.camZ));
  setAirUniforms(sky, scene, shading, sunInViewerFrame(scene, frame, shading));
  gl::setDepthTest(gl::DepthTest::kOff);
  vao.drawArrays(gl::Primitive::kTriangles, 0, 3);
  gl::setDepthTest(gl::DepthTest::kGreater, true);
}

Status setCommonUniforms(const gl::Program& p, const TerrainScene& scene, const FrameGeometry& frame,
                         const Shading& shading, const glm::dmat4& viewProj) {
  const auto& c = scene.georef().transform.c;
  const double w = scene.width(), h = scene.height();
  p.set("uViewProj", toFloat(viewProj));
  p.set("uPlanetary", scene.planetary() ? 1 : 0);
  p.set("uExaggeration", shading.exaggeration);
  p.set("uCamZ", float(frame.camZ));
  const glm::dvec2 size(w, h);
  p.set("uTexelPerMetre", glm::vec2(frame.uvPerMetre * size));
  p.set("uTexelPerRad", glm::vec2(1.0 / (c[1] * kDeg), 1.0 / (c[5] * kDeg)));
  p.set("uTexSize", glm::vec2(float(w), float(h)));
  p.set("uWrapU", scene.planetary() && isGlobalInLongitude(scene.georef()) ? 1 : 0);
  p.set("uRadius", float(scene.radiusM()));
  p.set("uCamLonLat", glm::vec2(float(frame.lonRad), float(frame.reducedLatRad)));
  p.set("uFlattening", float(scene.georef().body.flattening));
  p.set("uPoleAux", glm::vec3(frame.poleAux));
  p.set("uNadirNormal", glm::vec3(frame.nadirNormal));
  p.set("uFrameRot", glm::mat3(frame.frameRot));
  p.set("uGeoToUv", glm::vec4(float(c[0] * kDeg), float(1.0 / (c[1] * w * kDeg)), float(c[3] * kDeg),
                              float(1.0 / (c[5] * h * kDeg))));
  p.set("uHasWater", scene.waterTexture() ? 1 : 0);
  p.set("uHasLayers", scene.layerTexture() ? 1 : 0);
  p.set("uHasSediment", scene.sedimentTexture() && scene.waterTexture() ? 1 : 0);
  p.set("uHasWaterState", scene.waterStateTexture() ? 1 : 0);
  p.set("uHasVoidMask", scene.voidMaskTexture() ? 1 : 0);
  p.set("uHasDrape", scene.drapeTexture() ? 1 : 0);
  p.set("uDrapeOpacity", shading.drapeOpacity);
  if (scene.drapeTexture()) scene.drapeTexture()->bind(slots::kDrape);
  p.set("uHasShadow", scene.shadowTexture() ? 1 : 0);
  if (scene.shadowTexture()) scene.shadowTexture()->bind(slots::kShadow);
  p.set("uOverviewUvScale", scene.overviewUvScale());
  p.set("uAmbient", shading.ambient);
  const bool graticule = scene.lonLatTexture() && shading.graticuleDeg > 0;
  p.set("uGraticuleDeg", graticule ? float(shading.graticuleDeg) : 0.0f);
  if (graticule) scene.lonLatTexture()->bind(slots::kLonLat);
  if (scene.voidMaskTexture()) scene.voidMaskTexture()->bind(slots::kVoidMask);
  p.set("uSiltColour", shading.siltColour);
  p.set("uSiltConcentration", shading.siltConcentration);
  p.set("uHasSea", shading.seaLevelM ? 1 : 0);
  p.set("uSeaLevelM", shading.seaLevelM.value_or(0.0f));
  p.set("uWaterDepthScaleM", shading.waterDepthScaleM);
  p.set("uWaterFadeM", shading.waterFadeM);
  p.set("uLayerOpaqueM", shading.layerOpaqueM);
  for (int k = 0; k < 4; ++k) {
    const std::string name = "uLayerColour[" + std::to_string(k) + "]";
    p.set(name.c_str(), shading.layerColours[size_t(k)]);
  }
  glm::vec2 tint(scene.minElevationM(), scene.maxElevationM());
  if (shading.seaLevelM) tint.x = std::max(tint.x, *shading.seaLevelM);
  p.set("uElevRange", shading.tintRangeM.value_or(tint));
  p.set("uPalette", int(shading.palette));
  if (shading.palette == Palette::Ramp) {
    const int n = int(std::min(shading.ramp.elevationsM.size(), size_t(ColourRamp::kMaxStops)));
    if (n == 0) return fail("render: the user colour ramp has no stops");
    p.set("uRampCount", n);
    for (int k = 0; k < n; ++k) {
      const std::string i = "[" + std::to_string(k) + "]";
      p.set(("uRampElev" + i).c_str(), shading.ramp.elevationsM[size_t(k)]);
      p.set(("uRampColour" + i).c_str(), shading.ramp.colours[size_t(k)]);
    }
  }
  const glm::vec3 sun = sunInViewerFrame(scene, frame, shading);
  p.set("uSunDir", sun);
  setAirUniforms(p, scene, shading, sun);
  p.set("uPole", glm::vec3(frame.frameRot * frame.poleAux));
  p.set("uSky", shading.sky);
  p.set("uFogM", shading.fogM);
  if (scene.waterTexture()) scene.waterTexture()->bind(slots::kWater);
  if (scene.layerTexture()) scene.layerTexture()->bind(slots::kLayers);
  if (scene.sedimentTexture()) scene.sedimentTexture()->bind(slots::kSediment);
  if (scene.waterStateTexture()) scene.waterStateTexture()->bind(slots::kWaterState);
  StreamedElevation* s = scene.streamed();
  p.set("uStreamed", s ? 1 : 0);
  // The levels the shaders sample: each one's size, its texels per level-0 texel, and the viewer's
  // texel-centre coordinate on it split into an integer and a fraction (in double here, so that
  // the shaders only ever add small offsets: terrain_common.glsl, "Camera-relative").
  std::vector<glm::ivec2> sizes;
  std::vector<glm::dvec2> scales;
  if (!s) {
    for (int l = 0; l < scene.heightTexture().levels(); ++l) {
      const glm::ivec2 sz(std::max(1, scene.width() >> l), std::max(1, scene.height() >> l));
      sizes.push_back(sz);
      scales.push_back(glm::dvec2(sz) / size);
    }
    scene.heightTexture().bind(slots::kHeight);
  } else {
    STRATA_TRY_STATUS(s->update(frame.uvCam * size));
    const int lc = s->coarseLevel();
    p.set("uClipCoarse", lc);
    p.set("uClipSize", s->params().clipSize);
    p.set("uPageShift", int(std::countr_zero(unsigned(s->params().pageSize))));
    for (int l = 0; l < lc; ++l) {
      p.set(("uClipOrigin[" + std::to_string(l) + "]").c_str(), s->windowOrigin(l));
      sizes.push_back(s->levelSize(l));
      scales.push_back(glm::dvec2(std::ldexp(1.0, -l)));
    }
    // Level C and coarser: the coarse texture's mips. It covers whole level-C cells, a little
    // more than the grid when 2^C does not divide it.
    const glm::ivec2 coarse = s->levelSize(lc);
    for (int m = 0; m < s->coarseTexture().levels() && lc + m < kMaxLevels; ++m) {
      const glm::ivec2 sz(std::max(1, coarse.x >> m), std::max(1, coarse.y >> m));
      sizes.push_back(sz);
      scales.push_back(glm::dvec2(sz) / (glm::dvec2(coarse) * std::ldexp(1.0, lc)));
    }
    s->coarseTexture().bind(slots::kHeight);
    s->clipTexture().bind(slots::kClip);
    s->pageFlags().bind(slots::kClipPages);
  }
  STRATA_CHECK(sizes.size() <= size_t(kMaxLevels)) << sizes.size() << " levels";
  p.set("uLevelCount", int(sizes.size()));
  for (size_t l = 0; l < sizes.size(); ++l) {
    const glm::dvec2 cam = frame.uvCam * size * scales[l] - 0.5;
    const glm::dvec2 whole = glm::floor(cam);
    const std::string i = "[" + std::to_string(l) + "]";
    p.set(("uCamTexelI" + i).c_str(), glm::ivec2(whole));
    p.set(("uCamTexelF" + i).c_str(), glm::vec2(cam - whole));
    p.set(("uLevelScale" + i).c_str(), glm::vec2(scales[l]));
    p.set(("uLevelSize" + i).c_str(), sizes[l]);
  }
  return {};
}

}  // namespace detail

// ---- TerrainScene ------------------------------------------------------------------------------

namespace {
// A projected grid's point scale at its centre; 1 where the CRS has no lon/lat base.
glm::dvec2 metresPerCrsUnitOf(const gis::Georef& g) {
  if (g.geographic) return {1.0, 1.0};
  const auto k = gis::metresPerCrsUnit(g, 0.5 * g.width, 0.5 * g.height);
  return k ? glm::dvec2((*k)[0], (*k)[1]) : glm::dvec2(1.0, 1.0);
}
glm::dvec2 centreLonLatOf(const gis::Georef& g) {
  const auto p = gis::pixelToLonLat(g, 0.5 * g.width, 0.5 * g.height);
  return p ? glm::dvec2(p->lonDeg, p->latDeg) : glm::dvec2(std::numeric_limits<double>::quiet_NaN());
}
}  // namespace

Result<TerrainScene> TerrainScene::create(const gis::Raster& dem, const SceneOptions& options) {
  const auto& g = dem.georef;
  if (dem.values.width < 2 || dem.values.height < 2) {
    return fail("render: DEM of " + std::to_string(dem.values.width) + "x" + std::to_string(dem.values.height) +
                " cells: need at least 2x2");
  }
  if (g.width != dem.values.width || g.height != dem.values.height) {
    return fail("render: DEM georef size " + std::to_string(g.width) + "x" + std::to_string(g.height) +
                " differs from its grid " + std::to_string(dem.values.width) + "x" + std::to_string(dem.values.height));
  }
  if (!g.transform.isNorthUp() || g.transform.c[1] <= 0 || g.transform.c[5] >= 0) {
    return fail("render: DEM geotransform is not north-up (rotation terms or axis signs)");
  }
  if (options.planetary && !g.geographic) return fail("render: planetary mode needs a geographic (lon/lat) DEM");
  if (g.body.semiMajorM <= 0) return fail("render: DEM body '" + g.body.name + "' has no radius");

  TerrainScene s;
  s.georef_ = g;
  s.planetary_ = options.planetary;
  s.metresPerUnit_ = metresPerCrsUnitOf(g);
  s.centreLonLat_ = centreLonLatOf(g);
  s.heights_ = dem.values;
  float lo = std::numeric_limits<float>::infinity(), hi = -lo;
  for (float v : s.heights_.data) {
    if (gis::isNoData(v)) continue;
    lo = std::min(lo, v);
    hi = std::max(hi, v);
  }
  if (!(lo <= hi)) return fail("render: DEM has no valid elevation");
  const bool wrap = options.planetary && isGlobalInLongitude(g);
  if (options.voids == VoidMode::kHoles && std::any_of(s.heights_.data.begin(), s.heights_.data.end(), gis::isNoData)) {
    std::vector<float> mask(s.heights_.size());
    for (size_t i = 0; i < mask.size(); ++i) mask[i] = gis::isNoData(s.heights_.data[i]) ? 0.0f : 1.0f;
    s.voidMask_ = gl::Texture::create2D(gl::TextureFormat::kR32F, s.width(), s.height(), 1);
    s.voidMask_.upload(mask.data());
    if (wrap) s.voidMask_.setWrap(gl::Wrap::kRepeat, gl::Wrap::kClampToEdge);
  }
  STRATA_TRY(s.voids_, gis::fillVoids(s.heights_));
  s.minM_ = lo;
  s.maxM_ = hi;
  s.height_ = gl::Texture::create2D(gl::TextureFormat::kR32F, s.width(), s.height(), 0);
  s.height_.upload(s.heights_.data.data());
  s.height_.generateMipmap();
  if (options.planetary && isGlobalInLongitude(g)) s.height_.setWrap(gl::Wrap::kRepeat, gl::Wrap::kClampToEdge);
  return s;
}

Result<TerrainScene> TerrainScene::createStreamed(strata::terrain::TileStore store, const StreamParams& params,
                                                  const SceneOptions& options) {
  const gis::Georef g = store.desc().georef;
  if (options.planetary && !g.geographic) return fail("render: planetary mode needs a geographic (lon/lat) store");
  if (!g.transform.isNorthUp() || g.transform.c[1] <= 0 || g.transform.c[5] >= 0) {
    return fail("render: store " + store.dir().string() +
                ": geotransform is not north-up (rotation terms or axis signs)");
  }
  if (g.body.semiMajorM <= 0) return fail("render: store body '" + g.body.name + "' has no radius");
  if (g.width < 2 || g.height < 2) return fail("render: store " + store.dir().string() + " has fewer than 2x2 cells");
  STRATA_TRY(auto streamed,
             StreamedElevation::create(std::move(store), params, options.planetary && isGlobalInLongitude(g)));
  TerrainScene s;
  s.georef_ = g;
  s.planetary_ = options.planetary;
  s.metresPerUnit_ = metresPerCrsUnitOf(g);
  s.centreLonLat_ = centreLonLatOf(g);
  s.minM_ = streamed->minElevationM();
  s.maxM_ = streamed->maxElevationM();
  s.streamed_ = std::move(streamed);
  return s;
}

Status TerrainScene::setWaterDepth(const gis::Grid<float>& depthM) {
  if (streamed_) return fail("render: water depth is drawn on whole-DEM scenes only (this one is streamed)");
  if (depthM.width != width() || depthM.height != height()) {
    return fail("render: water depth grid " + std::to_string(depthM.width) + "x" + std::to_string(depthM.height) +
                " differs from the DEM's " + std::to_string(width()) + "x" + std::to_string(height()));
  }
  water_ = gl::Texture::create2D(gl::TextureFormat::kR32F, width(), height(), 0);
  water_.upload(depthM.data.data());
  water_.generateMipmap();
  return {};
}

Status TerrainScene::setSuspendedSediment(const gis::Grid<float>& sedimentM) {
  if (streamed_) return fail("render: suspended sediment is drawn on whole-DEM scenes only (this one is streamed)");
  if (sedimentM.width != width() || sedimentM.height != height()) {
    return fail("render: suspended sediment grid " + std::to_string(sedimentM.width) + "x" +
                std::to_string(sedimentM.height) + " differs from the DEM's " + std::to_string(width()) + "x" +
                std::to_string(height()));
  }
  sediment_ = gl::Texture::create2D(gl::TextureFormat::kR32F, width(), height(), 0);
  sediment_.upload(sedimentM.data.data());
  sediment_.generateMipmap();
  return {};
}

void TerrainScene::copyWaterState(const gl::Buffer& state, int x, int y, int w, int h) {
  STRATA_CHECK(!streamed_ && x >= 0 && y >= 0 && w > 0 && h > 0 && x + w <= width() && y + h <= height() &&
               state.size() >= size_t(w) * size_t(h) * 16)
      << "copyWaterState: streamed scene, window outside the grid, or a buffer too small";
  if (!waterState_) {
    waterState_ = gl::Texture::create2D(gl::TextureFormat::kRGBA32F, width(), height(), 0);
    clearWaterState();
  }
  // The buffer was written by compute shaders: make those writes visible to the unpack.
  gl::memoryBarrier(gl::Barrier::kPixelBuffer);
  waterState_.uploadFrom(state, 0, x, y, w, h);
  waterState_.generateMipmap();
}

void TerrainScene::clearWaterState() {
  if (!waterState_) return;
  waterState_.clear(0);
  waterState_.generateMipmap();
}

void TerrainScene::writeHeights(int x, int y, const gis::Grid<float>& patch) {
  STRATA_CHECK(x >= 0 && y >= 0 && x + patch.width <= width() && y + patch.height <= height())
      << "writeHeights: patch outside the grid";
  height_.upload(patch.data.data(), 0, x, y, patch.width, patch.height);
  height_.generateMipmap();
  for (int j = 0; j < patch.height; ++j) {
    std::copy_n(&patch.data[size_t(j) * size_t(patch.width)], patch.width, &heights_.at(x, y + j));
  }
  shadowsStale_ = shadowSun_.has_value();
}

void TerrainScene::heightsEditedOnGpu(int x, int y, int w, int h) {
  STRATA_CHECK(x >= 0 && y >= 0 && w > 0 && h > 0 && x + w <= width() && y + h <= height())
      << "heightsEditedOnGpu: window outside the grid";
  height_.generateMipmap();
  const auto window = height_.readRegion<float>(x, y, w, h);
  for (int j = 0; j < h; ++j) std::copy_n(&window[size_t(j) * size_t(w)], w, &heights_.at(x, y + j));
  shadowsStale_ = shadowSun_.has_value();
}

void TerrainScene::writeLayers(int x, int y, int w, int h, const std::vector<float>& thicknessM) {
  STRATA_CHECK(layers_ && x >= 0 && y >= 0 && x + w <= width() && y + h <= height() &&
               thicknessM.size() == size_t(w) * size_t(h) * 4)
      << "writeLayers: no layers, or the window is outside the grid";
  layers_.upload(thicknessM.data(), 0, x, y, w, h);
  layers_.generateMipmap();
}

std::vector<float> TerrainScene::layersEditedOnGpu(int x, int y, int w, int h) {
  STRATA_CHECK(layers_ && x >= 0 && y >= 0 && w > 0 && h > 0 && x + w <= width() && y + h <= height())
      << "layersEditedOnGpu: no layers, or the window is outside the grid";
  layers_.generateMipmap();
  return layers_.readRegion<float>(x, y, w, h);
}

Status TerrainScene::setMaterialLayers(const std::vector<gis::Grid<float>>& thicknessM) {
  if (streamed_) return fail("render: material layers are drawn on whole-DEM scenes only (this one is streamed)");
  if (thicknessM.empty() || thicknessM.size() > 4) {
    return fail("render: " + std::to_string(thicknessM.size()) + " material layers given, need 1 to 4");
  }
  std::vector<float> packed(size_t(width()) * size_t(height()) * 4, 0.0f);
  for (size_t k = 0; k < thicknessM.size(); ++k) {
    const auto& layer = thicknessM[k];
    if (layer.width != width() || layer.height != height()) {
      return fail("render: material layer " + std::to_string(k) + " grid " + std::to_string(layer.width) + "x" +
                  std::to_string(layer.height) + " differs from the DEM's");
    }
    for (size_t i = 0; i < layer.size(); ++i) packed[i * 4 + k] = layer.data[i];
  }
  layers_ = gl::Texture::create2D(gl::TextureFormat::kRGBA32F, width(), height(), 0);
  layers_.upload(packed.data());
  layers_.generateMipmap();
  return {};
}

Status TerrainScene::setDrape(const DrapeImage& image) {
  // The texels must cover the scene's extent (loadDrape warps onto it: on the scene's cells, or
  // at most 8192 texels a side over a larger or streamed scene), whatever their size.
  const auto& a = georef_.transform;
  const auto& b = image.georef.transform;
  const double tol = 1e-6 * std::max(std::abs(a.c[1]), std::abs(a.c[5]));
  const bool covers = image.georef.width == image.width && image.georef.height == image.height &&
                      std::abs(a.x(0, 0) - b.x(0, 0)) <= tol && std::abs(a.y(0, 0) - b.y(0, 0)) <= tol &&
                      std::abs(a.x(width(), height()) - b.x(image.width, image.height)) <= tol &&
                      std::abs(a.y(width(), height()) - b.y(image.width, image.height)) <= tol;
  if (image.width < 1 || image.height < 1 || image.rgba.size() != size_t(image.width) * size_t(image.height) * 4 ||
      !covers) {
    return fail("render: drape of " + std::to_string(image.width) + "x" + std::to_string(image.height) +
                " texels does not cover the scene's extent (" + std::to_string(width()) + "x" +
                std::to_string(height()) + " cells; loadDrape makes it so)");
  }
  drape_ = gl::Texture::create2D(gl::TextureFormat::kRGBA8, image.width, image.height, 0);
  drape_.upload(image.rgba.data());
  drape_.generateMipmap();
  return {};
}

// Streamed scenes compute shadows and the graticule's lon/lat once over the whole terrain, on
// the store's finest level at most this many cells a side.
constexpr int kOverviewSide = 2048;

Result<gis::Raster> TerrainScene::streamedOverview() const {
  STRATA_CHECK(streamed_) << "streamedOverview on a whole-DEM scene";
  return streamed_->overview(kOverviewSide);
}

void TerrainScene::setOverviewGrid(const gis::Georef& grid) {
  // uv spans the scene's cells; an overview level's cells may reach past them (ceil(n / 2^L)).
  overviewUvScale_ = glm::vec2(float(double(width()) * georef_.transform.c[1] / (grid.width * grid.transform.c[1])),
                               float(double(height()) * georef_.transform.c[5] / (grid.height * grid.transform.c[5])));
}

Status TerrainScene::castShadows(const SunSpec& sun, float exaggeration) {
  std::optional<gis::Raster> over;
  if (streamed_) {
    STRATA_TRY(over, streamedOverview());
  }
  const gis::Georef& grid = over ? over->georef : georef_;
  const gis::Grid<float> lit =
      render::castShadows(over ? over->values : heights_, grid, sun, exaggeration, metresPerUnit_);
  setOverviewGrid(grid);
  shadow_ = gl::Texture::create2D(gl::TextureFormat::kR32F, lit.width, lit.height, 0);
  shadow_.upload(lit.data.data());
  shadow_.generateMipmap();
  shadowSun_ = sun;
  shadowExaggeration_ = exaggeration;
  shadowsStale_ = false;
  return {};
}

Status TerrainScene::recastShadows() { return shadowSun_ ? castShadows(*shadowSun_, shadowExaggeration_) : Status{}; }

Status TerrainScene::enableGraticule() {
  // Lon/lat at the cell centres (of the overview level on a streamed scene, bilinear between).
  gis::Georef grid = georef_;
  if (streamed_) grid = streamed_->overviewGrid(kOverviewSide);
  const int gw = grid.width, gh = grid.height;
  const size_t n = size_t(gw) * size_t(gh);
  std::vector<double> x(n), y(n);
  const auto& t = grid.transform;
  for (int r = 0; r < gh; ++r) {
    for (int c = 0; c < gw; ++c) {
      x[size_t(r) * size_t(gw) + size_t(c)] = t.x(c + 0.5, r + 0.5);
      y[size_t(r) * size_t(gw) + size_t(c)] = t.y(c + 0.5, r + 0.5);
    }
  }
  if (!georef_.geographic) {
    STRATA_TRY(auto ct, gis::CrsTransform::toGeographic(georef_));
    (void)ct.transform(n, x.data(), y.data());  // cells without a lon/lat stay NaN: no line there
  }
  std::vector<float> packed(n * 2);
  for (size_t i = 0; i < n; ++i) packed[i * 2] = float(x[i]), packed[i * 2 + 1] = float(y[i]);
  setOverviewGrid(grid);
  lonLat_ = gl::Texture::create2D(gl::TextureFormat::kRG32F, gw, gh, 1);
  lonLat_.upload(packed.data());
  return {};
}

double TerrainScene::heightAt(double lon, double lat) const {
  const auto& c = georef_.transform.c;
  if (isGlobalInLongitude(georef_)) lon = c[0] + std::fmod(std::fmod(lon - c[0], 360.0) + 360.0, 360.0);
  const double x = std::clamp((lon - c[0]) / c[1] - 0.5, 0.0, double(width() - 1));
  const double y = std::clamp((lat - c[3]) / c[5] - 0.5, 0.0, double(height() - 1));
  const int i = std::min(int(x), width() - 2), j = std::min(int(y), height() - 2);
  const double fx = x - i, fy = y - j;
  std::array<float, 4> q;
  if (streamed_) {
    q = streamed_->cellQuad(i, j);
  } else {
    q = {heights_.at(i, j), heights_.at(i + 1, j), heights_.at(i, j + 1), heights_.at(i + 1, j + 1)};
  }
  return (1 - fy) * ((1 - fx) * q[0] + fx * q[1]) + fy * ((1 - fx) * q[2] + fx * q[3]);
}

double TerrainScene::gridSurfaceAt(double u, double v) const {
  STRATA_CHECK(!streamed_) << "gridSurfaceAt on a streamed scene";
  const double x = std::clamp(u * width() - 0.5, 0.0, double(width() - 1));
  const double y = std::clamp(v * height() - 0.5, 0.0, double(height() - 1));
  const int i = std::min(int(x), width() - 2), j = std::min(int(y), height() - 2);
  const double fx = x - i, fy = y - j;
  const auto& h = heights_;
  const double h00 = h.at(i, j), h10 = h.at(i + 1, j), h01 = h.at(i, j + 1), h11 = h.at(i + 1, j + 1);
  // Cell split along (i,j)-(i+1,j+1), as GridRenderer's index buffer.
  if (fx >= fy) return h00 + fx * (h10 - h00) + fy * (h11 - h10);
  return h00 + fy * (h01 - h00) + fx * (h11 - h01);
}

// ---- Frame geometry ----------------------------------------------------------------------------

std::optional<glm::dvec3> groundEnuAt(const FrameGeometry& f, const OffscreenTarget& target, int px, int py) {
  const int w = target.width(), h = target.height();
  if (px < 0 || py < 0 || px >= w || py >= h) return std::nullopt;
  const float d = target.depthAt(px, py);
  if (!(d > 0)) return std::nullopt;
  // Reversed-Z: eye-space distance along the axis is near / depth; unproject the pixel centre.
  const double dist = f.nearM / double(d);
  const glm::dvec4 ndc(2.0 * (px + 0.5) / w - 1.0, 1.0 - 2.0 * (py + 0.5) / h, 1.0, 1.0);  // on the near plane
  glm::dvec4 eye = glm::inverse(f.projection) * ndc;
  eye /= eye.w;
  const glm::dvec3 eyeDir = glm::dvec3(eye) / -eye.z * dist;  // on the plane z_eye = -dist
  const glm::dvec3 enu = glm::dvec3(glm::inverse(f.view) * glm::dvec4(eyeDir, 0.0));
  if (!std::isfinite(enu.x) || !std::isfinite(enu.y) || !std::isfinite(enu.z)) return std::nullopt;
  return enu;
}

glm::dmat4 reversedInfinitePerspective(double fovYRad, double aspect, double nearM) {
  const double f = 1.0 / std::tan(0.5 * fovYRad);
  glm::dmat4 m(0.0);
  m[0][0] = f / aspect;
  m[1][1] = f;
  m[2][3] = -1.0;
  m[3][2] = nearM;
  return m;
}

FrameGeometry frameGeometry(const TerrainScene& scene, const CameraPose& camera, const Shading& shading, int width,
                            int height) {
  const auto& g = scene.georef();
  const auto& c = g.transform.c;
  const double w = scene.width(), h = scene.height(), radius = scene.radiusM();
  FrameGeometry f;
  if (g.geographic) {
    const double mPerDegLon = radius * std::cos(camera.lat * kDeg) * kDeg, mPerDegLat = radius * kDeg;
    f.uvPerMetre = {1.0 / (c[1] * w * mPerDegLon), 1.0 / (c[5] * h * mPerDegLat)};
  } else {
    const glm::dvec2 k = scene.metresPerCrsUnit();
    f.uvPerMetre = {1.0 / (c[1] * w * k.x), 1.0 / (c[5] * h * k.y)};
  }
  f.uvCam = {(camera.lon - c[0]) / c[1] / w, (camera.lat - c[3]) / c[5] / h};
  if (scene.planetary() && isGlobalInLongitude(g)) f.uvCam.x -= std::floor(f.uvCam.x);
  f.groundM = shading.exaggeration * scene.heightAt(camera.lon, camera.lat);
  f.camZ = camera.heightM;
  f.heightAboveGroundM = std::max(camera.heightM - f.groundM, 0.0);
  f.exaggeration = shading.exaggeration;
  f.lonRad = camera.lon * kDeg;
  f.latRad = camera.lat * kDeg;
  // The ellipsoid as the auxiliary sphere of radius a squashed along the polar axis: the
  // nadir's reduced latitude, the pole and the ellipsoid normal in the sphere's nadir frame,
  // and the rotation that makes that normal the viewer's up.
  const double squash = 1.0 - g.body.flattening;
  f.reducedLatRad = std::atan2(squash * std::sin(f.latRad), std::cos(f.latRad));
  f.poleAux = {0.0, std::cos(f.reducedLatRad), std::sin(f.reducedLatRad)};
  glm::dvec3 q0(0.0, 0.0, radius);
  q0 -= g.body.flattening * glm::dot(q0, f.poleAux) * f.poleAux;
  f.nadirNormal = glm::normalize(q0 + (1.0 / (squash * squash) - 1.0) * glm::dot(q0, f.poleAux) * f.poleAux);
  const double theta = std::atan2(f.nadirNormal.y, f.nadirNormal.z);
  f.frameRot = glm::dmat3(1, 0, 0, 0, std::cos(theta), std::sin(theta), 0, -std::sin(theta), std::cos(theta));
  for (double u : {0.0, 1.0}) {
    for (double v : {0.0, 1.0}) {
      const glm::dvec2 m = (glm::dvec2(u, v) - f.uvCam) / f.uvPerMetre;
      f.farthestM = std::max(f.farthestM, glm::length(m));
    }
  }

  const double hd = camera.headingDeg * kDeg, p = camera.pitchDeg * kDeg;
  const glm::dvec3 forward(std::sin(hd) * std::cos(p), std::cos(hd) * std::cos(p), std::sin(p));
  const glm::dvec3 up = std::abs(camera.pitchDeg) > 89.9
                            ? glm::dvec3(std::sin(hd), std::cos(hd), 0.0) * (camera.pitchDeg < 0 ? 1.0 : -1.0)
                            : glm::dvec3(0, 0, 1);
  f.view = glm::lookAt(glm::dvec3(0.0), forward, up);
  // The near plane at half the clearance over the highest terrain (at least a tenth of the
  // height over the ground, at least 5 cm): reversed float depth keeps precision at any range.
  const double clearance = camera.heightM - shading.exaggeration * scene.maxElevationM();
  f.nearM = std::max(0.05, 0.5 * std::max(clearance, 0.2 * f.heightAboveGroundM));
  f.projection = reversedInfinitePerspective(camera.fovYDeg * kDeg, double(width) / double(height), f.nearM);
  return f;
}

// ---- OffscreenTarget ---------------------------------------------------------------------------

Result<OffscreenTarget> OffscreenTarget::create(int width, int height, int samples) {
  if (width <= 0 || height <= 0 || width > 16384 || height > 16384) {
    return fail("render: image size " + std::to_string(width) + "x" + std::to_string(height) + " out of range");
  }
  if (samples < 1 || samples > 8) return fail("render: " + std::to_string(samples) + " samples a pixel: 1 to 8");
  OffscreenTarget t;
  t.width_ = width;
  t.height_ = height;
  t.samples_ = samples;
  if (samples > 1) {
    t.msColour_ = gl::Texture::create2DMultisample(gl::TextureFormat::kRGBA8, width, height, samples);
    t.msElevation_ = gl::Texture::create2DMultisample(gl::TextureFormat::kR32F, width, height, samples);
    t.msDepth_ = gl::Texture::create2DMultisample(gl::TextureFormat::kDepth32F, width, height, samples);
    t.msFbo_ = gl::Framebuffer::create();
    t.msFbo_.attachColour(0, t.msColour_);
    t.msFbo_.attachColour(1, t.msElevation_);
    t.msFbo_.attachDepth(t.msDepth_);
    STRATA_TRY_STATUS(t.msFbo_.check());
  }
  t.colour_ = gl::Texture::create2D(gl::TextureFormat::kRGBA8, width, height, 1);
  t.elevation_ = gl::Texture::create2D(gl::TextureFormat::kR32F, width, height, 1);
  t.depth_ = gl::Texture::create2D(gl::TextureFormat::kDepth32F, width, height, 1);
  t.fbo_ = gl::Framebuffer::create();
  t.fbo_.attachColour(0, t.colour_);
  t.fbo_.attachColour(1, t.elevation_);
  t.fbo_.attachDepth(t.depth_);
  STRATA_TRY_STATUS(t.fbo_.check());
  t.colourFbo_ = gl::Framebuffer::create();
  t.colourFbo_.attachColour(0, t.colour_);
  STRATA_TRY_STATUS(t.colourFbo_.check());
  return t;
}

void OffscreenTarget::bind() const { (samples_ > 1 ? msFbo_ : fbo_).bind(); }

void OffscreenTarget::resolve() const {
  if (samples_ > 1) msFbo_.resolveTo(fbo_, {width_, height_});
}
void OffscreenTarget::bindColourOnly() const { colourFbo_.bind(); }

void OffscreenTarget::clear(const glm::vec4& sky) const {
  const gl::Framebuffer& f = samples_ > 1 ? msFbo_ : fbo_;
  f.clearColour(0, sky);
  f.clearColour(1, glm::vec4(std::numeric_limits<float>::quiet_NaN(), 0, 0, 0));
  f.clearDepth(0.0f);
}

namespace {
template <class T>
std::vector<T> flipRows(std::vector<T> pixels, int width, int height, int channels) {
  const size_t row = size_t(width) * size_t(channels);
  for (int y = 0; y < height / 2; ++y) {
    std::swap_ranges(pixels.begin() + ptrdiff_t(size_t(y) * row), pixels.begin() + ptrdiff_t(size_t(y + 1) * row),
                     pixels.begin() + ptrdiff_t(size_t(height - 1 - y) * row));
  }
  return pixels;
}
}  // namespace

std::vector<uint8_t> OffscreenTarget::colour() const { return flipRows(colour_.read<uint8_t>(), width_, height_, 4); }
std::vector<float> OffscreenTarget::depth() const { return flipRows(depth_.read<float>(), width_, height_, 1); }
float OffscreenTarget::depthAt(int x, int y) const {
  STRATA_CHECK(x >= 0 && y >= 0 && x < width_ && y < height_) << "depthAt(" << x << ", " << y << ") outside the target";
  return depth_.readRegion<float>(x, height_ - 1 - y, 1, 1)[0];
}

void OffscreenTarget::blitColourToWindow(int width, int height) const {
  fbo_.blitColourToWindow(0, {width_, height_}, {width, height},
                          width == width_ && height == height_ ? gl::Filter::kNearest : gl::Filter::kLinear);
}

std::vector<float> OffscreenTarget::elevation() const { return flipRows(elevation_.read<float>(), width_, height_, 1); }

// ---- RingRenderer ------------------------------------------------------------------------------

double RingLayout::radiusAt(double rho, bool planetary, double radiusM) const {
  const double a = rho * alphaMax;
  if (!planetary) return softHeightM * std::tan(a);
  const double d = radiusM + softHeightM, k = softHeightM * (2 * radiusM + softHeightM);
  const double cs = std::cos(a), sn = std::sin(a);
  const double t = k / (d * cs + std::sqrt(std::max(d * d * cs * cs - k, 0.0)));
  return radiusM * std::atan2(t * sn, d - t * cs);
}

Result<std::unique_ptr<RingRenderer>> RingRenderer::create(const RingParams& params) {
  if (params.circles < 1 || params.circles > 2048) {
    return fail("render: ring circles " + std::to_string(params.circles) + " out of range 1..2048");
  }
  if (params.maxSamples < 1 || params.maxSamples > 64) {
    return fail("render: ring maxSamples " + std::to_string(params.maxSamples) + " out of range 1..64");
  }
  if (!(params.softFactor > 0) || !(params.softMinM >= 0)) {
    return fail("render: ring softening factor must be positive and its floor not negative");
  }
  if (!(params.rangeM >= 0)) return fail("render: ring view range must not be negative");
  STRATA_TRY(auto program, gl::Program::graphics("render/shaders/ring.vert", "render/shaders/terrain.frag",
                                                 gl::definesFor(slots::kAll)));
  auto r = std::make_unique<RingRenderer>();
  r->params_ = params;
  r->program_ = std::move(program);
  STRATA_TRY(r->sky_, detail::createSkyProgram());
  const auto mesh = RingMesh::build(params.circles);
  r->vertices_ = gl::Buffer::from(std::span<const glm::vec2>(mesh.vertices), gl::BufferStorage::kImmutable);
  r->indices_ = gl::Buffer::from(std::span<const uint32_t>(mesh.strip), gl::BufferStorage::kImmutable);
  r->indexCount_ = int(mesh.strip.size());
  r->vao_ = gl::VertexArray::forMesh(r->vertices_, 2, r->indices_);
  return r;
}

RingLayout RingRenderer::layout(const TerrainScene& scene, const FrameGeometry& frame) const {
  RingLayout l;
  const double radius = scene.radiusM();
  // The view range: the renderer's, else all the terrain there is to see: the DEM's farthest
  // corner on a plane; on a body, the horizon of the viewer over the lowest terrain plus that of
  // the highest summit (nothing beyond can show above the horizon).
  double range = params_.rangeM;
  if (!(range > 0)) {
    if (scene.planetary()) {
      const double lo = scene.minElevationM() * frame.exaggeration, hi = scene.maxElevationM() * frame.exaggeration;
      range = std::sqrt(2 * radius * std::max(frame.camZ - lo, 1.0)) + std::sqrt(2 * radius * std::max(hi - lo, 1.0));
    } else {
      range = frame.farthestM;
    }
  }
  l.rangeM = range;
  // f(h) = max(K h, floor), the floor a twelfth of the range unless given (docs/render-rings.md).
  const double softMin = params_.softMinM > 0 ? params_.softMinM : range / 12;
  l.softHeightM = std::max({params_.softFactor * frame.heightAboveGroundM, softMin, 1.0});
  if (scene.planetary()) {
    // Up to the horizon of the sphere seen from the softened viewpoint, or to the view range.
    const double d = radius + l.softHeightM;
    l.alphaMax = std::asin(radius / d);
    if (const double gamma = range / radius; gamma < std::acos(radius / d)) {
      // The ray to the point at great-circle angle gamma, nearer than the horizon.
      l.alphaMax = std::atan2(radius * std::sin(gamma), d - radius * std::cos(gamma));
    }
    const auto& c = scene.georef().transform.c;
    l.texelM = radius * std::abs(c[5]) * kDeg;
  } else {
    l.alphaMax = std::atan(range / l.softHeightM);
    l.texelM = std::min(std::abs(1.0 / (frame.uvPerMetre.x * scene.width())),
                        std::abs(1.0 / (frame.uvPerMetre.y * scene.height())));
  }
  l.firstSpacingM = l.radiusAt(1.0 / params_.circles, scene.planetary(), radius);
  return l;
}

Status RingRenderer::draw(const TerrainScene& scene, const CameraPose& camera, const Shading& shading,
                          const OffscreenTarget& target, const glm::dmat4* observer) {
  const FrameGeometry frame = frameGeometry(scene, camera, shading, target.width(), target.height());
  const RingLayout l = layout(scene, frame);
  detail::FrameState state(target, shading.sky);
  detail::drawSky(sky_, vao_, scene, frame, shading, observer ? *observer : frame.viewProj());
  const auto& p = program_;
  STRATA_TRY_STATUS(detail::setCommonUniforms(p, scene, frame, shading, observer ? *observer : frame.viewProj()));
  p.set("uCircles", float(params_.circles));
  p.set("uAlphaMax", float(l.alphaMax));
  p.set("uSoftH", float(l.softHeightM));
  p.set("uSoftK", float(l.softHeightM * (2 * scene.radiusM() + l.softHeightM)));
  p.set("uFirstSpacingM", float(l.firstSpacingM));
  p.set("uTexelM", float(l.texelM));
  p.set("uMaxSamples", params_.maxSamples);
  p.set("uFlags", (params_.multiSample ? 1 : 0) | (params_.mipSelect ? 2 : 0));
  p.use();
  vao_.drawElements(gl::Primitive::kTriangleStrip, indexCount_);
  return {};
}

// ---- GridRenderer ------------------------------------------------------------------------------

Result<std::unique_ptr<GridRenderer>> GridRenderer::create() {
  STRATA_TRY(auto program, gl::Program::graphics("render/shaders/grid.vert", "render/shaders/terrain.frag",
                                                 gl::definesFor(slots::kAll)));
  auto r = std::make_unique<GridRenderer>();
  r->program_ = std::move(program);
  STRATA_TRY(r->sky_, detail::createSkyProgram());
  r->vao_ = gl::VertexArray::create();
  return r;
}

Status GridRenderer::draw(const TerrainScene& scene, const CameraPose& camera, const Shading& shading,
                          const OffscreenTarget& target, const glm::dmat4* observer) {
  if (scene.planetary()) return fail("render: the brute-force grid renderer draws planar scenes only");
  if (scene.streamed()) return fail("render: the brute-force grid renderer draws whole-DEM scenes only (not streamed)");
  if (gridW_ != scene.width() || gridH_ != scene.height()) {
    gridW_ = scene.width();
    gridH_ = scene.height();
    std::vector<uint32_t> idx;
    idx.reserve(size_t(gridW_ - 1) * size_t(gridH_ - 1) * 6);
    for (int j = 0; j + 1 < gridH_; ++j) {
      for (int i = 0; i + 1 < gridW_; ++i) {
        const uint32_t a = uint32_t(j * gridW_ + i), b = a + 1, c = a + uint32_t(gridW_), d = c + 1;
        // Split along (i,j)-(i+1,j+1), as TerrainScene::gridSurfaceAt.
        idx.insert(idx.end(), {a, b, d, a, d, c});
      }
    }
    indices_ = gl::Buffer::from(std::span<const uint32_t>(idx), gl::BufferStorage::kImmutable);
    indexCount_ = int(idx.size());
    vao_.setIndices(indices_);
  }
  const FrameGeometry frame = frameGeometry(scene, camera, shading, target.width(), target.height());
  detail::FrameState state(target, shading.sky);
  detail::drawSky(sky_, vao_, scene, frame, shading, observer ? *observer : frame.viewProj());
  STRATA_TRY_STATUS(
      detail::setCommonUniforms(program_, scene, frame, shading, observer ? *observer : frame.viewProj()));
  program_.use();
  vao_.drawElements(gl::Primitive::kTriangles, indexCount_);
  return {};
}

}  // namespace strata::render
