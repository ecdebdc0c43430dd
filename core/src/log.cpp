#include <strata/core/log.hpp>

#include <atomic>
#include <cstdio>
#include <cstdlib>
#include <mutex>

namespace strata::log {
namespace {

Level levelFromEnv() {
  const char* s = std::getenv("STRATA_LOG");
  if (!s) return Level::Info;
  const std::string_view v(s);
  if (v == "debug") return Level::Debug;
  if (v == "info") return Level::Info;
  if (v == "warn") return Level::Warn;
  if (v == "error") return Level::Error;
  if (v == "off") return Level::Off;
  return Level::Info;
}

std::atomic<Level>& currentLevel() {
  static std::atomic<Level> level{levelFromEnv()};
  return level;
}

std::mutex& sinkMutex() {
  static std::mutex m;
  return m;
}

Sink& currentSink() {
  static Sink sink;
  return sink;
}

const char* levelTag(Level level) {
  switch (level) {
    case Level::Debug: return "debug: ";
    case Level::Warn: return "warning: ";
    case Level::Error: return "error: ";
    default: return "";
  }
}

}  // namespace

void setLevel(Level level) { currentLevel().store(level); }
Level level() { return currentLevel().load(); }
bool enabled(Level l) { return l >= currentLevel().load() && l != Level::Off; }

void setSink(Sink sink) {
  std::lock_guard lock(sinkMutex());
  currentSink() = std::move(sink);
}
void resetSink() { setSink(nullptr); }

void write(Level level, std::string_view category, std::string_view message) {
  std::lock_guard lock(sinkMutex());
  if (currentSink()) {
    currentSink()(level, category, message);
    return;
  }
  std::fprintf(stderr, "%.*s: %s%.*s\n", int(category.size()), category.data(), levelTag(level), int(message.size()),
               message.data());
}

}  // namespace strata::log
