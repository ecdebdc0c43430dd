#include <cctype>
#include <cmath>
#include <fstream>
#include <sstream>

#include <strata/viewer/command.hpp>

#include <strata/core/files.hpp>

namespace strata::viewer {
namespace {

std::string upper(std::string s) {
  for (char& c : s) c = char(std::toupper(static_cast<unsigned char>(c)));
  return s;
}

// Reads exactly `n` finite numbers (then optionally `optional` more) from the rest of the line.
bool numbers(std::istringstream& in, std::vector<double>& out, size_t n, size_t optional = 0) {
  out.clear();
  std::string tok;
  while (in >> tok) {
    char* end = nullptr;
    const double v = std::strtod(tok.c_str(), &end);
    if (end == tok.c_str() || *end != '\0' || !std::isfinite(v)) return false;
    out.push_back(v);
  }
  return out.size() >= n && out.size() <= n + optional;
}

}  // namespace

Result<std::vector<TimedCommand>> parseScript(const std::string& text, const std::string& label) {
  std::vector<TimedCommand> out;
  std::istringstream lines(text);
  std::string line;
  int lineNo = 0, lastFrame = 0;
  while (std::getline(lines, line)) {
    ++lineNo;
    if (const auto hash = line.find('#'); hash != std::string::npos) line.resize(hash);
    std::istringstream in(line);
    std::string frameTok, verb;
    if (!(in >> frameTok)) continue;
    const auto where = label + ":" + std::to_string(lineNo) + ": ";
    char* end = nullptr;
    const long frame = std::strtol(frameTok.c_str(), &end, 10);
    if (*end != '\0' || frame < 0 || frame > 100000000) {
      return fail(where + "frame '" + frameTok + "': expected a whole number >= 0");
    }
    if (frame < lastFrame) return fail(where + "frame " + frameTok + " is before the previous line's");
    lastFrame = int(frame);
    if (!(in >> verb)) return fail(where + "a command is missing after the frame number");
    std::vector<double> v;
    auto bad = [&](const std::string& expected) { return fail(where + verb + ": expected " + expected); };
    Command c;
    if (verb == "key") {
      std::string name, state;
      if (!(in >> name >> state) || (state != "down" && state != "up")) return bad("key NAME down|up");
      c = KeyCommand{upper(name), state == "down"};
    } else if (verb == "mouse") {
      if (!numbers(in, v, 2)) return bad("mouse X Y (window pixels)");
      c = MouseMoveCommand{v[0], v[1]};
    } else if (verb == "button") {
      std::string b, state;
      if (!(in >> b >> state) || (b != "left" && b != "right") || (state != "down" && state != "up")) {
        return bad("button left|right down|up");
      }
      c = MouseButtonCommand{b == "left" ? MouseButtonCommand::kLeft : MouseButtonCommand::kRight, state == "down"};
    } else if (verb == "tool") {
      std::string name;
      if (!(in >> name)) return bad("tool NAME");
      c = ToolCommand{name};
    } else if (verb == "brush") {
      if (!numbers(in, v, 2, 1) || v[0] <= 0 || (v.size() > 2 && (v[2] < 0 || v[2] > 3 || v[2] != std::floor(v[2])))) {
        return bad("brush RADIUS_M STRENGTH [LAYER] (radius > 0, layer 0..3)");
      }
      c = BrushCommand{v[0], v[1], v.size() > 2 ? int(v[2]) : -1};
    } else if (verb == "stroke") {
      if (!numbers(in, v, 2)) return bad("stroke LON LAT");
      c = StrokeCommand{v[0], v[1]};
    } else if (verb == "goto") {
      if (!numbers(in, v, 2, 1)) return bad("goto LON LAT [AGL_M]");
      c = GoToCommand{v[0], v[1], v.size() > 2 ? v[2] : -1.0};
    } else if (verb == "look") {
      if (!numbers(in, v, 2) || std::abs(v[1]) > 90) return bad("look HEADING_DEG PITCH_DEG (pitch in -90..90)");
      c = LookCommand{v[0], v[1]};
    } else if (verb == "exaggeration") {
      if (!numbers(in, v, 1) || v[0] <= 0) return bad("exaggeration K (K > 0)");
      c = ExaggerationCommand{v[0]};
    } else if (verb == "undo") {
      c = UndoCommand{};
    } else if (verb == "redo") {
      c = RedoCommand{};
    } else if (verb == "region") {
      if (!numbers(in, v, 4)) return bad("region LON0 LAT0 LON1 LAT1");
      c = RegionCommand{v[0], v[1], v[2], v[3]};
    } else if (verb == "play" || verb == "pause") {
      c = SimCommand{verb == "play" ? SimCommand::kPlay : SimCommand::kPause, 1};
    } else if (verb == "step" || verb == "speed") {
      if (!numbers(in, v, 0, 1) || (!v.empty() && (v[0] < 1 || v[0] > 100000 || v[0] != std::floor(v[0])))) {
        return bad(verb + " [N] (a whole number >= 1)");
      }
      c = SimCommand{verb == "step" ? SimCommand::kStep : SimCommand::kSpeed, v.empty() ? 1 : int(v[0])};
    } else if (verb == "screenshot") {
      std::string path, hud;
      if (!(in >> path) || ((in >> hud) && hud != "hud")) return bad("screenshot PATH [hud]");
      c = ScreenshotCommand{path, hud == "hud"};
    } else if (verb == "save") {
      std::string path;
      in >> path;  // optional: empty saves where the viewer was told to (the store itself)
      c = SaveCommand{path};
    } else if (verb == "erosion") {
      std::string state;
      if (!(in >> state) || (state != "on" && state != "off")) return bad("erosion on|off");
      c = SimCommand{state == "on" ? SimCommand::kErosionOn : SimCommand::kErosionOff, 1};
    } else if (verb == "stamp") {
      std::string path, blend;
      if (!(in >> path >> blend) ||
          (blend != "add" && blend != "subtract" && blend != "multiply" && blend != "replace")) {
        return bad("stamp PATH add|subtract|multiply|replace");
      }
      c = StampCommand{path, blend};
    } else if (verb == "quit") {
      c = QuitCommand{};
    } else {
      return fail(where + "unknown command '" + verb + "'");
    }
    std::string extra;
    if (in >> extra) {  // (numeric commands have read the whole line already)
      return fail(where + verb + ": unexpected '" + extra + "'");
    }
    out.push_back({int(frame), std::move(c)});
  }
  return out;
}

Result<std::vector<TimedCommand>> loadScript(const std::string& path) {
  STRATA_TRY_STATUS(requireRegularFile(path, "a script"));
  std::ifstream f(path);
  if (!f) return fail(path + ": cannot read the script");
  std::stringstream ss;
  ss << f.rdbuf();
  return parseScript(ss.str(), path);
}

}  // namespace strata::viewer
