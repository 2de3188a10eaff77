// Unilateral links ([solver] slack = "allow") on strings over an edge or a peg ([[effects.edge]]; docs/model.md
// §9 "Slack over an edge"), each against a reference the slack machinery does not make:
//  - the chain sliding off a table over its edge never goes slack: with allow it follows the exact solution
//    (x0 cosh for f = 0, exact::edge_* for f > 0) and lifts off at the exact x* as without allow;
//  - a chain sliding off a table whose far part lies bunched (slack) on the table: the taut part picks it
//    up link by link over the edge (snaps whose impulses pass over the edge) until the chain lifts off;
//    the energy ledger (W_snap, W_links, the edge's W_shocks) and the momentum ledger (the table's and the
//    edge's forces and impulses) close;
//  - the same on a coarse mesh (5 nodes, 4 links): it finishes or stops with a located reason, never NaN;
//  - a link laid slack over a peg: the string does not press on the peg, and the run stops at once with the
//    lift-off event (on 4 and 40 links, 2D and 3D).
//  - the heavy Atwood chain over a peg whose rising end lies bunched (2D and 3D): snaps over the peg, ledgers;
//  - a snap that leaves the peg needing to pull stops the run at the snap (measured without the checks after a
//    snap: the run went on with the peg pulling until the string's end reached it, t = 0.1217 s).
#include <catch2/catch.hpp>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <memory>
#include <string>
#include <vector>

#include <fmt/format.h>

#include "cases/reduced/exact_solutions.hpp"
#include "cases/scene/scene.hpp"
#include "shocks/edge_front.hpp"
#include "shocks/front_tracker.hpp"
#include "solver/forces.hpp"
#include "solver/string_solver.hpp"

using namespace chainsim;

namespace {

constexpr double kG = 9.81;

template <int dim>
double term(const RunRecord& record, const std::string& name) {
  if (!record.terms.names) return 0.0;
  for (std::size_t k = 0; k < record.terms.names->size(); ++k)
    if ((*record.terms.names)[k].name == name) return record.terms.values[k];
  return 0.0;
}

/// The chain of cases/scenes/chain_off_table_edge.toml (1 m, 1 kg/m, x0 = 0.2 m hanging over the edge at the
/// origin, the rest on the table), `links` links, the kink's f, slack policy `slack`.
std::string table_scene(int links, double f, const std::string& slack) {
  return fmt::format(R"([string]
length = 1.0
density = 1.0
nodes = {}
[shape]
kind = "polyline"
points = [[-0.8, 0.0], [0.0, 0.0], [0.0, -0.2]]
[effects.gravity]
g = [0.0, -9.81]
[[effects.edge]]
point = [0.0, 0.0]
f = {}
table = "before"
[solver]
method = "erk5"
rtol = 1e-11
atol = 1e-13
slack = "{}"
[output]
interval = 0.05
[stop]
t_end = 2.0
)",
                     links + 1, f, slack);
}

struct EdgeRun {
  RunSummary summary;
  std::vector<Frame<2>> frames;
};

EdgeRun run_scene_text(const std::string& text) {
  StringScene<2> scene = build_string_scene<2>(parse_scene_text(text, "edge.toml"));
  StringSolver<2> solver(*scene.model, scene.solver);
  EdgeRun run;
  run.summary = solver.run();
  run.frames = solver.frames();
  return run;
}

}  // namespace

TEST_CASE("slack over an edge: the chain off a table stays taut with allow and meets the exact solution as without",
          "[slack][edge]") {
  const double x0 = 0.2, ell = 1.0;
  for (const int links : {4, 20, 81}) {
    for (const double f : {0.0, 0.5}) {
      const EdgeRun stop = run_scene_text(table_scene(links, f, "stop"));
      const EdgeRun allow = run_scene_text(table_scene(links, f, "allow"));
      INFO(links << " links, f = " << f << ": " << allow.summary.stop_reason);
      REQUIRE(allow.summary.status == "stopped");
      REQUIRE(allow.summary.events.size() == 1);
      CHECK(allow.summary.events[0].kind == "lift_off");
      REQUIRE(stop.summary.events.size() == 1);
      // The lift-off: the exact x* and its time, the same as without allow.
      const double x_star = exact::edge_lift_off_x(f, x0, ell, kG);
      const double t_star = exact::edge_time(f, x_star, x0, ell, kG);
      const double t_lift = allow.summary.events[0].t;
      CHECK(std::abs(t_lift - t_star) < 1e-6);
      CHECK(std::abs(t_lift - stop.summary.events[0].t) < 1e-9);
      CHECK(std::abs((ell - allow.frames.back().fronts[0].s0) - x_star) < 1e-6);
      // x(t) at every frame against the exact solution, and against the run without allow.
      REQUIRE(allow.frames.size() == stop.frames.size());
      double x_error = 0, difference = 0;
      for (std::size_t k = 0; k < allow.frames.size(); ++k) {
        const double x = ell - allow.frames[k].fronts[0].s0;
        x_error = std::max(x_error, std::abs(x - exact::edge_x(f, allow.frames[k].t, x0, ell, kG)));
        difference = std::max(difference, (allow.frames[k].x - stop.frames[k].x).cwiseAbs().maxCoeff());
      }
      std::printf("\ntable with allow, %d links, f = %g: |x - exact| %.2e m, |allow - stop| %.2e m, t* error %.2e s, "
                  "snaps %g, energy %.2e\n",
                  links, f, x_error, difference, std::abs(t_lift - t_star), term<2>(allow.frames.back(), "snaps"),
                  allow.summary.relative_energy_drift());
      CHECK(x_error < 1e-7);
      CHECK(difference < 1e-7);
      CHECK(term<2>(allow.frames.back(), "snaps") == 0.0);  // it never went slack
      CHECK(term<2>(allow.frames.back(), "W_snap") == 0.0);
      CHECK(allow.summary.relative_energy_drift() < 1e-9);
      CHECK(allow.summary.relative_momentum_residual() < 1e-9);
    }
  }
}

