// A folded chain whose ends are apart (cases/scenes/folded_chain_ends_apart.toml, docs/shocks.md):
// the resting arm hangs 0.3 m from the fixed start, the bight is a half circle of diameter d, the
// free arm stands beside the resting arm with its end 0.377 m above the start; released from rest.
// Its arms are not on one line, so the bight is no dissipative fold: the string solver resolves it.
//
// Measured here, against independent references:
//   - the free end's height converges under refinement (self-convergence, order 2);
//   - the energy is conserved (K + V constant: no shock dissipates);
//   - as d → 0 the motion tends to the paper's folded chain with f = 0 (the exact quadrature
//     folded_eta of the energy-conserving fold), not to the dissipative one: at equal initial
//     heights the free end's height at t = 0.4 s differs from the f = 0 law by O(d^1.7) and from the
//     f = 0.5 law by ~80 times more.
#include <catch2/catch.hpp>

#include <cmath>
#include <map>
#include <utility>
#include <string>
#include <vector>

#include <fmt/format.h>

#include "cases/reduced/exact_solutions.hpp"
#include "cases/scene/scene.hpp"
#include "solver/string_solver.hpp"

using namespace chainsim;

namespace {

constexpr double kTop = 0.377, kRest = 0.3, kG = 9.81;

struct Run {
  double length = 0;
  std::vector<double> t, end_height;  // at the output times 0, 0.1, …, 0.4 s
  double relative_drift = 0;
};

/// Runs the U (each (d, nodes) once per test binary: both test cases use d = 0.04 m with 321 nodes).
Run run_u(double d, int nodes) {
  static std::map<std::pair<double, int>, Run> done;
  const auto key = std::make_pair(d, nodes);
  if (const auto it = done.find(key); it != done.end()) return it->second;
  const std::string text = fmt::format(R"([string]
density = 1.0
nodes = {}
[shape]
kind = "polyline"
points = [[0.0, 0.0], [0.0, -{}], [{}, -{}], [{}, {}]]
corner_radius = {}
[ends]
start = "fixed"
[effects.gravity]
g = [0.0, -{}]
[solver]
method = "erk5"
rtol = 1e-10
atol = 1e-12
[output]
interval = 0.1
[stop]
t_end = 0.4
)",
                                       nodes, kRest, d, kRest, d, kTop, d / 2, kG);
  StringScene<2> scene = build_string_scene<2>(parse_scene_text(text, "u.toml"));
  StringSolver<2> solver(*scene.model, scene.solver);
  const RunSummary& summary = solver.run();
  Run run;
  run.length = scene.model->chain().length();
  for (const Frame<2>& frame : solver.frames()) {
    run.t.push_back(frame.t);
    run.end_height.push_back(frame.x(1, frame.x.cols() - 1));
  }
  run.relative_drift = summary.relative_energy_drift();
  return done[key] = run;
}

/// The free end's height in the paper's folded chain of the same length and the same initial height
/// of the free end (ℓ − 2 y0 = kTop), from the exact quadrature: ℓ − 2 y(t).
double tight_fold_end_height(double f, double length, double t) {
  const double eta0 = (length - kTop) / (2 * length);
  const double t0 = std::sqrt(2 * length / kG);
  return length - 2 * length * exact::folded_eta(f, t / t0, eta0);
}

}  // namespace

TEST_CASE("a folded chain with its ends apart: the resolved bight converges at order 2 and keeps its energy",
          "[convergence][shocks]") {
  const double d = 0.04;
  const std::vector<int> nodes = {81, 161, 321};
  std::vector<Run> runs;
  for (const int n : nodes) runs.push_back(run_u(d, n));
  // The rounded U's length by its closed form: 0.977 + d (π/2 − 1).
  CHECK(runs[0].length == Approx(kRest + kRest + kTop + d * (kPi / 2 - 1)).epsilon(1e-12));
  for (const Run& r : runs) CHECK(r.relative_drift < 1e-8);
  fmt::print("\nfolded chain, ends {} m apart: free end height (m)\n  t (s)   N = 81      N = 161     N = 321     order\n", d);
  for (std::size_t k = 1; k < runs[0].t.size(); ++k) {
    const double e1 = runs[0].end_height[k] - runs[1].end_height[k];
    const double e2 = runs[1].end_height[k] - runs[2].end_height[k];
    const double order = std::log2(std::abs(e1 / e2));
    fmt::print("  {:.1f}    {:.7f}  {:.7f}  {:.7f}  {:.2f}\n", runs[0].t[k], runs[0].end_height[k], runs[1].end_height[k],
               runs[2].end_height[k], order);
    {
      CAPTURE(runs[0].t[k], e1, e2);
      CHECK(order > 1.7);
      CHECK(order < 2.3);
    }
  }
}

TEST_CASE("a folded chain with its ends apart tends to the energy-conserving fold (f = 0) as the ends close",
          "[convergence][shocks]") {
  // d halves with h (N − 1 doubles), so h/d is fixed and the mesh resolves each bight alike.
  struct Case {
    double d;
    int nodes;
  };
  const std::vector<Case> cases = {{0.16, 81}, {0.08, 161}, {0.04, 321}};
  const double t = 0.4;
  std::vector<double> dev0, dev_half;
  fmt::print("\nfolded chain with ends d apart, free end height at t = {} s against the paper's fold\n"
             "  d (m)   N     string (m)   f = 0 (m)    f = 0.5 (m)  |string - f=0|\n",
             t);
  for (const Case& c : cases) {
    const Run r = run_u(c.d, c.nodes);
    REQUIRE(r.t.back() == Approx(t));
    const double y = r.end_height.back();
    const double y0 = tight_fold_end_height(0.0, r.length, t), y_half = tight_fold_end_height(0.5, r.length, t);
    dev0.push_back(std::abs(y - y0));
    dev_half.push_back(std::abs(y - y_half));
    fmt::print("  {:.2f}   {:<4}  {:.6f}    {:.6f}    {:.6f}    {:.2e}\n", c.d, c.nodes, y, y0, y_half, dev0.back());
  }
  for (std::size_t k = 1; k < cases.size(); ++k) {
    const double order = std::log2(dev0[k - 1] / dev0[k]);
    CAPTURE(k, dev0[k - 1], dev0[k], order);
    CHECK(order > 1.4);  // measured 1.65 and 1.87
  }
  CHECK(dev0.back() < 1.5e-3);            // 0.9 mm at d = 0.04 m
  CHECK(dev_half.back() > 40 * dev0.back());  // the dissipative law is ~80 times further away
}
