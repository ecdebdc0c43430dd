// strata-view's library on a real GL context (llvmpipe without a GPU): the height brushes and
// their exact undo/redo, copy/paste, the fly-through camera, and a brush edit across a store's
// tile boundary written back through TileStore::writeWindow.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <numbers>
#include <span>

#include <glm/glm.hpp>

#include <gtest/gtest.h>

#include <strata/gis/dem_io.hpp>
#include <strata/gis/geodesy.hpp>
#include <strata/terrain/ingest.hpp>
#include <strata/viewer/camera_controller.hpp>
#include <strata/viewer/shader_slots.hpp>
#include <strata/viewer/store_io.hpp>
#include <strata/viewer/terrain_editor.hpp>
#include <strata/viewer/viewer.hpp>

#include "gl_fixture.hpp"
#include "strata_test.hpp"
#include "terrain_fixture.hpp"

namespace strata {
namespace {

using render::TerrainScene;
using namespace viewer;

gis::Raster planarDem(int w, int h, float (*f)(int, int)) {
  gis::Raster r;
  r.georef.epsg = 32612;
  r.georef.crsName = "WGS 84 / UTM zone 12N";
  r.georef.transform = {{500000.0, 30.0, 0.0, 4000000.0, 0.0, -30.0}};
  r.georef.width = w;
  r.georef.height = h;
  r.georef.body = gis::Body::wgs84();
  r.values = gis::Grid<float>(w, h);
  for (int y = 0; y < h; ++y) {
    for (int x = 0; x < w; ++x) r.values.at(x, y) = f(x, y);
  }
  return r;
}

float gentle(int x, int y) {
  return 1000.0f + 0.5f * float(x) + 0.25f * float(y) + 3.0f * std::sin(0.3f * float(x * y));
}

bool bitEqual(const std::vector<float>& a, const std::vector<float>& b) {
  return a.size() == b.size() && (a.empty() || std::memcmp(a.data(), b.data(), a.size() * sizeof(float)) == 0);
}

using ViewerGpu = test::GlTest;

TEST_F(ViewerGpu, ShadersUseTheSlotsDeclaredInCpp) {
  test::expectProgramsMatchSlots("viewer/shaders/", slots::kAll, {{{"viewer/shaders/brush.comp"}}});
}

TEST_F(ViewerGpu, RaiseAddsTheBrushVolumeAndUndoRestoresEveryBit) {
  auto scene = TerrainScene::create(planarDem(96, 80, gentle));
  ASSERT_TRUE(scene) << scene.message();
  auto editor = TerrainEditor::create(*scene);
  ASSERT_TRUE(editor) << editor.message();
  const auto before = scene->heights().data;
  const auto gpuBefore = scene->heightTexture().read<float>();

  // Radius 20 cells, 4 m at the centre, centred on a cell corner. The radius is ground metres:
  // near the UTM central meridian a 30 m cell is 30 / 0.9996 m of ground (a hair under 20
  // cells, so that rounding keeps the stroke's box at 41 cells).
  const glm::dvec2 k = scene->metresPerCrsUnit();
  EXPECT_NEAR(k.x, 1 / 0.9996, 1e-6);
  EXPECT_NEAR(k.y, 1 / 0.9996, 1e-6);
  const Brush brush{Tool::kRaise, 30.0 * std::min(k.x, k.y) * (20 - 1e-6), 4.0};
  editor->beginStroke();
  ASSERT_TRUE(editor->dab(brush, {48.0, 40.0}));
  editor->endStroke();
  const auto after = scene->heights().data;
  // The CPU mirror is what the GPU holds.
  EXPECT_TRUE(bitEqual(after, scene->heightTexture().read<float>()));
  double addedM3 = 0;
  int changedOutside = 0;
  for (int y = 0; y < 80; ++y) {
    for (int x = 0; x < 96; ++x) {
      const size_t i = size_t(y) * 96 + size_t(x);
      const double dz = double(after[i]) - double(before[i]);
      addedM3 += dz * 900.0;
      const double r = std::hypot(x + 0.5 - 48.0, y + 0.5 - 40.0) / 20.0;
      if (r >= 1 && after[i] != before[i]) ++changedOutside;
      if (r < 1) {
        EXPECT_NEAR(dz, 4.0 * (1 - r * r) * (1 - r * r), 1e-3) << x << " " << y;  // float rounding at 1000 m
      }
    }
  }
  EXPECT_EQ(changedOutside, 0);
  // Volume of the falloff (1 - r^2)^2 over a disc of radius R: pi R^2 / 3 times the height.
  // The cell-centre sum of a 20-cell radius matches it to well under 1%.
  const double expected = std::numbers::pi * 600.0 * 600.0 / 3.0 * 4.0;  // in CRS units, as addedM3
  EXPECT_NEAR(addedM3, expected, 0.005 * expected);

  ASSERT_TRUE(editor->undo());
  EXPECT_TRUE(bitEqual(scene->heights().data, before));
  EXPECT_TRUE(bitEqual(scene->heightTexture().read<float>(), gpuBefore));
  ASSERT_TRUE(editor->redo());
  EXPECT_TRUE(bitEqual(scene->heights().data, after));
  EXPECT_FALSE(editor->redo());
  ASSERT_TRUE(editor->undo());
  EXPECT_FALSE(editor->undo());
  EXPECT_TRUE(bitEqual(scene->heights().data, before));
  // The history holds only the stroke's bounding box (41 x 41 cells), before and after.
  EXPECT_EQ(editor->historyBytes(), size_t(41 * 41 * 2 * 4));
}

TEST_F(ViewerGpu, AStrokeOfSeveralDabsIsOneUndoStep) {
  auto scene = TerrainScene::create(planarDem(64, 64, gentle));
  ASSERT_TRUE(scene);
  auto editor = TerrainEditor::create(*scene);
  ASSERT_TRUE(editor);
  const auto before = scene->heights().data;
  editor->beginStroke();
  for (int i = 0; i < 5; ++i) ASSERT_TRUE(editor->dab({Tool::kLower, 150.0, 1.0}, {10.0 + 8 * i, 20.0 + 4 * i}));
  editor->endStroke();
  EXPECT_EQ(editor->undoDepth(), 1u);
  EXPECT_FALSE(bitEqual(scene->heights().data, before));
  ASSERT_TRUE(editor->undo());
  EXPECT_TRUE(bitEqual(scene->heights().data, before));
}

TEST_F(ViewerGpu, SmoothLowersRoughnessAndFlattenReachesTheLevel) {
  // A checkerboard of +-5 m: one full smoothing dab at the centre averages a 3x3 block.
  auto scene = TerrainScene::create(planarDem(64, 64, [](int x, int y) { return (x + y) % 2 ? 105.0f : 95.0f; }));
  ASSERT_TRUE(scene);
  auto editor = TerrainEditor::create(*scene);
  ASSERT_TRUE(editor);
  editor->beginStroke();
  ASSERT_TRUE(editor->dab({Tool::kSmooth, 300.0, 1.0}, {32.0, 32.0}));
  editor->endStroke();
  // Cell (32, 32) holds 95 with four 105 neighbours: its 3x3 mean is 95 + 40/9; its centre is
  // 0.0707 radii from the brush's, weight w = (1 - 0.005)^2, so it becomes 95 + w 40/9.
  const double w = (1 - 0.005) * (1 - 0.005);
  EXPECT_NEAR(scene->heights().at(32, 32), 95.0 + w * 40.0 / 9.0, 1e-4);
  // Smoothing lowers the roughness: the sum of squared differences to the 100 m mean, near the centre.
  double rough = 0;
  for (int y = 29; y < 36; ++y) {
    for (int x = 29; x < 36; ++x) rough += std::pow(scene->heights().at(x, y) - 100.0, 2);
  }
  EXPECT_LT(rough, 0.1 * 49 * 25.0);  // at most a tenth of the checkerboard's
  // Flatten with strength 1 at the centre pulls the centre cell to the level of the cell under
  // the first dab.
  editor->beginStroke();
  const float level = scene->heights().at(20, 20);
  ASSERT_TRUE(editor->dab({Tool::kFlatten, 300.0, 1.0}, {20.5, 20.5}));
  editor->endStroke();
  EXPECT_FLOAT_EQ(scene->heights().at(20, 20), level);
  EXPECT_NEAR(scene->heights().at(21, 20), level, 5.0 * 0.05);  // weight 0.98 at 1/10 of the radius
}

TEST_F(ViewerGpu, PasteWritesTheCopiedCellsExactly) {
  auto scene = TerrainScene::create(planarDem(64, 64, gentle));
  ASSERT_TRUE(scene);
  auto editor = TerrainEditor::create(*scene);
  ASSERT_TRUE(editor);
  const auto original = scene->heights();
  editor->beginStroke();
  ASSERT_TRUE(editor->dab({Tool::kCopy, 90.0, 1.0}, {16.0, 16.0}));  // 3 cells: a 7x7 box at 13..19
  ASSERT_TRUE(editor->dab({Tool::kPaste, 90.0, 1.0}, {40.0, 30.0}));
  editor->endStroke();
  const auto& d = editor->lastDab();
  ASSERT_EQ(d.width, 7);
  ASSERT_EQ(d.height, 7);
  for (int y = 0; y < 7; ++y) {
    for (int x = 0; x < 7; ++x) EXPECT_EQ(scene->heights().at(d.x + x, d.y + y), original.at(13 + x, 13 + y));
  }
  ASSERT_TRUE(editor->undo());
  EXPECT_TRUE(bitEqual(scene->heights().data, original.data));
}

TEST_F(ViewerGpu, StampBlendsOverTheBrushSquareInAllFourModes) {
  auto scene = TerrainScene::create(planarDem(64, 64, gentle));
  ASSERT_TRUE(scene);
  auto editor = TerrainEditor::create(*scene);
  ASSERT_TRUE(editor);
  const auto original = scene->heights();
  // A uniform stamp t = 0.5: f = strength / 2 on every cell whose centre is in the square
  // centre +- radius (radius 4 cells: 8 x 8 cells), nothing elsewhere.
  const gis::Grid<float> half(4, 4, 0.5f);
  struct Case {
    Blend blend;
    double strength;
    glm::dvec2 centre;
    float (*expect)(float);
  };
  const Case cases[] = {{Blend::kAdd, 10.0, {12, 12}, [](float h) { return h + 5.0f; }},
                        {Blend::kSubtract, 10.0, {40, 12}, [](float h) { return h - 5.0f; }},
                        {Blend::kMultiply, 4.0, {12, 40}, [](float h) { return h * 2.0f; }},
                        {Blend::kReplace, 100.0, {40, 40}, [](float) { return 50.0f; }}};
  editor->beginStroke();
  for (const auto& c : cases) {
    editor->setStamp(half, c.blend);
    ASSERT_TRUE(editor->dab({Tool::kStamp, 120.0, c.strength}, c.centre));
  }
  editor->endStroke();
  int inside = 0;
  for (int y = 0; y < 64; ++y) {
    for (int x = 0; x < 64; ++x) {
      const float h0 = original.at(x, y), h = scene->heights().at(x, y);
      const Case* hit = nullptr;
      for (const auto& c : cases) {
        if (std::abs(x + 0.5 - c.centre.x) <= 4 && std::abs(y + 0.5 - c.centre.y) <= 4) hit = &c;
      }
      if (hit) {
        ++inside;
        EXPECT_EQ(h, hit->expect(h0)) << x << " " << y;  // one float operation: exact
      } else {
        EXPECT_EQ(h, h0) << x << " " << y;
      }
    }
  }
  EXPECT_EQ(inside, 4 * 64);
  ASSERT_TRUE(editor->undo());
  EXPECT_TRUE(bitEqual(scene->heights().data, original.data));
}

TEST_F(ViewerGpu, MaterialBrushesMoveTheSurfaceWithTheLayerAndUndoBoth) {
  auto scene = TerrainScene::create(planarDem(64, 64, gentle));
  ASSERT_TRUE(scene);
  auto editor = TerrainEditor::create(*scene);
  ASSERT_TRUE(editor);
  const auto original = scene->heights();
  // Add 2 m of layer 1 at the centre (radius 10 cells); the surface rises by what was added.
  editor->beginStroke();
  ASSERT_TRUE(editor->dab({Tool::kAddMaterial, 300.0, 2.0, 1}, {32.0, 32.0}));
  editor->endStroke();
  ASSERT_EQ(editor->layers().size(), size_t(64 * 64 * 4));
  const auto layersAfterAdd = editor->layers();
  const auto heightsAfterAdd = scene->heights().data;
  double added = 0;
  for (int i = 0; i < 64 * 64; ++i) {
    const float t = editor->layers()[size_t(i) * 4 + 1];
    EXPECT_EQ(editor->layers()[size_t(i) * 4 + 0], 0.0f);
    EXPECT_NEAR(scene->heights().data[size_t(i)] - original.data[size_t(i)], t, 1e-3);  // float sums at 1000 m
    added += t;
  }
  EXPECT_NEAR(added, std::numbers::pi * 100.0 / 3.0 * 2.0, 0.01 * std::numbers::pi * 100.0 / 3.0 * 2.0);
  // The layer texture the renderer draws holds the same thicknesses.
  EXPECT_TRUE(bitEqual(scene->layerTexture()->read<float>(), editor->layers()));
  // Removing 5 m takes away only what is there: layer 1 ends empty, the surface back to where it was.
  editor->beginStroke();
  ASSERT_TRUE(editor->dab({Tool::kRemoveMaterial, 300.0, 5.0, 1}, {32.0, 32.0}));
  editor->endStroke();
  for (int i = 0; i < 64 * 64; ++i) {
    EXPECT_EQ(editor->layers()[size_t(i) * 4 + 1], 0.0f);
    EXPECT_NEAR(scene->heights().data[size_t(i)], original.data[size_t(i)], 1e-3);
  }
  // Removing from an empty layer changes nothing and records nothing.
  editor->beginStroke();
  ASSERT_TRUE(editor->dab({Tool::kRemoveMaterial, 300.0, 5.0, 2}, {32.0, 32.0}));
  editor->endStroke();
  EXPECT_EQ(editor->undoDepth(), 2u);
  // Undo restores layers and elevations bit for bit, one stroke at a time.
  ASSERT_TRUE(editor->undo());
  EXPECT_TRUE(bitEqual(editor->layers(), layersAfterAdd));
  EXPECT_TRUE(bitEqual(scene->heights().data, heightsAfterAdd));
  EXPECT_TRUE(bitEqual(scene->layerTexture()->read<float>(), layersAfterAdd));
  ASSERT_TRUE(editor->undo());
  EXPECT_TRUE(bitEqual(scene->heights().data, original.data));
  for (float t : editor->layers()) ASSERT_EQ(t, 0.0f);
}

TEST_F(ViewerGpu, ShadowsFollowABrushStrokeOnceItEnds) {
  // Flat ground with shadows cast for a sun 10 degrees above the west: all lit. A raise of 60 m
  // (radius 300 m) makes a hill; while the stroke lasts the shadows are not recast, after it
  // the next frame casts them again and the ground east of the hill is in shadow, west of it lit.
  ViewerOptions options;
  options.width = 64;
  options.height = 48;
  options.circles = 32;
  auto viewer = Viewer::create(planarDem(100, 100, [](int, int) { return 500.0f; }), options);
  ASSERT_TRUE(viewer) << viewer.message();
  auto& v = **viewer;
  ASSERT_TRUE(
      v.scene().castShadows({.subsolarLonLat = std::nullopt, .dirEnu = render::sunDirectionEnu(270.0, 10.0)}, 1.0f));
  auto lit = [&] { return v.scene().shadowTexture()->read<float>(); };
  for (float f : lit()) ASSERT_EQ(f, 1.0f);
  auto& editor = v.editor();
  editor.beginStroke();
  ASSERT_TRUE(editor.dab(Brush{Tool::kRaise, 300.0 * v.scene().metresPerCrsUnit().x, 60.0}, {50.0, 50.0}));
  EXPECT_TRUE(v.scene().shadowsStale());
  ASSERT_TRUE(v.frame(0.0));
  for (float f : lit()) ASSERT_EQ(f, 1.0f);  // mid-stroke: not yet
  editor.endStroke();
  ASSERT_TRUE(v.frame(0.0));
  EXPECT_FALSE(v.scene().shadowsStale());
  const auto after = lit();
  // 8.5 cells (255 m) east of the top, 4.6 m up the hill's lee: the top 55 m higher is 12 degrees
  // up, above the sun; as far west, on the sunward flank: lit.
  EXPECT_LT(after[size_t(50) * 100 + 58], 0.05f);
  EXPECT_EQ(after[size_t(50) * 100 + 41], 1.0f);
}

TEST_F(ViewerGpu, PickFindsTheGroundPointUnderThePixel) {
  // Flat ground at 500 m, 6 km square; the camera 1000 m above its centre looking north. The
  // centre pixel of an odd-sized image is the view axis: it meets the ground 1000 / tan(-pitch)
  // metres north. Tolerance 2 m: the depth buffer is float, the ring mesh is exact on flat ground.
  ViewerOptions options;
  options.width = 101;
  options.height = 101;
  options.circles = 64;
  auto viewer = Viewer::create(planarDem(200, 200, [](int, int) { return 500.0f; }), options);
  ASSERT_TRUE(viewer) << viewer.message();
  auto& v = **viewer;
  for (const double pitch : {-30.0, -45.0, -90.0}) {
    ASSERT_TRUE(v.handle(GoToCommand{503000.0, 3997000.0, 1000.0}));
    ASSERT_TRUE(v.handle(LookCommand{0.0, pitch}));
    ASSERT_TRUE(v.frame(0.0));
    const auto at = v.pick(50.5, 50.5);
    ASSERT_TRUE(at) << pitch;
    const double north = pitch == -90.0 ? 0.0 : 1000.0 / std::tan(-pitch * std::numbers::pi / 180.0);
    EXPECT_NEAR(at->x, 503000.0, 2.0) << pitch;
    EXPECT_NEAR(at->y, 3997000.0 + north, 2.0) << pitch;
  }
  // G goes to the point under the cursor: 1000 m ahead at pitch -45.
  ASSERT_TRUE(v.handle(LookCommand{0.0, -45.0}));
  ASSERT_TRUE(v.frame(0.0));
  ASSERT_TRUE(v.handle(MouseMoveCommand{50.5, 50.5}));
  ASSERT_TRUE(v.handle(KeyCommand{"G", true}));
  EXPECT_NEAR(v.camera().pose().lat, 3997000.0 + 1000.0, 2.0);
  EXPECT_NEAR(v.camera().heightAboveGroundM(1.0), 1000.0, 1e-6);
  // Looking up at the sky: nothing to pick.
  ASSERT_TRUE(v.handle(LookCommand{0.0, 30.0}));
  ASSERT_TRUE(v.frame(0.0));
  EXPECT_FALSE(v.pick(50.5, 10.5));
}

TEST_F(ViewerGpu, PlanetaryPickFindsTheGroundPointOnTheBody) {
  // The Moon (LOLA LDEM 4 px/deg, a sphere) and the Earth (ETOPO 20', the WGS84 ellipsoid) in
  // planetary mode, 200 km up. Straight down, the centre pixel of an odd-sized image is the
  // nadir: it picks the camera's lon/lat (1e-3 deg, 30 m on the Moon). At pitch -45, every 10th
  // pixel's picked point, put back on the terrain at its elevation and projected with the frame's
  // matrices, lands on that pixel (0.2 px; measured 0.02: the ring mesh is not the bilinear surface exactly).
  struct Site {
    const char* path;
    double lon, lat;
  };
  for (const Site& b : {Site{"moon/LDEM_4.LBL", 20.0, 10.0}, Site{"earth/etopo20.tif", -30.0, 40.0}}) {
    SCOPED_TRACE(b.path);
    auto dem = gis::readDemLonLat(test::dataPath(b.path));
    ASSERT_TRUE(dem) << dem.message();
    ViewerOptions options;
    options.width = 101;
    options.height = 81;
    options.circles = 128;
    options.planetary = true;
    auto viewer = Viewer::create(*dem, options);
    ASSERT_TRUE(viewer) << viewer.message();
    auto& v = **viewer;
    ASSERT_TRUE(v.handle(GoToCommand{b.lon, b.lat, 2e5}));
    ASSERT_TRUE(v.handle(LookCommand{30.0, -90.0}));
    ASSERT_TRUE(v.frame(0.0));
    const auto nadir = v.pick(50.5, 40.5);
    ASSERT_TRUE(nadir);
    EXPECT_NEAR(nadir->x, b.lon, 1e-3);
    EXPECT_NEAR(nadir->y, b.lat, 1e-3);

    ASSERT_TRUE(v.handle(LookCommand{30.0, -45.0}));
    ASSERT_TRUE(v.frame(0.0));
    const auto& pose = v.camera().pose();
    const auto f = render::frameGeometry(v.scene(), pose, v.shading(), 101, 81);
    const gis::LocalFrame enuFrame({pose.lon, pose.lat, pose.heightM}, dem->georef.body);
    double worst = 0;
    int picked = 0;
    for (int y = 5; y < 81; y += 10) {
      for (int x = 5; x < 101; x += 10) {
        const auto at = v.pick(x + 0.5, y + 0.5);
        if (!at) continue;
        ++picked;
        const double elev = v.scene().heightAt(at->x, at->y);
        const gis::Enu e = enuFrame.toEnu(gis::LonLat{at->x, at->y, elev});
        const glm::dvec4 clip = f.viewProj() * glm::dvec4(e.e, e.n, e.u, 1.0);
        const glm::dvec2 px((clip.x / clip.w + 1) * 0.5 * 101, (1 - clip.y / clip.w) * 0.5 * 81);
        const double err = glm::length(px - glm::dvec2(x + 0.5, y + 0.5));
        worst = std::max(worst, err);
        EXPECT_LT(err, 0.2) << x << " " << y;
      }
    }
    EXPECT_GT(picked, 60);  // looking down at 45 degrees from 200 km: the ground fills the view
    std::printf("[ planetary pick %s ] %d pixels, worst reprojection %.3f px\n", b.path, picked, worst);

    // A mouse tool works there: raise under the centre pixel changes the cell it picks.
    const auto centre = v.pick(50.5, 40.5);
    ASSERT_TRUE(centre);
    const glm::dvec2 cell = v.editor().cellOf(centre->x, centre->y);
    const float before = v.scene().heights().at(int(cell.x), int(cell.y));
    ASSERT_TRUE(v.handle(ToolCommand{"raise"}));
    ASSERT_TRUE(v.handle(BrushCommand{100000.0, 100.0}));
    ASSERT_TRUE(v.handle(MouseMoveCommand{50.5, 40.5}));
    ASSERT_TRUE(v.handle(MouseButtonCommand{MouseButtonCommand::kLeft, true}));
    ASSERT_TRUE(v.handle(MouseButtonCommand{MouseButtonCommand::kLeft, false}));
    EXPECT_GT(v.scene().heights().at(int(cell.x), int(cell.y)) - before, 50.0f);
    EXPECT_EQ(v.editor().undoDepth(), 1u);
  }
}

TEST_F(ViewerGpu, ErosionInTheRegionMovesTheSurfaceWithTheLayers) {
  // A 30 m-cell slope falling 3 m a cell to the south; a 40 x 40 region fed by a spring at its top.
  ViewerOptions options;
  options.width = 64;
  options.height = 48;
  options.circles = 32;
  auto viewer = Viewer::create(
      planarDem(64, 64, [](int x, int y) { return 400.0f - 3.0f * float(y) + 0.1f * float(x % 3); }), options);
  ASSERT_TRUE(viewer) << viewer.message();
  auto& v = **viewer;
  const auto before = v.scene().heights();
  // Region cells 12..51 (easting 500360..501560, northing 3999640..3998440).
  ASSERT_TRUE(v.handle(RegionCommand{500360.0, 3999640.0, 501560.0, 3998440.0}));
  ASSERT_TRUE(v.handle(ToolCommand{"spring"}));
  ASSERT_TRUE(v.handle(BrushCommand{30.0, 20.0}));
  ASSERT_TRUE(v.handle(StrokeCommand{500975.0, 3999600.0}));  // cell (32, 13)
  ASSERT_TRUE(v.handle(SimCommand{SimCommand::kErosionOn}));
  ASSERT_EQ(v.editor().layers().size(), size_t(64 * 64 * 4));
  ASSERT_TRUE(v.handle(SimCommand{SimCommand::kStep, 200}));
  const auto& after = v.scene().heights();
  const auto& layers = v.editor().layers();
  double surfaceChange = 0, layerChange = 0, maxCut = 0;
  for (int y = 0; y < 64; ++y) {
    for (int x = 0; x < 64; ++x) {
      const size_t i = size_t(y) * 64 + size_t(x);
      const bool inRegion = x >= 12 && x < 52 && y >= 12 && y < 52;
      if (!inRegion) {
        ASSERT_EQ(after.data[i], before.data[i]) << x << " " << y;
        continue;
      }
      const double dh = double(after.data[i]) - double(before.data[i]);
      double dl = -2.0;  // the region started with 2 m of soil in layer 1
      for (int k = 0; k < 4; ++k) dl += layers[i * 4 + size_t(k)];
      // The base does not move: the surface changes by what the layers gain or lose (float
      // rounding of elevations near 300 m: 1e-4 m).
      EXPECT_NEAR(dh, dl, 1e-4) << x << " " << y;
      surfaceChange += dh;
      layerChange += dl;
      maxCut = std::max(maxCut, -dh);
    }
  }
  EXPECT_NEAR(surfaceChange, layerChange, 1e-2);
  EXPECT_GT(maxCut, 1e-3) << "the spring's water eroded nothing";
  // The water and the suspended sediment reach the scene (a GPU-to-GPU copy of the state): the
  // region's fields, bit for bit, zero outside.
  ASSERT_NE(v.scene().waterStateTexture(), nullptr);
  auto checkDrawn = [&](bool wantSediment) {
    const auto drawn = v.scene().waterStateTexture()->read<float>();
    ASSERT_EQ(drawn.size(), size_t(64 * 64 * 4));
    const auto depth = v.region()->sim->readWaterDepth();
    const auto suspended = v.region()->sim->readSuspended();
    double carried = 0;
    for (int y = 0; y < 64; ++y) {
      for (int x = 0; x < 64; ++x) {
        const bool inRegion = x >= 12 && x < 52 && y >= 12 && y < 52;
        const size_t i = (size_t(y) * 64 + size_t(x)) * 4;
        ASSERT_EQ(drawn[i], inRegion ? depth.at(x - 12, y - 12) : 0.0f) << x << " " << y;
        ASSERT_EQ(drawn[i + 1], inRegion ? suspended.at(x - 12, y - 12) : 0.0f) << x << " " << y;
        carried += drawn[i + 1];
      }
    }
    if (wantSediment) {
      EXPECT_GT(carried, 1e-3) << "no sediment in suspension";
    } else {
      EXPECT_EQ(carried, 0.0);
    }
  };
  checkDrawn(true);
  // Erosion off: the sim carries none, and the tint goes.
  ASSERT_TRUE(v.handle(SimCommand{SimCommand::kErosionOff}));
  ASSERT_TRUE(v.handle(SimCommand{SimCommand::kStep, 1}));
  checkDrawn(false);
}

TEST_F(ViewerGpu, SuspendedSedimentTintsTheWaterWhereItIs) {
  // Flat ground at 500 m under 1 m of water everywhere; 0.05 m of sediment in suspension over
  // the western half. Seen from straight above, the normal is up, so each pixel is the shading
  // formula of terrain.frag evaluated by hand: ground tint c0 lit by 0.25 + 0.75 sun_z, water
  // mixed in by 0.55 + 0.45 k (k = 1 - exp(-h / waterDepthScaleM)), and the western water moved
  // towards siltColour by 1 - exp(-(s / h) / siltConcentration). Tolerance 2/255 (8-bit rounding).
  const int n = 64;
  auto scene = TerrainScene::create(planarDem(n, n, [](int, int) { return 500.0f; }));
  ASSERT_TRUE(scene) << scene.message();
  ASSERT_TRUE(scene->setWaterDepth(gis::Grid<float>(n, n, 1.0f)));
  gis::Grid<float> sediment(n, n, 0.0f);
  for (int y = 0; y < n; ++y) {
    for (int x = 0; x < n / 2; ++x) sediment.at(x, y) = 0.05f;
  }
  auto renderer = render::RingRenderer::create({.circles = 64});
  ASSERT_TRUE(renderer) << renderer.message();
  auto target = render::OffscreenTarget::create(64, 64);
  ASSERT_TRUE(target) << target.message();
  render::Shading shading;
  const render::CameraPose camera{500960.0, 3999040.0, 2000.0, 0.0, -90.0, 45.0};  // over the centre

  auto expected = [&](double concentration) {
    const glm::dvec3 sun = glm::normalize(glm::dvec3(shading.sunDir));
    const glm::dvec3 ground = glm::dvec3(0.22, 0.42, 0.20) * (0.25 + 0.75 * std::max(sun.z, 0.0));
    const double k = 1 - std::exp(-1.0 / shading.waterDepthScaleM);
    glm::dvec3 water = glm::mix(glm::dvec3(0.25, 0.62, 0.70), glm::dvec3(0.02, 0.10, 0.32), k);
    water = glm::mix(water, glm::dvec3(shading.siltColour), 1 - std::exp(-concentration / shading.siltConcentration));
    return glm::mix(ground, water * (0.6 + 0.4 * std::max(sun.z, 0.0)), 0.55 + 0.45 * k) * 255.0;
  };
  auto pixel = [&](const std::vector<uint8_t>& px, int x, int y) {
    const size_t i = (size_t(y) * 64 + size_t(x)) * 4;
    return glm::dvec3(px[i], px[i + 1], px[i + 2]);
  };
  // Without a sediment field: clear water everywhere.
  ASSERT_TRUE((*renderer)->draw(*scene, camera, shading, *target));
  const auto clear = target->colour();
  ASSERT_TRUE(scene->setSuspendedSediment(sediment));
  ASSERT_TRUE((*renderer)->draw(*scene, camera, shading, *target));
  const auto tinted = target->colour();
  // The view spans about 1660 m (55 cells) across: image columns 4..20 are west of the
  // boundary by 8 cells or more, columns 44..60 east of it.
  const glm::dvec3 clearWant = expected(0.0), siltWant = expected(0.05);
  for (int y = 4; y < 60; y += 4) {
    for (int x = 4; x <= 20; x += 4) {
      for (int ch = 0; ch < 3; ++ch) {
        EXPECT_NEAR(pixel(tinted, x, y)[ch], siltWant[ch], 2.0) << x << " " << y << " channel " << ch;
        EXPECT_NEAR(pixel(clear, x, y)[ch], clearWant[ch], 2.0) << x << " " << y << " channel " << ch;
      }
    }
    for (int x = 44; x <= 60; x += 4) {
      for (int ch = 0; ch < 3; ++ch) {
        EXPECT_NEAR(pixel(tinted, x, y)[ch], clearWant[ch], 2.0) << x << " " << y << " channel " << ch;
        EXPECT_EQ(pixel(tinted, x, y)[ch], pixel(clear, x, y)[ch]) << x << " " << y << " channel " << ch;
      }
    }
  }
  // The same fields as a simulation state buffer (h, s, hu, hv per cell) copied GPU-to-GPU into
  // a fresh scene: the same image, pixel for pixel.
  auto stateScene = TerrainScene::create(planarDem(n, n, [](int, int) { return 500.0f; }));
  ASSERT_TRUE(stateScene) << stateScene.message();
  std::vector<float> state(size_t(n) * size_t(n) * 4, 0.0f);
  for (size_t i = 0; i < size_t(n) * size_t(n); ++i) {
    state[4 * i] = 1.0f;
    state[4 * i + 1] = sediment.data[i];
  }
  const auto stateBuffer = gl::Buffer::from(std::span<const float>(state));
  stateScene->copyWaterState(stateBuffer, 0, 0, n, n);
  ASSERT_TRUE((*renderer)->draw(*stateScene, camera, shading, *target));
  EXPECT_EQ(target->colour(), tinted);
  // The tint is visible: the silty water is at least 20 levels away from the clear in some channel.
  const glm::dvec3 diff = glm::abs(siltWant - clearWant);
  EXPECT_GT(std::max({diff.x, diff.y, diff.z}), 20.0);
}

TEST_F(ViewerGpu, FlightSpeedFollowsHeightAboveGround) {
  auto scene = TerrainScene::create(planarDem(64, 64, [](int, int) { return 500.0f; }));
  ASSERT_TRUE(scene);
  CameraController cam(*scene);
  ASSERT_TRUE(cam.goTo(500960.0, 3999040.0, 10.0, 1.0));
  EXPECT_DOUBLE_EQ(cam.heightAboveGroundM(1.0), 10.0);
  EXPECT_DOUBLE_EQ(cam.speedMS(1.0), 5.0);  // 0.5 per second of the height above ground
  ASSERT_TRUE(cam.goTo(500960.0, 3999040.0, 1.0, 1.0));
  EXPECT_DOUBLE_EQ(cam.speedMS(1.0), 2.0);  // the floor near the ground
  ASSERT_TRUE(cam.goTo(500960.0, 3999040.0, 2e5, 1.0));
  EXPECT_DOUBLE_EQ(cam.speedMS(1.0), 1e5);  // orbit-like heights fly fast
  // One second forward heading east moves 100 km of ground east (100 km x 0.9996 in UTM
  // eastings on the central meridian); Q pulls down but never below the ground.
  cam.pose().headingDeg = 90;
  cam.keys.forward = true;
  cam.update(1.0, 1.0);
  // 1 cm: the scale is taken at the DEM's centre, 960 m east of the central meridian, where it
  // differs from 0.9996 by about 1e-8 (1 mm over 100 km).
  EXPECT_NEAR(cam.pose().lon, 500960.0 + 1e5 * 0.9996, 0.01);
  EXPECT_NEAR(cam.pose().lat, 3999040.0, 1e-6);
  cam.keys = {};
  cam.keys.down = true;
  for (int i = 0; i < 50; ++i) cam.update(1.0, 1.0);
  EXPECT_NEAR(cam.heightAboveGroundM(1.0), 1.0, 1e-9);  // FlightParams::minClearanceM
  EXPECT_FALSE(cam.goTo(400000.0, 3999040.0, 10.0, 1.0));
}

// A 128 x 64 store of two 64-cell tiles (exponents 3..6): the west tile nearly flat (its
// exponent the minimum), the east one rough. A raise brush centred on the boundary changes both
// tiles, continuously, and saving re-evaluates their resolutions.
TEST_F(ViewerGpu, BrushOnATileBoundaryChangesBothTilesAndTheirResolutions) {
  const auto dir = test::tempDir("viewer_store");
  auto dem = planarDem(128, 64, [](int x, int y) {
    return x < 64 ? 200.0f + 0.001f * float(y) : 200.0f + 20.0f * std::sin(0.7f * float(x)) * std::cos(0.5f * float(y));
  });
  terrain::IngestOptions opts;
  opts.metric = {3, 6};
  opts.cache.prefetch = false;
  auto values = dem.values;
  const terrain::WindowReader reader = [values](int x, int y, int w, int h) -> Result<gis::Grid<float>> {
    gis::Grid<float> out(w, h, std::numeric_limits<float>::quiet_NaN());
    for (int j = 0; j < h; ++j) {
      for (int i = 0; i < w; ++i) {
        if (x + i < values.width && y + j < values.height) out.at(i, j) = values.at(x + i, y + j);
      }
    }
    return out;
  };
  ASSERT_TRUE(terrain::ingest(dir, dem.georef, {{{"bedrock", terrain::LayerKind::Bedrock, ""}, reader}}, opts));
  auto store = terrain::TileStore::open(dir);
  ASSERT_TRUE(store) << store.message();
  ASSERT_EQ(store->tilesX(), 2);
  EXPECT_EQ(store->tile(0, 0).exp, 3);
  EXPECT_EQ(store->tile(1, 0).exp, 6);
  auto loaded = loadStoreSurface(*store, {0, 0, 128, 64});
  ASSERT_TRUE(loaded) << loaded.message();
  auto scene = TerrainScene::create(loaded->surface);
  ASSERT_TRUE(scene);
  auto editor = TerrainEditor::create(*scene);
  ASSERT_TRUE(editor);
  const auto before = scene->heights();
  editor->beginStroke();
  ASSERT_TRUE(editor->dab({Tool::kRaise, 450.0, 200.0}, {64.0, 32.0}));  // 15 cells each side of x = 64
  editor->endStroke();
  const auto& edited = scene->heights();
  // Both tiles changed, and symmetrically: the brush is continuous across the boundary.
  for (int d = 0; d < 15; ++d) {
    const float west = edited.at(63 - d, 32) - before.at(63 - d, 32),
                east = edited.at(64 + d, 32) - before.at(64 + d, 32);
    EXPECT_GT(west, 0.0f) << d;
    EXPECT_NEAR(west, east, 1e-3) << d;
  }
  ASSERT_TRUE(saveStoreEdits(*store, *loaded, edited, editor->layers(), editor->dirty()));

  auto reopened = terrain::TileStore::open(dir);
  ASSERT_TRUE(reopened) << reopened.message();
  // The west tile's range went from 0.06 m to ~200 m of a ~240 m global range: its exponent
  // follows the metric, as chooseTileExp gives it from the stored ranges (the top bin: 6).
  const auto [lo, hi] = reopened->globalRange(0);
  for (int tx = 0; tx < 2; ++tx) {
    const auto& t = reopened->tile(tx, 0);
    EXPECT_EQ(t.exp, terrain::chooseTileExp({t.maxV[0] - t.minV[0]}, {hi - lo}, 3, 6)) << tx;
  }
  EXPECT_EQ(reopened->tile(0, 0).exp, 6);
  // At full resolution the store now holds exactly the edited surface, on both sides.
  auto back = reopened->readWindow(0, {0, 0, 128, 64});
  ASSERT_TRUE(back);
  EXPECT_TRUE(bitEqual(back->data, edited.data));
}

}  // namespace
}  // namespace strata