namespace {

/// A chain of `links` links (1 kg/m, h = 1/links) over a peg at the origin, both sides hanging straight down
/// on the vertical through it, the bent link `a` laid slack: node a at d⁻ below the peg, node a + 1 at d⁺,
/// d⁻ + d⁺ = h − δ (δ = 0: taut over the peg). The − side (nodes 0..a) hangs from node a down, the + side
/// from node a + 1 down; the − side's first `bunched` links lie bunched on its line (their nodes 0.5 h apart,
/// slack).
template <int dim>
StringModel<dim> slack_peg(int links, int a, double d_minus, double d_plus, double f, int bunched = 0) {
  const double ell = 1.0, h = ell / links;
  Chain<dim> chain = Chain<dim>::uniform(1.0, ell, links, false);
  for (int i = 0; i <= links; ++i) {
    chain.positions().col(i).setZero();
    chain.positions()(1, i) = i <= a ? -d_minus - (a - std::max(i, bunched)) * h - 0.5 * std::max(bunched - i, 0) * h
                                     : -d_plus - (i - a - 1) * h;
  }
  Vec<dim> down = Vec<dim>::Zero();
  down[1] = -kG;
  std::vector<std::unique_ptr<Force<dim>>> forces;
  forces.push_back(std::make_unique<Gravity<dim>>(down));
  EdgeSpec<dim> peg;
  peg.dissipation = f;
  peg.s0 = a * h + d_minus;  // the shape passes the peg there
  if constexpr (dim == 3) peg.axis = Vec<dim>(0, 0, 1);
  std::vector<std::unique_ptr<FrontKind<dim>>> fronts;
  fronts.push_back(std::make_unique<EdgeFront<dim>>(peg));
  StringModelOptions mo;
  mo.slack = SlackPolicy::kAllow;
  mo.stabilization_time = 0.009;
  StringModel<dim> model =
      make_front_model<dim>(std::move(chain), std::move(forces), {}, std::move(fronts), FrontOptions{}, mo);
  if (d_minus + d_plus < (1 - 1e-6) * h) model.set_slack(a, true);
  for (int j = 0; j < bunched; ++j) model.set_slack(j, true);
  return model;
}

}  // namespace

TEMPLATE_TEST_CASE_SIG("slack over an edge: a link laid slack over a peg stops the run at the start as a lift-off",
                       "[slack][edge][hard]", ((int dim), dim), 2, 3) {
  // A slack bent link does not press on the edge: the string has left it, which the point contact does not
  // follow (docs/model.md §9 "Slack over an edge"): the run stops at once, with the lift-off event, on every
  // mesh down to 4 links.
  for (const int links : {4, 40}) {
    const double h = 1.0 / links;
    StringModel<dim> model = slack_peg<dim>(links, links / 2 - 1, 0.2 * h, 0.4 * h, 0.5);
    StringSolverOptions so;
    so.t_end = 1.0;
    so.output_interval = 0.01;
    StringSolver<dim> solver(model, so);
    const RunSummary s = solver.run();
    INFO(links << " links: " << s.stop_reason << " " << s.error);
    REQUIRE(s.status == "stopped");
    CHECK(s.t_stop == 0.0);
    REQUIRE(s.events.size() == 1);
    CHECK(s.events[0].kind == "lift_off");
    CHECK_THAT(s.stop_reason, Catch::Matchers::Contains("has gone slack"));
  }
}

