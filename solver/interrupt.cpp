// Process-wide interrupt flag: see interrupt.hpp.
#include "interrupt.hpp"

#include <atomic>
#include <csignal>

namespace chainsim {

namespace {
/// 0: no interrupt; -1: request_interrupt(); else the signal that asked for it.
std::atomic<int> g_interrupt{0};
static_assert(std::atomic<int>::is_always_lock_free, "the interrupt flag must be safe in a signal handler");

extern "C" void on_interrupt_signal(int signal) {
  if (g_interrupt.load() != 0) {  // the second signal: its default action (terminate)
    std::signal(signal, SIG_DFL);
    std::raise(signal);
    return;
  }
  g_interrupt.store(signal);
}
}  // namespace

void request_interrupt() { g_interrupt.store(-1); }
bool interrupt_requested() { return g_interrupt.load() != 0; }
void clear_interrupt() { g_interrupt.store(0); }
const char* interrupt_cause() { return g_interrupt.load() == SIGTERM ? "SIGTERM" : "the user"; }
void install_sigint_handler() {
  std::signal(SIGINT, on_interrupt_signal);
  std::signal(SIGTERM, on_interrupt_signal);
}

ScopedSigintHandler::ScopedSigintHandler(bool active) : active_(active) {
  if (!active_) return;
  struct sigaction action {};
  action.sa_handler = on_interrupt_signal;
  sigemptyset(&action.sa_mask);
  sigaction(SIGINT, &action, &previous_);
}

ScopedSigintHandler::~ScopedSigintHandler() {
  if (!active_) return;
  sigaction(SIGINT, &previous_, nullptr);
}

}  // namespace chainsim
