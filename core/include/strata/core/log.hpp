#pragma once
// One tiny logger: levels, a category prefix, stderr by default.
//   strata::log::info("gis") << "reading " << path;   ->   "gis: reading dem.tif"
// The level comes from STRATA_LOG (debug, info, warn, error; default info) or setLevel().

#include <functional>
#include <sstream>
#include <string>
#include <string_view>

namespace strata::log {

enum class Level { Debug = 0, Info = 1, Warn = 2, Error = 3, Off = 4 };

void setLevel(Level level);
Level level();
bool enabled(Level level);

/// Where finished lines go (default: stderr). Tests install a sink to capture lines.
using Sink = std::function<void(Level, std::string_view category, std::string_view message)>;
void setSink(Sink sink);
void resetSink();

/// Emits one line.
void write(Level level, std::string_view category, std::string_view message);

/// A line being built; written when it goes out of scope.
class Line {
 public:
  Line(Level level, std::string_view category) : level_(level), category_(category), on_(enabled(level)) {}
  ~Line() {
    if (on_) write(level_, category_, out_.str());
  }
  Line(const Line&) = delete;
  Line& operator=(const Line&) = delete;
  template <class T>
  Line& operator<<(const T& v) {
    if (on_) out_ << v;
    return *this;
  }

 private:
  Level level_;
  std::string category_;
  bool on_;
  std::ostringstream out_;
};

inline Line debug(std::string_view category) { return Line(Level::Debug, category); }
inline Line info(std::string_view category) { return Line(Level::Info, category); }
inline Line warn(std::string_view category) { return Line(Level::Warn, category); }
inline Line error(std::string_view category) { return Line(Level::Error, category); }

}  // namespace strata::log
