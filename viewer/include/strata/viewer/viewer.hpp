#pragma once
// strata-view's state and behaviour, independent of the window system: a TerrainScene drawn
// by the ring renderer, a fly-through camera, the terrain editor, a live simulation region and
// the HUD. The window (apps/strata-view) and scripts feed it the same Commands; it draws into
// an offscreen target and presents that into the window's framebuffer. docs/viewer.md.

#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <strata/core/result.hpp>
#include <strata/gis/raster.hpp>
#include <strata/render/overlay.hpp>
#include <strata/render/terrain_renderer.hpp>
#include <strata/sim/gl/gl_solver.hpp>
#include <strata/viewer/camera_controller.hpp>
#include <strata/viewer/command.hpp>
#include <strata/viewer/terrain_editor.hpp>

namespace strata::viewer {

struct ViewerOptions {
  int width = 960, height = 600;  ///< framebuffer size (pixels)
  render::Shading shading;        ///< palette, exaggeration, sky
  bool planetary = false;         ///< draw on the body's ellipsoid (geographic DEMs)
  int circles = 256;              ///< ring renderer circles
  double rangeM = 0;              ///< ring renderer view range (m); 0: RingParams' default
  double softMinM = 0;            ///< ring renderer softening floor (m); 0: RingParams' default
  FlightParams flight;            ///< fly-through tuning
  bool showHud = true;            ///< draw the HUD (toggled with F2)
  bool scaleBar = false;          ///< draw a scale bar in the picture's bottom-left corner
  int samples = 1;                ///< MSAA samples a pixel of the offscreen target (1 to 8)
};

/// The live simulation region: a window of the terrain simulated on the GPU.
struct SimRegionState {
  CellRect rect;  ///< the region's cells in the scene grid
  std::unique_ptr<sim::GlSolver> sim;
  std::vector<std::pair<int, int>> springCells;  ///< region cells of placed springs
  std::vector<double> springRatesM3S;
  gis::Grid<float> rainMmPerHour;  ///< painted rain (rain tool), region cells; empty until painted
  double timeOffsetS = 0;          ///< simulated time before the last rebuild
  bool playing = false;
  bool erosion = false;  ///< erosion and deposition (docs/sim-erosion.md) on the editor's four layers
  int stepsPerFrame = 1;
  double lastStepMs = 0;  ///< wall time of the last frame's steps and water upload (ms)
};

class Viewer {
 public:
  /// Uploads `dem`, compiles the renderers and kernels. Needs a current GL 4.5 context.
  static Result<std::unique_ptr<Viewer>> create(const gis::Raster& dem, const ViewerOptions& options);

  /// Applies one input command. Fails (with a message for the HUD/log) on a command that cannot
  /// apply here, e.g. goto outside the terrain; the viewer stays usable.
  Status handle(const Command& command);
  /// Advances by `dtS` seconds: moves the camera, applies the held brush, steps the simulation,
  /// draws the terrain into the offscreen target.
  Status frame(double dtS);
  /// Copies the frame into the window's framebuffer, writes the screenshots asked for since the
  /// last call (the image without the HUD), then draws the HUD on top.
  Status present(int width, int height);
  /// Resizes the offscreen target to a new framebuffer size.
  Status resize(int width, int height);

  /// The map position (lon/lat or easting/northing) under window pixel (x, y), y from the top;
  /// nullopt for sky. Planetary mode: geodetic lon/lat on the body's ellipsoid.
  std::optional<glm::dvec2> pick(double x, double y) const;
  std::vector<std::string> hudLines() const;
  /// The last frame's timings (ms): CPU work of frame() (camera, brush, simulation, draw
  /// submission), GPU time of the terrain draw (GL_TIME_ELAPSED, read a frame late so nothing
  /// stalls), and wall time of the simulation steps with the water upload (0 without a region).
  struct FrameTimes {
    double cpuMs = 0, gpuMs = 0, simMs = 0;
  };
  FrameTimes times() const;
  static std::vector<std::string> helpLines();

  bool quitRequested() const { return quit_; }
  const std::string& lastMessage() const { return message_; }
  render::TerrainScene& scene() { return scene_; }
  const render::TerrainScene& scene() const { return scene_; }
  TerrainEditor& editor() { return *editor_; }
  CameraController& camera() { return *camera_; }
  const Brush& brush() const { return brush_; }
  const SimRegionState* region() const { return region_ ? &*region_ : nullptr; }
  const render::Shading& shading() const { return options_.shading; }
  render::Shading& shading() { return options_.shading; }
  /// Where save without a path writes (a store folder or a file); set by the app.
  std::string savePath;
  /// Saves the edited terrain: a GeoTIFF (.tif) of the whole grid. (Stores: apps/strata-view.)
  std::function<Status(const std::string& path)> saver;

 private:
  Viewer(render::TerrainScene scene, const ViewerOptions& options);
  Status key(const KeyCommand& k);
  Status applyToolAt(double lon, double lat, bool newStroke);
  Status startRegion(double lon0, double lat0, double lon1, double lat1);
  Status rebuildSimulation(const gis::Grid<float>& waterM);
  Status stepSimulation(int steps);
  Status showWater();
  Status setErosion(bool on);

  render::TerrainScene scene_;
  ViewerOptions options_;
  std::unique_ptr<render::RingRenderer> renderer_;
  std::optional<render::OffscreenTarget> target_;
  std::optional<TerrainEditor> editor_;
  std::optional<CameraController> camera_;
  std::optional<render::Overlay> hud_;
  std::optional<SimRegionState> region_;
  Brush brush_;
  glm::dvec2 cursor_{-1, -1}, regionStart_{0, 0};
  bool leftDown_ = false, rightDown_ = false, showHelp_ = false, quit_ = false;
  std::vector<ScreenshotCommand> pendingScreenshots_;
  std::string message_;
  // Timings for the HUD (ms): CPU work of the last frame, GPU time of the terrain draw.
  double cpuFrameMs_ = 0, gpuFrameMs_ = 0;
  gl::GpuTimer gpuTimers_[3];  // a ring: frame N reads the timer of frame N - 2
  int frameIndex_ = 0;
};

}  // namespace strata::viewer
