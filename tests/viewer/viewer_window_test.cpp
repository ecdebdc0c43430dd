// The whole strata-view program in a GLFW window under Xvfb, driven by a script through the
// same Command path as a person's input: it flies, chooses a simulation region, places a spring
// and runs the simulation, raises the terrain with the mouse and undoes it, saving the terrain
// and taking screenshots between the steps. Screenshots are compared with golden images; the
// undo must return the terrain to its exact earlier state. A second session draws the map layers
// (a drape, a graticule, a scale bar) from the command line.
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <vector>

#include <gtest/gtest.h>

#include <strata/core/process.hpp>
#include <strata/gis/dem_io.hpp>
#include <strata/gis/geodesy.hpp>
#include <strata/render/image_io.hpp>

#include "../render/drape_raster.hpp"
#include "gl_fixture.hpp"
#include "strata_test.hpp"
#include "terrain_fixture.hpp"

namespace strata {
namespace {

constexpr const char* kXvfbRun = "/usr/bin/xvfb-run";

// Runs strata-view in a virtual X server with `args`, without a shell (an argument vector: no
// path is ever parsed as a command line); writes its output to `log` for people to read and
// returns it, or the failure with it.
// Under the sanitizer build the viewer's leak check is off: GLX loads Mesa's X11 driver, which is
// unloaded before LeakSanitizer runs, so its allocations show as "<unknown module>" frames no
// library suppression (scripts/lsan.supp) can match. ASan's memory errors and UBSan still apply
// to that process, and the viewer's code is leak-checked by the headless tests
// (viewer_gpu_test.cpp). Outside a sanitizer build ASAN_OPTIONS is ignored; this process read
// its own at start-up, so changing it here affects the child only.
Result<std::string> runViewerWindow(const std::vector<std::string>& args, const std::filesystem::path& log) {
  const char* asan = std::getenv("ASAN_OPTIONS");
  const std::string before = asan ? asan : "";
  ::setenv("ASAN_OPTIONS", (before + ":detect_leaks=0").c_str(), 1);
  std::vector<std::string> argv{kXvfbRun, "-a", "-s", "-screen 0 1280x800x24", STRATA_VIEW_EXE};
  argv.insert(argv.end(), args.begin(), args.end());
  auto out = runProcess(argv);
  if (asan) {
    ::setenv("ASAN_OPTIONS", before.c_str(), 1);
  } else {
    ::unsetenv("ASAN_OPTIONS");
  }
  std::ofstream(log) << (out ? *out : out.message());
  return out;
}

TEST(ViewerWindow, ScriptedSessionMatchesGoldensAndUndoIsExact) {
  if (test::noGlRequested()) GTEST_SKIP() << "STRATA_NO_GL=1: this run has no GL context";
  ASSERT_TRUE(std::filesystem::exists(kXvfbRun))
      << "xvfb-run is missing (scripts/setup.sh installs xvfb): strata-view needs an X server";
  const auto out = test::outputDir("viewer");
  const std::string o = out.string() + "/";
  for (const char* f : {"fly.png", "sim.png", "raised.png", "undone.png", "before.tif", "raised.tif", "undone.tif"}) {
    std::filesystem::remove(out / f);
  }
  // Grand Canyon, 512 x 512 cells of 1/512 degree. Frames advance 1/30 s each (--dt). "@" stands
  // for the output folder.
  const char* lines[] = {"0 goto -112.09 36.01 2500",
                         "0 look 0 -25",
                         "0 key W down",
                         "20 key W up",
                         "21 screenshot @fly.png",
                         "22 region -112.15 36.04 -112.03 36.16",
                         "22 tool spring",
                         "22 brush 500 5000",
                         "23 stroke -112.09 36.10",
                         "24 speed 8",
                         "24 play",
                         "54 pause",
                         "55 screenshot @sim.png",
                         "56 save @before.tif",
                         "56 tool raise",
                         "56 brush 1500 150",
                         "57 mouse 240 180",
                         "57 button left down",
                         "58 button left up",
                         "58 save @raised.tif",
                         "59 screenshot @raised.png",
                         "60 undo",
                         "60 save @undone.tif",
                         "61 screenshot @undone.png"};
  {
    std::ofstream script(out / "session.txt");
    for (std::string line : lines) {
      if (const auto at = line.find('@'); at != std::string::npos) line.replace(at, 1, o);
      script << line << "\n";
    }
  }
  const auto run = runViewerWindow({test::dataPath("grand_canyon/grand_canyon_512.tif"), "--size", "480x320",
                                    "--circles", "128", "--script", o + "session.txt"},
                                   out / "session.log");
  ASSERT_TRUE(run) << run.message();

  // Tolerances as for the renderer's goldens (terrain_render_test): one pixel of displacement,
  // then 24/255 per pixel and 3/255 on average (llvmpipe vs a GPU's rasterisation and rounding).
  for (const char* name : {"fly", "sim", "raised"}) {
    auto image = render::readImage8(o + name + ".png");
    ASSERT_TRUE(image) << image.message();
    const auto r = test::compareWithGolden(std::string("viewer_") + name, *image, {}, test::outputDir("render"));
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

TEST(ViewerWindow, MapLayersFromTheCommandLineAreDrawn) {
  // strata-view with the UTM marker raster draped over the Grand Canyon, a 0.05 degree graticule
  // and a scale bar, looking straight down at the marker from 12 km: the centre is the marker's
  // red, the graticule's white lines cross the view, the bar sits in the bottom-left corner.
  if (test::noGlRequested()) GTEST_SKIP() << "STRATA_NO_GL=1: this run has no GL context";
  ASSERT_TRUE(std::filesystem::exists(kXvfbRun)) << "xvfb-run is missing (scripts/setup.sh installs it)";
  const auto out = test::outputDir("viewer");
  const std::string o = out.string() + "/";
  std::filesystem::remove(out / "layers.png");
  ASSERT_TRUE(test::writeUtmMarker(o + "utm_marker.tif"));
  auto ct = gis::CrsTransform::create("EPSG:32612", "EPSG:4326");
  ASSERT_TRUE(ct) << ct.message();
  double lon = test::kMarkerUtm[0], lat = test::kMarkerUtm[1];
  ASSERT_TRUE(ct->transform(1, &lon, &lat));
  {
    std::ofstream script(out / "layers.txt");
    script.precision(12);
    script << "0 goto " << lon << " " << lat << " 12000\n0 look 0 -89\n2 screenshot " << o << "layers.png\n";
  }
  const auto run = runViewerWindow(
      {test::dataPath("grand_canyon/grand_canyon_512.tif"), "--size", "480x320", "--circles", "128", "--drape",
       o + "utm_marker.tif", "--graticule", "0.05", "--scale-bar", "--script", o + "layers.txt"},
      out / "layers.log");
  ASSERT_TRUE(run) << run.message();
  const std::string& log = *run;
  EXPECT_NE(log.find("drape: RGB (3 Byte bands)"), std::string::npos) << log;
  auto image = render::readImage8(o + "layers.png");
  ASSERT_TRUE(image) << image.message();
  const int w = image->width, h = image->height;
  auto px = [&](int x, int y) { return &image->pixels[(size_t(y) * size_t(w) + size_t(x)) * size_t(image->channels)]; };
  const uint8_t* centre = px(w / 2, h / 2);
  EXPECT_GT(centre[0], 150);
  EXPECT_LT(centre[2], 80);
  int white = 0, whiteInBarCorner = 0;  // lines are 80% white over the drape
  for (int y = 0; y < h; ++y) {
    for (int x = 0; x < w; ++x) {
      const uint8_t* p = px(x, y);
      if (p[0] < 150 || p[1] < 150) continue;  // neither the drape's blue nor its red: a line or the bar
      (x < w / 4 && y > h - 40 ? whiteInBarCorner : white) += 1;
    }
  }
  EXPECT_GT(white, 300) << "graticule lines";  // 0.05 degree lines across a ~14 km view
  EXPECT_GT(whiteInBarCorner, 60) << "scale bar";
}

}  // namespace
}  // namespace strata
