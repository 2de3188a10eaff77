// What the comparisons with an exact solution share: see contact_compare.hpp.
#include "cases/canonical/contact_compare.hpp"

#include <cmath>

namespace chainsim {

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
