// What the comparisons with an exact solution share: see contact_compare.hpp.
#include "cases/canonical/contact_compare.hpp"

#include <cmath>
#include <limits>

#include <fmt/format.h>

namespace chainsim {

void require_safety_stop(double t_max_over_t0, double t0) {
  require_in_range("--t-max", t_max_over_t0, 0.0, INFINITY, Bound::kOpen);
  const double t_end = t_max_over_t0 * t0;
  if (!(t_end > 0) || !std::isfinite(t_end))
    throw InputError(fmt::format("--t-max = {} is out of range: the safety stop t_max t0 = {} s (t0 = {} s) must be a "
                                 "positive, finite time",
                                 t_max_over_t0, t_end, t0));
}

void require_shape_length(const char* option, double value, double length, const char* what, double shape_length) {
  const double shortest = std::sqrt(std::numeric_limits<double>::min());
  if (!(shape_length >= shortest))
    throw InputError(fmt::format("{} = {} is out of range with --length = {}: {} = {} m is below {:.3g} m, the "
                                 "shortest length whose square a double holds (the shape's geometry squares it)",
                                 option, value, length, what, shape_length, shortest));
}

StringSolverOptions exact_comparison_run(const IntegratorOptions& integrator, double t_end) {
  StringSolverOptions options;
  options.integrator = integrator;
  options.t_end = t_end;
  options.output_interval = t_end;
  options.record_steps = true;
  return options;
}

nlohmann::json exact_comparison_summary(const RunSummary& run, const char* problem, int nodes, double t_lift_exact,
                                        double x_lift_exact, std::optional<MeasuredLiftOff> lift_off,
                                        double max_abs_err_x) {
  nlohmann::json s = to_json(run);
  s["problem"] = problem;
  s["nodes"] = nodes;
  s["t_lift_off_exact"] = t_lift_exact;
  s["x_lift_off_exact"] = x_lift_exact;
  if (lift_off) {
    s["t_lift_off"] = lift_off->t;
    s["abs_err_t_lift_off"] = std::abs(lift_off->t - t_lift_exact);
    s["x_lift_off"] = lift_off->x;
    s["abs_err_x_lift_off"] = std::abs(lift_off->x - x_lift_exact);
  } else {
    for (const char* key : {"t_lift_off", "abs_err_t_lift_off", "x_lift_off", "abs_err_x_lift_off"}) s[key] = nullptr;
  }
  s["max_abs_err_x"] = max_abs_err_x;
  return s;
}

}  // namespace chainsim
