#pragma once
// Terrain renderers behind one interface: the concentric-ring renderer (RingRenderer, the fixed
// polar mesh displaced in the vertex shader) and the brute-force full grid (GridRenderer, the
// reference); the sliding sampling grid (sliding_grid.hpp) is the third. All draw a TerrainScene
// (a DEM on the GPU) seen from a CameraPose into an OffscreenTarget (colour RGBA8, reversed-Z
// float depth, elevation r32f). The maths: docs/render-rings.md.

#include <array>
#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <glm/glm.hpp>

#include <strata/core/result.hpp>
#include <strata/gis/raster.hpp>
#include <strata/gl/objects.hpp>
#include <strata/render/atmosphere.hpp>
#include <strata/render/colour_ramp.hpp>
#include <strata/render/drape.hpp>
#include <strata/render/ring_mesh.hpp>
#include <strata/render/streamed_elevation.hpp>
#include <strata/render/sun.hpp>

namespace strata::render {

/// Where the viewer is and where it looks.
struct CameraPose {
  double lon = 0;         ///< geographic DEM: longitude (deg); projected DEM: easting in the CRS (m)
  double lat = 0;         ///< geographic DEM: latitude (deg); projected DEM: northing in the CRS (m)
  double heightM = 1000;  ///< above the datum (planetary: above the body's ellipsoid) (m)
  double headingDeg = 0;  ///< view direction, clockwise from north (deg)
  double pitchDeg = -30;  ///< view direction above the horizontal (deg; negative looks down)
  double fovYDeg = 45;    ///< vertical field of view (deg)
};

/// Colour ramp over elevation: Ramp is Shading::ramp (a user's gdaldem color-relief file).
enum class Palette { Hypsometric, Grey, Rust, Ramp };
/// A body's own colours: grey (albedo-like) for the Moon, rust for Mars, hypsometric otherwise.
Palette paletteFor(const gis::Body& body);

/// How the terrain looks; uniform over a frame.
struct Shading {
  Palette palette = Palette::Hypsometric;  ///< elevation tint
  std::optional<glm::vec2> tintRangeM;     ///< elevations at the tint's ends (m); default: the scene's
                                           ///< range, from sea level up when seaLevelM is set
  float exaggeration = 1;                  ///< vertical exaggeration
  glm::vec3 sunDir = glm::normalize(glm::vec3(-0.5f, 0.4f, 0.6f));  ///< towards the sun, viewer's ENU frame
  glm::vec4 sky{0.62f, 0.74f, 0.88f, 1.0f};                         ///< background and haze colour
  float fogM = 0;                                                   ///< haze distance (m); 0: none
  std::optional<float> seaLevelM;                                   ///< water wherever the terrain is below (m)
  float waterDepthScaleM = 20;                ///< depth at which water is 1/e of the way to deep blue (m)
  float waterFadeM = 0;                       ///< water shallower than this fades in (m); 0: drawn at once
  glm::vec3 siltColour{0.62f, 0.50f, 0.32f};  ///< water colour at high suspended-sediment concentration
  float siltConcentration = 0.01f;  ///< concentration s / h at which water is 1 - 1/e of the way to siltColour
  float layerOpaqueM = 0.5f;        ///< thickness at which a layer hides 1/e of what is below (m)
  float drapeOpacity = 1;  ///< how much a draped raster (TerrainScene::setDrape) hides the tint, times its alpha
  /// Lines of longitude and latitude this many degrees apart (TerrainScene::enableGraticule); 0: none.
  double graticuleDeg = 0;
  /// The point (lon, lat, deg) where the sun stands overhead: the sun is then fixed on the body
  /// and `sunDir` is derived each frame in the viewer's frame (at the viewer's place on a
  /// geographic DEM, at the DEM's centre on a projected one), so a body shows its night side.
  std::optional<glm::dvec2> subsolarLonLat;
  float ambient = 0.25f;  ///< light on surfaces facing away from the sun or in shadow, 0 to 1
  ColourRamp ramp;        ///< the elevation colours when palette is Palette::Ramp
  /// The body's air (atmosphereFor): a sky along each pixel's ray and aerial perspective on the
  /// terrain instead of the flat `sky` colour; none: the flat sky and `fogM`'s haze.
  std::optional<Atmosphere> atmosphere;
  std::array<glm::vec3, 4> layerColours{glm::vec3(0.76f, 0.70f, 0.50f), glm::vec3(0.45f, 0.35f, 0.25f),
                                        glm::vec3(0.30f, 0.45f, 0.20f), glm::vec3(0.9f, 0.9f, 0.95f)};
};

/// How a DEM is drawn.
/// How a DEM's voids (no-data cells, e.g. SRTM's on steep summits) are drawn: never as pits.
enum class VoidMode {
  kFill,   ///< filled from the valid cells around them (gis::fillVoids, GDAL's fill-nodata)
  kHoles,  ///< not drawn: the filled surface carries the vertices, fragments over voids are dropped
};

struct SceneOptions {
  /// Draw on the DEM's body (its ellipsoid: a sphere when the flattening is 0) instead of a
  /// tangent plane. Needs a geographic DEM.
  bool planetary = false;
  VoidMode voids = VoidMode::kFill;
};

/// A DEM on the GPU (r32f, full mip chain) plus the CPU copy for height queries, or (streamed)
/// a tile store's elevation around the viewer (StreamedElevation). Voids are filled from the
/// valid cells around them (gis::fillVoids) and drawn so or as holes (SceneOptions::voids).
class TerrainScene {
 public:
  static Result<TerrainScene> create(const gis::Raster& dem, const SceneOptions& options = {});
  /// Streams the elevation of a tile store (taken over): the renderers that support it (ring,
  /// sliding grid) move the stack to each frame's viewer and refill it within the per-frame
  /// budget before drawing. Planetary mode needs a geographic store; a global one then wraps
  /// across the seam. Water, material layers, heights() and gridSurfaceAt() are for whole-DEM
  /// scenes only.
  static Result<TerrainScene> createStreamed(strata::terrain::TileStore store, const StreamParams& params = {},
                                             const SceneOptions& options = {});

