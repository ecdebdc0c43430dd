// strata-view: the interactive fly-through viewer. A GLFW window whose events become the same
// viewer Commands a --script file produces; everything else is in strata::viewer.
// docs/viewer.md.
#include <chrono>
#include <cstdio>
#include <deque>
#include <filesystem>
#include <optional>
#include <string>

#define GLFW_INCLUDE_NONE
#include <GLFW/glfw3.h>

#include <CLI/CLI.hpp>

#include <strata/core/log.hpp>
#include <strata/core/process.hpp>
#include <strata/gis/dem_io.hpp>
#include <strata/gl/context.hpp>
#include <strata/terrain/tile_store.hpp>
#include <strata/viewer/store_io.hpp>
#include <strata/viewer/viewer.hpp>

#include "../common/view_options.hpp"

namespace {

using namespace strata;
using namespace strata::viewer;

struct Args {
  std::string input;
  std::string size = "960x600";
  std::string script;
  std::vector<int> window;
  bool planetary = false;
  float exaggeration = 1;
  int circles = 256;
  double rangeM = 0, softMinM = 0;
  int frames = 0;
  double dtS = 1.0 / 30.0;
  std::string savePath;
  apps::ViewArgs view;
};

// GLFW key codes -> the viewer's key names.
std::string keyName(int key) {
  if (key >= GLFW_KEY_A && key <= GLFW_KEY_Z) return std::string(1, char('A' + (key - GLFW_KEY_A)));
  if (key >= GLFW_KEY_0 && key <= GLFW_KEY_9) return std::string(1, char('0' + (key - GLFW_KEY_0)));
  switch (key) {
    case GLFW_KEY_LEFT_SHIFT:
    case GLFW_KEY_RIGHT_SHIFT: return "SHIFT";
    case GLFW_KEY_SPACE: return "SPACE";
    case GLFW_KEY_ESCAPE: return "ESCAPE";
    case GLFW_KEY_F1: return "F1";
    case GLFW_KEY_F2: return "F2";
    case GLFW_KEY_LEFT_BRACKET: return "LEFT_BRACKET";
    case GLFW_KEY_RIGHT_BRACKET: return "RIGHT_BRACKET";
    case GLFW_KEY_MINUS: return "MINUS";
    case GLFW_KEY_EQUAL: return "EQUAL";
    case GLFW_KEY_COMMA: return "COMMA";
    case GLFW_KEY_PERIOD: return "PERIOD";
    case GLFW_KEY_PAGE_UP: return "PAGE_UP";
    case GLFW_KEY_PAGE_DOWN: return "PAGE_DOWN";
    default: return {};
  }
}

// Events of the current frame, in arrival order.
std::deque<Command>* gEvents = nullptr;

void onKey(GLFWwindow*, int key, int, int action, int) {
  if (action == GLFW_REPEAT) return;
  if (auto name = keyName(key); !name.empty()) gEvents->push_back(KeyCommand{name, action == GLFW_PRESS});
}
void onCursor(GLFWwindow*, double x, double y) { gEvents->push_back(MouseMoveCommand{x, y}); }
void onButton(GLFWwindow*, int button, int action, int) {
  if (button != GLFW_MOUSE_BUTTON_LEFT && button != GLFW_MOUSE_BUTTON_RIGHT) return;
  gEvents->push_back(MouseButtonCommand{
      button == GLFW_MOUSE_BUTTON_LEFT ? MouseButtonCommand::kLeft : MouseButtonCommand::kRight, action == GLFW_PRESS});
}

int run(const Args& a) {
  int w = 0, h = 0;
  if (std::sscanf(a.size.c_str(), "%dx%d", &w, &h) != 2 || w < 16 || h < 16 || w > 8192 || h > 8192) {
    std::fprintf(stderr, "strata-view: --size '%s': expected WxH, e.g. 960x600\n", a.size.c_str());
    return 1;
  }
  std::vector<TimedCommand> script;
  if (!a.script.empty()) {
    auto s = loadScript(a.script);
    if (!s) {
      std::fprintf(stderr, "strata-view: %s\n", s.message().c_str());
      return 1;
    }
    script = std::move(*s);
  }
  auto ctx = gl::WindowContext::create(
      {.width = w, .height = h, .title = "strata-view " + a.input, .vsync = a.script.empty(), .debugOutput = false});
  if (!ctx) {
    std::fprintf(stderr, "strata-view: %s\n", ctx.message().c_str());
    return 1;
  }
  int fbW = 0, fbH = 0;
  ctx->framebufferSize(fbW, fbH);

  // The terrain: a store folder (a window of its base grid) or any DEM GDAL reads.
  std::optional<terrain::TileStore> store;
  std::optional<StoreSurface> loaded;
  gis::Raster dem;
  if (std::filesystem::is_directory(a.input)) {
    auto s = terrain::TileStore::open(a.input);
    if (!s) {
      std::fprintf(stderr, "strata-view: %s\n", s.message().c_str());
      return 1;
    }
    store.emplace(std::move(*s));
    gis::CellRect win{0, 0, store->width(), store->height()};
    if (a.window.size() == 4) win = {a.window[0], a.window[1], a.window[2], a.window[3]};
    auto l = loadStoreSurface(*store, win);
    if (!l) {
      std::fprintf(stderr, "strata-view: %s\n", l.message().c_str());
      return 1;
    }
    loaded.emplace(std::move(*l));
    dem = loaded->surface;
  } else {
    auto d = a.planetary ? gis::readDemLonLat(a.input) : gis::readDem(a.input);
    if (!d) {
      std::fprintf(stderr, "strata-view: %s\n", d.message().c_str());
      return 1;
    }
    dem = std::move(*d);
  }
  ViewerOptions options;
  options.width = fbW;
  options.height = fbH;
  options.planetary = a.planetary;
  options.circles = a.circles;
  options.rangeM = a.rangeM;
  options.softMinM = a.softMinM;
  options.shading.exaggeration = a.exaggeration;
  options.scaleBar = a.view.layers.scaleBar;
  options.samples = a.view.msaa;
  if (a.planetary) options.shading.sky = {0, 0, 0, 1};
  auto viewer = Viewer::create(dem, options);
  if (!viewer) {
    std::fprintf(stderr, "strata-view: %s: %s\n", a.input.c_str(), viewer.message().c_str());
    return 1;
  }
  Viewer& v = **viewer;
  if (auto st = apps::applyView(a.view, v.scene(), v.shading()); !st) {
    std::fprintf(stderr, "strata-view: %s\n", st.message().c_str());
    return 1;
  }
  if (loaded && !loaded->layers.empty()) {
    if (auto s = v.editor().setLayers(loaded->layers); !s) {
      std::fprintf(stderr, "strata-view: %s\n", s.message().c_str());
      return 1;
    }
  }
  // Saving: back into the store (tiles re-evaluated, committed), or a whole-grid GeoTIFF.
  v.savePath = !a.savePath.empty() ? a.savePath : store ? a.input : "edited.tif";
  v.saver = [&](const std::string& path) -> Status {
    if (store && std::filesystem::equivalent(path, a.input)) {
      return saveStoreEdits(*store, *loaded, v.scene().heights(), v.editor().layers(), v.editor().dirty());
    }
    gis::Raster out{dem.georef, v.scene().heights()};
    return gis::writeGeoTiff(path, out);
  };

  std::deque<Command> events;
  gEvents = &events;
  GLFWwindow* win = ctx->window();
  glfwSetKeyCallback(win, onKey);
  glfwSetCursorPosCallback(win, onCursor);
  glfwSetMouseButtonCallback(win, onButton);

  // Scripted runs advance a fixed time per frame so they are reproducible; interactive ones
  // advance by the wall clock.
  const bool scripted = !a.script.empty();
  size_t next = 0;
  int failures = 0;
  auto last = std::chrono::steady_clock::now();
  // Mean timings over the run (printed at the end of scripted runs; docs/benchmarks.md).
  double sumWallMs = 0, sumCpuMs = 0, sumGpuMs = 0;
  int timedFrames = 0;
  for (int frame = 0; !ctx->shouldClose() && !v.quitRequested(); ++frame) {
    if (a.frames > 0 && frame >= a.frames) break;
    ctx->pollEvents();
    while (next < script.size() && script[next].frame <= frame) events.push_back(script[next++].command);
    while (!events.empty()) {
      if (auto s = v.handle(events.front()); !s) {
        std::fprintf(stderr, "strata-view: frame %d: %s\n", frame, s.message().c_str());
        ++failures;
      }
      events.pop_front();
    }
    const auto now = std::chrono::steady_clock::now();
    const double dt = scripted ? a.dtS : std::chrono::duration<double>(now - last).count();
    last = now;
    ctx->framebufferSize(fbW, fbH);
    if (fbW > 0 && fbH > 0) {
      if (auto s = v.resize(fbW, fbH); !s) std::fprintf(stderr, "strata-view: %s\n", s.message().c_str());
    }
    if (auto s = v.frame(dt); !s) {
      std::fprintf(stderr, "strata-view: frame %d: %s\n", frame, s.message().c_str());
      ++failures;
    }
    if (auto s = v.present(fbW, fbH); !s) {
      std::fprintf(stderr, "strata-view: frame %d: %s\n", frame, s.message().c_str());
      ++failures;
    }
    ctx->swapBuffers();
    if (frame > 0) {  // the first frame compiles and uploads
      sumWallMs += 1000.0 * std::chrono::duration<double>(std::chrono::steady_clock::now() - now).count();
      sumCpuMs += v.times().cpuMs;
      sumGpuMs += v.times().gpuMs;
      ++timedFrames;
    }
    if (scripted && next == script.size() && frame >= script.back().frame) break;
  }
  if (scripted) {
    for (const auto& l : v.hudLines()) std::printf("%s\n", l.c_str());
    if (timedFrames > 0) {
      std::printf("{\"frames\": %d, \"wall_ms\": %.2f, \"cpu_ms\": %.2f, \"gpu_ms\": %.2f, \"size\": \"%dx%d\"}\n",
                  timedFrames, sumWallMs / timedFrames, sumCpuMs / timedFrames, sumGpuMs / timedFrames, fbW, fbH);
    }
  }
  // A script whose commands fail is a failed run (the test relies on it).
  return scripted && failures > 0 ? 2 : 0;
}

}  // namespace

