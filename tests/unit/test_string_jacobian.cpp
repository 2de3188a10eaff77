// solver/string_jacobian.hpp: the analytic linearisation of the string's right-hand side against
// central differences of StringModel::rhs (an independent computation: the RHS knows nothing of the
// Jacobian), and the Newton solve against the linearisation it inverts.
#include <cmath>
#include <random>

#include <catch2/catch.hpp>

#include "mesh/discretize.hpp"
#include "shocks/front_tracker.hpp"
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
/// A chain of 20 links hanging from a pinned heap at the origin into gravity (the heap holds s > s0 when
/// `end_side`, as the falling chain's; else s < s0, as the sliding chain's), or lying on a plane.
StringModel<2> with_heap(bool end_side, bool on_plane) {
  const int links = 20;
  Chain<2> chain = Chain<2>::uniform(1.0, 1.0, links, false);
  for (int i = 0; i <= links; ++i) {
    const double s = 1.0 * i / links, sigma = end_side ? 0.62 - s : s - 0.38;  // distance from the front
    // pinned: a straight line from the heap point; on the plane: a curve above it, the heap's nodes on it
    chain.positions().col(i) = on_plane ? Vec<2>(0.2 * std::sin(2 * sigma), std::max(sigma, 0.0))
                                        : Vec<2>(0.5 * sigma, -0.8660254037844386 * sigma);
  }
  HeapSpec<2> heap;
  heap.side = end_side ? HeapSpec<2>::Side::kAfter : HeapSpec<2>::Side::kBefore;
  heap.point = Vec<2>::Zero();
  heap.dissipation = 0.6;
  heap.s0 = end_side ? 0.62 : 0.38;
  if (on_plane) heap.plane_normal = Vec<2>(0.0, 1.0);
  std::vector<std::unique_ptr<Force<2>>> forces;
  forces.push_back(std::make_unique<Gravity<2>>(Vec<2>(0.0, -9.81)));
  StringModelOptions options;
  options.stabilization_time = 0.03;
  return make_front_model<2>(std::move(chain), std::move(forces), {}, {heap}, std::nullopt, FrontOptions{}, options);
}

/// A chain of 20 links folded at s0 = 0.3 m, both arms hanging from near the origin, arc A's top end held.
StringModel<2> with_fold() {
  Points<2> vertices(2, 3);
  vertices << 0.0, 0.0, 0.05, 0.0, -0.3, -0.3 + std::sqrt(0.49 - 0.0025);
  Chain<2> chain = discretize<2>(*polyline_curve<2>(vertices), 1.0, 1.0, 20, false);
  FoldSpec fold;
  fold.s0 = 0.3;
  fold.dissipation = 0.5;
  std::vector<std::unique_ptr<Force<2>>> forces;
  forces.push_back(std::make_unique<Gravity<2>>(Vec<2>(0.0, -9.81)));
  StringModelOptions options;
  options.stabilization_time = 0.03;
  return make_front_model<2>(std::move(chain), std::move(forces), {{0, std::make_shared<FixedPoint<2>>(Vec<2>(0, 0))}},
                             {}, fold, FrontOptions{}, options);
}

/// A state near the model's own (positions moved by 1e-3 of a link: the fronts stay between their
/// crossings) with random velocities of `speed`.
template <int dim>
Eigen::VectorXd nearby_state(const StringModel<dim>& model, double speed, std::mt19937& rng) {
  Eigen::VectorXd y = model.state_from_chain();
  const int nx = dim * model.num_free_nodes();
  y.head(nx) += 1e-3 * model.chain().link_length(0) * random_vector(nx, rng);
  y.segment(nx, nx) = speed * random_vector(nx, rng);
  return y;
}
}  // namespace

TEST_CASE("with fronts, the Jacobian holds the partial links' masses and the jump conditions' forces",
          "[unit][model][jacobian][shocks]") {
  // The fronts' masses and loads depend on the end nodes' positions and velocities (a heap's partial
  // link λ l and end tension τ(ṡ0) e; a fold's two partial links and its tensions and momentum flux):
  // without their derivatives J d missed by 4e-4 to 0.1 of its size on these states (measured).
  std::mt19937 rng(5);
  auto check = [&](StringModel<2> model) {
    REQUIRE(model.newton_solver_exact());
    const Eigen::VectorXd y = nearby_state(model, 0.5, rng);
    for (int k = 0; k < 3; ++k) {
      Eigen::VectorXd d = random_vector(static_cast<int>(y.size()), rng);
      d.head(2 * model.num_free_nodes()) *= 1e-2 * model.chain().link_length(0);  // stay between crossings
      CHECK(jacobian_error(model, 0.0, y, d) < kFiniteDifference);
    }
  };
  SECTION("a pinned heap holding the end (the falling chain)") { check(with_heap(true, false)); }
  SECTION("a pinned heap feeding the start (the sliding chain)") { check(with_heap(false, false)); }
  SECTION("a heap on a plane") { check(with_heap(true, true)); }
  SECTION("a fold (the folded chain)") { check(with_fold()); }
}

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
