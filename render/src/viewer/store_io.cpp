#include <cmath>

#include <strata/render/viewer/store_io.hpp>

namespace strata::render::viewer {

Result<StoreSurface> loadStoreSurface(strata::terrain::TileStore& store, strata::terrain::Window window) {
  const auto& fields = store.desc().fields;
  const int bedrock = [&] {
    for (int f = 0; f < int(fields.size()); ++f) {
      if (fields[size_t(f)].kind == strata::terrain::LayerKind::Bedrock) return f;
    }
    return -1;
  }();
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
      if (!std::isnan(layer.data[i])) s.surface.values.data[i] += layer.data[i];
    }
  }
  s.surface.georef = store.windowGeoref(window, 0);
  return s;
}

Status saveStoreEdits(strata::terrain::TileStore& store, StoreSurface& loaded, const gis::Grid<float>& edited,
                      const CellRect& rect) {
  if (rect.empty()) return {};
  const int bedrock = [&] {
    const auto& fields = store.desc().fields;
    for (int f = 0; f < int(fields.size()); ++f) {
      if (fields[size_t(f)].kind == strata::terrain::LayerKind::Bedrock) return f;
    }
    return -1;
  }();
  STRATA_CHECK(bedrock >= 0) << "saveStoreEdits: no bedrock field";
  STRATA_CHECK(edited.width == loaded.surface.values.width && edited.height == loaded.surface.values.height)
      << "saveStoreEdits: edited grid differs from the loaded one";
  gis::Grid<float> patch(rect.w, rect.h);
  for (int y = 0; y < rect.h; ++y) {
    for (int x = 0; x < rect.w; ++x) {
      const int gx = rect.x + x, gy = rect.y + y;
      float& b = loaded.bedrock.at(gx, gy);
      float& s = loaded.surface.values.at(gx, gy);
      const float e = edited.at(gx, gy);
      // No-data cells were drawn filled (TerrainScene); they stay no data (edits there are not saved).
      if (!std::isnan(s) && e != s) {
        b += e - s;
        s = e;
      }
      patch.at(x, y) = b;
    }
  }
  STRATA_TRY_STATUS(store.writeWindow(bedrock, loaded.window.x + rect.x, loaded.window.y + rect.y, patch));
  return store.commit();
}

}  // namespace strata::render::viewer
