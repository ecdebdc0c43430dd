// Shader preprocessing shared by the build-time embedder and the runtime loader.
#include <strata/gl/shader_source.hpp>

#include <algorithm>
#include <cctype>
#include <filesystem>
#include <fstream>
#include <sstream>

namespace strata::gl {
namespace {

std::string parentDir(const std::string& path) {
  const auto slash = path.find_last_of('/');
  return slash == std::string::npos ? std::string() : path.substr(0, slash + 1);
}

std::string normalise(const std::string& path) {
  return std::filesystem::path(path).lexically_normal().generic_string();
}

// Returns the quoted file name of an `#include "x"` line, or nullopt.
std::optional<std::string> includeTarget(std::string_view line) {
  size_t i = line.find_first_not_of(" \t");
  if (i == std::string_view::npos || line[i] != '#') return std::nullopt;
  i = line.find_first_not_of(" \t", i + 1);
  if (i == std::string_view::npos || line.substr(i, 7) != "include") return std::nullopt;
  const size_t open = line.find('"', i + 7);
  const size_t close = open == std::string_view::npos ? open : line.find('"', open + 1);
  if (close == std::string_view::npos) return std::nullopt;
  return std::string(line.substr(open + 1, close - open - 1));
}

bool isVersionLine(std::string_view line) {
  const size_t i = line.find_first_not_of(" \t");
  return i != std::string_view::npos && line.substr(i, 8) == "#version";
}

struct Expander {
  const ShaderFileReader& read;
  ShaderSource out;

  int fileIndex(const std::string& path) {
    auto it = std::find(out.files.begin(), out.files.end(), path);
    if (it != out.files.end()) return -1;  // already included: include-once
    out.files.push_back(path);
    return int(out.files.size()) - 1;
  }

  Status expand(const std::string& path, const std::string& text, int index, bool top) {
    std::istringstream in(text);
    std::string line;
    int lineNo = 0;
    bool sawVersion = !top;
    while (std::getline(in, line)) {
      ++lineNo;
      if (!sawVersion) {
        if (line.find_first_not_of(" \t\r") == std::string::npos) {
          out.text += '\n';
          continue;
        }
        if (!isVersionLine(line))
          return fail(path + ":" + std::to_string(lineNo) + ": the first line must be #version");
        out.text += line + '\n';
        out.text += "#line " + std::to_string(lineNo + 1) + " " + std::to_string(index) + '\n';
        sawVersion = true;
        continue;
      }
      if (auto target = includeTarget(line)) {
        std::string resolved = normalise(parentDir(path) + *target);
        auto content = read(resolved);
        if (!content) {
          resolved = normalise(*target);
          content = read(resolved);
        }
        if (!content) {
          return fail(path + ":" + std::to_string(lineNo) + ": cannot find included file \"" + *target + "\"");
        }
        const int child = fileIndex(resolved);
        if (child >= 0) {
          out.text += "#line 1 " + std::to_string(child) + '\n';
          STRATA_TRY_STATUS(expand(resolved, *content, child, false));
        }
        out.text += "#line " + std::to_string(lineNo + 1) + " " + std::to_string(index) + '\n';
        continue;
      }
      out.text += line + '\n';
    }
    if (!sawVersion) return fail(path + ": empty shader (no #version line)");
    return {};
  }
};

}  // namespace

std::string insertDefines(std::string_view text, std::span<const ShaderDefine> defines) {
  if (defines.empty()) return std::string(text);
  std::string block;
  for (const auto& d : defines) {
    const bool identifier = !d.name.empty() && !std::isdigit(static_cast<unsigned char>(d.name[0])) &&
                            std::all_of(d.name.begin(), d.name.end(),
                                        [](char c) { return std::isalnum(static_cast<unsigned char>(c)) || c == '_'; });
    STRATA_CHECK(identifier) << "shader define '" << d.name << "' is not a GLSL identifier";
    block += "#define " + d.name + " " + std::to_string(d.value) + '\n';
  }
  size_t pos = 0;
  int lineNo = 0;
  while (pos < text.size()) {
    const size_t end = text.find('\n', pos);
    const size_t lineEnd = end == std::string_view::npos ? text.size() : end;
    ++lineNo;
    if (isVersionLine(text.substr(pos, lineEnd - pos))) {
      std::string out(text.substr(0, lineEnd));
      out += '\n';
      out += block;
      out += "#line " + std::to_string(lineNo + 1) + " 0\n";
      if (lineEnd < text.size()) out += text.substr(lineEnd + 1);
      return out;
    }
    pos = lineEnd + 1;
  }
  return block + "#line 1 0\n" + std::string(text);
}

Result<ShaderSource> preprocessShader(const std::string& name, const ShaderFileReader& read) {
  auto text = read(name);
  if (!text) return fail("shader '" + name + "' not found");
  Expander ex{read, {}};
  ex.out.name = name;
  ex.out.files.push_back(name);
  STRATA_TRY_STATUS(ex.expand(name, *text, 0, true));
  return std::move(ex.out);
}

ShaderFileReader directoryReader(std::string root) {
  return [root = std::move(root)](const std::string& path) -> std::optional<std::string> {
    std::ifstream f(root + "/" + path, std::ios::binary);
    if (!f) return std::nullopt;
    std::ostringstream s;
    s << f.rdbuf();
    return s.str();
  };
}

std::string mapInfoLog(std::string_view log, const std::vector<std::string>& files) {
  // Mesa: "S:L(C): ..."; NVIDIA: "S(L) : ...". Only rewritten at the start of a line.
  auto digits = [](std::string_view t, size_t at) {
    size_t e = at;
    while (e < t.size() && t[e] >= '0' && t[e] <= '9') ++e;
    return e;
  };
  std::string out;
  size_t start = 0;
  while (start < log.size()) {
    size_t end = log.find('\n', start);
    if (end == std::string_view::npos) end = log.size();
    std::string_view line = log.substr(start, end - start);
    const size_t s1 = digits(line, 0);
    std::string mapped(line);
    if (s1 > 0 && s1 < line.size()) {
      const size_t index = std::stoul(std::string(line.substr(0, s1)));
      const std::string file = index < files.size() ? files[index] : std::string(line.substr(0, s1));
      if (line[s1] == ':') {
        const size_t l1 = digits(line, s1 + 1);
        if (l1 > s1 + 1 && l1 < line.size() && line[l1] == '(') mapped = file + std::string(line.substr(s1));
      } else if (line[s1] == '(') {
        const size_t l1 = digits(line, s1 + 1);
        if (l1 > s1 + 1 && l1 < line.size() && line[l1] == ')') {
          mapped = file + ":" + std::string(line.substr(s1 + 1, l1 - s1 - 1)) + std::string(line.substr(l1 + 1));
        }
      }
    }
    out += mapped + '\n';
    start = end + 1;
  }
  return out;
}

}  // namespace strata::gl
