#pragma once
// Text screened before it reaches toml++ (Debian 12's 3.3.0), for every TOML file Strata reads:
// scenarios and tile-store manifests. That parser has defects that text can reach: undefined
// behaviour or a failed assertion instead of an error (found by fuzzing, scripts/fuzz.sh; see
// the definition for each). The screen refuses such text with one line naming the file and line,
// and refuses what no Strata file holds (a date or a time of day, control characters, deep
// nesting). Text it passes may still be invalid TOML: toml++ reports that.

#include <cstddef>
#include <string>
#include <string_view>

#include <strata/core/result.hpp>

namespace strata {

struct TomlScreenOptions {
  /// Refuse non-ASCII bytes in strings and comments too (a file whose writer escapes them all,
  /// as the tile store's manifest writer does). Outside strings and comments they are always
  /// refused: TOML allows none there.
  bool asciiOnly = false;
  /// What the file is, for the messages ("scenario", "manifest").
  std::string_view kind = "TOML";
  /// Appended to the refusal of a date or a time of day (e.g. how the file writes durations).
  std::string_view dateHint;
  std::size_t maxBytes = std::size_t(1) << 30;
  std::size_t maxNesting = 64;  ///< arrays and inline tables open at once
};

/// Empty when toml++ may parse `text`; otherwise "file:line: what" (one line).
Status screenToml(std::string_view text, const std::string& file, const TomlScreenOptions& options = {});

/// `text` without a leading UTF-8 byte-order mark (EF BB BF), which some editors write and TOML
/// does not allow; harmless, so a reader skips it rather than refuse the file.
inline std::string_view withoutBom(std::string_view text) {
  return text.substr(0, 3) == "\xEF\xBB\xBF" ? text.substr(3) : text;
}

/// "U+00E9" for the UTF-8 code point starting at text[i] ("byte 0xC3" when it is not one).
std::string codePointName(std::string_view text, std::size_t i);

}  // namespace strata
