#include <strata/render/flight_path.hpp>

#include <algorithm>
#include <cmath>
#include <fstream>
#include <sstream>

#include <strata/core/files.hpp>

namespace strata::render {

Result<FlightPath> FlightPath::parse(const std::string& text, const std::string& source) {
  FlightPath path;
  std::istringstream in(text);
  std::string line;
  int lineNo = 0;
  while (std::getline(in, line)) {
    ++lineNo;
    const auto first = line.find_first_not_of(" \t\r");
    if (first == std::string::npos || line[first] == '#') continue;
    std::istringstream fields(line);
    CameraPose p;
    if (!(fields >> p.lon >> p.lat >> p.heightM >> p.headingDeg >> p.pitchDeg)) {
      return fail(source + ":" + std::to_string(lineNo) +
                  ": expected 'lon lat heightM headingDeg pitchDeg [fovYDeg]', got '" + line + "'");
    }
    if (double fov = 0; fields >> fov) p.fovYDeg = fov;
    std::string extra;
    if (fields >> extra) return fail(source + ":" + std::to_string(lineNo) + ": unexpected '" + extra + "'");
    if (!(p.fovYDeg > 0 && p.fovYDeg < 180)) {
      return fail(source + ":" + std::to_string(lineNo) + ": field of view " + std::to_string(p.fovYDeg) +
                  " not in (0, 180) degrees");
    }
    if (std::abs(p.pitchDeg) > 90) {
      return fail(source + ":" + std::to_string(lineNo) + ": pitch " + std::to_string(p.pitchDeg) +
                  " not in [-90, 90] degrees");
    }
    path.keys.push_back(p);
  }
  if (path.keys.size() < 2) {
    return fail(source + ": " + std::to_string(path.keys.size()) + " keyframes, need at least 2");
  }
  return path;
}

Result<FlightPath> FlightPath::load(const std::string& path) {
  STRATA_TRY_STATUS(requireRegularFile(path, "a keyframe file"));
  std::ifstream in(path);
  if (!in) return fail(path + ": cannot open the keyframe file");
  std::stringstream text;
  text << in.rdbuf();
  return parse(text.str(), path);
}

CameraPose FlightPath::at(double t) const {
  STRATA_CHECK(keys.size() >= 2) << "flight path with " << keys.size() << " keyframes";
  const double s = std::clamp(t, 0.0, 1.0) * double(keys.size() - 1);
  const size_t i = std::min(size_t(s), keys.size() - 2);
  const double f = s - double(i);
  const CameraPose& a = keys[i];
  const CameraPose& b = keys[i + 1];
  auto lerp = [f](double x, double y) { return x + f * (y - x); };
  CameraPose p;
  p.lon = lerp(a.lon, b.lon);
  p.lat = lerp(a.lat, b.lat);
  p.heightM = lerp(a.heightM, b.heightM);
  const double dh = std::remainder(b.headingDeg - a.headingDeg, 360.0);
  p.headingDeg = a.headingDeg + f * dh;
  p.pitchDeg = lerp(a.pitchDeg, b.pitchDeg);
  p.fovYDeg = lerp(a.fovYDeg, b.fovYDeg);
  return p;
}

}  // namespace strata::render
