// The progress line of long runs: see progress.hpp.
#include "cases/cli/progress.hpp"

#include <unistd.h>

#include <fmt/format.h>

namespace chainsim {

bool progress_wanted(bool quiet) { return !quiet && isatty(STDERR_FILENO) == 1; }

ProgressLine::ProgressLine(double t_end, bool enabled)
    : t_end_(t_end), enabled_(enabled), start_(std::chrono::steady_clock::now()), last_(start_) {}

void ProgressLine::update(double t) {
  ++steps_;
  if (!enabled_) return;
  const auto now = std::chrono::steady_clock::now();
  if (now - last_ < std::chrono::milliseconds(250)) return;
  last_ = now;
  const double wall = std::chrono::duration<double>(now - start_).count();
  // Time left, assuming the cost per simulated second stays what it has been.
  const std::string left = t > 0 ? fmt::format("{:.1f} s", wall * (t_end_ - t) / t) : "?";
  std::fprintf(stderr, "\r  t = %-11.6g of %g s   %ld steps   %.1f s wall, about %s left   ", t, t_end_, steps_,
               wall, left.c_str());
  std::fflush(stderr);
  drawn_ = true;
}

void ProgressLine::finish() {
  if (!drawn_) return;
  std::fprintf(stderr, "\r%100s\r", "");
  std::fflush(stderr);
  drawn_ = false;
}

}  // namespace chainsim
