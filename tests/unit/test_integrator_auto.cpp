// solver/integrator.hpp: what method = "auto" picks, from the string's stiffness (links of a uniform
// chain) and its root functions (docs/string_solver.md, "The implicit path").
#include <catch2/catch.hpp>

#include "solver/integrator.hpp"
#include "tests/problems/string_test_support.hpp"

using namespace chainsim;
using namespace chainsim::testing;

TEST_CASE("method = auto: implicit from 50 links on, explicit below", "[unit][integrator][implicit]") {
  auto tilted = [](double sigma) { return 1e-3 * sigma; };  // off equilibrium, so Newton has work
  auto coarse = hanging_chain(49, 1.0, tilted, 0.03);
  auto fine = hanging_chain(50, 1.0, tilted, 0.03);
  // ℓ / h_min is the number of links of a uniform chain.
  CHECK(coarse->explicit_stiffness() == Approx(49));
  CHECK(fine->explicit_stiffness() == Approx(50));
  CHECK(Integrator::resolve_method("auto", *coarse) == kAutoExplicit);
  CHECK(Integrator::resolve_method("auto", *fine) == kAutoImplicit);
  CHECK(Integrator::resolve_method("erk4", *fine) == "erk4");  // any other name is kept
  IntegratorOptions options;
  options.method = "auto";
  options.validate();
  Integrator integrator(*fine, 0.0, fine->state_from_chain(), options);
  integrator.advance(0.01);
  const IntegratorStats stats = integrator.stats();
  CHECK(stats.implicit);
  CHECK(stats.method == "ARKODE_ARK436L2SA_DIRK_6_3_4");
  CHECK(stats.lin_solves > 0);  // the string's own Newton solver was used
}

TEST_CASE("method = auto: explicit with quadratic elements, whose implicit path is not O(N)",
          "[unit][integrator][implicit][quadratic]") {
  // Quadratic elements have no Newton solver of their own (ARKODE's dense difference-quotient
  // Jacobian would be O(N³) per set-up): auto keeps them explicit however stiff.
  auto quadratic = hanging_chain(100, 1.0, [](double) { return 0.0; }, 0.03, 0.0, "quadratic");
  CHECK(quadratic->explicit_stiffness() == Approx(100));
  CHECK_FALSE(quadratic->has_newton_solver());
  CHECK(Integrator::resolve_method("auto", *quadratic) == kAutoExplicit);
}
