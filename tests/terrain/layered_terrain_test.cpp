#include <gtest/gtest.h>

#include <strata/terrain/layered_terrain.hpp>

namespace strata::terrain {
namespace {

gis::Raster demOf(int w, int h, float z) {
  gis::Raster r;
  r.georef.width = w;
  r.georef.height = h;
  r.values = gis::Grid<float>(w, h, z);
  return r;
}

TEST(LayeredTerrain, SurfaceIsDatumPlusLayers) {
  auto t = LayeredTerrain::fromDem(demOf(4, 3, 100.0f));
  gis::Grid<float> soil(4, 3, 2.0f), sand(4, 3, 0.0f);
  sand.at(1, 1) = 0.5f;
  ASSERT_TRUE(t.addLayer("soil", "soil", soil));
  ASSERT_TRUE(t.addLayer("dune", "sand", sand));
  // 100 + 2 + 0.5 is exact in float32.
  EXPECT_EQ(t.surfaceAt(1, 1), 102.5f);
  EXPECT_EQ(t.surfaceAt(0, 0), 102.0f);
  EXPECT_EQ(t.surface().at(1, 1), 102.5f);
  EXPECT_EQ(t.topLayerAt(1, 1), 1);
  EXPECT_EQ(t.topLayerAt(0, 0), 0);
  EXPECT_EQ(t.fieldNames(), (std::vector<std::string>{"bedrock", "soil", "dune", "water"}));
  EXPECT_EQ(t.fieldKinds()[2], LayerKind::Material);
  EXPECT_EQ(&t.field(3), &t.waterM);
  EXPECT_EQ(t.materials[size_t(t.layers[1].material)].name, "sand");
}

TEST(LayeredTerrain, AddLayerRejectsBadInput) {
  auto t = LayeredTerrain::fromDem(demOf(4, 3, 0.0f));
  auto unknown = t.addLayer("x", "cheese", gis::Grid<float>(4, 3, 1.0f));
  ASSERT_FALSE(unknown);
  EXPECT_NE(unknown.message().find("cheese"), std::string::npos);
  EXPECT_FALSE(t.addLayer("x", "soil", gis::Grid<float>(3, 3, 1.0f)));
  EXPECT_FALSE(t.addLayer("water", "soil", gis::Grid<float>(4, 3, 1.0f)));
  EXPECT_FALSE(t.addLayer("x", "soil", gis::Grid<float>(4, 3, -1.0f)));
  EXPECT_TRUE(t.layers.empty());
}

TEST(Material, ValidateNamesTheField) {
  auto m = defaultMaterials();
  for (const auto& mat : m) EXPECT_TRUE(validateMaterial(mat)) << mat.name;
  m[0].talusAngleDeg = 95;
  auto s = validateMaterial(m[0]);
  ASSERT_FALSE(s);
  EXPECT_NE(s.message().find("talus_angle_deg"), std::string::npos);
}

TEST(LayerKind, RoundTripsThroughText) {
  for (auto k : {LayerKind::Bedrock, LayerKind::Material, LayerKind::Water}) EXPECT_EQ(*parseLayerKind(toString(k)), k);
  EXPECT_FALSE(parseLayerKind("lava"));
}

}  // namespace
}  // namespace strata::terrain