  /// Water depth (m) over the terrain, same grid as the DEM.
  Status setWaterDepth(const gis::Grid<float>& depthM);
  /// Suspended sediment (m of material per cell area), same grid as the DEM: tints the water
  /// drawn from setWaterDepth by the concentration s / h (Shading::siltColour, siltConcentration).
  Status setSuspendedSediment(const gis::Grid<float>& sedimentM);
  /// Water depth and suspended sediment straight from a simulation's state buffer (4 floats per
  /// cell: h, s, hu, hv, row-major, as sim::Simulation::stateBuffer) for the `w` x `h`
  /// cells at (x, y): a GPU-to-GPU copy into an rgba32f texture, no read-back. Cells outside keep
  /// what they had (zero at first; clearWaterState zeroes them). Drawn as setWaterDepth and
  /// setSuspendedSediment are.
  void copyWaterState(const gl::Buffer& state, int x, int y, int w, int h);
  void clearWaterState();
  /// Thicknesses (m) of up to four material layers (bottom first), same grid as the DEM;
  /// drawn with Shading::layerColours.
  Status setMaterialLayers(const std::vector<gis::Grid<float>>& thicknessM);
  /// A raster draped over the terrain (loadDrape, on this scene's grid): drawn over the elevation
  /// tint and the material layers, times its alpha and Shading::drapeOpacity, lit by the sun;
  /// water is drawn over it. On a streamed scene the drape covers the whole terrain at loadDrape's
  /// resolution (at most 8192 texels a side).
  Status setDrape(const DrapeImage& image);
  /// Cast shadows for `sun` at vertical exaggeration `exaggeration` (render::castShadows on the
  /// CPU, a lit-fraction texture the lighting multiplies): recast them when the sun, the
  /// exaggeration or the heights change. On a streamed scene they are cast once over the whole
  /// terrain on the store's finest level at most 2048 cells a side (StreamedElevation::overview):
  /// ridges cast the shadows of that level, not of the finer pages streamed around the viewer.
  Status castShadows(const SunSpec& sun, float exaggeration);
  /// Whether heights changed (writeHeights, heightsEditedOnGpu) since the shadows were cast.
  bool shadowsStale() const { return shadowsStale_; }
  /// Casts the shadows again for the sun and exaggeration they were last cast with; nothing if
  /// none were.
  Status recastShadows();
  /// Lon/lat of every cell centre on the GPU (through the CRS's own datum for projected DEMs), so
  /// that Shading::graticuleDeg can draw lines of longitude and latitude. On a streamed scene at
  /// the cells of the overview level (as castShadows), bilinear between them: exact on a
  /// geographic store, within the CRS's curvature over one such cell on a projected one.
  Status enableGraticule();
  /// Replaces the elevations of the `patch.width` x `patch.height` cells at (x, y) (m), on the
  /// GPU and in the CPU copy; the mip chain is rebuilt. The patch must lie inside the grid.
  void writeHeights(int x, int y, const gis::Grid<float>& patch);
  /// After GPU code wrote level 0 of heightTexture() in the window (x, y, w, h) (cells): rebuilds
  /// the mip chain and reads the window back into the CPU copy, so heightAt() sees the edit.
  void heightsEditedOnGpu(int x, int y, int w, int h);
  /// Replaces the layer thicknesses (4 per cell, bottom first) of `w` x `h` cells at (x, y) in
  /// the layer texture (setMaterialLayers first); the mip chain is rebuilt.
  void writeLayers(int x, int y, int w, int h, const std::vector<float>& thicknessM);
  /// After GPU code wrote level 0 of the layer texture in (x, y, w, h): rebuilds its mip chain and
  /// returns the window's thicknesses (4 per cell).
  std::vector<float> layersEditedOnGpu(int x, int y, int w, int h);

