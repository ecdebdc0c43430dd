#include "gl_fixture.hpp"

#include <algorithm>
#include <cstdlib>
#include <optional>
#include <set>
#include <string>

namespace strata::test {
bool noGlRequested() {
  const char* v = std::getenv("STRATA_NO_GL");
  return v && std::string(v) == "1";
}

namespace {

struct Shared {
  std::optional<gl::HeadlessContext> ctx;
  std::string error;
  bool tried = false;
};

Shared& state() {
  static Shared s;
  return s;
}

Shared& shared() {
  Shared& s = state();
  if (!s.tried) {
    s.tried = true;
    auto r = gl::HeadlessContext::create();
    if (r) {
      s.ctx.emplace(std::move(r).value());
    } else {
      s.error = r.message();
    }
  }
  return s;
}

// Destroys the shared context when the run ends, while the GL driver is still loaded: NVIDIA's EGL
// (580, H100) crashed with SIGSEGV when the context was destroyed by a static destructor after
// main returned, failing a run whose tests had all passed.
class ReleaseContext : public ::testing::Environment {
 public:
  void TearDown() override { state().ctx.reset(); }
};
[[maybe_unused]] const ::testing::Environment* const kReleaseContext =
    ::testing::AddGlobalTestEnvironment(new ReleaseContext);

}  // namespace

void GlTest::SetUp() {
  if (noGlRequested()) GTEST_SKIP() << "STRATA_NO_GL=1: this run has no GL context";
  auto& s = shared();
  ASSERT_TRUE(s.ctx.has_value()) << "no GL 4.5 context: " << s.error
                                 << " (install libegl-mesa0 libgl1-mesa-dri, or set STRATA_NO_GL=1 to skip)";
  s.ctx->makeCurrent();
  errorsBefore_ = gl::errorCount();
}

void GlTest::TearDown() {
  if (noGlRequested() || !shared().ctx) return;
  EXPECT_EQ(gl::errorCount(), errorsBefore_) << "GL reported errors during the test (see log)";
}

gl::HeadlessContext& GlTest::context() {
  auto& s = shared();
  STRATA_CHECK(s.ctx.has_value()) << s.error;
  return *s.ctx;
}

void expectProgramsMatchSlots(const std::string& folder, std::span<const gl::Binding> slots,
                              const std::vector<SlotProgram>& programs, std::vector<gl::ShaderDefine> defines) {
  if (defines.empty()) defines = gl::definesFor(slots);
  std::set<std::string> files, usedSlots;
  for (const auto& p : programs) {
    std::string label;
    Result<gl::Program> program = fail("no shaders");
    if (p.source) {
      label = p.source->name;
      program = gl::Program::link({{gl::ShaderStage::kCompute, p.source->text, p.source->files}}, label, defines);
      files.insert(p.source->files.begin(), p.source->files.end());
    } else if (p.shaders.size() == 1) {
      label = p.shaders[0];
      program = gl::Program::compute(p.shaders[0], defines);
    } else if (p.shaders.size() == 2) {
      label = p.shaders[0] + "+" + p.shaders[1];
      program = gl::Program::graphics(p.shaders[0], p.shaders[1], defines);
    }
    files.insert(p.shaders.begin(), p.shaders.end());
    ASSERT_TRUE(program) << label << ": " << program.message();
    const auto resources = program->resources();
    EXPECT_EQ(resources.empty(), p.bindsNothing) << label
                                                 << (p.bindsNothing ? " binds something: check it against the table"
                                                                    : " has no block, sampler or image to check");
    for (const auto& r : resources) usedSlots.insert(r.name + "/" + gl::resourceKindName(r.kind));
    const auto status = gl::checkBindings(*program, slots, label);
    EXPECT_TRUE(status) << status.message();
  }
  for (const auto& s : slots) {
    EXPECT_TRUE(usedSlots.count(std::string(s.resource) + "/" + gl::resourceKindName(s.kind)))
        << s.define << " (" << gl::resourceKindName(s.kind) << " '" << s.resource << "') is used by no program";
  }
  for (const auto& name : gl::embeddedShaderNames()) {
    if (name.rfind(folder, 0) == 0) {
      EXPECT_TRUE(files.count(name)) << name << " is in no checked program";
    }
  }
}

}  // namespace strata::test
