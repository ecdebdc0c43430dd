#pragma once
// The viewer's terrain from a TileStore and its edits written back. The surface drawn is the
// bedrock field plus every material layer; an edit changes the surface by a delta, which saving
// adds to the bedrock field (material layers keep their thickness) through writeWindow, so the
// tiles under the edit are re-evaluated by the seed metric; commit() makes it durable.

#include <strata/core/result.hpp>
#include <strata/gis/raster.hpp>
#include <strata/render/viewer/terrain_editor.hpp>
#include <strata/terrain/tile_store.hpp>

namespace strata::render::viewer {

/// A base-grid window of a store as a DEM, with the bedrock it was built from.
struct StoreSurface {
  strata::terrain::Window window;  ///< base-grid cells
  gis::Raster surface;             ///< bedrock + material layers (m), georeferenced
  gis::Grid<float> bedrock;
};

/// Reads `window` (level 0) of `store`: the bedrock field plus every material layer.
Result<StoreSurface> loadStoreSurface(strata::terrain::TileStore& store, strata::terrain::Window window);
/// Writes the cells `rect` (window cells) of `edited` (the surface, as drawn) back to the store's
/// bedrock field as bedrock + (edited - loaded surface), updates `loaded` to match, and commits.
Status saveStoreEdits(strata::terrain::TileStore& store, StoreSurface& loaded, const gis::Grid<float>& edited,
                      const CellRect& rect);

}  // namespace strata::render::viewer
