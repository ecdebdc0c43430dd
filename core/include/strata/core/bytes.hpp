#pragma once
// Plain values and vectors of them as bytes in native order, and back with every length checked
// against what is left: what Strata's binary formats (checkpoints, encoded solver states moved
// between MPI ranks) are written with. A reader that runs out or meets a length too large turns
// `ok` false and reads nothing more.

#include <cstdint>
#include <cstring>
#include <string>
#include <string_view>
#include <type_traits>
#include <vector>

namespace strata {

struct ByteWriter {
  std::string out;

  template <class T>
  void pod(const T& v) {
    static_assert(std::is_trivially_copyable_v<T>);
    out.append(reinterpret_cast<const char*>(&v), sizeof v);
  }
  /// The element count (uint64) then the elements.
  template <class T>
  void vec(const std::vector<T>& v) {
    static_assert(std::is_trivially_copyable_v<T>);
    pod(uint64_t(v.size()));
    if (!v.empty()) out.append(reinterpret_cast<const char*>(v.data()), v.size() * sizeof(T));
  }
  void str(std::string_view s) {
    pod(uint64_t(s.size()));
    out += s;
  }
};

struct ByteReader {
  std::string_view in;
  size_t at = 0;
  bool ok = true;

  size_t left() const { return in.size() - at; }
  template <class T>
  void pod(T& v) {
    static_assert(std::is_trivially_copyable_v<T>);
    if (!ok || left() < sizeof v) {
      ok = false;
      return;
    }
    std::memcpy(&v, in.data() + at, sizeof v);
    at += sizeof v;
  }
  template <class T>
  void vec(std::vector<T>& v) {
    static_assert(std::is_trivially_copyable_v<T>);
    uint64_t n = 0;
    pod(n);
    if (!ok || n > left() / sizeof(T)) {
      ok = false;
      return;
    }
    v.resize(size_t(n));
    if (n > 0) std::memcpy(v.data(), in.data() + at, size_t(n) * sizeof(T));  // data() may be null when empty
    at += size_t(n) * sizeof(T);
  }
  void str(std::string& s) {
    uint64_t n = 0;
    pod(n);
    if (!ok || n > left()) {
      ok = false;
      return;
    }
    s.assign(in.substr(at, size_t(n)));
    at += size_t(n);
  }
};

}  // namespace strata
