#include <algorithm>
#include <cmath>
#include <numbers>

#include <strata/core/angles.hpp>
#include <strata/viewer/camera_controller.hpp>

namespace strata::viewer {

namespace {}

CameraController::CameraController(const render::TerrainScene& scene, FlightParams params)
    : scene_(&scene), params_(params) {
  const auto& c = scene.georef().transform.c;
  pose_.lon = c[0] + c[1] * scene.width() / 2.0;
  pose_.lat = c[3] + c[5] * scene.height() / 2.0;
  pose_.heightM = scene.heightAt(pose_.lon, pose_.lat) + 1000.0;
}

double CameraController::heightAboveGroundM(double exaggeration) const {
  return pose_.heightM - exaggeration * scene_->heightAt(pose_.lon, pose_.lat);
}

double CameraController::speedMS(double exaggeration) const {
  const double v = std::max(params_.minSpeedMS, params_.speedPerAglPerS * heightAboveGroundM(exaggeration));
  return keys.fast ? v * params_.fastFactor : v;
}

void CameraController::clampAboveGround(double exaggeration) {
  const double ground = exaggeration * scene_->heightAt(pose_.lon, pose_.lat);
  pose_.heightM = std::max(pose_.heightM, ground + params_.minClearanceM);
}

void CameraController::update(double dtS, double exaggeration) {
  const double step = speedMS(exaggeration) * dtS;
  const double hd = pose_.headingDeg * kDeg;
  // Forward and right along the ground, in east/north metres.
  double east = 0, north = 0;
  const double f = (keys.forward ? 1.0 : 0.0) - (keys.back ? 1.0 : 0.0);
  const double r = (keys.right ? 1.0 : 0.0) - (keys.left ? 1.0 : 0.0);
  east = step * (f * std::sin(hd) + r * std::cos(hd));
  north = step * (f * std::cos(hd) - r * std::sin(hd));
  const auto& g = scene_->georef();
  if (g.geographic) {
    const double radius = scene_->radiusM();
    pose_.lat = std::clamp(pose_.lat + north / (radius * kDeg), -89.9, 89.9);
    pose_.lon += east / (radius * std::cos(pose_.lat * kDeg) * kDeg);
    if (pose_.lon > 180 && g.transform.c[0] < 0) pose_.lon -= 360;
    if (pose_.lon < -180) pose_.lon += 360;
  } else {
    const glm::dvec2 k = scene_->metresPerCrsUnit();
    pose_.lon += east / k.x;
    pose_.lat += north / k.y;
  }
  pose_.heightM += step * ((keys.up ? 1.0 : 0.0) - (keys.down ? 1.0 : 0.0));
  clampAboveGround(exaggeration);
}

void CameraController::look(double dxPixels, double dyPixels) {
  pose_.headingDeg = std::fmod(pose_.headingDeg + dxPixels * params_.degPerPixel + 360.0, 360.0);
  pose_.pitchDeg = std::clamp(pose_.pitchDeg - dyPixels * params_.degPerPixel, -89.0, 89.0);
}

Status CameraController::goTo(double lon, double lat, double aglM, double exaggeration) {
  const auto& g = scene_->georef();
  const auto& c = g.transform.c;
  const double x = (lon - c[0]) / c[1], y = (lat - c[3]) / c[5];
  const bool wraps = g.geographic && std::abs(c[1] * scene_->width()) >= 359.9;
  if ((!wraps && (x < 0 || x > scene_->width())) || y < 0 || y > scene_->height()) {
    return fail("goto " + std::to_string(lon) + " " + std::to_string(lat) + ": outside the terrain");
  }
  const double agl = aglM >= 0 ? aglM : heightAboveGroundM(exaggeration);
  pose_.lon = lon;
  pose_.lat = lat;
  pose_.heightM = exaggeration * scene_->heightAt(lon, lat) + agl;
  clampAboveGround(exaggeration);
  return {};
}

}  // namespace strata::viewer
