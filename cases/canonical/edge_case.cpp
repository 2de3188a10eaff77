// The chain over an edge or a peg on the string solver: see edge_case.hpp.
#include "cases/canonical/edge_case.hpp"

#include <algorithm>
#include <cmath>
#include <functional>
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
  if (problem == PointContactProblem::kPeg)
    require_in_range("--x0", x0, 0.5, 1.0, Bound::kOpen, Bound::kOpen);  // x0 = 0.5: at rest (unstable)
  else
    require_in_range("--x0", x0, 0.0, 1.0, Bound::kOpen, Bound::kOpen);
  // The edge front needs string on both sides: the point more than 2 kCross h from either end node
  // (EdgeFront::initialize). x0 = 1e-100 put it on the end node (s0 = l - x0 l = l in doubles).
  const double h = chain.length / (nodes - 1), closest = 2 * EdgeFront<2>::kCross * h;
  const double sides[] = {x0 * chain.length, chain.length - x0 * chain.length};
  for (int k = 0; k < 2; ++k)
    if (!(sides[k] > closest))
      throw InputError(fmt::format(
          "--x0 = {} is out of range with --length = {} and --nodes = {}: {} = {} m puts the {} within {:.3g} m "
          "(2e-8 of a link) of the string's end, and it needs string on both sides",
          x0, chain.length, nodes,
          problem == PointContactProblem::kPeg ? (k == 0 ? "the longer side x0 l" : "the shorter side (1 - x0) l")
                                               : (k == 0 ? "the hanging length x0 l" : "the table's part (1 - x0) l"),
          sides[k], problem == PointContactProblem::kPeg ? "peg" : "edge", closest));
  require_safety_stop(t_max_over_t0, chain.t0());
  integrator.validate();
}

