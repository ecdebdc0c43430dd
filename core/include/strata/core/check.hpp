#pragma once
// STRATA_CHECK(cond) << "why": contract violations inside the library (bugs, not bad user
// data) abort with the file, line, condition and message. Bad user data returns Result<T>.

#include <sstream>

namespace strata::detail {

class CheckFailure {
 public:
  CheckFailure(const char* file, int line, const char* condition);
  [[noreturn]] ~CheckFailure();
  CheckFailure(const CheckFailure&) = delete;
  CheckFailure& operator=(const CheckFailure&) = delete;
  std::ostream& stream() { return out_; }

 private:
  std::ostringstream out_;
};

// Lets `cond ? (void)0 : Voidify() & stream << ...` type-check as void.
struct Voidify {
  void operator&(std::ostream&) {}
};

}  // namespace strata::detail

#define STRATA_CHECK(cond) \
  (cond) ? (void)0 : ::strata::detail::Voidify() & ::strata::detail::CheckFailure(__FILE__, __LINE__, #cond).stream()
