#pragma once
// Lays GLSL structs out by the std430 rules, so tests can compare a C++ mirror of a buffer
// layout with its GLSL declaration field by field.
#include <gtest/gtest.h>

#include <fstream>
#include <map>
#include <regex>
#include <sstream>
#include <string>
#include <vector>

namespace strata::test {

struct Field {
  std::string name;
  size_t offset;
};

// std430 base alignment and size of the scalar and vector types Strata uses in buffers.
inline std::pair<size_t, size_t> alignAndSize(const std::string& type) {
  static const std::map<std::string, std::pair<size_t, size_t>> kTypes = {
      {"float", {4, 4}},   {"int", {4, 4}},    {"uint", {4, 4}},    {"vec2", {8, 8}},   {"ivec2", {8, 8}},
      {"uvec2", {8, 8}},   {"vec3", {16, 12}}, {"ivec3", {16, 12}}, {"vec4", {16, 16}}, {"ivec4", {16, 16}},
      {"uvec4", {16, 16}}, {"mat4", {16, 64}}, {"double", {8, 8}}};
  auto it = kTypes.find(type);
  if (it == kTypes.end()) ADD_FAILURE() << "type " << type << " not handled by the std430 test";
  return it == kTypes.end() ? std::pair<size_t, size_t>{4, 4} : it->second;
}

// Lays out `struct NAME { ... };` from a GLSL file by std430.
inline std::vector<Field> glslLayout(const std::string& path, const std::string& name, size_t& size) {
  std::ifstream f(path);
  std::stringstream s;
  s << f.rdbuf();
  const std::string text = s.str();
  const auto start = text.find("struct " + name);
  EXPECT_NE(start, std::string::npos) << name << " not in " << path;
  const auto open = text.find('{', start), close = text.find("};", start);
  std::string body = text.substr(open + 1, close - open - 1);
  body = std::regex_replace(body, std::regex("//[^\n]*"), "");
  std::vector<Field> fields;
  size_t offset = 0, structAlign = 16;
  const std::regex member(R"((\w+)\s+(\w+)\s*;)");
  for (auto it = std::sregex_iterator(body.begin(), body.end(), member); it != std::sregex_iterator(); ++it) {
    auto [align, bytes] = alignAndSize((*it)[1]);
    offset = (offset + align - 1) / align * align;
    fields.push_back({(*it)[2], offset});
    offset += bytes;
    structAlign = std::max(structAlign, align);
  }
  size = (offset + structAlign - 1) / structAlign * structAlign;
  return fields;
}

}  // namespace strata::test
