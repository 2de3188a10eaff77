#pragma once
/// @file progress.hpp
/// A progress line for long runs on a terminal: simulated time / t_end, steps, wall time and an
/// estimate of the time left, on stderr, redrawn at most four times a second; nothing when stderr is
/// not a terminal or the user asked for quiet.
#include <chrono>
#include <cstdio>

namespace chainsim {

class ProgressLine {
 public:
  /// `enabled` false: every call does nothing. Use progress_wanted() for the usual rule.
  ProgressLine(double t_end, bool enabled);
  ~ProgressLine() { finish(); }
  /// After an accepted step at simulated time t.
  void update(double t);
  /// Clears the line (called by the destructor too).
  void finish();

 private:
  double t_end_;
  bool enabled_, drawn_ = false;
  long steps_ = 0;
  std::chrono::steady_clock::time_point start_, last_;
};

/// True when stderr is a terminal and `quiet` is false.
bool progress_wanted(bool quiet);

}  // namespace chainsim
