#include <strata/terrain/sim/region.hpp>

#include <string>

namespace strata::terrain::sim {
namespace {

std::string describe(const CellRect& r) {
  return "(" + std::to_string(r.x0) + ", " + std::to_string(r.y0) + ") " + std::to_string(r.width) + "x" +
         std::to_string(r.height);
}

Status checkRect(const CellRect& r, int w, int h) {
  if (r.width < 2 || r.height < 2) return fail("sim region " + describe(r) + ": must be at least 2x2 cells");
  if (r.x0 < 0 || r.y0 < 0 || r.x0 + r.width > w || r.y0 + r.height > h) {
    return fail("sim region " + describe(r) + ": not inside the " + std::to_string(w) + "x" + std::to_string(h) +
                " grid");
  }
  return {};
}

gis::Grid<float> crop(const gis::Grid<float>& g, const CellRect& r) {
  if (g.size() == 0) return {};
  gis::Grid<float> out(r.width, r.height);
  for (int y = 0; y < r.height; ++y) {
    for (int x = 0; x < r.width; ++x) out.at(x, y) = g.at(r.x0 + x, r.y0 + y);
  }
  return out;
}

}  // namespace

Result<SimInput> cutRegion(const SimInput& full, const CellRect& rect) {
  STRATA_TRY_STATUS(checkRect(rect, full.baseM.width, full.baseM.height));
  SimInput out;
  out.baseM = crop(full.baseM, rect);
  for (const auto& l : full.layersM) out.layersM.push_back(crop(l, rect));
  out.materials = full.materials;
  out.waterDepthM = crop(full.waterDepthM, rect);
  out.rainMmPerHour = crop(full.rainMmPerHour, rect);
  if (full.rowDxM.size() == 1) {
    out.rowDxM = full.rowDxM;
  } else if (full.rowDxM.size() == size_t(full.baseM.height)) {
    out.rowDxM.assign(full.rowDxM.begin() + rect.y0, full.rowDxM.begin() + rect.y0 + rect.height);
  } else {
    return fail("sim region: rowDxM has " + std::to_string(full.rowDxM.size()) + " values, expected 1 or one per row");
  }
  out.dyM = full.dyM;
  out.datumM = full.datumM;
  return out;
}

Status writeBackLayers(std::vector<gis::Grid<float>>& fullLayers, const std::vector<gis::Grid<float>>& regionLayers,
                       const CellRect& rect) {
  if (fullLayers.size() != regionLayers.size()) {
    return fail("sim region write-back: " + std::to_string(regionLayers.size()) + " region layers for " +
                std::to_string(fullLayers.size()) + " terrain layers");
  }
  if (fullLayers.empty()) return {};
  STRATA_TRY_STATUS(checkRect(rect, fullLayers[0].width, fullLayers[0].height));
  for (size_t l = 0; l < fullLayers.size(); ++l) {
    if (regionLayers[l].width != rect.width || regionLayers[l].height != rect.height) {
      return fail("sim region write-back: region layer " + std::to_string(l) + " is " +
                  std::to_string(regionLayers[l].width) + "x" + std::to_string(regionLayers[l].height) +
                  ", the region is " + describe(rect));
    }
    for (int y = 0; y < rect.height; ++y) {
      for (int x = 0; x < rect.width; ++x) fullLayers[l].at(rect.x0 + x, rect.y0 + y) = regionLayers[l].at(x, y);
    }
  }
  return {};
}

}  // namespace strata::terrain::sim
