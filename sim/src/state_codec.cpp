#include <strata/sim/state_codec.hpp>

#include <strata/core/bytes.hpp>

#include <cstdint>
#include <cstring>
#include <type_traits>

namespace strata::sim {
namespace {

constexpr char kMagic[8] = {'S', 'T', 'R', 'A', 'T', 'A', 'S', '3'};  // 3: 11 accumulator floats per cell

struct Writer : ByteWriter {
  void state(const SolverState& s) {
    SolverState::forEachField(s, [this](const char*, const auto& field) { write(field); });
  }
  template <class T>
  void write(const T& v) {
    if constexpr (std::is_same_v<T, std::vector<SolverState>>) {
      pod(uint64_t(v.size()));
      for (const auto& part : v) state(part);
    } else if constexpr (std::is_trivially_copyable_v<T>) {
      pod(v);
    } else {
      vec(v);
    }
  }
};

struct Reader : ByteReader {
  void state(SolverState& s, int depth) {
    SolverState::forEachField(s, [this, depth](const char*, auto& field) { read(field, depth); });
  }
  template <class T>
  void read(T& v, int depth) {
    if constexpr (std::is_same_v<T, std::vector<SolverState>>) {
      uint64_t n = 0;
      pod(n);
      // A part is at least its counters (> 64 bytes), which bounds the count by what is left.
      if (!ok || depth > 4 || n > left() / 64) {
        ok = false;
        return;
      }
      v.resize(size_t(n));
      for (auto& part : v) state(part, depth + 1);
    } else if constexpr (std::is_trivially_copyable_v<T>) {
      pod(v);
    } else {
      vec(v);
    }
  }
};

}  // namespace

std::string encodeState(const SolverState& state) {
  Writer w;
  w.out.append(kMagic, sizeof kMagic);
  w.state(state);
  return w.out;
}

Result<SolverState> decodeState(std::string_view bytes) {
  if (bytes.size() < sizeof kMagic || std::memcmp(bytes.data(), kMagic, sizeof kMagic) != 0) {
    return fail("sim state: not an encoded solver state");
  }
  Reader r;
  r.in = bytes;
  r.at = sizeof kMagic;
  SolverState s;
  r.state(s, 0);
  if (!r.ok || r.at != bytes.size()) return fail("sim state: truncated or corrupt encoded solver state");
  return s;
}

}  // namespace strata::sim