  /// Elevation (m) at a camera position (lon/lat or easting/northing as in CameraPose),
  /// bilinear between texel centres, clamped at the edges.
  double heightAt(double lon, double lat) const;
  /// The elevation of the full-grid reference surface (two triangles per cell, split along the
  /// cell's main diagonal, as GridRenderer draws it) at texture coordinates (u, v).
  double gridSurfaceAt(double u, double v) const;

  const gis::Georef& georef() const { return georef_; }
  const gis::Grid<float>& heights() const { return heights_; }  ///< empty when streamed
  bool planetary() const { return planetary_; }
  float minElevationM() const { return minM_; }
  /// No-data cells of the DEM (filled; drawn as holes when SceneOptions::voids says so).
  size_t voidCount() const { return voids_; }
  float maxElevationM() const { return maxM_; }
  int width() const { return georef_.width; }
  int height() const { return georef_.height; }
  /// The streamed elevation, or null for a whole-DEM scene.
  StreamedElevation* streamed() const { return streamed_.get(); }
  /// Radius of the body (m) used for the local frame and planetary mode.
  double radiusM() const { return georef_.body.semiMajorM; }
  /// Projected DEMs: ground metres per CRS unit east and north at the DEM's centre (the inverse
  /// of the projection's point scale: about 0.81 for Web Mercator over the Grand Canyon, 0.9990
  /// to 1.0004 across a UTM zone); the renderers, the camera and the brushes work in these ground
  /// metres. 1 for CRSs without a lon/lat base (local grids) and for geographic DEMs.
  glm::dvec2 metresPerCrsUnit() const { return metresPerUnit_; }

  const gl::Texture& heightTexture() const { return height_; }
  const gl::Texture* waterTexture() const { return water_ ? &water_ : nullptr; }
  const gl::Texture* layerTexture() const { return layers_ ? &layers_ : nullptr; }
  const gl::Texture* sedimentTexture() const { return sediment_ ? &sediment_ : nullptr; }
  const gl::Texture* waterStateTexture() const { return waterState_ ? &waterState_ : nullptr; }
  const gl::Texture* drapeTexture() const { return drape_ ? &drape_ : nullptr; }
  const gl::Texture* lonLatTexture() const { return lonLat_ ? &lonLat_ : nullptr; }
  const gl::Texture* shadowTexture() const { return shadow_ ? &shadow_ : nullptr; }
  /// The shadow and lon/lat textures' coordinates are uv times this: (1, 1) on a whole-DEM scene;
  /// on a streamed one their overview level may reach past the scene's cells.
  glm::vec2 overviewUvScale() const { return overviewUvScale_; }
  /// Lon/lat (deg) of the DEM's centre (its own for geographic DEMs; through its CRS otherwise,
  /// NaN where that fails).
  glm::dvec2 centreLonLat() const { return centreLonLat_; }
  /// r32f: 1 where the DEM has data, 0 over voids; null unless voids are drawn as holes.
  const gl::Texture* voidMaskTexture() const { return voidMask_ ? &voidMask_ : nullptr; }

 private:
  gis::Georef georef_;
  gis::Grid<float> heights_;
  bool planetary_ = false;
  float minM_ = 0, maxM_ = 0;
  glm::dvec2 metresPerUnit_{1.0, 1.0};
  size_t voids_ = 0;
  gl::Texture height_, water_, layers_, sediment_, waterState_, voidMask_, drape_, lonLat_, shadow_;
  glm::dvec2 centreLonLat_{0.0, 0.0};
  std::optional<SunSpec> shadowSun_;  // what the shadows were cast for
  float shadowExaggeration_ = 1;
  bool shadowsStale_ = false;
  std::shared_ptr<StreamedElevation> streamed_;
  glm::vec2 overviewUvScale_{1.0f, 1.0f};

