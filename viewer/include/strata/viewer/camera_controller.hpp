#pragma once
// Fly-through camera: WASD moves along the view heading, Q/E down and up, the mouse turns the
// view, and the speed scales with the height above the ground so that a canyon floor (metres a
// second) and orbit (thousands of km a second) are both usable. docs/viewer.md, "Flying".

#include <strata/render/terrain_renderer.hpp>

namespace strata::viewer {

/// Which movement keys are held.
struct MoveKeys {
  bool forward = false, back = false, left = false, right = false, up = false, down = false, fast = false;
};

/// Tuning of the fly-through controls.
struct FlightParams {
  double speedPerAglPerS = 0.5;  ///< speed = this * height above ground (1/s), at least minSpeedMS
  double minSpeedMS = 2;         ///< floor of the speed near the ground (m/s)
  double fastFactor = 5;         ///< speed multiplier while SHIFT is held
  double minClearanceM = 1;      ///< the camera never goes lower than this above the ground (m)
  double degPerPixel = 0.2;      ///< mouse look: degrees of heading/pitch per pixel of motion
};

/// Moves a CameraPose over a TerrainScene.
class CameraController {
 public:
  CameraController(const render::TerrainScene& scene, FlightParams params = {});

  const render::CameraPose& pose() const { return pose_; }
  render::CameraPose& pose() { return pose_; }
  const FlightParams& params() const { return params_; }

  /// Speed (m/s) at the current height above the ground with the current keys.
  double speedMS(double exaggeration) const;
  /// Height of the camera above the (exaggerated) ground under it (m).
  double heightAboveGroundM(double exaggeration) const;
  /// Advances the camera by `dtS` seconds with the held keys; keeps it above the ground.
  void update(double dtS, double exaggeration);
  /// Turns the view by a mouse motion of (dx, dy) pixels (right and down positive).
  void look(double dxPixels, double dyPixels);
  /// Moves over (lon, lat) at `aglM` above the ground there (keeps the current height above
  /// ground if aglM < 0). Fails outside the scene.
  Status goTo(double lon, double lat, double aglM, double exaggeration);

  MoveKeys keys;

 private:
  void clampAboveGround(double exaggeration);
  const render::TerrainScene* scene_;
  FlightParams params_;
  render::CameraPose pose_;
};

}  // namespace strata::viewer
