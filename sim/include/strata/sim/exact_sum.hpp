#pragma once
// Sums whose result does not depend on the order of the terms, nor so on how cells are spread
// over ranks: each term (a double) is rounded once to a multiple of 2^-64 and added as a 128-bit
// integer, and integer addition is associative. Range: |sum| < 2^63 (9.2e18 m^3, more than the
// oceans); each term is off by at most 2^-65 (2.7e-20 m^3). Reduced over MPI ranks by
// allreduceExact (strata/sim/mpi/ranks.hpp): this header needs no MPI.
#include <cmath>
#include <cstdint>
#include <limits>

namespace strata::sim {

__extension__ typedef __int128 Int128;

struct ExactSum {
  Int128 fixed = 0;  // sum * 2^64
  int64_t bad = 0;   // terms that were not finite or out of range: the sum is NaN
  int64_t pad = 0;

  void add(double x) {
    if (!(std::abs(x) < 0x1p62)) {  // NaN, infinite, or too large
      ++bad;
      return;
    }
    fixed += Int128(std::nearbyint(x * 0x1p64));  // exact scaling, one rounding
  }
  ExactSum& operator+=(const ExactSum& o) {
    fixed += o.fixed;
    bad += o.bad;
    return *this;
  }
  double value() const { return bad ? std::numeric_limits<double>::quiet_NaN() : double(fixed) * 0x1p-64; }
};
static_assert(sizeof(ExactSum) == 32);

}  // namespace strata::sim
