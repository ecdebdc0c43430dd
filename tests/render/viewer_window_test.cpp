// The whole strata-view program in a GLFW window under Xvfb, driven by a script through the
// same Command path as a person's input: it flies, chooses a simulation region, places a spring
// and runs the simulation, raises the terrain with the mouse and undoes it, saving the terrain
// and taking screenshots between the steps. Screenshots are compared with golden images; the
// undo must return the terrain to its exact earlier state.
#include <cstdlib>
#include <cstring>
#include <fstream>

#include <gtest/gtest.h>

#include <strata/gis/dem_io.hpp>
#include <strata/render/image_io.hpp>

#include "strata_test.hpp"
#include "terrain_fixture.hpp"

namespace strata {
namespace {

TEST(ViewerWindow, ScriptedSessionMatchesGoldensAndUndoIsExact) {
  if (std::getenv("STRATA_NO_GL")) GTEST_SKIP() << "STRATA_NO_GL set: no GL in this run";
  ASSERT_EQ(std::system("command -v xvfb-run > /dev/null"), 0)
      << "xvfb-run is missing (scripts/setup.sh installs xvfb): strata-view needs an X server";
  const auto out = test::outputDir("viewer");
  const std::string o = out.string() + "/";
  for (const char* f : {"fly.png", "sim.png", "raised.png", "undone.png", "before.tif", "raised.tif", "undone.tif"}) {
    std::filesystem::remove(out / f);
  }
  // Grand Canyon, 512 x 512 cells of 1/512 degree. Frames advance 1/30 s each (--dt).
  std::ofstream(out / "session.txt") << "0 goto -112.09 36.01 2500\n"
                                        "0 look 0 -25\n"
                                        "0 key W down\n"
                                        "20 key W up\n"
                                        "21 screenshot " +
                                            o +
                                            "fly.png\n"
                                            "22 region -112.15 36.04 -112.03 36.16\n"
                                            "22 tool spring\n"
                                            "22 brush 500 5000\n"
                                            "23 stroke -112.09 36.10\n"
                                            "24 speed 8\n"
                                            "24 play\n"
                                            "54 pause\n"
                                            "55 screenshot " +
                                            o +
                                            "sim.png\n"
                                            "56 save " +
                                            o +
                                            "before.tif\n"
                                            "56 tool raise\n"
                                            "56 brush 1500 150\n"
                                            "57 mouse 240 180\n"
                                            "57 button left down\n"
                                            "58 button left up\n"
                                            "58 save " +
                                            o +
                                            "raised.tif\n"
                                            "59 screenshot " +
                                            o +
                                            "raised.png\n"
                                            "60 undo\n"
                                            "60 save " +
                                            o +
                                            "undone.tif\n"
                                            "61 screenshot " +
                                            o + "undone.png\n";
  const std::string cmd = std::string("xvfb-run -a -s '-screen 0 1280x800x24' ") + STRATA_VIEW_EXE + " " +
                          STRATA_DATA_DIR +
                          "/grand_canyon/grand_canyon_512.tif --size 480x320 --circles 128 --script " + o +
                          "session.txt > " + o + "session.log 2>&1";
  const int rc = std::system(cmd.c_str());
  std::ifstream logFile(out / "session.log");
  const std::string log((std::istreambuf_iterator<char>(logFile)), std::istreambuf_iterator<char>());
  ASSERT_EQ(rc, 0) << cmd << "\n" << log;

  // Tolerances as for the renderer's goldens (terrain_render_test): a channel may differ by 24
  // (llvmpipe vs a GPU's rasterisation and float rounding) on at most 2% of the pixels.
  for (const char* name : {"fly", "sim", "raised"}) {
    auto image = render::readImage8(o + name + ".png");
    ASSERT_TRUE(image) << image.message();
    const auto r = test::compareWithGolden(std::string("viewer_") + name, *image, 24, 0.02, test::outputDir("render"));
    EXPECT_TRUE(r.ok) << r.message;
  }
  // The undo restores the terrain bit for bit (the saved grids) and hence the image.
  auto before = gis::readDem(o + "before.tif");
  auto raised = gis::readDem(o + "raised.tif");
  auto undone = gis::readDem(o + "undone.tif");
  ASSERT_TRUE(before && raised && undone);
  ASSERT_EQ(before->values.data.size(), undone->values.data.size());
  EXPECT_EQ(std::memcmp(before->values.data.data(), undone->values.data.data(), before->values.data.size() * 4), 0);
  int changed = 0;
  for (size_t i = 0; i < before->values.data.size(); ++i) changed += before->values.data[i] != raised->values.data[i];
  EXPECT_GT(changed, 100) << "the raise brush changed too little";
  auto sim = render::readImage8(o + "sim.png");
  auto und = render::readImage8(o + "undone.png");
  ASSERT_TRUE(sim && und);
  EXPECT_EQ(sim->pixels, und->pixels) << "same terrain, same (paused) water: the same image";
}

}  // namespace
}  // namespace strata
