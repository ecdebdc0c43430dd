#pragma once
// A quantity that varies over time: samples (t, value) joined by straight lines, holding the
// first value before the first sample and the last value after the last one. Hydrographs
// (discharge), stages (water levels) and every other time-varying input are this one type, with
// this one end rule: an inflow that stops ends with a zero sample.

#include <array>
#include <vector>

#include <strata/core/result.hpp>

namespace strata {

class TimeSeries {
 public:
  using Sample = std::array<double, 2>;  ///< (time s, value)

  /// Zero at all times.
  TimeSeries() = default;
  /// Samples with strictly increasing times and finite values (a contract: user data goes
  /// through create(), which says what is wrong instead).
  explicit TimeSeries(std::vector<Sample> samples);
  /// The same from user data: fails naming the first bad sample (index from 0).
  static Result<TimeSeries> create(std::vector<Sample> samples);
  /// `value` at all times.
  static TimeSeries constant(double value) { return TimeSeries({{0.0, value}}); }

  bool empty() const { return samples_.empty(); }
  const std::vector<Sample>& samples() const { return samples_; }

  /// The value at time `t`.
  double at(double t) const;
  /// The exact integral over [t0, t1] (0 when t1 <= t0).
  double integral(double t0, double t1) const;
  /// The largest value over [t0, t1] (its ends and the samples inside).
  double maxOver(double t0, double t1) const;
  /// The same series with every value times `k`.
  TimeSeries scaled(double k) const;

 private:
  std::vector<Sample> samples_;
};

}  // namespace strata
