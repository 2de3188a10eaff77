// The chain sliding off a table over an edge on the string solver: see edge_case.hpp.
#include "cases/canonical/edge_case.hpp"

#include <algorithm>
#include <cmath>
#include <memory>

#include <fmt/format.h>

#include "cases/reduced/exact_solutions.hpp"
#include "mesh/discretize.hpp"
#include "mesh/errors.hpp"
#include "shocks/edge_front.hpp"

namespace chainsim {

void EdgeCaseSetup::validate() const {
  chain.validate();
  if (nodes < 3 || nodes > 200001)
    throw InputError(fmt::format("--nodes = {} is out of range: allowed 3 <= nodes <= 200001", nodes));
  require_in_range("--x0", x0, 0.0, 1.0, Bound::kOpen, Bound::kOpen);
  require_in_range("t_max_over_t0", t_max_over_t0, 0.0, INFINITY, Bound::kOpen);
  integrator.validate();
}

EdgeComparison compare_edge_with_exact(const EdgeCaseSetup& setup) {
  setup.validate();
  const double ell = setup.chain.length, lambda = setup.chain.density, g = setup.chain.gravity;
  const double f = setup.chain.dissipation, x0 = setup.x0 * ell, t0 = setup.chain.t0();
  Points<2> vertices(2, 3);
  vertices << -(ell - x0), 0.0, 0.0, 0.0, 0.0, -x0;
  Chain<2> chain = discretize<2>(*polyline_curve<2>(vertices), ell, lambda, setup.nodes - 1, false);
  std::vector<std::unique_ptr<Force<2>>> forces;
  forces.push_back(std::make_unique<Gravity<2>>(Vec<2>(0.0, -g)));
  EdgeSpec<2> edge;
  edge.point = Vec<2>::Zero();
  edge.dissipation = f;
  edge.s0 = ell - x0;
  edge.table = EdgeSpec<2>::Table::kBefore;
  std::vector<std::unique_ptr<FrontKind<2>>> fronts;
  fronts.push_back(std::make_unique<EdgeFront<2>>(edge));
  StringModelOptions model_options;
  model_options.stabilization_time = 0.02 * std::sqrt(ell / g);  // as a scene's default
  StringModel<2> model = make_front_model<2>(std::move(chain), std::move(forces), {}, std::move(fronts),
                                             FrontOptions{}, model_options);
  StringSolverOptions options;
  options.integrator = setup.integrator;
  options.t_end = setup.t_max_over_t0 * t0;
  options.output_interval = options.t_end;
  options.record_steps = true;
  StringSolver<2> solver(model, options);
  try {
    solver.run();
  } catch (const NumericalError&) {  // the run's status says "failed" and why
  }
  EdgeComparison c;
  c.run = solver.summary();
  // x(t), and the tension at the edge τ⁻ = F0·e_x + λ v² (the table part's pull), at every step.
  double err_x = 0, err_tension = 0;
  for (const StepSample& s : c.run.samples) {
    const double x = ell - s.fronts[0].s0, v = s.fronts[0].s0_dot;
    const double tension = s.forces[0] + lambda * v * v;
    const double t = std::min(s.t, exact::edge_time(f, ell, x0, ell, g));
    const double x_exact = exact::edge_x(f, t, x0, ell, g);
    const double tension_exact = lambda * (ell - x_exact) * exact::edge_acceleration(f, x_exact, x0, ell, g);
    err_x = std::max(err_x, std::abs(x - x_exact));
    err_tension = std::max(err_tension, std::abs(tension - tension_exact));
    c.exact.add_row({s.t, x_exact, std::sqrt(exact::edge_speed_squared(f, x_exact, x0, ell, g)), tension_exact});
  }
  const double x_lift = exact::edge_lift_off_x(f, x0, ell, g);
  const double t_lift = exact::edge_time(f, x_lift, x0, ell, g);
  c.summary = to_json(c.run);
  c.summary["problem"] = "edge";
  c.summary["nodes"] = setup.nodes;
  c.summary["f"] = f;
  c.summary["x0"] = setup.x0;
  c.summary["t_stop_over_t0"] = c.run.t_stop / t0;
  c.summary["t_stop_over_t0_exact"] = t_lift / t0;
  c.summary["rel_err_t_stop"] = std::abs(c.run.t_stop - t_lift) / t_lift;
  c.summary["t_lift_off_exact"] = t_lift;
  c.summary["x_lift_off_exact"] = x_lift;
  const auto lift = std::find_if(c.run.events.begin(), c.run.events.end(),
                                 [](const RunEvent& e) { return e.kind == "lift_off"; });
  if (lift != c.run.events.end() && !c.run.samples.empty()) {
    const double x = ell - c.run.samples.back().fronts[0].s0;  // the last step ends at the event
    c.summary["t_lift_off"] = lift->t;
    c.summary["abs_err_t_lift_off"] = std::abs(lift->t - t_lift);
    c.summary["x_lift_off"] = x;
    c.summary["abs_err_x_lift_off"] = std::abs(x - x_lift);
  } else {
    for (const char* key : {"t_lift_off", "abs_err_t_lift_off", "x_lift_off", "abs_err_x_lift_off"})
      c.summary[key] = nullptr;
  }
  c.summary["max_abs_err_x"] = err_x;
  c.summary["max_abs_err_tension"] = err_tension;
  c.summary["max_rel_err_tension"] = err_tension / setup.chain.P0();
  return c;
}

}  // namespace chainsim
