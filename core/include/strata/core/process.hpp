#pragma once
// Child processes without a shell: an argument vector, never a command line, so no character of
// a file name is ever interpreted. The child runs in its own process group, so a Ctrl-C at the
// terminal reaches Strata (which stops cleanly) and not the child in the middle of its work.

#include <string>
#include <string_view>
#include <vector>

#include <strata/core/result.hpp>

namespace strata {

/// Runs `argv[0]` (an absolute path) with `argv`, writes `input` to its standard input, and
/// returns what it printed (stdout and stderr together). Fails, with that output, when it cannot
/// start or exits with a non-zero status or on a signal.
Result<std::string> runProcess(const std::vector<std::string>& argv, std::string_view input = {});

}  // namespace strata
