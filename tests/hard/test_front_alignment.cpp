// Fronts on any mesh (issue #21): the three canonical problems on every node count from the smallest
// the setup accepts (4) to 40, each from several starts η0 — the paper's, 0.25, 0.5 and two that put
// the front exactly on a node and exactly h/2 past one — against the reduced ODE, with the bounds of
// the canonical tests (test_front_tracking.cpp). A front at exactly h/2 used to sit on its heap's
// removal threshold; ARKODE ignores a root function that is zero where the integration starts, so
// the front ran past the threshold unseen and the run stalled ("time integration stalled at
// t = 0.1419 s", the falling chain from η0 = 0.5 on 4, 6 and 10 nodes).
#include <cmath>
#include <string>
#include <vector>

#include <catch2/catch.hpp>

#include "cases/canonical/canonical_string.hpp"
#include "../convergence/canonical_test_support.hpp"

using namespace chainsim;
using test::setup_for;

namespace {

/// The starts tried on a mesh of `nodes` nodes: the problem's own range, with a front on a node and
/// one exactly h/2 past a node, both near the middle of the string.
std::vector<double> starts(Problem problem, int nodes) {
  const int links = nodes - 1;
  const double h = 1.0 / links;
  const int k = links / 2;
  std::vector<double> eta0 = {problem == Problem::kFalling ? 1.0 : 0.0, 0.25, 0.5, k * h, (k + 0.5) * h};
  return eta0;
}

}  // namespace

TEST_CASE("fronts cross on every mesh from 4 to 40 nodes, from starts on a node and at h/2", "[hard][shocks][convergence]") {
  // The erk5 runs of `chainsim compare` at rtol 1e-9 (the canonical default). Measured: 555 runs in
  // 13 s (Release, 2 cores), all stopped at the cutoff or the empty heap; rel_err_t_stop <= 2.1e-11,
  // max_abs_err_eta <= 8.5e-9, max_rel_err_P <= 3.7e-6, energy <= 1.7e-9, momentum <= 1.0e-9.
  double worst_t = 0, worst_eta = 0, worst_P = 0, worst_E = 0, worst_p = 0;
  int runs = 0;
  for (Problem problem : {Problem::kFalling, Problem::kFolded, Problem::kSliding})
    for (int nodes = 4; nodes <= 40; ++nodes)
      for (double eta0 : starts(problem, nodes)) {
        StringCaseSetup setup = setup_for(problem, 0.5, nodes);
        setup.eta0 = eta0;
        INFO(to_string(problem) << " nodes = " << nodes << " eta0 = " << eta0);
        const Comparison c = compare_with_reduced(setup);
        const auto& s = c.summary;
        REQUIRE(s["status"] == "stopped");
        CHECK(c.string.run.error.empty());
        CHECK(s["rel_err_t_stop"].get<double>() < 1e-7);
        CHECK(s["max_abs_err_eta"].get<double>() < 1e-7);
        CHECK(s["max_rel_err_P"].get<double>() < 1e-5);
        CHECK(s["energy_residual"].get<double>() < 1e-7);
        CHECK(s["momentum_residual"].get<double>() < 1e-7);
        for (const StepSample& sample : c.string.run.samples)
          REQUIRE(sample.moving_mass + sample.terms["heap_mass"] == Approx(1.0).epsilon(1e-12));
        worst_t = std::max(worst_t, s["rel_err_t_stop"].get<double>());
        worst_eta = std::max(worst_eta, s["max_abs_err_eta"].get<double>());
        worst_P = std::max(worst_P, s["max_rel_err_P"].get<double>());
        worst_E = std::max(worst_E, s["energy_residual"].get<double>());
        worst_p = std::max(worst_p, s["momentum_residual"].get<double>());
        ++runs;
      }
  std::printf("%d runs: rel_err_t_stop %.2e, err_eta %.2e, rel_err_P %.2e, energy %.2e, momentum %.2e\n", runs, worst_t,
              worst_eta, worst_P, worst_E, worst_p);
}

TEST_CASE("chainsim compare falling --eta0 0.5 on 4, 6 and 10 nodes agrees with the reduced ODE", "[hard][shocks]") {
  // The reproducers: the front starts exactly h/2 past node (links − 1)/2.
  for (int nodes : {4, 6, 10}) {
    StringCaseSetup setup = setup_for(Problem::kFalling, 0.5, nodes);
    setup.eta0 = 0.5;
    INFO("nodes = " << nodes);
    const Comparison c = compare_with_reduced(setup);
    REQUIRE(c.summary["status"] == "stopped");
    CHECK(c.summary["rel_err_t_stop"].get<double>() < 1e-7);
    CHECK(c.summary["max_abs_err_eta"].get<double>() < 1e-7);
  }
}
