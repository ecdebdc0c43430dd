#include <cmath>

#include <strata/viewer/store_io.hpp>

namespace strata::viewer {

namespace {

int bedrockField(const strata::terrain::TileStore& store) {
  const auto& fields = store.desc().fields;
  for (int f = 0; f < int(fields.size()); ++f) {
    if (fields[size_t(f)].kind == strata::terrain::LayerKind::Bedrock) return f;
  }
  return -1;
}

}  // namespace

Result<StoreSurface> loadStoreSurface(strata::terrain::TileStore& store, strata::gis::CellRect window) {
  const auto& fields = store.desc().fields;
  const int bedrock = bedrockField(store);
  if (bedrock < 0) return fail(store.dir().string() + ": the store has no bedrock field to draw");
  if (window.width < 2 || window.height < 2 || window.x < 0 || window.y < 0 ||
      window.x + window.width > store.width() || window.y + window.height > store.height()) {
    return fail(store.dir().string() + ": window " + std::to_string(window.x) + " " + std::to_string(window.y) + " " +
                std::to_string(window.width) + " " + std::to_string(window.height) + " is not inside the " +
                std::to_string(store.width()) + "x" + std::to_string(store.height()) + " grid");
  }
  StoreSurface s;
  s.window = window;
  STRATA_TRY(s.bedrock, store.readWindow(bedrock, window));
  s.surface.values = s.bedrock;
  for (int f = 0; f < int(fields.size()); ++f) {
    if (fields[size_t(f)].kind != strata::terrain::LayerKind::Material) continue;
    STRATA_TRY(auto layer, store.readWindow(f, window));
    for (size_t i = 0; i < layer.data.size(); ++i) {
      if (std::isnan(layer.data[i])) continue;
      s.surface.values.data[i] += layer.data[i];
    }
    if (s.layers.size() < 4) {
      for (float& t : layer.data) t = std::isnan(t) ? 0.0f : t;
      s.layers.push_back(std::move(layer));
      s.layerFields.push_back(f);
    }
  }
  s.surface.georef = store.windowGeoref(window, 0);
  return s;
}

Status saveStoreEdits(strata::terrain::TileStore& store, StoreSurface& loaded, const gis::Grid<float>& edited,
                      const std::vector<float>& editedLayers, const CellRect& rect) {
  if (rect.empty()) return {};
  const int bedrock = bedrockField(store);
  STRATA_CHECK(bedrock >= 0) << "saveStoreEdits: no bedrock field";
  auto& surface = loaded.surface.values;
  STRATA_CHECK(edited.width == surface.width && edited.height == surface.height)
      << "saveStoreEdits: edited grid differs from the loaded one";
  STRATA_CHECK(editedLayers.empty() || editedLayers.size() == surface.data.size() * 4)
      << "saveStoreEdits: layer thicknesses are not 4 per cell";
  // Layers the editor created on a store without material fields cannot be stored: their
  // thickness stays in the surface, hence in the bedrock.
  const size_t kept = editedLayers.empty() ? 0 : loaded.layers.size();
  gis::Grid<float> bedPatch(rect.width, rect.height);
  std::vector<gis::Grid<float>> layerPatches(kept, gis::Grid<float>(rect.width, rect.height));
  for (int y = 0; y < rect.height; ++y) {
    for (int x = 0; x < rect.width; ++x) {
      const int gx = rect.x + x, gy = rect.y + y;
      const size_t i = size_t(gy) * size_t(surface.width) + size_t(gx);
      float& b = loaded.bedrock.data[i];
      float& s = surface.data[i];
      // No-data cells were drawn filled (TerrainScene); they stay no data (edits there are not saved).
      if (!std::isnan(s) && edited.data[i] != s) {
        double delta = double(edited.data[i]) - double(s);
        for (size_t k = 0; k < kept; ++k) delta -= double(editedLayers[i * 4 + k]) - double(loaded.layers[k].data[i]);
        if (delta != 0) b = float(double(b) + delta);
        s = edited.data[i];
      }
      for (size_t k = 0; k < kept; ++k) {
        if (!std::isnan(s)) loaded.layers[k].data[i] = editedLayers[i * 4 + k];
        layerPatches[k].at(x, y) = loaded.layers[k].data[i];
      }
      bedPatch.at(x, y) = b;
    }
  }
  STRATA_TRY_STATUS(store.writeWindow(bedrock, loaded.window.x + rect.x, loaded.window.y + rect.y, bedPatch));
  for (size_t k = 0; k < kept; ++k) {
    STRATA_TRY_STATUS(
        store.writeWindow(loaded.layerFields[k], loaded.window.x + rect.x, loaded.window.y + rect.y, layerPatches[k]));
  }
  return store.commit();
}

}  // namespace strata::viewer
