#include <strata/terrain/layered_terrain.hpp>

#include <cmath>

namespace strata::terrain {

const char* toString(LayerKind kind) {
  switch (kind) {
    case LayerKind::Bedrock: return "bedrock";
    case LayerKind::Material: return "material";
    case LayerKind::Water: return "water";
  }
  return "?";
}

Result<LayerKind> parseLayerKind(const std::string& text) {
  if (text == "bedrock") return LayerKind::Bedrock;
  if (text == "material") return LayerKind::Material;
  if (text == "water") return LayerKind::Water;
  return fail("layer kind '" + text + "': expected bedrock, material or water");
}

LayeredTerrain LayeredTerrain::fromDem(const gis::Raster& dem) {
  LayeredTerrain t;
  t.georef = dem.georef;
  t.bedrockM = dem.values;
  t.waterM = gis::Grid<float>(dem.values.width, dem.values.height, 0.0f);
  return t;
}

Status LayeredTerrain::addLayer(const std::string& name, const std::string& materialName, gis::Grid<float> thicknessM) {
  const int m = findMaterial(materials, materialName);
  if (m < 0) return fail("layer '" + name + "': unknown material '" + materialName + "'");
  if (thicknessM.width != width() || thicknessM.height != height()) {
    return fail("layer '" + name + "': " + std::to_string(thicknessM.width) + "x" + std::to_string(thicknessM.height) +
                " does not match the terrain's " + std::to_string(width()) + "x" + std::to_string(height()));
  }
  for (const auto& n : fieldNames()) {
    if (n == name) return fail("layer '" + name + "': name already used");
  }
  for (float v : thicknessM.data) {
    if (v < 0) return fail("layer '" + name + "': negative thickness " + std::to_string(v));
  }
  layers.push_back({name, m, std::move(thicknessM)});
  return {};
}

float LayeredTerrain::surfaceAt(int x, int y) const {
  float z = bedrockM.at(x, y);
  for (const auto& l : layers) z += l.thicknessM.at(x, y);
  return z;
}

gis::Grid<float> LayeredTerrain::surface() const {
  gis::Grid<float> s = bedrockM;
  for (const auto& l : layers) {
    for (size_t i = 0; i < s.size(); ++i) s.data[i] += l.thicknessM.data[i];
  }
  return s;
}

int LayeredTerrain::topLayerAt(int x, int y) const {
  for (int i = int(layers.size()) - 1; i >= 0; --i) {
    if (layers[size_t(i)].thicknessM.at(x, y) > 0) return i;
  }
  return -1;
}

std::vector<std::string> LayeredTerrain::fieldNames() const {
  std::vector<std::string> names{"bedrock"};
  for (const auto& l : layers) names.push_back(l.name);
  names.push_back("water");
  return names;
}

std::vector<LayerKind> LayeredTerrain::fieldKinds() const {
  std::vector<LayerKind> kinds{LayerKind::Bedrock};
  for (size_t i = 0; i < layers.size(); ++i) kinds.push_back(LayerKind::Material);
  kinds.push_back(LayerKind::Water);
  return kinds;
}

const gis::Grid<float>& LayeredTerrain::field(size_t i) const {
  STRATA_CHECK(i < fieldCount()) << "field " << i << " of " << fieldCount();
  if (i == 0) return bedrockM;
  if (i == fieldCount() - 1) return waterM;
  return layers[i - 1].thicknessM;
}

gis::Grid<float>& LayeredTerrain::field(size_t i) {
  return const_cast<gis::Grid<float>&>(static_cast<const LayeredTerrain&>(*this).field(i));
}

}  // namespace strata::terrain
