#pragma once
// GLSL sources: `#include "file.glsl"` resolved (each file once), `#line L S` directives
// inserted so that a compiler message "S:L" maps back to the real file and line.
// Shaders under <library>/shaders/ are embedded into the binary at build time by the same code
// (gl/tools/shader_embed.cpp); STRATA_SHADER_DIR=<source tree> reads them from there
// instead, for editing shaders without rebuilding. No GL here: usable by host tools.

#include <functional>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include <strata/core/result.hpp>

namespace strata::gl {

/// A shader with its includes expanded. files[i] is the name of GLSL source-string number i
/// (0 is the shader itself); the compiler's messages say "i:line".
struct ShaderSource {
  std::string name;
  std::string text;
  std::vector<std::string> files;
};

/// `#define name value`, given to a program when it is compiled (Program::compute, graphics,
/// link): how C++ hands binding slots and other integer constants to GLSL.
struct ShaderDefine {
  std::string name;
  int value;
};

/// `text` with `defines` inserted right after its `#version` line (at the top when it has none),
/// followed by a `#line` directive that gives the next line its number in source string 0, so
/// compiler messages still name the right file:line. A name that is not a GLSL identifier is a
/// contract violation.
std::string insertDefines(std::string_view text, std::span<const ShaderDefine> defines);

/// Reads a file given its path relative to the shader root; nullopt when it does not exist.
using ShaderFileReader = std::function<std::optional<std::string>(const std::string& path)>;

/// Expands `#include "..."` (relative to the including file, then to the root; each file once).
/// The first non-blank line of `name` must be `#version`. Fails on a missing include or a cycle
/// is impossible (include-once), and names the including file and line.
Result<ShaderSource> preprocessShader(const std::string& name, const ShaderFileReader& read);

/// A reader over a folder on disk.
ShaderFileReader directoryReader(std::string root);

/// Rewrites source-string numbers in a GL info log into file names, e.g. (Mesa)
/// "1:12(5): error: ..." -> "common/grid.glsl:12(5): error: ...", or (NVIDIA)
/// "1(12) : error C0000: ..." -> "common/grid.glsl(12) : error C0000: ...".
std::string mapInfoLog(std::string_view log, const std::vector<std::string>& files);

/// The shader `name` (e.g. "tests/gl/shaders/reduce.comp"): from STRATA_SHADER_DIR if that is set,
/// else the copy embedded at build time.
Result<ShaderSource> loadShader(const std::string& name);

/// Names of all embedded shaders.
std::vector<std::string> embeddedShaderNames();

}  // namespace strata::gl
