// The GL layer's boundary, checked on the source tree (no GL context): no public header includes
// a GL header or names a GL type, no code outside gl/ calls GL, and no shader of a library whose
// slots are declared in C++ writes a binding number (docs/architecture.md, "The GL layer").
#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <functional>
#include <regex>
#include <set>
#include <sstream>
#include <string>
#include <vector>

namespace strata::test {
namespace {

namespace fs = std::filesystem;

const fs::path kRoot = STRATA_SOURCE_DIR;

// Folders whose code may call GL: the GL layer itself, and its context test (it queries GL to
// check what the layer set up).
const std::vector<std::string> kGlAllowed = {"gl/", "tests/gl/gl_context_test.cpp"};

// Shader folders whose binding slots are declared in C++ (<library>/include/strata/<library>/shader_slots.hpp;
// sim/include/strata/sim/gl/shader_slots.hpp for sim).
const std::vector<std::string> kSlotShaderFolders = {"render/shaders", "viewer/shaders", "procgen/shaders",
                                                     "sim/shaders"};

std::string read(const fs::path& p) {
  std::ifstream f(p, std::ios::binary);
  std::ostringstream s;
  s << f.rdbuf();
  return s.str();
}

// The text with comments blanked, and with the contents of string and character literals
// blanked too when `blankLiterals` (line breaks kept, so line numbers hold).
std::string codeOnly(const std::string& text, bool blankLiterals) {
  std::string out = text;
  const size_t n = out.size();
  auto blank = [&](size_t from, size_t to) {
    for (size_t k = from; k < to && k < n; ++k) {
      if (out[k] != '\n') out[k] = ' ';
    }
  };
  size_t i = 0;
  while (i < n) {
    const char c = out[i], next = i + 1 < n ? out[i + 1] : '\0';
    if (c == '/' && next == '/') {
      const size_t e = out.find('\n', i);
      blank(i, e == std::string::npos ? n : e);
      i = e == std::string::npos ? n : e;
    } else if (c == '/' && next == '*') {
      const size_t e = out.find("*/", i + 2);
      const size_t stop = e == std::string::npos ? n : e + 2;
      blank(i, stop);
      i = stop;
    } else if (c == '"' && i > 0 && out[i - 1] == 'R') {  // raw string R"delim( ... )delim"
      const size_t open = out.find('(', i);
      const std::string close = ")" + out.substr(i + 1, open - i - 1) + "\"";
      const size_t e = open == std::string::npos ? std::string::npos : out.find(close, open);
      const size_t stop = e == std::string::npos ? n : e + close.size();
      if (blankLiterals) blank(i + 1, stop - 1);
      i = stop;
    } else if (c == '"' || c == '\'') {
      size_t k = i + 1;
      while (k < n && out[k] != c && out[k] != '\n') k += out[k] == '\\' ? 2 : 1;
      if (blankLiterals) blank(i + 1, k);
      i = k + 1;
    } else {
      ++i;
    }
  }
  return out;
}

// Every file under the project's source folders (build trees and dot folders skipped) whose
// name ends in one of `extensions`, as paths relative to the root with '/'.
std::vector<std::string> sourceFiles(const std::vector<std::string>& extensions) {
  std::vector<std::string> out;
  for (const auto& top : fs::directory_iterator(kRoot)) {
    const std::string name = top.path().filename().string();
    if (!top.is_directory() || name.starts_with("build") || name.starts_with(".")) continue;
    for (const auto& e : fs::recursive_directory_iterator(top.path())) {
      if (!e.is_regular_file()) continue;
      const std::string rel = fs::relative(e.path(), kRoot).generic_string();
      for (const auto& ext : extensions) {
        if (rel.ends_with(ext)) out.push_back(rel);
      }
    }
  }
  return out;
}

using LineTest = std::function<bool(const std::string&)>;

// "file:line: text" for each line of `file` that `test` flags, comments (and, when `inLiterals`
// is false, literals' contents) removed first.
std::vector<std::string> matches(const std::string& file, const LineTest& test, bool inLiterals = false) {
  std::vector<std::string> out;
  std::istringstream in(codeOnly(read(kRoot / file), !inLiterals));
  std::string line;
  for (int n = 1; std::getline(in, line); ++n) {
    if (test(line)) out.push_back(file + ":" + std::to_string(n) + ": " + line);
  }
  return out;
}

LineTest matching(const std::regex& re) {
  return [&re](const std::string& line) { return std::regex_search(line, re); };
}

// Every GL and EGL function name, from the loader's own header (glDrawArrays, eglGetDisplay, ...):
// Strata's functions that merely start with "gl" (glSolverFactory) are not GL calls.
const std::set<std::string>& glFunctions() {
  static const std::set<std::string> names = [] {
    std::set<std::string> out;
    const std::regex define(R"(#define\s+(e?gl[A-Z]\w*)\s+epoxy_)");
    for (const char* header : {"/epoxy/gl_generated.h", "/epoxy/egl_generated.h"}) {
      const std::string text = read(fs::path(STRATA_EPOXY_INCLUDE_DIR + std::string(header)));
      for (auto it = std::sregex_iterator(text.begin(), text.end(), define); it != std::sregex_iterator(); ++it) {
        out.insert((*it)[1]);
      }
    }
    return out;
  }();
  return names;
}

std::string joined(const std::vector<std::string>& lines) {
  std::string s;
  for (const auto& l : lines) s += "\n  " + l;
  return s;
}

const std::regex kGlInclude(R"(^\s*#\s*include\s*[<"](epoxy/|GL/|GLES\d*/|EGL/|KHR/|GLFW/|glad/))");
const std::regex kGlType(R"(\bGL(enum|uint|int|sizei|bitfield|boolean|float|double|char|ubyte|byte|ushort|short|)"
                         R"(sizeiptr|intptr|int64|uint64|sync|DEBUGPROC)\b)");
const std::regex kGlConstant(R"(\bE?GL_[A-Z0-9_]+\b|\bepoxy_\w+)");
const std::regex kIdentifier(R"(\b[A-Za-z_]\w*\b)");

// A GL or EGL constant or function, or a loader function.
bool namesGl(const std::string& line) {
  if (std::regex_search(line, kGlConstant)) return true;
  for (auto it = std::sregex_iterator(line.begin(), line.end(), kIdentifier); it != std::sregex_iterator(); ++it) {
    if (glFunctions().count(it->str())) return true;
  }
  return false;
}

TEST(GlBoundary, NoPublicHeaderIncludesAGlHeaderOrNamesAGlType) {
  // Every library's public headers, the GL layer's own included.
  std::vector<std::string> found;
  size_t headers = 0;
  for (const auto& file : sourceFiles({".hpp", ".h"})) {
    if (file.find("/include/") == std::string::npos || file.starts_with("tests/")) continue;
    ++headers;
    for (const LineTest& test : {matching(kGlType), LineTest(namesGl)}) {
      const auto m = matches(file, test);
      found.insert(found.end(), m.begin(), m.end());
    }
    const auto m = matches(file, matching(kGlInclude), true);
    found.insert(found.end(), m.begin(), m.end());
  }
  EXPECT_GT(headers, 50u) << "the scan found too few public headers under " << kRoot;
  EXPECT_TRUE(found.empty()) << "GL in public headers:" << joined(found);
}

TEST(GlBoundary, NoCodeOutsideTheGlLayerCallsGl) {
  std::vector<std::string> found;
  size_t files = 0;
  for (const auto& file : sourceFiles({".cpp", ".hpp", ".h"})) {
    const bool allowed =
        std::any_of(kGlAllowed.begin(), kGlAllowed.end(), [&](const std::string& a) { return file.starts_with(a); });
    if (allowed) continue;
    ++files;
    for (const LineTest& test : {matching(kGlType), LineTest(namesGl)}) {
      const auto m = matches(file, test);
      found.insert(found.end(), m.begin(), m.end());
    }
    // A window toolkit (GLFW with GLFW_INCLUDE_NONE) is fine in an app; a GL loader is not.
    for (const auto& m : matches(file, matching(kGlInclude), true)) {
      if (m.find("GLFW/") == std::string::npos) found.push_back(m);
    }
  }
  EXPECT_GT(files, 100u) << "the scan found too few source files under " << kRoot;
  EXPECT_TRUE(found.empty()) << "GL outside gl/ (add a named operation to strata_gl instead):" << joined(found);
}

TEST(GlBoundary, ShadersNameTheirBindingSlots) {
  // binding = <number> in a shader duplicates a slot C++ declares; write binding = SLOT_NAME.
  const std::regex literal(R"(\bbinding\s*=\s*[0-9])");
  std::vector<std::string> found;
  size_t shaders = 0;
  for (const auto& file : sourceFiles({".comp", ".vert", ".frag", ".geom", ".glsl"})) {
    const bool checked = std::any_of(kSlotShaderFolders.begin(), kSlotShaderFolders.end(),
                                     [&](const std::string& d) { return file.starts_with(d + "/"); });
    if (!checked) continue;
    ++shaders;
    const auto m = matches(file, matching(literal));
    found.insert(found.end(), m.begin(), m.end());
  }
  EXPECT_GE(shaders, 12u) << "the scan found too few shaders";
  EXPECT_TRUE(found.empty()) << "binding numbers written in shaders:" << joined(found);
}

TEST(GlBoundary, TheScansFindWhatTheyLookFor) {
  // The patterns on lines they must and must not flag.
  EXPECT_TRUE(std::regex_search("#include <epoxy/gl.h>", kGlInclude));
  EXPECT_TRUE(std::regex_search("  # include \"GL/gl.h\"", kGlInclude));
  EXPECT_FALSE(std::regex_search("#include <glm/glm.hpp>", kGlInclude));
  EXPECT_TRUE(std::regex_search("void f(GLuint id);", kGlType));
  EXPECT_FALSE(std::regex_search("GLFWwindow* w; GLSL", kGlType));
  EXPECT_GT(glFunctions().size(), 2000u) << "GL function names read from " << STRATA_EPOXY_INCLUDE_DIR;
  EXPECT_TRUE(namesGl("  glDrawArrays(GL_TRIANGLES, 0, 3);"));
  EXPECT_TRUE(namesGl("auto f = &glFinish;"));
  EXPECT_TRUE(namesGl("eglMakeCurrent(d, s, s, c);"));
  EXPECT_TRUE(namesGl("x = GL_RGBA;"));
  EXPECT_TRUE(namesGl("if (epoxy_gl_version() < 45)"));
  EXPECT_FALSE(namesGl("gl::memoryBarrier(gl::Barrier::kStorage); glm::vec3 v; gl::errorCount();"));
  EXPECT_FALSE(namesGl("auto f = glSolverFactory(); bench::sharedContext(); glfwPollEvents(); \"AGL_M\""));
  EXPECT_EQ(codeOnly("a; // glFinish()\nb /* GL_RGBA\n */ c = \"//x\" + '\"' + R\"(GL_RGBA\")\";", true),
            std::string("a;") + std::string(14, ' ') + "\nb" + std::string(11, ' ') +
                "\n    c = \"   \" + ' ' + R\"          \";");
  EXPECT_EQ(codeOnly("#include \"GL/gl.h\" // x", false), "#include \"GL/gl.h\"     ");
}

}  // namespace
}  // namespace strata::test