namespace {

/// The exact solution of one problem at x (m): the motion, the tensions on both sides of the point,
/// its reaction (N), all per the problem's exact::* functions.
struct ExactState {
  double x_dot = 0, tension_minus = 0, tension_plus = 0;
  Vec<2> reaction = Vec<2>::Zero();
};

/// What distinguishes the edge from the peg: the initial shape through the point at the origin, the
/// exact solution, and how the run's reaction splits into the tensions on either side.
struct PointProblem {
  const char* name;
  const char* tension_minus_column;
  Points<2> vertices;  ///< the initial polyline, through the origin at s0 = ℓ − x0
  std::function<double(double x)> time;   ///< exact t(x) (s)
  std::function<double(double t)> x_at;   ///< exact x(t) (m)
  std::function<ExactState(double x)> state;
  double x_lift = 0;  ///< exact lift-off x (m)
  /// τ⁻ and τ⁺ of the string from its recorded reaction F0 and the speed v (jump conditions).
  std::function<std::pair<double, double>(const Vec<2>& reaction, double v)> tensions;
  /// The exact kink's dissipation from the release to x (J): the exact energy balance's loss.
  std::function<double(double x)> dissipated;
};

EdgeComparison compare_over_point(const EdgeCaseSetup& setup, const PointProblem& p) {
  setup.validate();
  const double ell = setup.chain.length, lambda = setup.chain.density, g = setup.chain.gravity;
  const double f = setup.chain.dissipation, x0 = setup.x0 * ell, t0 = setup.chain.t0();
  Chain<2> chain = discretize<2>(*polyline_curve<2>(p.vertices), ell, lambda, setup.nodes - 1, false);
  std::vector<std::unique_ptr<Force<2>>> forces;
  forces.push_back(std::make_unique<Gravity<2>>(Vec<2>(0.0, -g)));
  EdgeSpec<2> edge;
  edge.point = Vec<2>::Zero();
  edge.dissipation = f;
  edge.s0 = ell - x0;
  const bool table_surface = setup.problem == PointContactProblem::kEdge && setup.table_surface;
  if (setup.problem == PointContactProblem::kEdge && !table_surface) edge.table = EdgeSpec<2>::Table::kBefore;
  std::vector<std::unique_ptr<FrontKind<2>>> fronts;
  fronts.push_back(std::make_unique<EdgeFront<2>>(edge));
  StringModelOptions model_options;
  model_options.stabilization_time = 0.02 * std::sqrt(ell / g);  // as a scene's default
  // The table y = 0, x < 0 as a surface that ends at the edge: the contact module around the fronts.
  std::unique_ptr<StringModule<2>> module;
  if (table_surface) {
    FrontKind<2>& edge_front = *fronts.front();
    std::vector<Obstacle<2>> table{edge_table<2>(dynamic_cast<EdgeFront<2>&>(edge_front), Vec<2>(0.0, 1.0),
                                                 Vec<2>(-1.0, 0.0), true, Vec<2>::Zero(), "table")};
    module = make_contact_module<2>(std::move(table), std::make_unique<FrontTracker<2>>(std::move(fronts), FrontOptions{}));
  } else {
    module = std::make_unique<FrontTracker<2>>(std::move(fronts), FrontOptions{});
  }
  StringModel<2> model(std::move(chain), std::move(forces), {}, model_options, std::move(module));
  StringSolver<2> solver(model, exact_comparison_run(setup.integrator, setup.t_max_over_t0 * t0));
  EdgeComparison c{run_to_stop(solver),
                   CsvTable({"t", "x", "x_dot", p.tension_minus_column, "tension_plus", "reaction_x", "reaction_y"}),
                   {}};
  // x(t), the tensions on both sides of the point and its reaction (forces.csv's R_front0), at every step.
  const double t_end = p.time(ell);
  double err_x = 0, err_tension = 0, err_tension_plus = 0, err_reaction = 0;
  for (const StepSample& s : c.run.samples) {
    const double x = ell - s.fronts[0].s0, v = s.fronts[0].s0_dot;
    const Vec<2> reaction(s.forces[0], s.forces[1]);
    const auto [tension_minus, tension_plus] = p.tensions(reaction, v);
    const double x_exact = p.x_at(std::min(s.t, t_end));
    const ExactState e = p.state(x_exact);
    err_x = std::max(err_x, std::abs(x - x_exact));
    err_tension = std::max(err_tension, std::abs(tension_minus - e.tension_minus));
    err_tension_plus = std::max(err_tension_plus, std::abs(tension_plus - e.tension_plus));
    err_reaction = std::max(err_reaction, (reaction - e.reaction).norm());
    c.exact.add_row({s.t, x_exact, e.x_dot, e.tension_minus, e.tension_plus, e.reaction.x(), e.reaction.y()});
  }
  const double t_lift = p.time(p.x_lift);
  // The string's lift-off: the edge front's event, which stops the run (its last step ends there).
  std::optional<MeasuredLiftOff> lift_off;
  const auto lift = std::find_if(c.run.events.begin(), c.run.events.end(),
                                 [](const RunEvent& e) { return e.kind == "lift_off"; });
  if (lift != c.run.events.end() && !c.run.samples.empty())
    lift_off = MeasuredLiftOff{lift->t, ell - c.run.samples.back().fronts[0].s0};
  c.summary = exact_comparison_summary(c.run, p.name, setup.nodes, t_lift, p.x_lift, lift_off, err_x);
  c.summary["t_stop_over_t0"] = c.run.t_stop / t0;
  c.summary["t_stop_over_t0_exact"] = t_lift / t0;
  c.summary["rel_err_t_stop"] = std::abs(c.run.t_stop - t_lift) / t_lift;
  c.summary["f"] = f;
  c.summary["x0"] = setup.x0;
  c.summary["max_abs_err_tension"] = err_tension;
  c.summary["max_rel_err_tension"] = err_tension / setup.chain.P0();
  c.summary["max_abs_err_tension_plus"] = err_tension_plus;
  c.summary["max_abs_err_reaction"] = err_reaction;
  // The kink's dissipation: the run books −∫ D dt in W_shocks (the edge does no work, F0 · v0 = 0).
  const double dissipated = c.run.samples.empty() ? 0.0 : 0.0 - c.run.samples.back().terms["W_shocks"];
  const double dissipated_exact = p.dissipated(p.x_lift);
  c.summary["dissipated"] = dissipated;
  c.summary["dissipated_exact"] = dissipated_exact;
  c.summary["abs_err_dissipated"] = std::abs(dissipated - dissipated_exact);
  if (setup.problem == PointContactProblem::kPeg) c.summary["t_end_at_peg_exact"] = t_end;
  return c;
}

}  // namespace

