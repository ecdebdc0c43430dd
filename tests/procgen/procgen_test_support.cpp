#include "procgen_test_support.hpp"

#include <OpenImageIO/imageio.h>

#include <algorithm>
#include <cmath>

#include <strata/core/check.hpp>
#include <strata/gis/dem_io.hpp>

namespace strata::test {

gis::Grid<float> readDemForTest(const std::string& path) {
  auto dem = gis::readDem(path);
  STRATA_CHECK(dem.ok()) << dem.message();
  return std::move(dem->values);
}

bool writeHillshadePng(const gis::Grid<float>& h, double cellSizeM, const std::filesystem::path& png) {
  const int w = h.width, ht = h.height;
  std::vector<unsigned char> pixels(size_t(w) * size_t(ht));
  const double az = 315.0 * M_PI / 180.0, alt = 45.0 * M_PI / 180.0;
  const double sx = std::sin(az) * std::cos(alt), sy = std::cos(az) * std::cos(alt), sz = std::sin(alt);
  for (int y = 0; y < ht; ++y) {
    for (int x = 0; x < w; ++x) {
      auto at = [&](int xx, int yy) { return double(h.at(std::clamp(xx, 0, w - 1), std::clamp(yy, 0, ht - 1))); };
      const double dzdx = (at(x + 1, y) - at(x - 1, y)) / (2 * cellSizeM);
      const double dzdy = (at(x, y - 1) - at(x, y + 1)) / (2 * cellSizeM);  // +y is north (row up)
      const double nx = -dzdx, ny = -dzdy, nz = 1.0, len = std::sqrt(nx * nx + ny * ny + nz * nz);
      const double shade = std::max(0.0, (nx * sx + ny * sy + nz * sz) / len);
      pixels[h.index(x, y)] = (unsigned char)std::lround(std::clamp(shade, 0.0, 1.0) * 255.0);
    }
  }
  auto out = OIIO::ImageOutput::create(png.string());
  if (!out) return false;
  OIIO::ImageSpec spec(w, ht, 1, OIIO::TypeDesc::UINT8);
  if (!out->open(png.string(), spec)) return false;
  const bool ok = out->write_image(OIIO::TypeDesc::UINT8, pixels.data());
  return out->close() && ok;
}

}  // namespace strata::test
