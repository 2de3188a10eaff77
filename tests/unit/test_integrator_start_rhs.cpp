// solver/integrator.hpp: Integrator::provide_start_rhs, the right-hand side at a restart's state given by
// the caller (who has evaluated it for a record of that state) instead of evaluated again by ARKODE.
#include <catch2/catch.hpp>

#include <cmath>

#include "solver/integrator.hpp"

using namespace chainsim;

namespace {

/// y'' = −y (y = cos t from y(0) = 1, y'(0) = 0), counting its evaluations.
class Oscillator : public OdeSystem {
 public:
  long evaluations = 0;
  int size() const override { return 2; }
  void rhs(double, const Eigen::Ref<const Eigen::VectorXd>& y, Eigen::Ref<Eigen::VectorXd> ydot) override {
    ++evaluations;
    ydot[0] = y[1];
    ydot[1] = -y[0];
  }
  double time_scale() const override { return 1.0; }
};

struct Run {
  Eigen::VectorXd y;
  long evaluations = 0, rhs_evals = 0;
};

/// To t = 0.5, a restart there (with F given if `give`; given before the restart if `early`), on to t = 1.
Run run(bool give, bool early = false) {
  Oscillator system;
  IntegratorOptions options;
  options.method = "erk5";
  options.rtol = 1e-8;
  options.atol = 1e-12;
  Eigen::VectorXd y0(2);
  y0 << 1.0, 0.0;
  Integrator integrator(system, 0.0, y0, options);
  integrator.advance(0.5);
  const Eigen::VectorXd y = integrator.state();
  Eigen::VectorXd f(2);
  system.rhs(0.5, y, f);
  --system.evaluations;  // the caller's own evaluation
  if (give && early) integrator.provide_start_rhs(f);
  integrator.restart(0.5, y);
  if (give && !early) integrator.provide_start_rhs(f);
  integrator.advance(1.0);
  return {integrator.state(), system.evaluations, integrator.stats().rhs_evals};
}

}  // namespace

TEST_CASE("provide_start_rhs: the restart's first evaluation taken from the caller, the run bit for bit the same",
          "[unit][integrator]") {
  const Run plain = run(false), given = run(true);
  // The exact solution, independently: erk5 at rtol 1e-8 over one radian.
  CHECK(std::abs(plain.y[0] - std::cos(1.0)) < 1e-7);
  CHECK(std::abs(plain.y[1] + std::sin(1.0)) < 1e-7);
  // One evaluation fewer (ARKODE's at the restart's state), ARKODE's count as before, every bit the same.
  CHECK(given.evaluations == plain.evaluations - 1);
  CHECK(given.rhs_evals == plain.rhs_evals);
  CHECK(given.y[0] == plain.y[0]);
  CHECK(given.y[1] == plain.y[1]);
  // Given before the restart: the restart discards it (it may belong to another state).
  const Run early = run(true, /*early=*/true);
  CHECK(early.evaluations == plain.evaluations);
  CHECK(early.y[0] == plain.y[0]);
}
