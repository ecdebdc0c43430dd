#pragma once
// The viewer's input commands and the script format that produces them. A window turns GLFW
// events into these same commands (apps/strata-view), so a script drives the viewer through the
// path a person's input takes. The format: docs/viewer.md.

#include <string>
#include <variant>
#include <vector>

#include <strata/core/result.hpp>

namespace strata::viewer {

/// A key pressed or released; `name` is upper case ("W", "SHIFT", "SPACE", "F1", "1", ...).
struct KeyCommand {
  std::string name;
  bool down = true;
};
/// The cursor moved to (x, y) window pixels, y from the top.
struct MouseMoveCommand {
  double x = 0, y = 0;
};
/// A mouse button pressed or released at the cursor. Left: the active tool; right: look.
struct MouseButtonCommand {
  enum Button { kLeft, kRight } button = kLeft;
  bool down = true;
};
/// Selects the active tool by name (raise, lower, smooth, flatten, copy, paste, water, spring,
/// region, stamp, rain, material+, material-).
struct ToolCommand {
  std::string name;
};
/// Brush radius (m) and strength (tool units per dab: m for raise/lower/water/stamp, fraction
/// for smooth/flatten, m^3/s for a spring, mm/h for rain).
struct BrushCommand {
  double radiusM = 0, strength = 0;
  int layer = -1;  ///< add/remove material: the layer 0..3 (-1: keep the current one)
};
/// One stroke of the active tool at a map position (lon/lat deg, or easting/northing m).
struct StrokeCommand {
  double lon = 0, lat = 0;
};
/// Moves the camera over (lon, lat), `aglM` above the ground (keeps the height if < 0).
struct GoToCommand {
  double lon = 0, lat = 0, aglM = -1;
};
/// Sets the camera's view direction (deg).
struct LookCommand {
  double headingDeg = 0, pitchDeg = -30;
};
/// Vertical exaggeration.
struct ExaggerationCommand {
  double factor = 1;
};
/// Editing history.
struct UndoCommand {};
struct RedoCommand {};
/// The simulation region: the map rectangle between two corners.
struct RegionCommand {
  double lon0 = 0, lat0 = 0, lon1 = 0, lat1 = 0;
};
/// Simulation control: play, pause, `count` single steps, `count` steps per frame while
/// playing, erosion and deposition on or off.
struct SimCommand {
  enum Action { kPlay, kPause, kStep, kSpeed, kErosionOn, kErosionOff } action = kPlay;
  int count = 1;
};
/// Writes the window's image to `path` (PNG): the terrain only, or with the HUD and help on top.
struct ScreenshotCommand {
  std::string path;
  bool withHud = false;
};
/// Writes the edited terrain: to the input store, or to a new GeoTIFF.
struct SaveCommand {
  std::string path;
};
/// Loads the stamp image (an 8-bit image: t = first channel / 255; or a raster GDAL reads:
/// t = its values) and sets how the stamp tool blends it: add, subtract, multiply or replace.
struct StampCommand {
  std::string path;
  std::string blend = "add";
};
/// Ends the session.
struct QuitCommand {};

using Command = std::variant<KeyCommand, MouseMoveCommand, MouseButtonCommand, ToolCommand, BrushCommand, StrokeCommand,
                             GoToCommand, LookCommand, ExaggerationCommand, UndoCommand, RedoCommand, RegionCommand,
                             SimCommand, ScreenshotCommand, SaveCommand, StampCommand, QuitCommand>;

/// A command due at frame `frame` (0-based; commands of one frame run in file order).
struct TimedCommand {
  int frame = 0;
  Command command;
};

/// Parses a script: one `FRAME VERB ARGS...` per line, `#` comments, blank lines ignored;
/// frames must not decrease. Errors name `label`, the line and what was wrong.
Result<std::vector<TimedCommand>> parseScript(const std::string& text, const std::string& label);
/// Reads and parses a script file.
Result<std::vector<TimedCommand>> loadScript(const std::string& path);

}  // namespace strata::viewer
