#pragma once
/// @file reduced_models.hpp
/// The reduced (one-degree-of-freedom) models of the paper's three canonical chain problems,
/// docs/model.md §4, integrated with ARKODE in physical units.
///
///  (a) falling chain onto a table, heap at the contact point; y = height of the falling part:
///        (1 + f sgn ẏ) ẏ² + (ÿ + g) y = 0                                   stop at y = ε ℓ
///  (b) folded chain, one end fixed, free arm falling beside the resting arm, optional upward
///      force F on the free end; y = length of the arm at rest:
///        λ (1 − f sgn ẏ) ẏ² + λ (g − 2ÿ)(ℓ − y) = F                        stop at y = (1 − ε) ℓ
///  (c) sliding chain from a heap through a hole; y = hanging length:
///        (1 + f sgn ẏ) ẏ² + (ÿ − g) y = 0                                   stop at y = ℓ
///
/// sgn ẏ only ever multiplies ẏ², so the right-hand sides use ẏ|ẏ|, continuous with a continuous
/// first derivative at ẏ = 0. Where ẏ can change sign (the folded chain with F > 0), ẏ = 0 is an
/// event and the integrator is restarted there, so the high-order method never steps across the
/// jump in the second derivative.
#include <optional>
#include <string>

#include <nlohmann/json.hpp>

#include "solver/integrator.hpp"
#include "solver/output.hpp"

namespace chainsim {

enum class Problem { kFalling, kFolded, kSliding };

/// "falling" | "folded" | "sliding"; anything else throws InputError listing the allowed names.
Problem parse_problem(const std::string& name, const std::string& what = "problem");
std::string to_string(Problem problem);

/// The chain's constants, SI units.
struct ChainParameters {
  double length = 1.0;       ///< ℓ (m), in [1e-100, 1e100] (kMinScale, kMaxScale)
  double density = 1.0;      ///< λ (kg/m), in [1e-100, 1e100]
  double gravity = 9.81;     ///< g (m/s²), in [1e-100, 1e100]; λ g ℓ² in [1e-200, 1e200]
  double dissipation = 0.83; ///< f, the shock dissipation parameter, in [0, 1]
  void validate() const;
  double t0() const;         ///< sqrt(2 ℓ / g): time of free fall from height ℓ (s)
  double P0() const;         ///< λ ℓ g: static weight (N)
};

struct ReducedSetup {
  Problem problem = Problem::kFalling;
  ChainParameters chain;
  /// Cutoff ε in (0, 1): the falling chain stops at η = ε, the folded chain at η = 1 − ε.
  /// (The sliding chain stops when the whole chain hangs, η = 1.) For the falling and folded
  /// chains ε must also be at least min_cutoff(): see there.
  double eps = 0.01;
  /// Initial η = y(0)/ℓ, released from rest. Defaults: falling 1, folded 0, sliding 0.
  /// Ranges: falling (ε, 1], folded [0, 1 − ε), sliding [0, 1).
  std::optional<double> eta0;
  /// Upward force on the free end of the folded chain (N), >= 0; other problems require 0.
  /// Released at η0 = 0 the force must not exceed the chain's weight λgℓ: a larger one would lift
  /// the free end above its start at once, out of the model's domain η >= 0.
  double force = 0.0;
  /// Safety stop (units of t0): a run that has not met its stop event by then ends with
  /// stop_reason "t_max" (e.g. a folded chain held in equilibrium by F).
  double t_max_over_t0 = 50.0;
  /// Most rows the series may hold, fixed before the run (>= 16). A longer run is thinned: one
  /// accepted step in 2, 4, 8, … is kept (the stride doubles each time the limit is reached), and
  /// the last state is always the last row. Memory and file size are bounded whatever the steps.
  long max_rows = 100000;
  /// The integrator; max_step = 0 selects t0/500 so the recorded series resolves the plots. Its
  /// max_steps bounds the accepted steps of the whole run.
  IntegratorOptions integrator = default_integrator();

  static IntegratorOptions default_integrator();
  /// Smallest cutoff ε the run can resolve (falling and folded chains; 0 for the sliding chain):
  /// the exact time left between the cutoff and the singular end of the fall, from the power law
  /// of the speed there, must be at least kMinTimeToEnd · t0 (about 10³ round-off units of t).
  /// Falling (η → 0):  Δξ = ½√(3−2f) η0^−(3−2f)/2 ε^(2−f)/(2−f);
  /// folded (1−η → 0): Δξ = √(1−f/2) (1−η0)^−(2−f)/2 ε^((3−f)/2)/((3−f)/2)   (F = 0; a force F > 0
  /// slows the fall, so this is a lower bound of the time left).
  double min_cutoff() const;
  static constexpr double kMinTimeToEnd = 2e-13;
  double initial_eta() const;  ///< eta0 or the problem's default
  void validate() const;       ///< throws InputError naming the option, value and allowed range
};

/// Everything one run produces: the time series, and a JSON summary.
struct ReducedRun {
  CsvTable series;          ///< one row per accepted step, thinned to max_rows (see series_columns())
  nlohmann::json summary;   ///< see docs/reduced.md for the keys
};

/// Column names of ReducedRun::series: physical (SI) then scaled.
std::vector<std::string> series_columns();

/// Integrates the reduced model from rest to its stop event. Throws InputError for a bad setup,
/// NumericalError if the integration fails.
ReducedRun solve_reduced(const ReducedSetup& setup);

/// The exact references of exact_solutions.hpp for a problem released from rest at η0 (F = 0):
/// the scaled time ξ(η), the squared scaled speed η'², P/P0 at η, and the full fall time ξ_f.
namespace exact {
double xi(Problem problem, double f, double eta, double eta0);
double eta_prime_squared(Problem problem, double f, double eta, double eta0);
double P(Problem problem, double f, double eta, double eta0);
double fall_time(Problem problem, double f, double eta0);
}  // namespace exact

/// The sliding chain started from η0 = 0 follows the non-trivial branch y = a t²/2,
/// a = g/(3 + 2f); the ODE is singular at y = 0, so the integration starts on that branch at
/// η = kSlidingStartEta (an attracting solution: deviations decay like y^(−2(1+f))).
inline constexpr double kSlidingStartEta = 1e-6;

}  // namespace chainsim
