#pragma once
// Progress of long work. On a terminal: one self-updating bar on stderr (at most ~10 redraws
// a second). Otherwise: a plain log line every `logEverySeconds` (STRATA_PROGRESS_EVERY, in
// seconds, overrides it), so logs stay readable. The ETA follows the rate measured over the last
// seconds of work, not the mean since the start (a run that slows down, or speeds up once its
// first expensive stretch is over, is estimated from what it does now).

#include <chrono>
#include <functional>
#include <string>

namespace strata {

class Progress {
 public:
  using Clock = std::function<std::chrono::steady_clock::time_point()>;
  /// `total` in the caller's units (steps, seconds of simulated time, bytes...). `clock` is the
  /// wall clock (tests pass their own).
  Progress(std::string label, double total, double logEverySeconds = 10.0, Clock clock = {});
  ~Progress();
  Progress(const Progress&) = delete;
  Progress& operator=(const Progress&) = delete;

  /// Sets the amount done and an optional note shown after the bar (e.g. "412 steps/s").
  void update(double done, const std::string& note = {});
  /// Whether update() would draw now: a caller with a costly note can ask first (and must then
  /// call update, which also samples the rate).
  bool due() const;
  /// Ends the bar with a final line.
  void finish(const std::string& note = {});

  /// Fraction done in [0,1] and seconds elapsed since construction.
  double fraction() const;
  double elapsedSeconds() const;
  /// Estimated seconds left at the recent rate (negative when unknown).
  double etaSeconds() const;
  /// The recent rate (units of `total` per second; an exponential mean over samples at least a
  /// second apart, each weighing 30 %); 0 before the first sample.
  double rate() const { return rate_; }

  /// Whether a bar is drawn (stderr is a terminal and STRATA_PROGRESS is not "0").
  bool interactive() const { return interactive_; }

 private:
  void draw(const std::string& note, bool final);

  std::chrono::steady_clock::time_point now() const { return clock_ ? clock_() : std::chrono::steady_clock::now(); }

  Clock clock_;
  std::string label_;
  double total_;
  double done_ = 0;
  double logEvery_;
  bool interactive_;
  bool finished_ = false;
  std::chrono::steady_clock::time_point start_, lastDraw_, lastSample_;
  double sampledDone_ = 0, rate_ = 0;
};

/// "1 h 02 min", "3 min 10 s", "4.2 s".
std::string formatDuration(double seconds);

}  // namespace strata
