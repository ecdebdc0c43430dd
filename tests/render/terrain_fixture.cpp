#include "terrain_fixture.hpp"

#include <strata/gis/dem_io.hpp>

#include <algorithm>
#include <cmath>

namespace strata::test {

GoldenResult compareWithGolden(const std::string& name, const render::Image8& actual, int maxChannelDiff,
                               double allowedFraction, const std::filesystem::path& outDir) {
  GoldenResult res;
  const std::string goldenPath = std::string(STRATA_SOURCE_DIR) + "/tests/render/golden/" + name + ".png";
  const std::string actualPath = (outDir / (name + ".actual.png")).string();
  const std::string diffPath = (outDir / (name + ".diff.png")).string();
  const auto written = render::writeImage8(actualPath, actual.width, actual.height, actual.channels, actual.pixels);
  const std::string writeNote = written ? "" : " (could not write the actual image: " + written.message() + ")";
  auto golden = render::readImage8(goldenPath);
  if (!golden) {
    res.message = "no golden image " + goldenPath + " (" + golden.message() + "); actual written to " + actualPath +
                  ": check it and run scripts/promote-golden.sh" + writeNote;
    return res;
  }
  if (golden->width != actual.width || golden->height != actual.height || golden->channels != actual.channels) {
    res.message = "golden " + goldenPath + " is " + std::to_string(golden->width) + "x" +
                  std::to_string(golden->height) + "x" + std::to_string(golden->channels) + ", actual " +
                  std::to_string(actual.width) + "x" + std::to_string(actual.height) + "x" +
                  std::to_string(actual.channels);
    return res;
  }
  const size_t pixels = size_t(actual.width) * size_t(actual.height);
  const int ch = actual.channels;
  std::vector<uint8_t> diff(pixels * 4, 0);
  size_t differing = 0;
  res.maxDiff = 0;
  for (size_t p = 0; p < pixels; ++p) {
    int d = 0;
    for (int c = 0; c < ch; ++c) {
      d = std::max(d, std::abs(int(actual.pixels[p * size_t(ch) + size_t(c)]) -
                               int(golden->pixels[p * size_t(ch) + size_t(c)])));
    }
    res.maxDiff = std::max(res.maxDiff, d);
    if (d > maxChannelDiff) ++differing;
    const uint8_t v = uint8_t(std::min(255, d * 4));
    diff[p * 4 + 0] = d > maxChannelDiff ? 255 : v;
    diff[p * 4 + 1] = v;
    diff[p * 4 + 2] = v;
    diff[p * 4 + 3] = 255;
  }
  res.differingFraction = double(differing) / double(pixels);
  res.ok = res.differingFraction <= allowedFraction;
  if (!res.ok) {
    const auto wroteDiff = render::writeImage8(diffPath, actual.width, actual.height, 4, diff);
    res.message = name + ": " + std::to_string(res.differingFraction * 100) + "% of pixels differ by more than " +
                  std::to_string(maxChannelDiff) + " (allowed " + std::to_string(allowedFraction * 100) +
                  "%); actual " + actualPath + ", diff " + diffPath + writeNote +
                  (wroteDiff ? "" : " (diff not written: " + wroteDiff.message() + ")");
  }
  return res;
}

}  // namespace strata::test
