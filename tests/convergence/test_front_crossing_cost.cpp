// The cost of a front crossing (docs/shocks.md, "The cost of a crossing"), counted, not timed: each
// crossing is a located root, polished, and the integrator resumes with the step it would have taken
// next (no fresh first step and no ramp). A crossing then costs a bounded number of right-hand sides,
// the same on every mesh: the right-hand sides per crossing of the three canonical problems on two
// meshes. (The cost of a run still grows like N²: N crossings, each with O(1) right-hand sides of O(N)
// work; docs/work-precision.md, "Fronts on fine meshes".)
#include <catch2/catch.hpp>

#include <cstdio>

#include <nlohmann/json.hpp>

#include "cases/canonical/canonical_string.hpp"
#include "canonical_test_support.hpp"

using namespace chainsim;
using test::setup_for;

TEST_CASE("a front crossing costs a bounded number of right-hand sides on every mesh", "[convergence][shocks]") {
  for (Problem problem : {Problem::kFalling, Problem::kFolded, Problem::kSliding}) {
    const int meshes[2] = {100, 400};
    double per_crossing[2] = {0, 0};
    for (int m = 0; m < 2; ++m) {
      StringCaseSetup setup = setup_for(problem, 0.83, meshes[m]);
      setup.eps = 0.5;  // half of each run (the sliding chain: from the start to half the chain out)
      const Comparison c = compare_with_reduced(setup);
      const auto& s = c.summary;
      const double crossings = s["transfers"].get<double>();
      const double rhs = s["rhs_evals"].get<double>(), steps = s["steps"].get<double>();
      per_crossing[m] = rhs / crossings;
      std::printf("%-8s %4d nodes: %4.0f crossings, %5.0f steps, %6.0f right-hand sides: %4.2f steps and %5.2f "
                  "right-hand sides per crossing\n",
                  to_string(problem).c_str(), meshes[m], crossings, steps, rhs, steps / crossings, rhs / crossings);
      INFO(to_string(problem) << ", " << meshes[m] << " nodes");
      REQUIRE(s["status"] == "stopped");
      CHECK(crossings >= 0.48 * meshes[m]);
      // Measured 30-49 (erk5, rtol 1e-9) before the crossings were predicted (the falling chain's now
      // 11-21): the step that finds the root, the polish's step and corrections, the steps to the next
      // crossing. Resuming each crossing from ARKODE's estimate of a first step and its ramp took more
      // than twice as many.
      CHECK(rhs / crossings <= 60);
    }
    // Not more on the finer mesh: a crossing's cost does not grow with N.
    CHECK(per_crossing[1] <= 1.1 * per_crossing[0]);
  }
}

// The crossing predicted (integrator.hpp, OdeSystem::num_recurring_events): the step ends just past the
// next crossing instead of overstepping it, locating its root on the interpolant and recomputing the
// step. Falling compare (rtol 1e-9, erk5): 35.7 and 31.6 right-hand sides per crossing on 200 and 800
// nodes before; 19.5 and 9.9 with the prediction (about one step per crossing on 800 nodes, where the
// crossings set the step; docs/shocks.md "On fine meshes").
TEST_CASE("the falling chain's crossings are predicted, not overstepped", "[convergence][shocks]") {
  for (const int nodes : {200, 800}) {
    const Comparison c = compare_with_reduced(setup_for(Problem::kFalling, 0.83, nodes));
    const auto& s = c.summary;
    INFO(nodes << " nodes");
    REQUIRE(s["status"] == "stopped");
    const double per_crossing = s["rhs_evals"].get<double>() / s["transfers"].get<double>();
    std::printf("falling %4d nodes: %5.2f right-hand sides per crossing\n", nodes, per_crossing);
    CHECK(per_crossing <= (nodes == 200 ? 24 : 14));
    CHECK(s["rel_err_t_stop"].get<double>() <= 1e-11);
  }
}

// A canonical compare whose crossings are predicted: about one step per crossing on the finer mesh, at most
// `bound_200` and `bound_800` right-hand sides per crossing on 200 and 800 nodes, the errors at the integrator's
// tolerance. And on 800 nodes at most 16 evaluations of the model in all per crossing (`tension_solves`: ARKODE's,
// the polish's, the crossing's projection and record): 13.9 (folded) and 13.4 (sliding) since a predicted step
// ends as ARKODE's first step and the polish's slope is a secant; 16.9 and 16.3 before (docs/work-precision.md,
// "Two evaluations fewer per crossing").
static void check_predicted_crossings(Problem problem, const char* name, double bound_200, double bound_800) {
  for (const int nodes : {200, 800}) {
    const Comparison c = compare_with_reduced(setup_for(problem, 0.83, nodes));
    const auto& s = c.summary;
    INFO(name << ", " << nodes << " nodes");
    REQUIRE(s["status"] == "stopped");
    const double crossings = s["transfers"].get<double>();
    const double per_crossing = s["rhs_evals"].get<double>() / crossings;
    std::printf("%s %4d nodes: %5.2f right-hand sides and %4.2f steps per crossing\n", name, nodes, per_crossing,
                s["steps"].get<double>() / crossings);
    CHECK(per_crossing <= (nodes == 200 ? bound_200 : bound_800));
    if (nodes == 800) CHECK(s["tension_solves"].get<double>() / crossings <= 16);
    CHECK(s["steps"].get<double>() <= 1.2 * crossings + 150);
    CHECK(s["rel_err_t_stop"].get<double>() <= 1e-11);
    CHECK(s["max_abs_err_eta"].get<double>() <= 1e-10);
  }
}

// The folded chain's crossings are predicted too. Its first prediction (from the secant, before any
// event's rate) ran the step past the zero until the fold's check met its root; the prediction was then
// turned off for the whole run, and every crossing was a root located on ARKODE's interpolant and a
// recomputed step: 39.7 and 49.0 right-hand sides per crossing on 200 and 800 nodes (2 - 3.6 steps per
// crossing). Turned off only until the next event: 15.8 and 9.8 (docs/shocks.md "On fine meshes").
TEST_CASE("the folded chain's crossings are predicted after a refused prediction", "[convergence][shocks]") {
  check_predicted_crossings(Problem::kFolded, "folded", 24, 14);
}

// The sliding chain's nodes leave its heap: the heap's second crossing function, predicted too, aimed 1 % past
// its zero from farther than ARKODE's next step (integrator.cpp, predict_recurring_event). Sliding compare (rtol
// 1e-9, erk5): 32.3 and 28.8 right-hand sides per crossing on 200 and 800 nodes with those zeros located on
// ARKODE's interpolant; 15.5 and 10.2 predicted, about one step per crossing on 800 nodes (910 steps, 797
// crossings; docs/shocks.md "A node out of a heap, predicted").
TEST_CASE("the sliding chain's nodes out of the heap are predicted and not overstepped", "[convergence][shocks]") {
  check_predicted_crossings(Problem::kSliding, "sliding", 20, 13);
}
