#include "gl_fixture.hpp"

#include <cstdlib>
#include <optional>
#include <string>

namespace strata::test {
namespace {

bool noGlRequested() {
  const char* v = std::getenv("STRATA_NO_GL");
  return v && std::string(v) == "1";
}

struct Shared {
  std::optional<render::gl::HeadlessContext> ctx;
  std::string error;
  bool tried = false;
};

Shared& shared() {
  static Shared s;
  if (!s.tried) {
    s.tried = true;
    auto r = render::gl::HeadlessContext::create();
    if (r) {
      s.ctx.emplace(std::move(r).value());
    } else {
      s.error = r.message();
    }
  }
  return s;
}

}  // namespace

void GlTest::SetUp() {
  if (noGlRequested()) GTEST_SKIP() << "STRATA_NO_GL=1: this run has no GL context";
  auto& s = shared();
  ASSERT_TRUE(s.ctx.has_value()) << "no GL 4.5 context: " << s.error
                                 << " (install libegl-mesa0 libgl1-mesa-dri, or set STRATA_NO_GL=1 to skip)";
  s.ctx->makeCurrent();
  errorsBefore_ = render::gl::glErrorCount();
}

void GlTest::TearDown() {
  if (noGlRequested() || !shared().ctx) return;
  EXPECT_EQ(render::gl::glErrorCount(), errorsBefore_) << "GL reported errors during the test (see log)";
}

render::gl::HeadlessContext& GlTest::context() {
  auto& s = shared();
  STRATA_CHECK(s.ctx.has_value()) << s.error;
  return *s.ctx;
}

}  // namespace strata::test
