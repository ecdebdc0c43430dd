#include <strata/render/synthetic_dem.hpp>

#include <random>

#include <vector>

#include <strata/core/check.hpp>

namespace strata::render {

gis::Raster syntheticDem(int size, double cellM, double amplitudeM, uint32_t seed) {
  STRATA_CHECK(size >= 4 && cellM > 0) << "synthetic DEM of " << size << " cells of " << cellM << " m";
  gis::Raster r;
  r.georef.geographic = false;
  r.georef.crsName = "synthetic (projected metres)";
  r.georef.width = r.georef.height = size;
  r.georef.transform.c[0] = 500000.0;
  r.georef.transform.c[1] = cellM;
  r.georef.transform.c[3] = 4000000.0;
  r.georef.transform.c[5] = -cellM;
  r.values = gis::Grid<float>(size, size);
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> uni(-1.0f, 1.0f);
  double amp = amplitudeM;
  for (int period = size / 2; period >= 2; period /= 2) {
    const int lattice = size / period + 2;
    std::vector<float> v(size_t(lattice * lattice));
    for (auto& x : v) x = uni(rng);
    for (int y = 0; y < size; ++y) {
      for (int x = 0; x < size; ++x) {
        const double fx = double(x) / period, fy = double(y) / period;
        const int i = int(fx), j = int(fy);
        double sx = fx - i, sy = fy - j;
        sx = sx * sx * (3 - 2 * sx);
        sy = sy * sy * (3 - 2 * sy);
        auto at = [&](int a, int b) { return double(v[size_t(b * lattice + a)]); };
        const double n = (1 - sy) * ((1 - sx) * at(i, j) + sx * at(i + 1, j)) +
                         sy * ((1 - sx) * at(i, j + 1) + sx * at(i + 1, j + 1));
        r.values.at(x, y) += float(amp * n);
      }
    }
    amp *= 0.55;
  }
  for (auto& z : r.values.data) z += float(amplitudeM);
  return r;
}

}  // namespace strata::render
