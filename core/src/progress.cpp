#include <strata/core/progress.hpp>

#include <strata/core/log.hpp>

#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>

namespace strata {

namespace {
bool stderrIsTerminal() {
  const char* env = std::getenv("STRATA_PROGRESS");
  if (env && std::strcmp(env, "0") == 0) return false;
  return isatty(STDERR_FILENO) == 1;
}
// STRATA_PROGRESS_EVERY: seconds between log lines (0.1 .. 3600), else `fallback`.
double logInterval(double fallback) {
  const char* env = std::getenv("STRATA_PROGRESS_EVERY");
  if (!env) return fallback;
  char* end = nullptr;
  const double v = std::strtod(env, &end);
  return end != env && *end == '\0' && v >= 0.1 && v <= 3600 ? v : fallback;
}
constexpr double kRateSampleS = 1.0;  // rate samples at least this far apart
constexpr double kRateWeight = 0.3;   // the newest sample's weight in the rate
}  // namespace

std::string formatDuration(double s) {
  char buf[64];
  if (!std::isfinite(s) || s < 0) return "?";
  if (s < 60) {
    std::snprintf(buf, sizeof buf, "%.1f s", s);
  } else if (s < 3600) {
    std::snprintf(buf, sizeof buf, "%d min %02d s", int(s / 60), int(std::fmod(s, 60)));
  } else {
    std::snprintf(buf, sizeof buf, "%d h %02d min", int(s / 3600), int(std::fmod(s, 3600) / 60));
  }
  return buf;
}

Progress::Progress(std::string label, double total, double logEverySeconds, Clock clock)
    : clock_(std::move(clock)),
      label_(std::move(label)),
      total_(total),
      logEvery_(logInterval(logEverySeconds)),
      interactive_(stderrIsTerminal()),
      start_(now()),
      lastDraw_(start_),
      lastSample_(start_) {}

Progress::~Progress() {
  if (!finished_ && interactive_) std::fputc('\n', stderr);
}

double Progress::fraction() const { return total_ > 0 ? std::clamp(done_ / total_, 0.0, 1.0) : 0.0; }

double Progress::elapsedSeconds() const { return std::chrono::duration<double>(now() - start_).count(); }

double Progress::etaSeconds() const {
  const double f = fraction();
  if (f <= 0) return -1;
  if (rate_ > 0) return std::max(0.0, total_ - done_) / rate_;
  return elapsedSeconds() * (1 - f) / f;  // before the first rate sample: the mean so far
}

bool Progress::due() const {
  const double since = std::chrono::duration<double>(now() - lastDraw_).count();
  return since >= (interactive_ ? 0.1 : logEvery_);
}

void Progress::update(double done, const std::string& note) {
  done_ = done;
  const auto t = now();
  const double sampleAge = std::chrono::duration<double>(t - lastSample_).count();
  if (sampleAge >= kRateSampleS) {
    const double r = (done - sampledDone_) / sampleAge;
    rate_ = rate_ > 0 ? kRateWeight * r + (1 - kRateWeight) * rate_ : r;
    lastSample_ = t;
    sampledDone_ = done;
  }
  const double since = std::chrono::duration<double>(t - lastDraw_).count();
  if (since < (interactive_ ? 0.1 : logEvery_)) return;
  lastDraw_ = t;
  draw(note, false);
}

void Progress::finish(const std::string& note) {
  if (finished_) return;
  done_ = total_;
  draw(note, true);
  finished_ = true;
}

void Progress::draw(const std::string& note, bool final) {
  const double f = fraction();
  const std::string eta = final ? formatDuration(elapsedSeconds()) : "ETA " + formatDuration(etaSeconds());
  if (interactive_) {
    constexpr int kWidth = 30;
    const int filled = int(std::lround(f * kWidth));
    std::string bar(size_t(filled), '#');
    bar.resize(kWidth, '.');
    std::fprintf(stderr, "\r%s [%s] %5.1f%% %s %s\x1b[K", label_.c_str(), bar.c_str(), 100 * f, eta.c_str(),
                 note.c_str());
    if (final) std::fputc('\n', stderr);
    std::fflush(stderr);
  } else {
    log::info("progress") << label_ << ": " << int(std::lround(100 * f)) << "% " << eta << (note.empty() ? "" : ", ")
                          << note;
  }
}

}  // namespace strata