int main(int argc, char** argv) {
  strata::preferSleepingOpenMpWaits(argv);  // may start this program again, before anything else
  CLI::App app{"strata-view: fly through a DEM or a terrain store, edit it and simulate water live"};
  auto a = std::make_shared<Args>();
  app.add_option("input", a->input, "DEM file (any raster GDAL reads) or a store folder")->required();
  app.add_option("--size", a->size, "Window size WxH");
  app.add_option("--window", a->window, "Store: base-grid window X Y W H to load (default: all)")->expected(4);
  app.add_flag("--planetary", a->planetary, "Draw on the body's ellipsoid (geographic DEMs)");
  app.add_option("--exaggeration", a->exaggeration, "Vertical exaggeration");
  app.add_option("--circles", a->circles, "Ring renderer circles (6n^2 triangles)")->check(CLI::Range(8, 2048));
  app.add_option("--range", a->rangeM,
                 "View range (m; of arc on a body); default: the DEM's farthest corner, or the horizon over the "
                 "lowest terrain plus the highest summit's")
      ->check(CLI::NonNegativeNumber);
  app.add_option("--soft-min", a->softMinM,
                 "Floor of the softened viewer height f(h) = max(5h, this) (m); default: a twelfth of the range")
      ->check(CLI::NonNegativeNumber);
  apps::addViewOptions(app, a->view);
  app.add_option("--script", a->script, "Timed commands (docs/viewer.md); the viewer exits after the last");
  app.add_option("--frames", a->frames, "Stop after this many frames (0: run until closed)");
  app.add_option("--dt", a->dtS, "Scripted runs: seconds of flight per frame")->check(CLI::PositiveNumber);
  app.add_option("--save-to", a->savePath, "Where 'save' writes by default (the store itself, or a .tif)");
  CLI11_PARSE(app, argc, argv);
  return run(*a);
}