TEMPLATE_TEST_CASE_SIG("slack over an edge: a heavy Atwood chain whose rising side's end lies bunched snaps it taut "
                       "over a peg and closes its ledgers",
                       "[slack][edge]", ((int dim), dim), 2, 3) {
  // 40 links over a peg (f = 0.5): the − side 15 links plus 0.3 h of the bent link, its lowest 6 links bunched
  // (slack, nodes 0.5 h apart); the + side the rest. The longer side falls and pulls the − side up over the
  // peg; the bunched end, falling freely, is picked up link by link (snaps whose impulses pass over the peg,
  // the peg taking P (e⁻ − e⁺)), until the chain lifts off the peg or its end reaches it.
  const int links = 40;
  const double h = 1.0 / links;
  StringModel<dim> model = slack_peg<dim>(links, 15, 0.3 * h, 0.7 * h, 0.5, 6);
  StringSolverOptions so;
  so.integrator.rtol = 1e-10;
  so.integrator.atol = 1e-12;
  so.t_end = 1.0;
  so.output_interval = 0.01;
  StringSolver<dim> solver(model, so);
  const RunSummary s = solver.run();
  const Frame<dim>& last = solver.frames().back();
  std::printf("\nbunched Atwood over a peg (%dD): %s at t = %.6g s (%s), snaps %g, W_snap %.4e J, W_shocks %.4e J, "
              "W_links %.2e J, crossings %ld, energy %.2e, momentum %.2e\n",
              dim, s.status.c_str(), s.t_stop, s.stop_reason.c_str(), term<dim>(last, "snaps"), term<dim>(last, "W_snap"),
              term<dim>(last, "W_shocks"), term<dim>(last, "W_links"), s.transfers, s.relative_energy_drift(),
              s.relative_momentum_residual());
  INFO(s.stop_reason << " " << s.error);
  REQUIRE(s.status == "stopped");
  CHECK(term<dim>(last, "snaps") >= 3);
  CHECK(term<dim>(last, "W_snap") < 0);
  CHECK(term<dim>(last, "W_shocks") < 0);
  CHECK(s.transfers > 0);
  CHECK(s.relative_energy_drift() < 1e-9);
  CHECK(s.relative_momentum_residual() < 1e-9);
}

TEST_CASE("slack over an edge: a snap that leaves the peg unable to push stops the run at the snap as a lift-off",
          "[slack][edge][hard]") {
  // 40 links nearly balanced over a peg (0.48 and 0.52 m of material on its sides, at rest), the − side's
  // lowest 6 links bunched and thrown down at 30 m/s: their snaps yank the chain over the peg, whose
  // margin, (τ − λ ṡ0²)(1 − cos θ), a snap makes negative (0.15 kg at 30 m/s gives the 1 kg chain up to
  // 4.5 m/s, against √(τ/λ) ≈ 2.2 m/s): ARKODE restarts after the snap and would not see that sign change,
  // so the checks after a snap stop the run there, located at the snap, with the lift-off event.
  const int links = 40;
  const double h = 1.0 / links;
  StringModel<2> model = slack_peg<2>(links, 19, 0.3 * h, 0.7 * h, 0.0, 6);
  for (int i = 0; i <= 5; ++i) model.chain().velocities().col(i) = Vec<2>(0.0, -30.0);
  StringSolverOptions so;
  so.integrator.rtol = 1e-10;
  so.integrator.atol = 1e-12;
  so.t_end = 0.5;
  so.output_interval = 0.01;
  StringSolver<2> solver(model, so);
  const RunSummary s = solver.run();
  std::printf("\nthrown end over a peg: %s at t = %.6g s (%s), snaps %g, energy %.2e, momentum %.2e\n", s.status.c_str(),
              s.t_stop, s.stop_reason.c_str(), term<2>(solver.frames().back(), "snaps"), s.relative_energy_drift(),
              s.relative_momentum_residual());
  INFO(s.stop_reason << " " << s.error);
  REQUIRE(s.status == "stopped");
  REQUIRE(s.events.size() == 1);
  CHECK(s.events[0].kind == "lift_off");
  CHECK_THAT(s.stop_reason, Catch::Matchers::StartsWith("at the snap taut at t = "));
  CHECK(s.relative_energy_drift() < 1e-9);
  CHECK(s.relative_momentum_residual() < 1e-9);
}

