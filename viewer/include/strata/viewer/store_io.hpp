#pragma once
// The viewer's terrain from a TileStore and its edits written back. The surface drawn is the
// bedrock field plus every material layer; an edit changes the surface by a delta, which saving
// adds to the bedrock field (material layers keep their thickness) through writeWindow, so the
// tiles under the edit are re-evaluated by the seed metric; commit() makes it durable.

#include <strata/core/result.hpp>
#include <strata/gis/raster.hpp>
#include <strata/terrain/tile_store.hpp>
#include <strata/viewer/terrain_editor.hpp>

namespace strata::viewer {

/// A base-grid window of a store as a DEM, with the bedrock it was built from.
struct StoreSurface {
  strata::gis::CellRect window;  ///< base-grid cells
  gis::Raster surface;           ///< bedrock + material layers (m), georeferenced
  gis::Grid<float> bedrock;
  std::vector<gis::Grid<float>> layers;  ///< the first four material layers (m), bottom first
  std::vector<int> layerFields;          ///< their store fields
};

/// Reads `window` (level 0) of `store`: the bedrock field plus every material layer.
Result<StoreSurface> loadStoreSurface(strata::terrain::TileStore& store, strata::gis::CellRect window);
/// Writes the cells `rect` (window cells) of an edit back to the store and commits: `edited` is
/// the surface as drawn, `editedLayers` the thicknesses (4 per cell, TerrainEditor::layers(); empty
/// if never edited). Each material layer is written as edited; bedrock as bedrock + (surface
/// change) - (sum of the layer changes), so unchanged cells stay bit for bit. `loaded` is updated.
Status saveStoreEdits(strata::terrain::TileStore& store, StoreSurface& loaded, const gis::Grid<float>& edited,
                      const std::vector<float>& editedLayers, const CellRect& rect);

}  // namespace strata::viewer