  // A streamed scene's shadows and graticule are computed on its overview level
  // (StreamedElevation::overview); a whole-DEM scene's on its own cells.
  Result<gis::Raster> streamedOverview() const;
  void setOverviewGrid(const gis::Georef& grid);
};

/// Everything the shaders need about one frame's view, computed in double on the CPU.
struct FrameGeometry {
  glm::dmat4 view{1.0};             ///< viewer-relative ENU -> eye (rotation only)
  glm::dmat4 projection{1.0};       ///< reversed-Z infinite perspective (depth 1 at near, 0 at infinity)
  double nearM = 1;                 ///< near plane distance (m)
  double groundM = 0;               ///< elevation under the viewer (m, exaggerated)
  double heightAboveGroundM = 0;    ///< h (m)
  glm::dvec2 uvCam{0};              ///< texture coordinates under the viewer
  glm::dvec2 uvPerMetre{0};         ///< planar: d(u, v) / d(east, north)
  double camZ = 0;                  ///< planar: viewer z (m); planetary: height above the ellipsoid (m)
  double lonRad = 0, latRad = 0;    ///< planetary: the viewer's nadir (geodetic latitude)
  double reducedLatRad = 0;         ///< planetary: the nadir's reduced latitude, atan((1 - f) tan(lat))
  glm::dvec3 poleAux{0, 0, 1};      ///< planetary: polar axis in the auxiliary sphere's nadir frame
  glm::dvec3 nadirNormal{0, 0, 1};  ///< planetary: ellipsoid normal at the nadir, same frame
  glm::dmat3 frameRot{1.0};         ///< planetary: that frame -> the viewer's ENU frame (normal up)
  double farthestM = 0;             ///< planar: distance to the DEM's farthest corner (m)
  double exaggeration = 1;          ///< the shading's vertical exaggeration
  glm::dmat4 viewProj() const { return projection * view; }
};

/// Builds a frame's geometry for a `width` x `height` image.
FrameGeometry frameGeometry(const TerrainScene& scene, const CameraPose& camera, const Shading& shading, int width,
                            int height);

class OffscreenTarget;

/// The viewer-relative east-north-up offset (m) of the ground point drawn at pixel (px, py) of
/// `target` (y from the top row), unprojected from its depth; nullopt where nothing was drawn.
/// `f` is the geometry of the frame the target holds.
std::optional<glm::dvec3> groundEnuAt(const FrameGeometry& f, const OffscreenTarget& target, int px, int py);

/// Reversed-Z infinite perspective: clip z = near, w = -z_eye (depth = near / distance along the axis).
glm::dmat4 reversedInfinitePerspective(double fovYRad, double aspect, double nearM);

/// An offscreen framebuffer: colour RGBA8, elevation r32f (m, NaN where no terrain), depth
/// 32F (reversed: 1 at the near plane, 0 = nothing drawn).
class OffscreenTarget {
 public:
  /// `samples` > 1: drawn multisampled (MSAA: edges antialiased), resolved into the plain
  /// attachments when a renderer's draw ends; 1 to 8.
  static Result<OffscreenTarget> create(int width, int height, int samples = 1);
  int samples() const { return samples_; }
  /// Multisampled targets: averages the samples into the attachments that colour(), depth(),
  /// elevation(), depthAt() and blits read (the renderers call it at the end of each draw).
  void resolve() const;
  int width() const { return width_; }
  int height() const { return height_; }
  void bind() const;
  /// Binds the colour attachment alone, for overlays drawn over the picture (render::Overlay):
  /// the elevation and depth keep the terrain's values under them.
  void bindColourOnly() const;
  /// Clears colour to `sky`, depth to 0 and elevation to NaN.
  void clear(const glm::vec4& sky) const;
  /// Pixels, top row first.
  std::vector<uint8_t> colour() const;
  std::vector<float> depth() const;
  std::vector<float> elevation() const;
  /// The reversed depth at pixel (x, y), y counted from the top row (0: nothing drawn).
  float depthAt(int x, int y) const;
  /// Copies the colour attachment to the window's framebuffer, scaled to `width` x `height` pixels.
  void blitColourToWindow(int width, int height) const;