namespace {

/// 1 m of chain (1 kg/m, `links` links) on a table (y = 0) over its edge at the origin, s0 of it before the
/// edge, the rest hanging straight down; the table part's first `bunched` links lie bunched on the table
/// (their nodes 0.5 h apart, slack), the rest straight. The kink's f.
StringModel<2> bunched_table(int links, int bunched, double s0, double f) {
  const double h = 1.0 / links;
  Chain<2> chain = Chain<2>::uniform(1.0, 1.0, links, false);
  for (int i = 0; i <= links; ++i) {
    const double s = i * h;
    if (i < bunched)
      chain.positions().col(i) = Vec<2>(bunched * h - s0 - 0.5 * (bunched - i) * h, 0.0);
    else if (s <= s0)
      chain.positions().col(i) = Vec<2>(s - s0, 0.0);
    else
      chain.positions().col(i) = Vec<2>(0.0, -(s - s0));
  }
  std::vector<std::unique_ptr<Force<2>>> forces;
  forces.push_back(std::make_unique<Gravity<2>>(Vec<2>(0.0, -kG)));
  EdgeSpec<2> edge;
  edge.dissipation = f;
  edge.s0 = s0;
  edge.table = EdgeSpec<2>::Table::kBefore;
  std::vector<std::unique_ptr<FrontKind<2>>> fronts;
  fronts.push_back(std::make_unique<EdgeFront<2>>(edge));
  StringModelOptions mo;
  mo.slack = SlackPolicy::kAllow;
  mo.stabilization_time = 0.009;
  StringModel<2> model = make_front_model<2>(std::move(chain), std::move(forces), {}, std::move(fronts), FrontOptions{}, mo);
  for (int j = 0; j < bunched; ++j) model.set_slack(j, true);
  return model;
}

RunSummary run_model(StringModel<2>& model, double t_end, std::vector<Frame<2>>* frames = nullptr) {
  StringSolverOptions so;
  so.integrator.rtol = 1e-10;
  so.integrator.atol = 1e-12;
  so.t_end = t_end;
  so.output_interval = 0.01;
  StringSolver<2> solver(model, so);
  RunSummary s = solver.run();
  if (frames) *frames = solver.frames();
  return s;
}

}  // namespace

TEST_CASE("slack over an edge: a bunched chain picked up over a table's edge closes its energy and momentum ledgers",
          "[slack][edge]") {
  // 50 links, 0.29 m hanging, the table part's far 15 links bunched: the taut part slides towards the edge
  // and picks the bunched links up one snap at a time; each snap's impulse passes over the edge (the bent
  // link's impulsive tension, the edge's impulse booked with the momentum); the edge's kink dissipates
  // (f = 0.5, W_shocks). The run ends where the chain lifts off the edge.
  StringModel<2> model = bunched_table(50, 15, 0.71, 0.5);
  std::vector<Frame<2>> frames;
  const RunSummary s = run_model(model, 1.5, &frames);
  const Frame<2>& last = frames.back();
  std::printf("\nbunched table: %s at t = %.6g s (%s), snaps %g, W_snap %.4e J, W_shocks %.4e J, W_links %.2e J, "
              "crossings %ld, energy %.2e, momentum %.2e\n",
              s.status.c_str(), s.t_stop, s.stop_reason.c_str(), term<2>(last, "snaps"), term<2>(last, "W_snap"),
              term<2>(last, "W_shocks"), term<2>(last, "W_links"), s.transfers, s.relative_energy_drift(),
              s.relative_momentum_residual());
  INFO(s.stop_reason << " " << s.error);
  REQUIRE(s.status == "stopped");
  REQUIRE(s.events.size() == 1);
  CHECK(s.events[0].kind == "lift_off");
  CHECK(term<2>(last, "snaps") >= 5);
  CHECK(term<2>(last, "W_snap") < 0);
  CHECK(term<2>(last, "W_shocks") < 0);
  CHECK(s.transfers > 0);  // nodes crossed the edge
  CHECK(s.relative_energy_drift() < 1e-9);
  CHECK(s.relative_momentum_residual() < 1e-9);
}

TEST_CASE("slack over an edge: a coarse bunched chain (5 nodes) over a table's edge finishes or stops located",
          "[slack][edge][hard]") {
  StringModel<2> model = bunched_table(4, 1, 0.6, 0.0);
  std::vector<Frame<2>> frames;
  const RunSummary s = run_model(model, 2.0, &frames);
  std::printf("\nbunched table, 4 links: %s at t = %.6g s (%s), snaps %g, energy %.2e, momentum %.2e\n",
              s.status.c_str(), s.t_stop, s.stop_reason.c_str(), term<2>(frames.back(), "snaps"),
              s.relative_energy_drift(), s.relative_momentum_residual());
  INFO(s.stop_reason << " " << s.error);
  REQUIRE((s.status == "stopped" || s.status == "completed"));
  if (s.status == "stopped") CHECK(!s.stop_reason.empty());
  for (const Frame<2>& frame : frames) REQUIRE(frame.x.allFinite());
  CHECK(s.relative_energy_drift() < 1e-8);
  CHECK(s.relative_momentum_residual() < 1e-8);
}
