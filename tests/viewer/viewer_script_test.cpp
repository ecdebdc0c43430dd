// strata-view's script format (CPU only): every command parses to what it says, and bad lines
// are refused with the file, line and reason.
#include <gtest/gtest.h>

#include <strata/viewer/command.hpp>

namespace strata {
namespace {

using namespace viewer;

TEST(ViewerScript, ParsesEveryCommand) {
  const auto s = parseScript(R"(# a comment
0 goto -112.1 36.05 1500
0 look 290 -20
0 key w down   # case-insensitive key names
5 key W up
6 mouse 240.5 160
6 button left down
7 button right up
8 tool raise
8 brush 300 4.5 2
9 stroke -112.08 36.06
10 undo
10 redo
11 region -112.2 36.0 -112.1 36.1
12 play
12 speed 8
13 step 4
14 pause
15 exaggeration 2
16 screenshot out.png
16 screenshot hud.png hud
17 save edited.tif
18 stamp crater.png multiply
18 save
18 erosion on
18 quit
)",
                             "t.txt");
  ASSERT_TRUE(s) << s.message();
  ASSERT_EQ(s->size(), 25u);
  const auto& v = *s;
  EXPECT_EQ(v[0].frame, 0);
  const auto& g = std::get<GoToCommand>(v[0].command);
  EXPECT_DOUBLE_EQ(g.lon, -112.1);
  EXPECT_DOUBLE_EQ(g.aglM, 1500);
  EXPECT_EQ(std::get<KeyCommand>(v[2].command).name, "W");
  EXPECT_TRUE(std::get<KeyCommand>(v[2].command).down);
  EXPECT_FALSE(std::get<KeyCommand>(v[3].command).down);
  EXPECT_EQ(v[3].frame, 5);
  EXPECT_DOUBLE_EQ(std::get<MouseMoveCommand>(v[4].command).x, 240.5);
  EXPECT_EQ(std::get<MouseButtonCommand>(v[6].command).button, MouseButtonCommand::kRight);
  EXPECT_EQ(std::get<ToolCommand>(v[7].command).name, "raise");
  EXPECT_DOUBLE_EQ(std::get<BrushCommand>(v[8].command).strength, 4.5);
  EXPECT_EQ(std::get<BrushCommand>(v[8].command).layer, 2);
  EXPECT_DOUBLE_EQ(std::get<StrokeCommand>(v[9].command).lat, 36.06);
  EXPECT_TRUE(std::holds_alternative<UndoCommand>(v[10].command));
  EXPECT_DOUBLE_EQ(std::get<RegionCommand>(v[12].command).lat1, 36.1);
  EXPECT_EQ(std::get<SimCommand>(v[14].command).action, SimCommand::kSpeed);
  EXPECT_EQ(std::get<SimCommand>(v[14].command).count, 8);
  EXPECT_EQ(std::get<SimCommand>(v[15].command).count, 4);
  EXPECT_EQ(std::get<ScreenshotCommand>(v[18].command).path, "out.png");
  EXPECT_FALSE(std::get<ScreenshotCommand>(v[18].command).withHud);
  EXPECT_TRUE(std::get<ScreenshotCommand>(v[19].command).withHud);
  EXPECT_EQ(std::get<StampCommand>(v[21].command).blend, "multiply");
  EXPECT_EQ(std::get<SaveCommand>(v[22].command).path, "");
  EXPECT_EQ(std::get<SimCommand>(v[23].command).action, SimCommand::kErosionOn);
  EXPECT_TRUE(std::holds_alternative<QuitCommand>(v[24].command));
}

TEST(ViewerScript, RefusesBadLinesNamingThem) {
  struct Case {
    const char* text;
    const char* message;
  };
  for (const Case& c :
       {Case{"0 fly 1 2", "t.txt:1: unknown command 'fly'"},
        Case{"\n3 goto 1", "t.txt:2: goto: expected goto LON LAT [AGL_M]"}, Case{"x key W down", "t.txt:1: frame 'x'"},
        Case{"5 undo\n4 redo", "t.txt:2: frame 4 is before the previous line's"},
        Case{"0 key W sideways", "t.txt:1: key: expected key NAME down|up"},
        Case{"0 brush -1 2", "t.txt:1: brush: expected brush RADIUS_M STRENGTH [LAYER] (radius > 0, layer 0..3)"},
        Case{"0 brush 10 2 4", "t.txt:1: brush: expected"}, Case{"0 step 2.5", "t.txt:1: step: expected step [N]"},
        Case{"0 undo now", "t.txt:1: undo: unexpected 'now'"},
        Case{"0 screenshot", "t.txt:1: screenshot: expected screenshot PATH"},
        Case{"0 look 0 95", "t.txt:1: look: expected"}, Case{"0", "t.txt:1: a command is missing"}}) {
    const auto s = parseScript(c.text, "t.txt");
    ASSERT_FALSE(s) << c.text;
    EXPECT_NE(s.message().find(c.message), std::string::npos) << s.message();
  }
}

}  // namespace
}  // namespace strata
