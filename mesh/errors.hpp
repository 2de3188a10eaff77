#pragma once
/// @file errors.hpp
/// The three kinds of failure chainsim distinguishes, and the checks that raise them.
///
///  - InputError:       the user asked for something invalid (a value out of range, an unknown name).
///                      The message names the option or key, the value and what is allowed.
///  - NumericalError:   the run cannot go on (slack, blow-up at a singularity, step size underflow).
///                      The message says what happened and at which time.
///  - RecoverableError: thrown inside a right-hand side when the trial state is unusable; the
///                      integrator turns it into ARKODE's "recoverable" return code (+1) and retries
///                      with a smaller step.
#include <stdexcept>
#include <string>
#include <string_view>

namespace chainsim {

class Error : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

class InputError : public Error {
 public:
  using Error::Error;
};

class NumericalError : public Error {
 public:
  NumericalError(const std::string& what, double time)
      : Error(what), time_(time) {}
  /// Simulation time (s) at which the trouble was detected.
  double time() const { return time_; }

 private:
  double time_;
};

class RecoverableError : public Error {
 public:
  using Error::Error;
};

/// Interval end types for range checks.
enum class Bound { kClosed, kOpen };

/// Throws InputError unless lo (<|<=) value (<|<=) hi. `name` is how the user spelled the
/// input (e.g. "--f" or "string.length"); the message reads
///   "--f = 1.5 is out of range: allowed 0 <= f <= 1".
void require_in_range(std::string_view name, double value, double lo, double hi,
                      Bound lo_bound = Bound::kClosed, Bound hi_bound = Bound::kClosed);

/// The range of a physical scale (a length, a density, |g|, a speed, a time, a force) that the solvers
/// accept: they form squares and products of the scales (energies, tensions), which must stay finite
/// and normal, so an input scale lies in [kMinScale, kMaxScale] and a derived one (a product of two)
/// in [kMinScale², kMaxScale²].
inline constexpr double kMinScale = 1e-100, kMaxScale = 1e100;

/// Throws InputError unless value > 0 (finite).
void require_positive(std::string_view name, double value);

/// Throws InputError unless value is finite.
void require_finite(std::string_view name, double value);

[[noreturn]] void verify_failed(const char* condition, const char* file, int line, const std::string& msg);

}  // namespace chainsim

/// Always-on invariant check: a violated invariant is a bug in chainsim, not bad input.
#define CHAINSIM_VERIFY(cond, msg)                                             \
  do {                                                                         \
    if (!(cond)) ::chainsim::verify_failed(#cond, __FILE__, __LINE__, (msg)); \
  } while (0)
