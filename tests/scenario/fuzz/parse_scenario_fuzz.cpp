// libFuzzer target over the scenario parser: the input bytes are a scenario file's text, read by
// parseScenario (TOML through toml++, then every key, unit and range check). Whatever the bytes,
// the answer is a scenario or a one-line error naming the file: no crash, no sanitizer report,
// no assertion of the TOML library. The same bytes go through checkScenarioText (strata check):
// it finds a problem exactly when parseScenario refuses, the first in reading order being
// parseScenario's own message. Built and run by scripts/fuzz.sh (toml++'s own assertions
// on: no NDEBUG), not by CMake.
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <string_view>

#include <strata/scenario/scenario.hpp>

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string_view text(reinterpret_cast<const char*>(data), size);
  auto s = strata::scenario::parseScenario(text, "/fuzz/scenario.toml");
  if (!s) {
    const std::string& m = s.message();
    // Every refusal names the file and is one line.
    if (m.rfind("/fuzz/scenario.toml", 0) != 0 || m.find('\n') != std::string::npos) {
      std::fprintf(stderr, "not a one-line message naming the file: %s\n", m.c_str());
      std::abort();
    }
  }
  const auto check = strata::scenario::checkScenarioText(text, "/fuzz/scenario.toml");
  if (check.problems.empty() != bool(s) || (!s && check.problems.front().message != s.message())) {
    std::fprintf(stderr, "strata check disagrees with parseScenario: %s\n",
                 check.problems.empty() ? "(no problem)" : check.problems.front().message.c_str());
    std::abort();
  }
  return 0;
}