EdgeComparison compare_edge_with_exact(const EdgeCaseSetup& setup) {
  CHAINSIM_VERIFY(setup.problem == PointContactProblem::kEdge, "compare_edge_with_exact needs problem = edge");
  setup.validate();
  const double ell = setup.chain.length, lambda = setup.chain.density, g = setup.chain.gravity;
  const double f = setup.chain.dissipation, x0 = setup.x0 * ell;
  PointProblem p;
  p.name = "edge";
  p.tension_minus_column = "tension_edge";
  p.vertices.resize(2, 3);
  p.vertices << -(ell - x0), 0.0, 0.0, 0.0, 0.0, -x0;
  p.time = [=](double x) { return exact::edge_time(f, x, x0, ell, g); };
  p.x_at = [=](double t) { return exact::edge_x(f, t, x0, ell, g); };
  p.state = [=](double x) {
    // τ⁻ = λ (ℓ − x) ẍ pulls the table part, τ⁺ = τ⁻ + f λ ẋ²; F0 = (τ⁻ − λ ẋ²) e_x + (τ⁺ − λ ẋ²) e_y.
    const double u = exact::edge_speed_squared(f, x, x0, ell, g);
    ExactState e;
    e.x_dot = std::sqrt(u);
    e.tension_minus = lambda * (ell - x) * exact::edge_acceleration(f, x, x0, ell, g);
    e.tension_plus = e.tension_minus + f * lambda * u;
    e.reaction = Vec<2>(e.tension_minus - lambda * u, e.tension_plus - lambda * u);
    return e;
  };
  p.x_lift = exact::edge_lift_off_x(f, x0, ell, g);
  p.tensions = [=](const Vec<2>& reaction, double v) {
    return std::make_pair(reaction.x() + lambda * v * v, reaction.y() + lambda * v * v);
  };
  // d/dt (½ λ ℓ ẋ² − ½ λ g x²) = −D.
  p.dissipated = [=](double x) {
    return 0.5 * lambda * g * (x * x - x0 * x0) - 0.5 * lambda * ell * exact::edge_speed_squared(f, x, x0, ell, g);
  };
  return compare_over_point(setup, p);
}

PegComparison compare_peg_with_exact(const PegCaseSetup& setup) {
  CHAINSIM_VERIFY(setup.problem == PointContactProblem::kPeg, "compare_peg_with_exact needs problem = peg");
  setup.validate();
  const double ell = setup.chain.length, lambda = setup.chain.density, g = setup.chain.gravity;
  const double f = setup.chain.dissipation, x0 = setup.x0 * ell;
  PointProblem p;
  p.name = "peg";
  p.tension_minus_column = "tension_minus";
  // Up the shorter side to the peg at the origin, then down the longer side.
  p.vertices.resize(2, 3);
  p.vertices << 0.0, 0.0, 0.0, -(ell - x0), 0.0, -x0;
  p.time = [=](double x) { return exact::peg_time(f, x, x0, ell, g); };
  p.x_at = [=](double t) { return exact::peg_x(f, t, x0, ell, g); };
  p.state = [=](double x) {
    // τ⁻ = λ (ℓ − x)(g + ẍ) pulls the rising side, τ⁺ = τ⁻ + 2 f λ ẋ²; F0 = (τ⁻ + τ⁺ − 2 λ ẋ²) e_y.
    const double u = exact::peg_speed_squared(f, x, x0, ell, g);
    ExactState e;
    e.x_dot = std::sqrt(u);
    e.tension_minus = lambda * (ell - x) * (g + exact::peg_acceleration(f, x, x0, ell, g));
    e.tension_plus = e.tension_minus + 2 * f * lambda * u;
    e.reaction = Vec<2>(0.0, e.tension_minus + e.tension_plus - 2 * lambda * u);
    return e;
  };
  p.x_lift = exact::peg_lift_off_x(f, x0, ell, g);
  // F0 · e_y = τ⁻ + τ⁺ − 2 λ v² and the jump τ⁺ − τ⁻ = 2 f λ v² that the edge front applies.
  p.tensions = [=](const Vec<2>& reaction, double v) {
    const double minus = 0.5 * (reaction.y() + 2 * (1 - f) * lambda * v * v);
    return std::make_pair(minus, minus + 2 * f * lambda * v * v);
  };
  // d/dt (½ λ ℓ ẋ² − λ g (x² − ℓ x)) = −D.
  p.dissipated = [=](double x) {
    return lambda * g * ((x * x - ell * x) - (x0 * x0 - ell * x0)) -
           0.5 * lambda * ell * exact::peg_speed_squared(f, x, x0, ell, g);
  };
  return compare_over_point(setup, p);
}

}  // namespace chainsim
