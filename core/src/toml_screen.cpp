#include <strata/core/toml_screen.hpp>

#include <algorithm>
#include <cctype>
#include <cstdint>
#include <cstdio>

namespace strata {

// Debian 12's toml++ (3.3.0) has defects that text can reach, found by fuzzing (scripts/fuzz.sh,
// the scenario and manifest targets; upstream issue marzer/tomlplusplus#190):
// - a code point in U+00A1..U+0499, U+2C5E..U+3057 or U+FB06..U+FEFE where it looks for
//   whitespace reaches __builtin_unreachable() in is_non_ascii_horizontal_whitespace (outside
//   strings, after a backslash in a multi-line string, or first on the line after a line-ending
//   backslash of one);
// - a table header starting with neither a bare-key character nor a quote ("[!]", "[&") fails an
//   assertion in parse_key;
// - its date and time scanning fails assertions on malformed ones ("1979-05-27T:",
//   "1979-05-27 1]", "1908-05-\6 7", "x= 5301-04-0s 3,": parse_time, parse_value, scan);
// - a '}' where an array's value is expected ("a = [1, }]", "u=[}") fails one in parse_value.
// Release builds turn the assertions into undefined behaviour or errors; Debug and fuzzing builds
// abort. All of that text is invalid TOML or holds a date or a time, which no Strata file does,
// except the line-ending backslash case, whose message says how to write it. Control characters
// (TOML allows tab and line breaks only) are refused with a clearer message than toml++'s.

std::string codePointName(std::string_view text, std::size_t i) {
  const auto b = static_cast<unsigned char>(text[i]);
  const int n = b >= 0xF0 ? 4 : b >= 0xE0 ? 3 : b >= 0xC0 ? 2 : 1;
  uint32_t cp = n == 1 ? b : b & (0x7F >> n);
  char buf[24];
  for (int k = 1; k < n; ++k) {
    if (i + size_t(k) >= text.size() || (static_cast<unsigned char>(text[i + size_t(k)]) & 0xC0) != 0x80) {
      std::snprintf(buf, sizeof buf, "byte 0x%02X", b);
      return buf;
    }
    cp = (cp << 6) | (static_cast<unsigned char>(text[i + size_t(k)]) & 0x3F);
  }
  std::snprintf(buf, sizeof buf, "U+%04X", cp);
  return buf;
}

Status screenToml(std::string_view text, const std::string& file, const TomlScreenOptions& options) {
  if (text.size() > options.maxBytes) {
    return fail(file + ": larger than " + std::to_string(options.maxBytes >> 20) + " MiB: not a " +
                std::string(options.kind));
  }
  // What the reader is in: between tokens (keys, brackets, '=', ','), a comment, a string, or a
  // bare value (a number, date, boolean: toml++ reads it up to whitespace, ']', '}', ',' or '#',
  // quotes and brackets included).
  enum class State { Normal, Comment, Basic, Literal, MultiBasic, MultiLiteral, Bare };
  State state = State::Normal;
  int line = 1;
  bool lineStart = true;           // only whitespace so far on this line
  bool expectValue = false;        // a value comes next (after '=', '[' or an array's ',')
  std::string open;                // brackets of the value being read, innermost last
  bool afterBackslashEnd = false;  // multi-line basic string: skipping whitespace after a line-ending '\'
  size_t bareStart = 0;            // where the bare value began
  auto refuse = [&](const std::string& what) { return fail(file + ":" + std::to_string(line) + ": " + what); };
  auto outside = [&](size_t i) {
    return refuse(codePointName(text, i) + " outside a string or a comment (TOML allows ASCII only there)");
  };
  auto quotes = [&](size_t i, char q) {
    size_t n = 0;
    while (i + n < text.size() && text[i + n] == q) ++n;
    return n;
  };
  for (size_t i = 0; i < text.size(); ++i) {
    const char c = text[i];
    const auto u = static_cast<unsigned char>(c);
    if ((u < 0x20 && c != '\t' && c != '\n' && !(c == '\r' && i + 1 < text.size() && text[i + 1] == '\n')) ||
        u == 0x7F) {
      return refuse(codePointName(text, i) + ": a control character (TOML allows tab and line breaks only)");
    }
    if (u >= 0x80 && options.asciiOnly) {
      return refuse(codePointName(text, i) + ": not ASCII (a " + std::string(options.kind) +
                    " is ASCII; its strings write other characters as \\uXXXX escapes)");
    }
    if (state == State::Bare &&
        (c == ' ' || c == '\t' || c == '\r' || c == '\n' || c == ']' || c == '}' || c == ',' || c == '#')) {
      state = State::Normal;  // the terminator is read again as a token
      expectValue = false;
    }
    if (c == '\n') {
      ++line;
      if (state == State::Comment || state == State::Basic || state == State::Literal) state = State::Normal;
      if (state == State::Normal) {
        lineStart = true;
        if (open.empty()) expectValue = false;
      }
      continue;
    }
    switch (state) {
      case State::Normal:
        if (u >= 0x80) return outside(i);
        if (c == '#') {
          state = State::Comment;
        } else if ((c == '"' || c == '\'') &&
                   (i == 0 || std::string_view(" \t\r\n=[{,.").find(text[i - 1]) != std::string_view::npos)) {
          // A string starts where a key or a value can; a quote glued to a key is read by toml++
          // as the end of that key.
          const size_t n = quotes(i, c);
          state = n >= 3 ? (c == '"' ? State::MultiBasic : State::MultiLiteral)
                         : (c == '"' ? State::Basic : State::Literal);
          if (n == 2) state = State::Normal;  // an empty string
          i += (n >= 3 ? 3 : n) - 1;
          expectValue = false;
        } else if (c == '=') {
          expectValue = true;
        } else if (c == '[' && lineStart && open.empty() && !expectValue) {
          // A table header: its first key starts with a bare-key character or a quote.
          size_t k = i + (i + 1 < text.size() && text[i + 1] == '[' ? 2 : 1);
          while (k < text.size() && (text[k] == ' ' || text[k] == '\t')) ++k;
          const char first = k < text.size() ? text[k] : ']';
          const auto f = static_cast<unsigned char>(first);
          if (first == '\n' || first == '\r') return refuse("a table name is missing after '['");
          // (Control and non-ASCII characters are refused when the loop reaches them.)
          if (f >= 0x21 && f < 0x7F && !std::isalnum(f) && first != '_' && first != '-' && first != '"' &&
              first != '\'' && first != ']') {
            return refuse(std::string("'") + first +
                          "' starts a table name (TOML allows ASCII letters, digits, _ and -, or a quoted name)");
          }
          i = k - 1;
        } else if (c == '[' || c == '{') {
          if (open.size() >= options.maxNesting) {
            return refuse("arrays and inline tables nested deeper than " + std::to_string(options.maxNesting));
          }
          open += c;
          expectValue = c == '[';
        } else if (c == ']' || c == '}') {
          if (!open.empty()) {
            // A '}' where an array's value is expected fails an assertion (parse_value); the
            // other mismatch is as invalid.
            if (c == '}' && open.back() == '[') return refuse("'}' inside an array (no inline table to close)");
            if (c == ']' && open.back() == '{') return refuse("']' inside an inline table (no array to close)");
            open.pop_back();
          }
          expectValue = false;
        } else if (c == ',') {
          expectValue = !open.empty() && open.back() == '[';
        } else if (expectValue && c != ' ' && c != '\t' && c != '\r') {
          state = State::Bare;
          bareStart = i;
        }
        if (c != ' ' && c != '\t' && c != '\r') lineStart = false;
        break;
      case State::Bare:
        if (u >= 0x80) return outside(i);
        // A '-' inside a value (not its sign, not an exponent's) or a ':' makes toml++ read a
        // date or a time, and its date and time scanning fails assertions on malformed ones
        // ("1979-05-27T:", "1979-05-27 1]", "1908-05-\6 7": parse_time, parse_value). No
        // scenario key takes a date or a time of day, so none reaches it.
        if (c == ':' || (c == '-' && i > bareStart && text[i - 1] != 'e' && text[i - 1] != 'E')) {
          return refuse(std::string("'") + c + "' inside a value: a date or a time of day, which no " +
                        std::string(options.kind) + " key takes" +
                        (options.dateHint.empty() ? "" : " (" + std::string(options.dateHint) + ")"));
        }
        break;
      case State::Comment: break;
      case State::Basic:
        if (c == '\\') {
          ++i;  // the escaped character (a line break there is toml++'s error to report)
          if (i < text.size() && text[i] == '\n') --i;
        } else if (c == '"') {
          state = State::Normal;
        }
        break;
      case State::Literal:
        if (c == '\'') state = State::Normal;
        break;
      case State::MultiBasic:
        if (afterBackslashEnd) {
          if (c == ' ' || c == '\t' || c == '\r') break;
          afterBackslashEnd = false;
          if (u >= 0x80) {
            return refuse(codePointName(text, i) +
                          " first after a line-ending backslash: the TOML reader (toml++ 3.3.0) cannot read it there; "
                          "start the line with an ASCII character or join the lines");
          }
        }
        if (c == '\\') {
          size_t k = i + 1;
          while (k < text.size() && (text[k] == ' ' || text[k] == '\t' || text[k] == '\r')) ++k;
          if (k < text.size() && text[k] == '\n') {
            afterBackslashEnd = true;  // skips whitespace and line breaks up to the next character
            i = k - 1;
          } else if (k < text.size() && static_cast<unsigned char>(text[k]) >= 0x80) {
            // toml++ asks whether the escaped character (or the one after the backslash's
            // spaces) is whitespace: undefined behaviour for these; no TOML escape anyway.
            return refuse(codePointName(text, k) +
                          " after a backslash in a multi-line string (not an escape TOML knows)");
          } else {
            ++i;  // an escape sequence
            if (i < text.size() && text[i] == '\n') --i;
          }
        } else if (c == '"' && quotes(i, '"') >= 3) {
          i += std::min<size_t>(quotes(i, '"'), 5) - 1;  // up to two quotes belong to the string
          state = State::Normal;
          lineStart = false;
        }
        break;
      case State::MultiLiteral:
        if (c == '\'' && quotes(i, '\'') >= 3) {
          i += std::min<size_t>(quotes(i, '\''), 5) - 1;
          state = State::Normal;
          lineStart = false;
        }
        break;
    }
  }
  return {};
}

}  // namespace strata
