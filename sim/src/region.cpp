#include <strata/sim/region.hpp>

#include <cmath>
#include <memory>
#include <string>

namespace strata::sim {
namespace {

std::string describe(const CellRect& r) {
  return "(" + std::to_string(r.x) + ", " + std::to_string(r.y) + ") " + std::to_string(r.width) + "x" +
         std::to_string(r.height);
}

Status checkRect(const CellRect& r, int w, int h) {
  if (r.width < 2 || r.height < 2) return fail("sim region " + describe(r) + ": must be at least 2x2 cells");
  if (r.x < 0 || r.y < 0 || r.x + r.width > w || r.y + r.height > h) {
    return fail("sim region " + describe(r) + ": not inside the " + std::to_string(w) + "x" + std::to_string(h) +
                " grid");
  }
  return {};
}

gis::Grid<float> crop(const gis::Grid<float>& g, const CellRect& r) {
  if (g.size() == 0) return {};
  gis::Grid<float> out(r.width, r.height);
  for (int y = 0; y < r.height; ++y) {
    for (int x = 0; x < r.width; ++x) out.at(x, y) = g.at(r.x + x, r.y + y);
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
  out.manningN = crop(full.manningN, rect);
  out.infiltrationMmPerHour = crop(full.infiltrationMmPerHour, rect);
  out.infiltrationSuctionM = crop(full.infiltrationSuctionM, rect);
  if (full.rowDxM.size() == 1) {
    out.rowDxM = full.rowDxM;
  } else if (full.rowDxM.size() == size_t(full.baseM.height)) {
    out.rowDxM.assign(full.rowDxM.begin() + rect.y, full.rowDxM.begin() + rect.y + rect.height);
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
      for (int x = 0; x < rect.width; ++x) fullLayers[l].at(rect.x + x, rect.y + y) = regionLayers[l].at(x, y);
    }
  }
  return {};
}

RegionSource regionSourceOf(SimInput whole) {
  auto held = std::make_shared<const SimInput>(std::move(whole));
  RegionSource r;
  r.width = held->baseM.width;
  r.height = held->baseM.height;
  r.materials = held->materials;
  r.rowDxM = held->rowDxM;
  r.dyM = held->dyM;
  r.datumM = held->datumM;
  r.read = [held](const CellRect& window) { return cutRegion(*held, window); };
  return r;
}

Status checkRegionSource(const RegionSource& r) {
  if (r.width < 2 || r.height < 2) return fail("sim region source: must be at least 2x2 cells");
  if (r.materials.empty()) return fail("sim region source: no materials (need at least one layer)");
  if (r.rowDxM.size() != 1 && r.rowDxM.size() != size_t(r.height)) {
    return fail("sim region source: rowDxM has " + std::to_string(r.rowDxM.size()) + " values, expected 1 or " +
                std::to_string(r.height) + " (one per row)");
  }
  for (double dx : r.rowDxM) {
    if (!(dx > 0) || !std::isfinite(dx)) return fail("sim region source: rowDxM has a cell size " + std::to_string(dx));
  }
  if (!(r.dyM > 0) || !std::isfinite(r.dyM)) return fail("sim region source: dyM must be positive");
  if (!std::isfinite(r.datumM)) return fail("sim region source: datumM is not finite");
  if (!r.read) return fail("sim region source: no reader");
  return {};
}

Result<SimInput> readWindow(const RegionSource& region, const CellRect& window) {
  STRATA_TRY_STATUS(checkRect(window, region.width, region.height));
  auto in = region.read(window);
  if (!in) return fail("sim region window " + describe(window) + ": " + in.message());
  const SimInput& s = *in;
  auto sized = [&](const gis::Grid<float>& g, bool optional) {
    return (optional && g.size() == 0) || (g.width == window.width && g.height == window.height);
  };
  bool ok = sized(s.baseM, false) && sized(s.waterDepthM, true) && sized(s.rainMmPerHour, true) &&
            sized(s.manningN, true) && sized(s.infiltrationMmPerHour, true) && sized(s.infiltrationSuctionM, true) &&
            s.layersM.size() == region.materials.size() && s.materials.size() == region.materials.size() &&
            (s.rowDxM.size() == 1 || s.rowDxM.size() == size_t(window.height)) && s.dyM == region.dyM &&
            s.datumM == region.datumM;
  for (const auto& l : s.layersM) ok = ok && sized(l, false);
  if (!ok) {
    return fail("sim region window " + describe(window) +
                ": the reader returned grids of another size or another layer stack, cell size or datum");
  }
  return in;
}

}  // namespace strata::sim
