#pragma once
// Result<T>: the value of an operation that can fail on user data, or an Error whose message
// names the file, the field and what was wrong. C++20 has no std::expected; this is the one
// small type Strata uses instead (see docs/architecture.md, "Errors").

#include <string>
#include <utility>
#include <variant>

#include <strata/core/check.hpp>

namespace strata {

/// A failure on user data: one line, naming the thing and the problem. Code that checks named
/// fields (a solver's parameters) also says which one and what is wrong with it, so a caller
/// that knows the field by another name (a scenario key) can say so without reading the message.
struct Error {
  std::string message;
  std::string field;   ///< the parameter the error is about, when there is one
  std::string reason;  ///< what is wrong with it ("must be positive"), without its name
};

/// Makes an Error; `return fail("dem.tif: not a raster");` converts into any Result<T>.
inline Error fail(std::string message) { return Error{std::move(message), {}, {}}; }
/// The same about the named `field`: `reason` is what is wrong with it.
inline Error failField(std::string message, std::string field, std::string reason) {
  return Error{std::move(message), std::move(field), std::move(reason)};
}

template <class T>
class [[nodiscard]] Result {
 public:
  Result(T value) : v_(std::move(value)) {}      // NOLINT(google-explicit-constructor)
  Result(Error error) : v_(std::move(error)) {}  // NOLINT(google-explicit-constructor)

  bool ok() const { return v_.index() == 0; }
  explicit operator bool() const { return ok(); }

  T& value() & {
    STRATA_CHECK(ok()) << "Result::value() on an error: " << std::get<1>(v_).message;
    return std::get<0>(v_);
  }
  const T& value() const& {
    STRATA_CHECK(ok()) << "Result::value() on an error: " << std::get<1>(v_).message;
    return std::get<0>(v_);
  }
  T&& value() && {
    STRATA_CHECK(ok()) << "Result::value() on an error: " << std::get<1>(v_).message;
    return std::get<0>(std::move(v_));
  }
  T& operator*() & { return value(); }
  const T& operator*() const& { return value(); }
  T&& operator*() && { return std::move(*this).value(); }
  T* operator->() { return &value(); }
  const T* operator->() const { return &value(); }

  const Error& error() const {
    STRATA_CHECK(!ok()) << "Result::error() on a value";
    return std::get<1>(v_);
  }
  const std::string& message() const { return error().message; }

 private:
  std::variant<T, Error> v_;
};

/// Result of an operation with no value.
template <>
class [[nodiscard]] Result<void> {
 public:
  Result() = default;
  Result(Error error) : error_(std::move(error)), ok_(false) {}  // NOLINT(google-explicit-constructor)
  bool ok() const { return ok_; }
  explicit operator bool() const { return ok_; }
  const Error& error() const {
    STRATA_CHECK(!ok_) << "Result::error() on success";
    return error_;
  }
  const std::string& message() const { return error().message; }

 private:
  Error error_;
  bool ok_ = true;
};

using Status = Result<void>;

/// The outcome of `r` without its value (to hand a failure on, e.g. to the other MPI ranks).
template <class T>
Status statusOf(const Result<T>& r) {
  return r ? Status{} : Status{r.error()};
}

}  // namespace strata

/// Propagates an error: `STRATA_TRY(auto dem, readDem(path));` or `STRATA_TRY(existing, expr);`.
/// It expands to several statements: under an `if`, put it in braces.
#define STRATA_TRY_CONCAT_(a, b) a##b
#define STRATA_TRY_NAME_(line) STRATA_TRY_CONCAT_(strata_try_result_, line)
#define STRATA_TRY(decl, expr)                                                \
  auto STRATA_TRY_NAME_(__LINE__) = (expr);                                   \
  if (!STRATA_TRY_NAME_(__LINE__)) return STRATA_TRY_NAME_(__LINE__).error(); \
  decl = std::move(STRATA_TRY_NAME_(__LINE__)).value()
/// Propagates the error of a Status.
#define STRATA_TRY_STATUS(expr)                         \
  do {                                                  \
    auto strata_status_ = (expr);                       \
    if (!strata_status_) return strata_status_.error(); \
  } while (false)
