#include "terrain_fixture.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>

namespace strata::test {
namespace {

// Largest channel difference between pixel p of `a` and pixel q of `b`.
int pixelDiff(const render::Image8& a, size_t p, const render::Image8& b, size_t q) {
  const size_t ch = size_t(a.channels);
  int d = 0;
  for (size_t c = 0; c < ch; ++c) d = std::max(d, std::abs(int(a.pixels[p * ch + c]) - int(b.pixels[q * ch + c])));
  return d;
}

// For pixel (x, y) of `a`: the smallest difference to a pixel of `b` in its 3 x 3 neighbourhood.
int displacedDiff(const render::Image8& a, const render::Image8& b, int x, int y) {
  const size_t p = size_t(y) * size_t(a.width) + size_t(x);
  int best = 255;
  for (int dy = -1; dy <= 1; ++dy) {
    for (int dx = -1; dx <= 1; ++dx) {
      const int qx = x + dx, qy = y + dy;
      if (qx < 0 || qy < 0 || qx >= b.width || qy >= b.height) continue;
      best = std::min(best, pixelDiff(a, p, b, size_t(qy) * size_t(b.width) + size_t(qx)));
    }
  }
  return best;
}

std::string fmt(const char* f, double v) {
  char buf[64];
  std::snprintf(buf, sizeof buf, f, v);
  return buf;
}

}  // namespace

GoldenResult compareImages(const render::Image8& expected, const render::Image8& actual, const GoldenTolerance& tol) {
  GoldenResult res;
  if (expected.width != actual.width || expected.height != actual.height || expected.channels != actual.channels) {
    res.message = "expected " + std::to_string(expected.width) + "x" + std::to_string(expected.height) + "x" +
                  std::to_string(expected.channels) + ", actual " + std::to_string(actual.width) + "x" +
                  std::to_string(actual.height) + "x" + std::to_string(actual.channels);
    return res;
  }
  const size_t pixels = size_t(actual.width) * size_t(actual.height);
  res.diff.assign(pixels * 4, 0);
  std::vector<uint8_t> overCap(pixels, 0);
  res.maxDiff = 0;
  res.maxDisplacedDiff = 0;
  double sum = 0;
  size_t plainOver = 0;
  for (int y = 0; y < actual.height; ++y) {
    for (int x = 0; x < actual.width; ++x) {
      const size_t p = size_t(y) * size_t(actual.width) + size_t(x);
      const int d = pixelDiff(actual, p, expected, p);
      sum += d;
      res.maxDiff = std::max(res.maxDiff, d);
      plainOver += d > tol.maxPixelDiff;
      // Both ways: a defect in either image has no match in the other's neighbourhood.
      const int dd = d <= tol.maxPixelDiff
                         ? d
                         : std::max(displacedDiff(actual, expected, x, y), displacedDiff(expected, actual, x, y));
      res.maxDisplacedDiff = std::max(res.maxDisplacedDiff, dd);
      const bool over = dd > tol.maxPixelDiff;
      res.pixelsOverCap += over;
      overCap[p] = over;
      const uint8_t v = uint8_t(std::min(255, d * 4));
      res.diff[p * 4 + 0] = over ? 255 : v;
      res.diff[p * 4 + 1] = over ? 0 : v;
      res.diff[p * 4 + 2] = over ? 0 : v;
      res.diff[p * 4 + 3] = 255;
    }
  }
  res.meanDiff = sum / double(pixels);
  res.plainFractionOver = double(plainOver) / double(pixels);
  auto overAt = [&](int x, int y) {
    return x >= 0 && y >= 0 && x < actual.width && y < actual.height &&
           overCap[size_t(y) * size_t(actual.width) + size_t(x)] != 0;
  };
  for (int y = 0; y < actual.height; ++y) {
    for (int x = 0; x < actual.width; ++x) {
      if (!overAt(x, y)) continue;
      bool touches = false;
      for (int dy = -1; dy <= 1 && !touches; ++dy) {
        for (int dx = -1; dx <= 1 && !touches; ++dx) touches = (dx != 0 || dy != 0) && overAt(x + dx, y + dy);
      }
      res.lonePixels += !touches;
    }
  }
  const size_t touching = res.pixelsOverCap - res.lonePixels;
  res.ok = touching == 0 && res.lonePixels <= size_t(tol.maxLonePixels) && res.meanDiff <= tol.maxMeanDiff;
  res.message = std::to_string(res.pixelsOverCap) + " pixels differ by more than " + std::to_string(tol.maxPixelDiff) +
                " after one pixel of displacement (largest " + std::to_string(res.maxDisplacedDiff) + "; " +
                std::to_string(touching) + " touching another, allowed none; " + std::to_string(res.lonePixels) +
                " alone, allowed " + std::to_string(tol.maxLonePixels) + "), mean difference " +
                fmt("%.3f", res.meanDiff) + " (allowed " + fmt("%.3f", tol.maxMeanDiff) +
                "), largest plain difference " + std::to_string(res.maxDiff);
  return res;
}

std::filesystem::path goldenPath(const std::string& name) {
  return std::filesystem::path(STRATA_SOURCE_DIR) / "tests/render/golden" / (name + ".png");
}

GoldenResult compareWithGolden(const std::string& name, const render::Image8& actual, const GoldenTolerance& tol,
                               const std::filesystem::path& outDir) {
  const std::string golden = goldenPath(name).string();
  const std::string actualPath = (outDir / (name + ".actual.png")).string();
  const std::string diffPath = (outDir / (name + ".diff.png")).string();
  const auto written = render::writeImage8(actualPath, actual.width, actual.height, actual.channels, actual.pixels);
  const std::string writeNote = written ? "" : " (could not write the actual image: " + written.message() + ")";
  auto expected = render::readImage8(golden);
  if (!expected) {
    GoldenResult res;
    res.message = "no golden image " + golden + " (" + expected.message() + "); actual written to " + actualPath +
                  ": check it and run scripts/promote-golden.sh" + writeNote;
    return res;
  }
  GoldenResult res = compareImages(*expected, actual, tol);
  res.message = name + ": " + res.message;
  if (!res.ok && !res.diff.empty()) {
    const auto wroteDiff = render::writeImage8(diffPath, actual.width, actual.height, 4, res.diff);
    res.message += "; actual " + actualPath + ", diff " + diffPath + " (red: over the cap)" + writeNote +
                   (wroteDiff ? "" : " (diff not written: " + wroteDiff.message() + ")");
  }
  return res;
}

}  // namespace strata::test
