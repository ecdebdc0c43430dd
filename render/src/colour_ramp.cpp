#include <strata/render/colour_ramp.hpp>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <fstream>
#include <numeric>
#include <sstream>

#include <strata/core/files.hpp>

namespace strata::render {

glm::vec3 ColourRamp::at(float elevationM) const {
  if (elevationsM.empty()) return glm::vec3(0.5f);
  if (!(elevationM > elevationsM.front())) return colours.front();
  if (elevationM >= elevationsM.back()) return colours.back();
  const size_t i = size_t(std::upper_bound(elevationsM.begin(), elevationsM.end(), elevationM) - elevationsM.begin());
  const float e0 = elevationsM[i - 1], e1 = elevationsM[i];
  const float t = e1 > e0 ? (elevationM - e0) / (e1 - e0) : 1.0f;
  return colours[i - 1] + t * (colours[i] - colours[i - 1]);
}

namespace {
constexpr double kMaxStopM = 1e6;
}  // namespace

Result<ColourRamp> loadColourRamp(const std::string& path, float minM, float maxM) {
  STRATA_TRY_STATUS(requireRegularFile(path, "a colour ramp"));
  std::ifstream in(path);
  if (!in) return fail(path + ": cannot open the colour ramp");
  std::vector<std::pair<float, glm::vec3>> stops;
  std::string line;
  for (int number = 1; std::getline(in, line); ++number) {
    const std::string where = path + ":" + std::to_string(number) + ": ";
    if (const auto hash = line.find('#'); hash != std::string::npos) line.resize(hash);
    std::replace(line.begin(), line.end(), ',', ' ');
    std::replace(line.begin(), line.end(), '\t', ' ');
    std::istringstream words(line);
    std::vector<std::string> w;
    for (std::string s; words >> s;) w.push_back(s);
    if (w.empty()) continue;
    if (w.size() < 4 || w.size() > 5) {
      return fail(where + "expected ELEVATION R G B [A] (e.g. 1500 120 200 80), found " + std::to_string(w.size()) +
                  " fields");
    }
    glm::vec3 colour;
    for (int k = 0; k < 3; ++k) {
      char* end = nullptr;
      const long v = std::strtol(w[size_t(k + 1)].c_str(), &end, 10);
      if (*end != '\0' || v < 0 || v > 255) {
        return fail(where + "colour '" + w[size_t(k + 1)] +
                    "': expected a whole number 0-255 (named colours are not read)");
      }
      colour[k] = float(v) / 255.0f;
    }
    if (w[0] == "nv") continue;  // the no-data colour: voids are filled or drawn as holes
    std::string value = w[0];
    const bool percent = !value.empty() && value.back() == '%';
    if (percent) value.pop_back();
    char* end = nullptr;
    const double v = std::strtod(value.c_str(), &end);
    if (value.empty() || *end != '\0' || !std::isfinite(v)) {
      return fail(where + "elevation '" + w[0] + "': expected a number of metres, a percentage such as 50%, or nv");
    }
    // Beyond a thousand kilometres no relief of any body reaches (the deepest trench and the
    // highest volcano are within 25 km of their datum); a larger stop (1e308 became inf as a
    // float and drew every cell black) is a typing slip.
    const double m = percent ? minM + v / 100.0 * (maxM - minM) : v;
    if (!(std::abs(m) <= kMaxStopM)) {
      return fail(where + "elevation '" + w[0] + "': outside +-1000 km of the datum (" + std::to_string(m) + " m)");
    }
    stops.emplace_back(float(m), colour);
  }
  if (stops.empty()) return fail(path + ": no colour stops (lines of ELEVATION R G B)");
  if (stops.size() > size_t(ColourRamp::kMaxStops)) {
    return fail(path + ": " + std::to_string(stops.size()) + " colour stops; at most " +
                std::to_string(ColourRamp::kMaxStops) + " are drawn");
  }
  std::stable_sort(stops.begin(), stops.end(), [](const auto& a, const auto& b) { return a.first < b.first; });
  ColourRamp ramp;
  for (const auto& [e, c] : stops) {
    ramp.elevationsM.push_back(e);
    ramp.colours.push_back(c);
  }
  return ramp;
}

}  // namespace strata::render
