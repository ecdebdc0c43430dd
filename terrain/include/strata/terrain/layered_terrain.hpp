#pragma once
// The layered terrain in memory: a bedrock datum, an ordered stack of material layers (thickness
// fields, bottom to top) and water. The surface is the datum plus the sum of the layers; the water
// surface is the surface plus the water depth. All fields are float32 metres, NaN = no data.

#include <string>
#include <vector>

#include <strata/core/result.hpp>
#include <strata/gis/raster.hpp>
#include <strata/terrain/material.hpp>

namespace strata::terrain {

/// What a stored field is: the datum (elevation), a material layer (thickness) or water (depth).
enum class LayerKind { Bedrock, Material, Water };

/// "bedrock", "material", "water" (the manifest spelling).
const char* toString(LayerKind kind);
/// Parses toString()'s spelling.
Result<LayerKind> parseLayerKind(const std::string& text);

/// One material layer: `thicknessM` metres of `material` (an index into the terrain's table).
struct MaterialLayer {
  std::string name;
  int material = 0;
  gis::Grid<float> thicknessM;
};

/// A layered terrain held in memory (a window of a store, or a small scene).
struct LayeredTerrain {
  gis::Georef georef;
  std::vector<Material> materials = defaultMaterials();
  gis::Grid<float> bedrockM;          ///< datum elevation (m above the body's reference)
  std::vector<MaterialLayer> layers;  ///< bottom to top
  gis::Grid<float> waterM;            ///< water depth above the surface (m, >= 0)

  /// A terrain whose datum is the DEM, with no material layers and no water.
  static LayeredTerrain fromDem(const gis::Raster& dem);

  int width() const { return bedrockM.width; }
  int height() const { return bedrockM.height; }

  /// Adds `thicknessM` of material `materialName` on top of the stack. Fails (naming the layer)
  /// on an unknown material, a size mismatch, a duplicate name or a negative thickness.
  Status addLayer(const std::string& name, const std::string& materialName, gis::Grid<float> thicknessM);

  /// Datum + sum of the layers at one cell (NaN where the datum is NaN).
  float surfaceAt(int x, int y) const;
  /// The whole surface grid.
  gis::Grid<float> surface() const;
  /// Index of the topmost layer with a thickness > 0 at (x, y), or -1 where only bedrock shows.
  int topLayerAt(int x, int y) const;

  /// The stored fields in store order: bedrock, layers bottom to top, water.
  std::vector<std::string> fieldNames() const;
  std::vector<LayerKind> fieldKinds() const;
  /// Field `i` in store order.
  const gis::Grid<float>& field(size_t i) const;
  gis::Grid<float>& field(size_t i);
  size_t fieldCount() const { return layers.size() + 2; }
};

}  // namespace strata::terrain
