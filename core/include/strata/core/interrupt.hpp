#pragma once
// Ctrl-C for long work: the first SIGINT/SIGTERM sets a flag that the work polls between steps
// so it can stop cleanly (finish the interval, write a checkpoint); a second one exits at once.

namespace strata {

/// Installs the handlers (idempotent). Returns nothing; poll interrupted().
void installInterruptHandler();
/// True once SIGINT or SIGTERM arrived after installInterruptHandler().
bool interrupted();
/// For tests: raise or clear the flag as if a signal arrived.
void setInterrupted(bool value);

}  // namespace strata
