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

/// Whether other work keeps this machine's cores busy: as many other tasks runnable right now as
/// there are cores (/proc/loadavg's fourth field).
bool machineIsBusy();

/// OpenMP threads that wait by sleeping, not spinning, on a busy machine (issue 35). Called first
/// in main(): when OMP_WAIT_POLICY is unset and machineIsBusy(), it sets it to PASSIVE and starts
/// the same program again in this process (execv of /proc/self/exe with `argv`), because the
/// OpenMP runtime read its environment when it was loaded, before main() (a setenv from the
/// executable's .preinit_array is undone by libc's own initializer). Returns when nothing is to
/// be done or the program cannot be started again. libgomp spins at barriers before it sleeps:
/// harmless, and quickest, on free cores; on busy ones a spinning thread takes a core from the one
/// the join waits for, and two threads ran 2-18x slower than one (240 steps of a 36,864-cell flood
/// beside twice as many busy threads as cores: 2.2-23 s against 1.3 s; sleeping, 0.7-1.4 s). Not
/// always: starting again costs ~0.25 s here (273 shared libraries loaded twice).
void preferSleepingOpenMpWaits(char** argv);

}  // namespace strata
