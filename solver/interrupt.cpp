// Process-wide interrupt flag: see interrupt.hpp.
#include "interrupt.hpp"

#include <atomic>
#include <csignal>

namespace chainsim {

namespace {
std::atomic<bool> g_interrupt{false};
static_assert(std::atomic<bool>::is_always_lock_free, "the interrupt flag must be safe in a signal handler");

extern "C" void on_sigint(int signal) {
  if (g_interrupt.load()) {  // the second Ctrl-C: the default action (terminate)
    std::signal(signal, SIG_DFL);
    std::raise(signal);
    return;
  }
  g_interrupt.store(true);
}
}  // namespace

void request_interrupt() { g_interrupt.store(true); }
bool interrupt_requested() { return g_interrupt.load(); }
void clear_interrupt() { g_interrupt.store(false); }
void install_sigint_handler() { std::signal(SIGINT, on_sigint); }

ScopedSigintHandler::ScopedSigintHandler(bool active) : active_(active) {
  if (!active_) return;
  struct sigaction action {};
  action.sa_handler = on_sigint;
  sigemptyset(&action.sa_mask);
  sigaction(SIGINT, &action, &previous_);
}

ScopedSigintHandler::~ScopedSigintHandler() {
  if (!active_) return;
  sigaction(SIGINT, &previous_, nullptr);
}

}  // namespace chainsim
