#pragma once
/// @file contact_compare.hpp
/// What the comparisons of a chain on an obstacle with its exact solution share (`chainsim compare edge`,
/// `peg`, `pulley`: edge_case.hpp, pulley_case.hpp): the run's options and its record of every step,
/// and the summary keys every one of them has. Each comparison adds its own keys and columns.
#include <optional>

#include <nlohmann/json.hpp>

#include "mesh/errors.hpp"
#include "solver/output.hpp"
#include "solver/string_solver.hpp"

namespace chainsim {

/// A string run against an exact solution (`chainsim compare edge|peg|pulley`).
struct ExactComparison {
  RunSummary run;
  /// The exact solution at the string's step times (exact_series.csv; columns per comparison).
  CsvTable exact{std::vector<std::string>{}};
  nlohmann::json summary;  ///< summary.json and `--json`
};

/// The safety stop t_max t0 (s) of a comparison: InputError naming --t-max unless t_max > 0 and t_max t0 is a
/// positive, finite time (a t_max of 5e-324 made t_end 0, which the run refused as "stop.t_end = 0").
void require_safety_stop(double t_max_over_t0, double t0);

/// InputError naming `option` = `value` and the chain's `length` unless `shape_length` (m), a length of the initial
/// shape that they set (`what`), is at least sqrt(DBL_MIN) ≈ 1.5e-154 m: the shape's geometry squares its lengths,
/// and a shorter one's square underflows (x0 = 5e-324 made "the polyline's points 1 and 2 coincide").
void require_shape_length(const char* option, double value, double length, const char* what, double shape_length);

/// The options of a comparison's run: `integrator`, to `t_end` (s, the safety stop), one frame at the
/// start and one at the stop, a record of every step (string_series.csv).
StringSolverOptions exact_comparison_run(const IntegratorOptions& integrator, double t_end);

/// Runs `solver` to its stop; a numerical failure ends the run, whose status says "failed" and why.
template <int dim>
const RunSummary& run_to_stop(StringSolver<dim>& solver) {
  try {
    solver.run();
  } catch (const NumericalError&) {  // the run's status says "failed" and why
  }
  return solver.summary();
}

/// The string's lift-off: its time (s) and x there (m).
struct MeasuredLiftOff {
  double t = 0, x = 0;
};

/// The summary keys every comparison has (besides the string run's, to_json(run)):
///   problem, nodes,
///   t_lift_off, t_lift_off_exact, abs_err_t_lift_off       the string's lift-off time against t* (s),
///   x_lift_off, x_lift_off_exact, abs_err_x_lift_off       the string's x there against x* (m),
///   max_abs_err_x                                          max over the steps of |x − exact x(t)| (m).
/// Without a lift-off (`lift_off` none: a failed run, or the safety stop) the string's lift-off keys are null.
nlohmann::json exact_comparison_summary(const RunSummary& run, const char* problem, int nodes, double t_lift_exact,
                                        double x_lift_exact, std::optional<MeasuredLiftOff> lift_off,
                                        double max_abs_err_x);

}  // namespace chainsim
