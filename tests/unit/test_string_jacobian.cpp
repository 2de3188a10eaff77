// solver/string_jacobian.hpp: the analytic linearisation of the string's right-hand side against
// central differences of StringModel::rhs (an independent computation: the RHS knows nothing of the
// Jacobian), and the Newton solve against the linearisation it inverts.
#include <cmath>
#include <random>

#include <catch2/catch.hpp>

#include "mesh/discretize.hpp"
#include "solver/string_jacobian.hpp"
#include "solver/string_model.hpp"

using namespace chainsim;

namespace {
/// Central differences with a relative step of 1e-6 carry a truncation error ~1e-12 and a round-off
/// error ~1e-16 / 1e-6 = 1e-10 of the RHS's scale; 1e-7 leaves room for the conditioning of the
/// tension solve (a formula error shows at O(1)).
constexpr double kFiniteDifference = 1e-7;
/// The augmented sparse solve is exact up to round-off amplified by the condition of I − γJ.
constexpr double kNewtonSolve = 1e-9;

Eigen::VectorXd random_vector(int n, std::mt19937& rng) {
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  Eigen::VectorXd d(n);
  for (int i = 0; i < n; ++i) d[i] = u(rng);
  return d;
}

/// ‖J d − (F(y + εd) − F(y − εd)) / 2ε‖ / ‖…‖ over the position and velocity rows.
template <int dim>
double jacobian_error(StringModel<dim>& model, double t, const Eigen::VectorXd& y, const Eigen::VectorXd& d) {
  StringJacobian<dim> jac(model);
  jac.linearize(t, y);
  const Eigen::VectorXd Jd = jac.apply(d);
  const double eps = 1e-6 * y.norm() / d.norm();
  Eigen::VectorXd fp(y.size()), fm(y.size());
  model.rhs(t, y + eps * d, fp);
  model.rhs(t, y - eps * d, fm);
  const int nxv = 2 * dim * model.num_free_nodes();
  const Eigen::VectorXd fd = (fp - fm).head(nxv) / (2 * eps);
  return (Jd.head(nxv) - fd).norm() / fd.norm();
}

/// A state of `model` off its constraints (so every term of the tension equation is exercised) with
/// random velocities.
template <int dim>
Eigen::VectorXd perturbed_state(const StringModel<dim>& model, std::mt19937& rng) {
  Eigen::VectorXd y = model.state_from_chain();
  const int nx = dim * model.num_free_nodes();
  y.head(nx) += 1e-2 * model.chain().link_length(0) * random_vector(nx, rng);
  y.segment(nx, nx) = random_vector(nx, rng);
  return y;
}

std::unique_ptr<StringModel<2>> hanging(int links, std::vector<PrescribedNode<2>> ends, double tau_b) {
  Chain<2> chain = Chain<2>::uniform(1.0, 1.0, links, false);
  for (int i = 0; i <= links; ++i)
    chain.positions().col(i) = Vec<2>(0.3 * std::sin(1.0 * i / links), -1.0 * i / links);
  std::vector<std::unique_ptr<Force<2>>> forces;
  forces.push_back(std::make_unique<Gravity<2>>(Vec<2>(0.0, -9.81)));
  StringModelOptions options;
  options.stabilization_time = tau_b;
  auto model = std::make_unique<StringModel<2>>(std::move(chain), std::move(forces), std::move(ends), options);
  model->make_consistent(0.0);
  return model;
}
}  // namespace

TEST_CASE("the string's Jacobian equals central differences of its right-hand side", "[unit][model][jacobian]") {
  std::mt19937 rng(7);
  SECTION("hanging chain from a fixed point, with and without Baumgarte stabilisation") {
    for (double tau_b : {0.0, 0.03}) {
      auto model = hanging(12, {{0, std::make_shared<FixedPoint<2>>(Vec<2>(0, 0))}}, tau_b);
      const Eigen::VectorXd y = perturbed_state(*model, rng);
      for (int k = 0; k < 3; ++k) CHECK(jacobian_error(*model, 0.0, y, random_vector(y.size(), rng)) < kFiniteDifference);
    }
  }
  SECTION("a fixed and a driven end: prescribed accelerations enter the tension equation") {
    auto model = hanging(9,
                         {{0, std::make_shared<FixedPoint<2>>(Vec<2>(0, 0))},
                          {9, std::make_shared<HarmonicPath<2>>(Vec<2>(0.3, -0.8), Vec<2>(0.05, 0.02), 6.0, false)}},
                         0.05);
    const Eigen::VectorXd y = perturbed_state(*model, rng);
    for (int k = 0; k < 3; ++k) CHECK(jacobian_error(*model, 0.4, y, random_vector(y.size(), rng)) < kFiniteDifference);
  }
  SECTION("a closed loop in 3D (cyclic tension system), no gravity") {
    Chain<3> chain = discretize(*circle_curve<3>(Vec<3>(0, 0, 0), 1.0, Vec<3>(1, 0, 0), Vec<3>(0, 1, 0)), 2 * kPi,
                                1.0, 16, true);
    StringModelOptions options;
    options.stabilization_time = 0.1;
    StringModel<3> model(std::move(chain), {}, {}, options);
    model.make_consistent(0.0);
    const Eigen::VectorXd y = perturbed_state(model, rng);
    for (int k = 0; k < 3; ++k) CHECK(jacobian_error(model, 0.0, y, random_vector(y.size(), rng)) < kFiniteDifference);
  }
}

TEST_CASE("the Newton solve inverts I - gamma J of the linearisation", "[unit][model][jacobian]") {
  std::mt19937 rng(11);
  auto model = hanging(40, {{0, std::make_shared<FixedPoint<2>>(Vec<2>(0, 0))}}, 0.03);
  const Eigen::VectorXd y = perturbed_state(*model, rng);
  StringJacobian<2> jac(*model);
  jac.linearize(0.0, y);
  const int nxv = 4 * model->num_free_nodes();
  // γ from a non-stiff step to far beyond the explicit stability limit (h / √(gℓ) ≈ 8e-3 s).
  for (double gamma : {1e-5, 1e-3, 1e-1, 1.0}) {
    jac.factor(gamma);
    const Eigen::VectorXd r = random_vector(y.size(), rng);
    Eigen::VectorXd z(y.size());
    jac.solve(r, z);
    const Eigen::VectorXd residual = (z - gamma * jac.apply(z)).head(nxv) - r.head(nxv);
    CHECK(residual.norm() / r.norm() < kNewtonSolve);
    CHECK(z.tail(y.size() - nxv) == r.tail(y.size() - nxv));  // the ledger rows: identity
  }
}