 private:
  int width_ = 0, height_ = 0, samples_ = 1;
  gl::Texture colour_, elevation_, depth_;
  gl::Framebuffer fbo_, colourFbo_;
  gl::Texture msColour_, msElevation_, msDepth_;  // samples_ > 1: what is drawn into
  gl::Framebuffer msFbo_;
};

/// A terrain renderer. draw() clears `target` and draws the scene.
class TerrainRenderer {
 public:
  virtual ~TerrainRenderer() = default;
  virtual std::string name() const = 0;
  /// `observer`: if given, a viewer-relative -> clip matrix that replaces the camera's own
  /// (the terrain is still laid out around `camera`); the undulation test looks at the rings
  /// from a fixed orthographic observer this way.
  virtual Status draw(const TerrainScene& scene, const CameraPose& camera, const Shading& shading,
                      const OffscreenTarget& target, const glm::dmat4* observer = nullptr) = 0;
  /// Triangles submitted per frame for `scene`.
  virtual size_t trianglesPerFrame(const TerrainScene& scene) const = 0;
};

/// The concentric-ring renderer's parameters.
struct RingParams {
  int circles = 128;      ///< n: the mesh has 6n^2 triangles
  double softFactor = 5;  ///< f(h) = max(softFactor * h, softMinM): the softened viewer height
  /// Floor of the softened height (m); 0: a twelfth of the view range, which keeps distant relief
  /// at low altitude (docs/render-rings.md, "Low-altitude views of distant relief").
  double softMinM = 0;
  /// View range: radius of the disc (m; of arc on a body). 0: planar, the DEM's farthest corner;
  /// on a body, the horizon of the viewer over the lowest terrain plus the highest summit's.
  double rangeM = 0;
  int maxSamples = 8;       ///< cap on the elevation samples per vertex
  bool multiSample = true;  ///< average several samples between neighbouring circles
  bool mipSelect = true;    ///< pick the MIP level from the circle spacing
};

/// Per-frame ring layout (what ring.vert gets), computed on the CPU; exposed for tests.
struct RingLayout {
  double rangeM = 0;         ///< the view range (m; of arc on a body)
  double softHeightM = 0;    ///< H = f(h)
  double alphaMax = 0;       ///< half-angle of the cap seen from the softened viewpoint (rad)
  double firstSpacingM = 0;  ///< radius of circle 1 (m)
  double texelM = 0;         ///< texel size of level 0 (m)
  /// Distance from the nadir of the circle at normalised radius rho (metres; of arc when planetary).
  double radiusAt(double rho, bool planetary, double radiusM) const;
};

/// The concentric-ring renderer: the RingMesh, built once, placed around the viewer by ring.vert.
class RingRenderer final : public TerrainRenderer {
 public:
  /// Compiles the shaders and uploads the mesh; fails on out-of-range parameters.
  static Result<std::unique_ptr<RingRenderer>> create(const RingParams& params = {});
  std::string name() const override { return "ring"; }
  Status draw(const TerrainScene& scene, const CameraPose& camera, const Shading& shading,
              const OffscreenTarget& target, const glm::dmat4* observer = nullptr) override;
  size_t trianglesPerFrame(const TerrainScene&) const override { return RingMesh::triangleCount(params_.circles); }
  const RingParams& params() const { return params_; }
  /// The layout draw() uses for this frame.
  RingLayout layout(const TerrainScene& scene, const FrameGeometry& frame) const;

 private:
  RingParams params_;
  gl::Program program_, sky_;
  gl::VertexArray vao_;
  gl::Buffer vertices_, indices_;
  int indexCount_ = 0;
};

/// The brute-force reference: every texel of level 0 a vertex, two triangles per cell. Planar
/// scenes only.
class GridRenderer final : public TerrainRenderer {
 public:
  /// Compiles the shaders; the index buffer is built for each scene size on first draw.
  static Result<std::unique_ptr<GridRenderer>> create();
  std::string name() const override { return "grid"; }
  Status draw(const TerrainScene& scene, const CameraPose& camera, const Shading& shading,
              const OffscreenTarget& target, const glm::dmat4* observer = nullptr) override;
  size_t trianglesPerFrame(const TerrainScene& scene) const override {
    return 2 * size_t(scene.width() - 1) * size_t(scene.height() - 1);
  }

 private:
  gl::Program program_, sky_;
  gl::VertexArray vao_;
  gl::Buffer indices_;
  int gridW_ = 0, gridH_ = 0;
  int indexCount_ = 0;
};

}  // namespace strata::render
