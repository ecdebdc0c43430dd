// Runs user generation scripts (docs/procgen.md): splice, compile, fill, match, inverse.
#include <strata/procgen/generator.hpp>

#include <regex>
#include <sstream>

#include <strata/gl/objects.hpp>
#include <strata/gl/state.hpp>
#include <strata/procgen/shader_slots.hpp>
#include <strata/procgen/wavelet.hpp>
#include <strata/procgen/wavelet_gpu.hpp>

namespace strata::procgen {
namespace {

constexpr const char* kTemplate = "procgen/shaders/generate.comp";
constexpr const char* kMarker = "//@strata-user-script";

bool mentions(const std::string& text, const char* pattern) { return std::regex_search(text, std::regex(pattern)); }

// Which DEMs a script reads (1 + the highest index used, 0 when none).
int demsUsed(const std::string& glsl) {
  if (mentions(glsl, R"(\bdem1Level\b)")) return 2;
  if (mentions(glsl, R"(\bdem0Level\b)")) return 1;
  return 0;
}

}  // namespace

Result<ScriptForm> detectForm(const UserScript& script) {
  const bool height = mentions(script.glsl, R"(\bfloat\s+height\s*\(\s*vec2\b)");
  const bool level = mentions(script.glsl, R"(\bfloat\s+level\s*\(\s*vec2\b[^,)]*,\s*int\b)");
  if (height == level) {
    return fail(script.fileName + ": the script must define exactly one of `float height(vec2 p)` and " +
                "`float level(vec2 p, int lvl)`" + (height ? " (it defines both)" : ""));
  }
  return height ? ScriptForm::Height : ScriptForm::Level;
}

Result<gl::ShaderSource> spliceScript(const UserScript& script, ScriptForm form) {
  STRATA_TRY(auto src, gl::loadShader(kTemplate));
  // Walk the preprocessed template, following its #line directives, to learn which file and
  // line the marker is on, so that numbering resumes correctly after the user's text.
  std::istringstream in(src.text);
  std::string line, out;
  int lineNo = 0, fileNo = 0;
  bool spliced = false;
  static const std::regex kLine(R"(^\s*#line\s+(\d+)\s+(\d+))");
  const int userFile = int(src.files.size());
  while (std::getline(in, line)) {
    std::smatch m;
    if (std::regex_search(line, m, kLine)) {
      lineNo = std::stoi(m[1]) - 1;
      fileNo = std::stoi(m[2]);
      out += line + '\n';
      continue;
    }
    ++lineNo;
    if (!spliced && line.find(kMarker) != std::string::npos) {
      out += "#define STRATA_USER_SCRIPT 1\n";
      if (form == ScriptForm::Level) out += "#define STRATA_FORM_LEVEL 1\n";
      out += "#line " + std::to_string(script.firstLine) + " " + std::to_string(userFile) + '\n';
      out += script.glsl;
      if (script.glsl.empty() || script.glsl.back() != '\n') out += '\n';
      out += "#line " + std::to_string(lineNo + 1) + " " + std::to_string(fileNo) + '\n';
      spliced = true;
      continue;
    }
    out += line + '\n';
  }
  STRATA_CHECK(spliced) << kTemplate << " has no " << kMarker << " line";
  src.text = std::move(out);
  src.files.push_back(script.fileName);
  src.name = script.fileName;
  return src;
}

int effectiveLevels(int width, int height, int requested) {
  return std::clamp(requested, 1, std::max(1, procgen::maxLevels(width, height)));
}

Result<gis::Grid<float>> generate(const UserScript& script, const GenerateOptions& options) {
  const int w = options.width, h = options.height;
  if (w < 2 || h < 2 || w > 16384 || h > 16384) {
    return fail(script.fileName + ": output size " + std::to_string(w) + "x" + std::to_string(h) +
                " is outside 2..16384 cells");
  }
  STRATA_TRY(const ScriptForm form, detectForm(script));
  const int needDems = std::max(demsUsed(script.glsl), options.matchDem + 1);
  if (needDems > int(options.dems.size())) {
    return fail(script.fileName + ": the script needs " + std::to_string(needDems) + " input DEM(s) (dem0Level" +
                (needDems > 1 ? "/dem1Level" : "") + " or matching), " + std::to_string(options.dems.size()) +
                " given");
  }
  if (options.matchDem >= 0 && form != ScriptForm::Level) {
    return fail(script.fileName + ": histogram matching needs the level form (float level(vec2 p, int lvl))");
  }
  STRATA_TRY(auto source, spliceScript(script, form));
  STRATA_TRY(auto program, gl::Program::link({{gl::ShaderStage::kCompute, source.text, source.files}}, script.fileName,
                                             gl::definesFor(slots::kAll)));
  STRATA_TRY(auto wavelet, WaveletGpu::create());
  // The level form fills the pyramid the user asked for: too many levels is an error, not a
  // silent clamp. The height form has no pyramid; its DEMs (if any) use what the size allows.
  if (form == ScriptForm::Level) {
    auto valid = procgen::validateLevels(w, h, options.levels);
    if (!valid) return fail(script.fileName + ": " + valid.message());
  }
  const int levels = effectiveLevels(w, h, options.levels);

  // Input DEMs: resampled to the output grid, then transformed with the same levels.
  std::vector<gl::Texture> dems;
  std::vector<gis::Grid<float>> demCoeffs;
  for (int i = 0; i < needDems; ++i) {
    STRATA_TRY(auto filled, procgen::fillNoData(options.dems[size_t(i)], "dem" + std::to_string(i)));
    auto tex = uploadGrid(procgen::resampleBilinear(filled, w, h));
    wavelet.forward(tex, levels, options.wavelet);
    if (i == options.matchDem) demCoeffs.push_back(downloadGrid(tex));
    dems.push_back(std::move(tex));
  }
  auto dummy = gl::Texture::create2D(gl::TextureFormat::kR32F, 1, 1);
  const float zero = 0.0f;
  dummy.upload(&zero);
  (dems.size() > 0 ? dems[0] : dummy).bindImage(slots::kDem0, gl::Access::kRead);
  (dems.size() > 1 ? dems[1] : dummy).bindImage(slots::kDem1, gl::Access::kRead);

  auto field = gl::Texture::create2D(gl::TextureFormat::kR32F, w, h);
  field.bindImage(slots::kField, gl::Access::kWrite);
  program.set("uSeed", unsigned(options.seed));
  program.set("uSize", glm::ivec2(w, h));
  program.set("uLevels", levels);
  program.dispatchCovering(w, h);
  gl::memoryBarrier(gl::Barrier::kImageAccess | gl::Barrier::kTextureUpdate);

  if (form == ScriptForm::Level) {
    if (options.matchDem >= 0) {
      // Histogram matching on the CPU (sorting per band): docs/procgen.md, "Synthesis like a DEM".
      auto coeffs = downloadGrid(field);
      procgen::matchLevels(coeffs, demCoeffs.front(), levels, options.matchCoarse);
      field.upload(coeffs.data.data());
    }
    wavelet.inverse(field, levels, options.wavelet);
  }
  return downloadGrid(field);
}

}  // namespace strata::procgen
