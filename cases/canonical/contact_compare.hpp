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
