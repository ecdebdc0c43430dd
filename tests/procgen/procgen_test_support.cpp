#include "procgen_test_support.hpp"

#include <gdal_priv.h>

#include <OpenImageIO/imageio.h>

#include <algorithm>
#include <cmath>

#include <strata/core/check.hpp>

namespace strata::test {

std::string procgenDataPath(const std::string& relative) { return std::string(STRATA_DATA_DIR) + "/" + relative; }

gis::Grid<float> readDemForTest(const std::string& path) {
  GDALAllRegister();
  auto* ds = static_cast<GDALDataset*>(GDALOpen(path.c_str(), GA_ReadOnly));
  STRATA_CHECK(ds != nullptr) << "cannot open " << path;
  auto* band = ds->GetRasterBand(1);
  gis::Grid<float> g(ds->GetRasterXSize(), ds->GetRasterYSize());
  const CPLErr err =
      band->RasterIO(GF_Read, 0, 0, g.width, g.height, g.data.data(), g.width, g.height, GDT_Float32, 0, 0, nullptr);
  STRATA_CHECK(err == CE_None) << "cannot read " << path;
  int hasNoData = 0;
  const double noData = band->GetNoDataValue(&hasNoData);
  if (hasNoData) {
    for (float& v : g.data) {
      if (double(v) == noData) v = gis::kNoData;
    }
  }
  GDALClose(ds);
  return g;
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
