// The implicit path with fronts (docs/string_solver.md, "The implicit path"): the fronts' masses and
// jump-condition loads are in the Newton systems (FrontKind::add_load_derivatives), so an implicit
// method solves each stage by Newton's method with the string's own solver, as without fronts. Counted,
// not timed: right-hand sides per step of dirk4 on the three canonical compares, and their errors
// against the reduced models.
#include <catch2/catch.hpp>

#include <cstdio>

#include <nlohmann/json.hpp>

#include "cases/canonical/canonical_string.hpp"
#include "canonical_test_support.hpp"

using namespace chainsim;
using test::setup_for;

TEST_CASE("dirk4 on the canonical compares takes a few right-hand sides per step", "[convergence][shocks][implicit]") {
  for (Problem problem : {Problem::kFalling, Problem::kFolded, Problem::kSliding}) {
    StringCaseSetup setup = setup_for(problem, 0.83, 200);
    setup.integrator.method = "dirk4";
    const Comparison c = compare_with_reduced(setup);
    const auto& s = c.summary;
    const double steps = s["steps"].get<double>(), rhs = s["rhs_evals"].get<double>();
    std::printf("%-8s dirk4 200 nodes: %4.0f steps, %6.0f right-hand sides (%5.2f per step), t_stop error %.2e\n",
                to_string(problem).c_str(), steps, rhs, rhs / steps, s["rel_err_t_stop"].get<double>());
    INFO(to_string(problem));
    REQUIRE(s["status"] == "stopped");
    // Measured 17.6-17.9 (rtol 1e-9). Without the fronts' terms in the Newton systems each Newton
    // correction was a GMRES solve with products J·v by difference quotients of the right-hand side:
    // 39.8-40.7 per step, 16,424-26,955 right-hand sides.
    CHECK(rhs / steps <= 24);
    // The stop time against the reduced model's (measured 3.5e-11-3.3e-10; 2.3e-13-3.4e-10 before).
    CHECK(s["rel_err_t_stop"].get<double>() < 1e-9);
  }
}
