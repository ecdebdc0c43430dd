#include <strata/core/interrupt.hpp>

#include <unistd.h>

#include <atomic>
#include <csignal>

namespace strata {
namespace {

std::atomic<bool> gInterrupted{false};

void onSignal(int sig) {
  if (gInterrupted.exchange(true)) {
    // Second signal: the user insists.
    std::signal(sig, SIG_DFL);
    std::raise(sig);
    return;
  }
  constexpr char kMsg[] = "\nstopping after this interval (Ctrl-C again to abort)\n";
  [[maybe_unused]] auto n = ::write(STDERR_FILENO, kMsg, sizeof kMsg - 1);
}

}  // namespace

void installInterruptHandler() {
  struct sigaction sa {};
  sa.sa_handler = onSignal;
  sigemptyset(&sa.sa_mask);
  sigaction(SIGINT, &sa, nullptr);
  sigaction(SIGTERM, &sa, nullptr);
}

bool interrupted() { return gInterrupted.load(); }
void setInterrupted(bool value) { gInterrupted.store(value); }

}  // namespace strata
