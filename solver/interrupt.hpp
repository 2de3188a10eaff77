#pragma once
/// @file interrupt.hpp
/// A run stopped by the user (Ctrl-C) or by a batch scheduler (SIGTERM) ends cleanly: the runner
/// checks this flag after every accepted step and stops with status "interrupted", so the outputs
/// written so far stay valid.
///
/// The flag is process-wide and async-signal-safe (a lock-free atomic). `install_sigint_handler()`
/// makes SIGINT and SIGTERM set it (the command-line tool does this); a second signal while the flag
/// is still set restores the default action and re-raises, so a run that does not stop can still be
/// killed.
#include <signal.h>

namespace chainsim {

/// Asks every running StringSolver to stop at its next accepted step.
void request_interrupt();
/// True once an interrupt was requested (until clear_interrupt()).
bool interrupt_requested();
void clear_interrupt();
/// Who asked: "SIGTERM", or "the user" (SIGINT, request_interrupt()), for "interrupted by ...".
const char* interrupt_cause();
/// SIGINT and SIGTERM -> the interrupt flag (the second signal kills the process).
void install_sigint_handler();

/// SIGINT -> the interrupt flag for the scope's lifetime, then the previous handler back (with its
/// flags): for a host program, such as the Python interpreter, whose own handler cannot act while a
/// run holds the thread (the Python module installs it around a run that released the GIL).
/// `active` = false does nothing (a run outside the host's main thread).
class ScopedSigintHandler {
 public:
  explicit ScopedSigintHandler(bool active = true);
  ~ScopedSigintHandler();
  ScopedSigintHandler(const ScopedSigintHandler&) = delete;
  ScopedSigintHandler& operator=(const ScopedSigintHandler&) = delete;

 private:
  bool active_;
  struct sigaction previous_ {};
};

}  // namespace chainsim
