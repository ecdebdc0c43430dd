#include <strata/terrain/dem_sources.hpp>

#include <strata/gis/dem_io.hpp>

namespace strata::terrain {

namespace {

// The georeference of cells [x, x+w) x [y, y+h) of `g`.
gis::Georef windowOf(const gis::Georef& g, int x, int y, int w, int h) {
  gis::Georef out = g;
  const auto& c = g.transform.c;
  out.transform.c[0] = c[0] + x * c[1] + y * c[2];
  out.transform.c[3] = c[3] + x * c[4] + y * c[5];
  out.width = w;
  out.height = h;
  return out;
}

bool sameGrid(const gis::Georef& a, const gis::Georef& b) {
  for (int i = 0; i < 6; ++i) {
    if (a.transform.c[i] != b.transform.c[i]) return false;
  }
  return a.width == b.width && a.height == b.height && a.crsWkt == b.crsWkt;
}

}  // namespace

WindowReader demReader(const std::string& path) {
  return [path](int x, int y, int w, int h) -> Result<gis::Grid<float>> {
    gis::ReadOptions o;
    o.window = gis::PixelWindow{x, y, w, h};
    o.allowAllNoData = true;  // tiles outside a non-rectangular domain are expected
    STRATA_TRY(auto r, gis::readDem(path, o));
    return std::move(r.values);
  };
}

Result<WindowReader> mosaicReader(std::vector<gis::MosaicInput> inputs, const gis::Georef& grid) {
  if (inputs.empty()) return fail("mosaic: no inputs");
  if (inputs.size() == 1 && !inputs[0].raster && inputs[0].mode == gis::BlendMode::Replace && inputs[0].band == 1) {
    STRATA_TRY(auto info, gis::probeDem(inputs[0].path));
    if (sameGrid(info.georef, grid)) return demReader(inputs[0].path);
  }
  return WindowReader([inputs = std::move(inputs), grid](int x, int y, int w, int h) -> Result<gis::Grid<float>> {
    const auto target = windowOf(grid, x, y, w, h);
    gis::Grid<float> layer(w, h, gis::kNoData);
    for (const auto& in : inputs) {
      STRATA_TRY(auto warped, gis::warpToGrid(in, target));
      gis::blendInto(layer, warped.values, in.mode);
    }
    return layer;
  });
}

}  // namespace strata::terrain
