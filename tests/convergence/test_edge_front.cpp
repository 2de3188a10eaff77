// An edge front (shocks/edge_front.hpp, docs/model.md §8): the chain sliding off a smooth table over
// a sharp edge against its exact solution (cases/reduced/exact_solutions.hpp: exact::edge_*), the
// heavy Atwood chain over a peg, the energy ledger with the edge's dissipation booked, and the hard cases.
#include <catch2/catch.hpp>

#include <algorithm>
#include <cmath>
#include <memory>
#include <string>
#include <vector>

#include "cases/reduced/exact_solutions.hpp"
#include "mesh/discretize.hpp"
#include "mesh/errors.hpp"
#include "shocks/edge_front.hpp"
#include "shocks/front_tracker.hpp"
#include "solver/string_solver.hpp"

using namespace chainsim;

namespace {

constexpr double kG = 9.81;

struct TableRun {
  RunSummary run;
  double x_error = 0;        ///< max over the steps of |x − exact::edge_x| (m)
  double tension_error = 0;  ///< max over the steps of |τ⁻ − λ (ℓ − x) ẍ| (N), the tension at the edge
  double t_lift = 0;         ///< the lift-off event's time (s)
};

/// A chain of length 1 m and density 1 kg/m of `links` links lying straight on a table (y = 0, x < 0),
/// x0 of it hanging over the edge at the origin, released at rest; edge dissipation f.
TableRun table(int links, double f, double x0, double t_end = 10, const std::string& method = "") {
  const double ell = 1.0, lambda = 1.0;
  Points<2> vertices(2, 3);
  vertices << -(ell - x0), 0.0, 0.0, 0.0, 0.0, -x0;
  Chain<2> chain = discretize<2>(*polyline_curve<2>(vertices), lambda, ell, links, false);
  std::vector<std::unique_ptr<Force<2>>> forces;
  forces.push_back(std::make_unique<Gravity<2>>(Vec<2>(0.0, -kG)));
  EdgeSpec<2> edge;
  edge.point = Vec<2>::Zero();
  edge.dissipation = f;
  edge.s0 = ell - x0;
  edge.table = EdgeSpec<2>::Table::kBefore;
  std::vector<std::unique_ptr<FrontKind<2>>> fronts;
  fronts.push_back(std::make_unique<EdgeFront<2>>(edge));
  StringModel<2> model = make_front_model<2>(std::move(chain), std::move(forces), {}, std::move(fronts), FrontOptions{});
  StringSolverOptions options;
  options.t_end = t_end;
  options.output_interval = t_end;
  options.record_steps = true;
  options.integrator.rtol = 1e-11;
  options.integrator.atol = 1e-13;
  if (!method.empty()) options.integrator.method = method;
  StringSolver<2> solver(model, options);
  TableRun out;
  out.run = solver.run();
  for (const StepSample& s : out.run.samples) {
    const double x = ell - s.s0[0];
    const double x_exact = exact::edge_x(f, s.t, x0, ell, kG);
    out.x_error = std::max(out.x_error, std::abs(x - x_exact));
    const double v = s.s0_dot[0];
    const double tension = s.forces[0] + lambda * v * v;  // F0·e_x = τ⁻ − λ v²
    const double tension_exact = lambda * (ell - x_exact) * exact::edge_acceleration(f, x_exact, x0, ell, kG);
    out.tension_error = std::max(out.tension_error, std::abs(tension - tension_exact));
  }
  if (!out.run.events.empty()) out.t_lift = out.run.events.front().t;
  return out;
}

}  // namespace

TEST_CASE("edge: a chain sliding off a table, first look", "[edge]") {
  for (int links : {10, 20, 40, 80}) {
    const TableRun r = table(links + 1, 0.0, 0.2);
    const double x_star = exact::edge_lift_off_x(0.0, 0.2, 1.0, kG);
    const double t_star = exact::edge_time(0.0, x_star, 0.2, 1.0, kG);
    WARN(links << ": status " << r.run.status << " reason " << r.run.stop_reason << " err " << r.run.error << " x err " << r.x_error << " T err " << r.tension_error
               << " t_lift " << r.t_lift << " exact " << t_star << " energy " << r.run.relative_energy_drift()
               << " transfers " << r.run.transfers);
  }
}
