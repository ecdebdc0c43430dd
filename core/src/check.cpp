#include <strata/core/check.hpp>

#include <cstdio>
#include <cstdlib>

namespace strata::detail {

CheckFailure::CheckFailure(const char* file, int line, const char* condition) {
  out_ << file << ":" << line << ": check failed: " << condition << ": ";
}

CheckFailure::~CheckFailure() {
  std::fprintf(stderr, "%s\n", out_.str().c_str());
  std::fflush(stderr);
  std::abort();
}

}  // namespace strata::detail
