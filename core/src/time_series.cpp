#include <strata/core/time_series.hpp>

#include <algorithm>
#include <cmath>
#include <string>

namespace strata {
namespace {

// The index of the first bad sample, or -1.
long firstBadSample(const std::vector<TimeSeries::Sample>& s) {
  for (size_t i = 0; i < s.size(); ++i) {
    if (!std::isfinite(s[i][0]) || !std::isfinite(s[i][1])) return long(i);
    if (i > 0 && !(s[i][0] > s[i - 1][0])) return long(i);
  }
  return -1;
}

}  // namespace

TimeSeries::TimeSeries(std::vector<Sample> samples) : samples_(std::move(samples)) {
  STRATA_CHECK(firstBadSample(samples_) < 0)
      << "time series sample " << firstBadSample(samples_) << ": times must increase and values be finite";
}

Result<TimeSeries> TimeSeries::create(std::vector<Sample> samples) {
  const long bad = firstBadSample(samples);
  if (bad >= 0) {
    const auto& s = samples[size_t(bad)];
    if (!std::isfinite(s[0]) || !std::isfinite(s[1])) {
      return fail("sample " + std::to_string(bad) + " is not a finite number");
    }
    return fail("sample " + std::to_string(bad) + ": times must increase");
  }
  return TimeSeries(std::move(samples));
}

double TimeSeries::at(double t) const {
  if (samples_.empty()) return 0.0;
  if (t <= samples_.front()[0]) return samples_.front()[1];
  if (t >= samples_.back()[0]) return samples_.back()[1];
  const auto it =
      std::upper_bound(samples_.begin(), samples_.end(), t, [](double v, const Sample& s) { return v < s[0]; });
  const Sample& b = *it;
  const Sample& a = *(it - 1);
  return a[1] + (b[1] - a[1]) * (t - a[0]) / (b[0] - a[0]);
}

double TimeSeries::integral(double t0, double t1) const {
  if (samples_.empty() || !(t1 > t0)) return 0.0;
  double sum = 0;
  // Before the first sample and after the last: the held end values.
  const double first = samples_.front()[0], last = samples_.back()[0];
  if (t0 < first) sum += samples_.front()[1] * (std::min(t1, first) - t0);
  if (t1 > last) sum += samples_.back()[1] * (t1 - std::max(t0, last));
  for (size_t i = 1; i < samples_.size(); ++i) {
    const Sample& a = samples_[i - 1];
    const Sample& b = samples_[i];
    const double lo = std::max(t0, a[0]), hi = std::min(t1, b[0]);
    if (!(hi > lo)) continue;
    auto v = [&](double t) { return a[1] + (b[1] - a[1]) * (t - a[0]) / (b[0] - a[0]); };
    sum += 0.5 * (v(lo) + v(hi)) * (hi - lo);  // trapezoid: exact on a straight piece
  }
  return sum;
}

double TimeSeries::maxOver(double t0, double t1) const {
  double m = std::max(at(t0), at(t1));
  for (const Sample& s : samples_) {
    if (s[0] > t0 && s[0] < t1) m = std::max(m, s[1]);
  }
  return m;
}

TimeSeries TimeSeries::scaled(double k) const {
  TimeSeries out = *this;
  for (Sample& s : out.samples_) s[1] *= k;
  return out;
}

}  // namespace strata
