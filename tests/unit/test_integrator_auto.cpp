// solver/integrator.hpp: what method = "auto" picks, from the string's stiffness (links of a uniform
// chain) and its root functions (docs/string_solver.md, "The implicit path").
#include <catch2/catch.hpp>

#include "solver/integrator.hpp"
#include "solver/string_solver.hpp"
#include "tests/problems/string_test_support.hpp"

using namespace chainsim;
using namespace chainsim::testing;

TEST_CASE("method = auto: implicit from 50 links on at a loose tolerance, explicit below", "[unit][integrator][implicit]") {
  auto tilted = [](double sigma) { return 1e-3 * sigma; };  // off equilibrium, so Newton has work
  auto coarse = hanging_chain(49, 1.0, tilted, 0.03);
  auto fine = hanging_chain(50, 1.0, tilted, 0.03);
  // ℓ / h_min is the number of links of a uniform chain.
  CHECK(coarse->explicit_stiffness() == Approx(49));
  CHECK(fine->explicit_stiffness() == Approx(50));
  CHECK(Integrator::resolve_method("auto", *coarse, 1e-5) == kAutoExplicitLoose);
  CHECK(Integrator::resolve_method("auto", *fine, 1e-5) == kAutoImplicit);
  CHECK(Integrator::resolve_method("auto", *fine) == kAutoExplicitStiff);  // the library's rtol 1e-10: tight
  CHECK(Integrator::resolve_method("erk4", *fine) == "erk4");  // any other name is kept
  IntegratorOptions options;
  options.method = "auto";
  options.rtol = 1e-5;
  options.validate();
  Integrator integrator(*fine, 0.0, fine->state_from_chain(), options);
  integrator.advance(0.01);
  const IntegratorStats stats = integrator.stats();
  CHECK(stats.implicit);
  CHECK(stats.method == "ARKODE_ARK436L2SA_DIRK_6_3_4");
  CHECK(stats.lin_solves > 0);  // the string's own Newton solver was used
}

TEST_CASE("the method is checked where it enters and where it is loaded, not at every copy of the options",
          "[unit][integrator]") {
  // Issue 22: a scene's run checked its method eleven times (each [solver] key, the scene's parts,
  // the solver's options, the integrator). Now a scene checks it once at its key, and the Integrator,
  // its one user, refuses an unknown name where it loads the table: a C++ caller that skips validate()
  // still gets the options' message, not a crash.
  auto chain = hanging_chain(10, 1.0, [](double) { return 0.0; }, 0.03);
  IntegratorOptions options;
  options.method = "rk99";
  CHECK_NOTHROW(options.validate_numbers());
  CHECK_THROWS_WITH(options.validate_method(), Catch::Contains("method = \"rk99\" is not a known integration method"));
  CHECK_THROWS_AS(Integrator(*chain, 0.0, chain->state_from_chain(), options), InputError);
  CHECK_THROWS_WITH(Integrator(*chain, 0.0, chain->state_from_chain(), options),
                    Catch::Contains("method = \"rk99\" is not a known integration method"));
  // The solver's options check their numbers only: the method is the Integrator's.
  StringSolverOptions run;
  run.integrator = options;
  CHECK_NOTHROW(run.validate());
  run.integrator.rtol = 1.0;
  CHECK_THROWS_WITH(run.validate(), Catch::Contains("rtol"));
}

TEST_CASE("method = auto: implicit from 50 links on at a loose tolerance with quadratic elements too, on their own Newton solver",
          "[unit][integrator][implicit][quadratic]") {
  // Quadratic elements solve their Newton systems themselves (O(N), quadratic_string.hpp): auto treats
  // them as the links, by the stiffness ℓ / h_min.
  auto tilted = [](double sigma) { return 1e-3 * sigma; };
  auto quadratic = hanging_chain(50, 1.0, tilted, 0.03, 0.0, "quadratic");
  auto coarse = hanging_chain(48, 1.0, tilted, 0.03, 0.0, "quadratic");
  CHECK(quadratic->explicit_stiffness() == Approx(50));
  REQUIRE(quadratic->has_newton_solver());
  CHECK(quadratic->newton_solver_exact());
  CHECK(Integrator::resolve_method("auto", *coarse, 1e-5) == kAutoExplicitLoose);
  CHECK(Integrator::resolve_method("auto", *quadratic, 1e-5) == kAutoImplicit);
  IntegratorOptions options;
  options.method = "auto";
  options.rtol = 1e-5;
  Integrator integrator(*quadratic, 0.0, quadratic->state_from_chain(), options);
  integrator.advance(0.01);
  const IntegratorStats stats = integrator.stats();
  CHECK(stats.implicit);
  CHECK(stats.lin_solves > 0);  // the elements' own Newton solver was used
  CHECK(stats.nonlin_conv_fails == 0);
}

