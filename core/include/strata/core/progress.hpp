#pragma once
// Progress of long work. On a terminal: one self-updating bar on stderr (at most ~10 redraws
// a second). Otherwise: a plain log line every `logEverySeconds`, so logs stay readable.

#include <chrono>
#include <string>

namespace strata {

class Progress {
 public:
  /// `total` in the caller's units (steps, seconds of simulated time, bytes...).
  Progress(std::string label, double total, double logEverySeconds = 10.0);
  ~Progress();
  Progress(const Progress&) = delete;
  Progress& operator=(const Progress&) = delete;

  /// Sets the amount done and an optional note shown after the bar (e.g. "412 steps/s").
  void update(double done, const std::string& note = {});
  /// Ends the bar with a final line.
  void finish(const std::string& note = {});

  /// Fraction done in [0,1] and seconds elapsed since construction.
  double fraction() const;
  double elapsedSeconds() const;
  /// Estimated seconds left from the mean rate so far (negative when unknown).
  double etaSeconds() const;

  /// Whether a bar is drawn (stderr is a terminal and STRATA_PROGRESS is not "0").
  bool interactive() const { return interactive_; }

 private:
  void draw(const std::string& note, bool final);

  std::string label_;
  double total_;
  double done_ = 0;
  double logEvery_;
  bool interactive_;
  bool finished_ = false;
  std::chrono::steady_clock::time_point start_, lastDraw_;
};

/// "1 h 02 min", "3 min 10 s", "4.2 s".
std::string formatDuration(double seconds);

}  // namespace strata
