#include <strata/render/drape.hpp>

#include <algorithm>
#include <cmath>
#include <cstdio>

#include <strata/gis/dem_io.hpp>

namespace strata::render {

std::array<uint8_t, 3> drapeRamp(double t) {
  // Five stops of viridis (matplotlib's, sampled at 0, 1/4, 1/2, 3/4, 1).
  static constexpr double kStops[5][3] = {{68, 1, 84}, {59, 82, 139}, {33, 145, 140}, {94, 201, 98}, {253, 231, 37}};
  t = std::clamp(std::isfinite(t) ? t : 0.0, 0.0, 1.0) * 4;
  const int i = std::min(int(t), 3);
  const double f = t - i;
  std::array<uint8_t, 3> c{};
  for (int k = 0; k < 3; ++k) c[size_t(k)] = uint8_t(std::lround(kStops[i][k] + (kStops[i + 1][k] - kStops[i][k]) * f));
  return c;
}

Result<DrapeImage> drapeFromGrid(const gis::Grid<float>& values, const gis::Georef& georef, const DrapeOptions& options,
                                 const std::string& name) {
  std::array<double, 2> range{0, 0};
  if (options.range) {
    range = *options.range;
    if (!(std::isfinite(range[0]) && std::isfinite(range[1]) && range[0] < range[1])) {
      return fail(name + ": drape range " + std::to_string(range[0]) + " .. " + std::to_string(range[1]) +
                  " is not an interval");
    }
  } else {
    std::vector<float> valid;
    for (float v : values.data) {
      if (std::isfinite(v)) valid.push_back(v);
    }
    if (valid.empty()) return fail(name + ": no data over the terrain to drape");
    auto at = [&](double q) {
      auto it = valid.begin() + std::ptrdiff_t(q * double(valid.size() - 1));
      std::nth_element(valid.begin(), it, valid.end());
      return double(*it);
    };
    range = {at(0.02), at(0.98)};
    if (!(range[1] > range[0])) range[1] = range[0] + 1;
  }
  DrapeImage img;
  img.width = values.width;
  img.height = values.height;
  img.georef = georef;
  img.rgba.assign(values.size() * 4, 0);
  for (size_t i = 0; i < values.size(); ++i) {
    const float v = values.data[i];
    if (!std::isfinite(v) || (options.transparentBelow && v < range[0])) continue;
    const auto c = drapeRamp((v - range[0]) / (range[1] - range[0]));
    img.rgba[i * 4 + 0] = c[0], img.rgba[i * 4 + 1] = c[1], img.rgba[i * 4 + 2] = c[2], img.rgba[i * 4 + 3] = 255;
  }
  img.range = range;
  char text[96];
  std::snprintf(text, sizeof text, "ramp %.4g .. %.4g", range[0], range[1]);
  img.description = text;
  return img;
}

Result<DrapeImage> loadDrape(const std::string& path, const gis::Georef& scene, const DrapeOptions& options) {
  gis::ReadOptions probe;
  probe.allowAllNoData = true;
  STRATA_TRY(gis::DemInfo info, gis::probeDem(path, probe));
  if (options.texelsPerCell < 1) return fail(path + ": drape texels per cell must be at least 1");
  // `texelsPerCell` texels a cell while that stays within 8192 a side; a larger (or streamed)
  // scene gets at most 8192 texels a side over its whole extent, each covering several cells.
  constexpr int kMaxSide = 8192;
  int f = options.texelsPerCell;
  while (f > 1 && std::max(scene.width, scene.height) * f > kMaxSide) --f;
  gis::Georef target = scene;
  target.width = scene.width * f;
  target.height = scene.height * f;
  if (std::max(scene.width, scene.height) > kMaxSide) {
    const double shrink = double(kMaxSide) / std::max(scene.width, scene.height);
    target.width = std::max(1, int(std::lround(scene.width * shrink)));
    target.height = std::max(1, int(std::lround(scene.height * shrink)));
  }
  // The warp reads every source pixel (GDAL's warper takes no overviews): a source far finer than
  // the texture would be decoded whole, minutes and gigabytes for a picture 8192 texels a side at
  // most. Above 256 M pixels and 64 times the texels it is refused, saying how to resample it.
  const double sourcePixels = double(info.georef.width) * double(info.georef.height);
  const double texels = double(target.width) * double(target.height);
  const double limit = std::max(double(1 << 28), 64 * texels);
  if (sourcePixels > limit) {
    const int fits = int(std::floor(info.georef.width * std::sqrt(limit / sourcePixels)));
    char msg[320];
    std::snprintf(msg, sizeof msg,
                  ": %d x %d pixels, %.0f times the %d x %d texels drawn: resample it first "
                  "(gdal_translate -r average -outsize %d 0 %s small.tif)",
                  info.georef.width, info.georef.height, sourcePixels / texels, target.width, target.height, fits,
                  path.c_str());
    return fail(path + msg);
  }
  const double fx = double(target.width) / scene.width, fy = double(target.height) / scene.height;
  for (int k : {1, 4}) target.transform.c[k] /= fx;
  for (int k : {2, 5}) target.transform.c[k] /= fy;

  // What the bands are is read from their number: 1 to 4 Byte bands are grey, grey and alpha,
  // RGB, RGBA; one band of another type is coloured by a ramp. Anything else would be drawn from
  // bands chosen silently: refused, saying how to pick them.
  const bool bytes = info.bandType == "Byte";
  if ((bytes && info.bandCount > 4) || (!bytes && info.bandCount > 1)) {
    return fail(path + ": " + std::to_string(info.bandCount) + " " + info.bandType +
                " bands; a drape is 1 to 4 Byte bands (grey, grey and alpha, RGB, RGBA) or one band of values to "
                "colour: pick them first (gdal_translate -b 1 -b 2 -b 3 " +
                path + " rgb.tif)");
  }
  const int bands = bytes ? info.bandCount : 1;
  std::vector<gis::Grid<float>> values;
  for (int b = 1; b <= bands; ++b) {
    gis::MosaicInput in;
    in.path = path;
    in.band = b;
    in.resampling = options.resampling;
    STRATA_TRY(gis::Raster r, gis::warpToGrid(in, target));
    values.push_back(std::move(r.values));
  }
  if (!bytes) {
    STRATA_TRY(DrapeImage ramp, drapeFromGrid(values[0], target, options, path));
    ramp.description += " (" + info.bandType + ")";
    return ramp;
  }

  DrapeImage img;
  img.width = target.width;
  img.height = target.height;
  img.georef = target;
  img.rgba.assign(size_t(img.width) * size_t(img.height) * 4, 0);
  const size_t n = size_t(img.width) * size_t(img.height);
  auto byte = [](float v) { return uint8_t(std::clamp(std::lround(v), 0L, 255L)); };
  char text[160];
  if (bytes && bands >= 3) {
    for (size_t i = 0; i < n; ++i) {
      const float r = values[0].data[i], g = values[1].data[i], b = values[2].data[i];
      if (std::isnan(r) || std::isnan(g) || std::isnan(b)) continue;
      const float a = bands == 4 ? values[3].data[i] : 255.0f;
      img.rgba[i * 4 + 0] = byte(r), img.rgba[i * 4 + 1] = byte(g), img.rgba[i * 4 + 2] = byte(b);
      img.rgba[i * 4 + 3] = std::isnan(a) ? 0 : byte(a);
    }
    std::snprintf(text, sizeof text, "%s (%d Byte bands)", bands == 4 ? "RGBA" : "RGB", bands);
  } else {
    for (size_t i = 0; i < n; ++i) {
      const float v = values[0].data[i];
      if (std::isnan(v)) continue;
      const float a = bands >= 2 ? values[1].data[i] : 255.0f;
      img.rgba[i * 4 + 0] = img.rgba[i * 4 + 1] = img.rgba[i * 4 + 2] = byte(v);
      img.rgba[i * 4 + 3] = std::isnan(a) ? 0 : byte(a);
    }
    std::snprintf(text, sizeof text, "grey%s (Byte)", bands >= 2 ? " and alpha" : "");
  }
  img.description = text;
  return img;
}

}  // namespace strata::render