namespace {
// Only what "auto" looks at: the stiffness and the root functions.
struct StubSystem : OdeSystem {
  StubSystem(double stiffness, int events) : stiffness_(stiffness), events_(events) {}
  int size() const override { return 1; }
  void rhs(double, const Eigen::Ref<const Eigen::VectorXd>&, Eigen::Ref<Eigen::VectorXd> ydot) override {
    ydot.setZero();
  }
  int num_events() const override { return events_; }
  double explicit_stiffness() const override { return stiffness_; }
  double stiffness_;
  int events_;
};
}  // namespace

TEST_CASE("method = auto looks at the tolerance and the fronts: erk3 at loose rtol, erk5 at tight, explicit with "
          "fronts", "[unit][integrator]") {
  // Issue 24 item 4: auto chose erk8 for every front scene and every non-stiff string, which the
  // work-precision study measured 1.5 - 2.3 times slower than erk3 at rtol 1e-3 - 1e-6 and up to 1.2 times
  // slower than erk5 at rtol 1e-8 - 1e-9 (docs/work-precision.md, "What auto picks").
  const StubSystem fronts(200, 2), coarse(20, 0), stiff(200, 0);
  CHECK(Integrator::resolve_method("auto", fronts, 1e-3) == "erk3");
  CHECK(Integrator::resolve_method("auto", fronts, 1e-6) == "erk3");
  CHECK(Integrator::resolve_method("auto", fronts, 1e-9) == "erk5");
  CHECK(Integrator::resolve_method("auto", coarse, 1e-5) == "erk3");
  CHECK(Integrator::resolve_method("auto", coarse, 1e-8) == "erk5");
  CHECK(Integrator::resolve_method("auto", stiff, 1e-5) == "dirk4");  // stiff and no fronts: implicit
  CHECK(Integrator::resolve_method("auto", stiff, 1e-6) == "dirk4");
  // ... at a loose tolerance only: at a tight one dirk4's steps follow the tolerance (5,394 on the 81-node
  // hanging chain at rtol 1e-9, 0.35 s) and erk3's stability-bound ones are cheaper (11,514, 0.13 s).
  CHECK(Integrator::resolve_method("auto", stiff, 1e-7) == "erk3");
  CHECK(Integrator::resolve_method("auto", stiff, 1e-9) == "erk3");
  // ... up to the finest string measured (641 nodes): beyond it dirk4 at every rtol.
  const StubSystem finer(640, 0), finest(641, 0);
  CHECK(Integrator::resolve_method("auto", finer, 1e-8) == "erk3");
  CHECK(Integrator::resolve_method("auto", finest, 1e-8) == "dirk4");
  CHECK(Integrator::resolve_method("erk8", fronts, 1e-3) == "erk8");
  // The Integrator resolves it with its own rtol: a front scene at rtol 1e-4 runs Bogacki-Shampine.
  auto chain = hanging_chain(10, 1.0, [](double) { return 0.0; }, 0.03);
  IntegratorOptions options;
  options.method = "auto";
  options.rtol = 1e-4;
  Integrator loose(*chain, 0.0, chain->state_from_chain(), options);
  CHECK(loose.stats().method == "ARKODE_BOGACKI_SHAMPINE_4_2_3");
  options.rtol = 1e-9;
  Integrator tight(*chain, 0.0, chain->state_from_chain(), options);
  CHECK(tight.stats().method == "ARKODE_DORMAND_PRINCE_7_4_5");
}
