// solver/banded_lu.hpp and the banded Newton solve of solver/string_jacobian.hpp: the band LU against
// a dense LU (Eigen's PartialPivLU, an independent factorisation) of the same matrix, on random
// matrices of the band structure and on the augmented Newton matrices of open and closed strings,
// whose bandwidth in the order along the string must not grow with the links.
#include <algorithm>
#include <cmath>
#include <numeric>
#include <random>

#include <Eigen/Dense>
#include <catch2/catch.hpp>

#include "mesh/discretize.hpp"
#include "solver/banded_lu.hpp"
#include "solver/string_jacobian.hpp"
#include "solver/string_model.hpp"

using namespace chainsim;

namespace {

Eigen::VectorXd random_vector(int n, std::mt19937& rng) {
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  Eigen::VectorXd d(n);
  for (int i = 0; i < n; ++i) d[i] = u(rng);
  return d;
}

/// ‖x − x_dense‖ / ‖x_dense‖ over ε times the 1-norm condition of `m`: a backward-stable solve makes
/// it of order one (a few units for pivoting growth).
double relative_to_condition(const Eigen::MatrixXd& m, const Eigen::VectorXd& x, const Eigen::VectorXd& x_dense) {
  const Eigen::PartialPivLU<Eigen::MatrixXd> lu(m);
  const double cond = lu.rcond() > 0 ? 1.0 / lu.rcond() : INFINITY;
  return (x - x_dense).norm() / x_dense.norm() / (std::numeric_limits<double>::epsilon() * cond);
}

/// A chain hanging from a fixed point, bent sideways, with `links` links (gravity, Baumgarte 0.03 s),
/// optionally with a driven end; at a state off its constraints with random velocities.
std::unique_ptr<StringModel<2>> hanging(int links, const std::string& solver, bool driven_end) {
  Chain<2> chain = Chain<2>::uniform(1.0, 1.0, links, false);
  for (int i = 0; i <= links; ++i) chain.positions().col(i) = Vec<2>(0.3 * std::sin(1.0 * i / links), -1.0 * i / links);
  std::vector<std::unique_ptr<Force<2>>> forces;
  forces.push_back(std::make_unique<Gravity<2>>(Vec<2>(0.0, -9.81)));
  std::vector<PrescribedNode<2>> ends = {{0, std::make_shared<FixedPoint<2>>(Vec<2>(0, 0))}};
  if (driven_end)
    ends.push_back({links, std::make_shared<HarmonicPath<2>>(Vec<2>(0.3, -0.8), Vec<2>(0.05, 0.02), 6.0, false)});
  StringModelOptions options;
  options.stabilization_time = 0.03;
  options.linear_solver = solver;
  auto model = std::make_unique<StringModel<2>>(std::move(chain), std::move(forces), std::move(ends), options);
  model->make_consistent(0.0);
  return model;
}

/// A closed loop (a circle of radius 1) in 3D with `links` links, no gravity, moving.
std::unique_ptr<StringModel<3>> loop(int links, const std::string& solver) {
  Chain<3> chain = discretize(*circle_curve<3>(Vec<3>(0, 0, 0), 1.0, Vec<3>(1, 0, 0), Vec<3>(0, 1, 0)), 2 * kPi, 1.0,
                              links, true);
  StringModelOptions options;
  options.stabilization_time = 0.1;
  options.linear_solver = solver;
  auto model = std::make_unique<StringModel<3>>(std::move(chain), std::vector<std::unique_ptr<Force<3>>>{},
                                                std::vector<PrescribedNode<3>>{}, options);
  model->make_consistent(0.0);
  return model;
}

template <int dim>
Eigen::VectorXd moving_state(const StringModel<dim>& model, std::mt19937& rng) {
  Eigen::VectorXd y = model.state_from_chain();
  const int nx = dim * model.num_free_nodes();
  y.head(nx) += 1e-2 * model.chain().link_length(0) * random_vector(nx, rng);
  y.segment(nx, nx) = random_vector(nx, rng);
  return y;
}

/// Linearises both models at y, factors I − γJ for each γ, and checks the banded solve against a
/// dense LU of the same augmented matrix and against KLU's solve. Returns the bandwidths.
template <int dim>
std::pair<int, int> check_banded_against_dense(StringModel<dim>& banded, StringModel<dim>& klu, const Eigen::VectorXd& y,
                                               std::mt19937& rng) {
  StringJacobian<dim> jb(banded), jk(klu);
  jb.linearize(0.1, y);
  jk.linearize(0.1, y);
  REQUIRE(jb.banded());
  REQUIRE_FALSE(jk.banded());
  const int nv = dim * banded.num_free_nodes();
  for (double gamma : {1e-5, 1e-3, 1e-1, 1.0}) {
    jb.factor(gamma);
    jk.factor(gamma);
    const Eigen::MatrixXd m = jb.augmented_matrix();
    REQUIRE((m - jk.augmented_matrix()).norm() == 0.0);  // the same matrix, only factored differently
    // With rx = 0, solve() is the augmented solve of (rv, 0): zv is the head of its solution.
    Eigen::VectorXd r = random_vector(static_cast<int>(y.size()), rng);
    r.head(nv).setZero();
    Eigen::VectorXd zb(y.size()), zk(y.size());
    jb.solve(r, zb);
    jk.solve(r, zk);
    Eigen::VectorXd rhs = Eigen::VectorXd::Zero(m.rows());
    rhs.head(nv) = r.segment(nv, nv);
    const Eigen::VectorXd dense = m.partialPivLu().solve(rhs);
    const Eigen::VectorXd zv_band = zb.segment(nv, nv), zv_klu = zk.segment(nv, nv);
    INFO("gamma " << gamma);
    CHECK(relative_to_condition(m, zv_band, dense.head(nv)) < 10);
    CHECK(relative_to_condition(m, zv_klu, dense.head(nv)) < 10);
  }
  return {jb.lower_bandwidth(), jb.upper_bandwidth()};
}

}  // namespace

TEST_CASE("the band LU solves random band matrices as a dense LU does", "[unit][banded]") {
  std::mt19937 rng(3);
  for (int n : {7, 60, 400}) {
    for (int lower : {0, 2, 5, 11, 20}) {  // 20: beyond the blocks (SUNDIALS' band LU)
      for (int upper : {1, 5}) {
        // A random order: the band lives in the permuted numbering, as the string's does.
        std::vector<int> position(static_cast<std::size_t>(n));
        std::iota(position.begin(), position.end(), 0);
        std::shuffle(position.begin(), position.end(), rng);
        std::vector<int> unknown_at(position.size());
        for (int k = 0; k < n; ++k) unknown_at[static_cast<std::size_t>(position[static_cast<std::size_t>(k)])] = k;
        BandedLU band;
        band.reset(position, lower, upper);
        Eigen::MatrixXd dense = Eigen::MatrixXd::Zero(n, n);
        std::uniform_real_distribution<double> u(-1.0, 1.0);
        for (int i = 0; i < n; ++i)
          for (int j = std::max(0, i - lower); j <= std::min(n - 1, i + upper); ++j) {
            // SPD-like: a diagonal of about half the sum of the row's other entries (not dominant:
            // the blocks' partial pivoting is exercised), random entries in [−1, 1] elsewhere.
            const double v = (i == j ? 1.0 + 0.5 * (lower + upper) : 0.0) + u(rng);
            const int r = unknown_at[static_cast<std::size_t>(i)], c = unknown_at[static_cast<std::size_t>(j)];
            band.add(r, c, v);
            dense(r, c) += v;
          }
        REQUIRE(band.factor());
        const Eigen::VectorXd b = random_vector(n, rng);
        Eigen::VectorXd x = b;
        band.solve(x.data());
        const Eigen::VectorXd x_dense = dense.partialPivLu().solve(b);
        INFO("n " << n << ", lower " << lower << ", upper " << upper);
        CHECK(relative_to_condition(dense, x, x_dense) < 10);
        // Backward stable: the residual is round-off of ‖A‖ ‖x‖, whatever the condition.
        CHECK((dense * x - b).norm() / (dense.norm() * x.norm()) < 1e-14);
      }
    }
  }
}

TEST_CASE("the band LU reports a singular matrix", "[unit][banded]") {
  BandedLU band;
  band.reset({0, 1, 2}, 1, 1);
  band.add(0, 0, 1.0);
  band.add(1, 1, 1.0);  // row and column 2 are zero
  CHECK_FALSE(band.factor());
}

TEST_CASE("the banded Newton solve of a string equals a dense LU of its augmented matrix, and KLU's", "[unit][banded]") {
  std::mt19937 rng(5);
  SECTION("an open string hanging from a fixed point; bandwidth independent of the links") {
    std::pair<int, int> widths[2];
    int k = 0;
    for (int links : {40, 400}) {
      auto b = hanging(links, "banded", false);
      auto kl = hanging(links, "klu", false);
      const Eigen::VectorXd y = moving_state(*b, rng);
      widths[k++] = check_banded_against_dense(*b, *kl, y, rng);
    }
    std::printf("open 2D string: bandwidths %d / %d (40 links), %d / %d (400 links)\n", widths[0].first,
                widths[0].second, widths[1].first, widths[1].second);
    CHECK(widths[0] == widths[1]);
    CHECK(widths[0].first + widths[0].second <= 4 * 3);  // within two nodes each way (d + 1 unknowns per node)
  }
  SECTION("an open string between a fixed and a driven end") {
    auto b = hanging(30, "banded", true);
    auto kl = hanging(30, "klu", true);
    check_banded_against_dense(*b, *kl, moving_state(*b, rng), rng);
  }
  SECTION("a closed loop in 3D: folded order, bandwidth independent of the links") {
    std::pair<int, int> widths[2];
    int k = 0;
    for (int links : {16, 160}) {
      auto b = loop(links, "banded");
      auto kl = loop(links, "klu");
      widths[k++] = check_banded_against_dense(*b, *kl, moving_state(*b, rng), rng);
    }
    std::printf("closed 3D loop: bandwidths %d / %d (16 links), %d / %d (160 links)\n", widths[0].first,
                widths[0].second, widths[1].first, widths[1].second);
    CHECK(widths[0] == widths[1]);
    CHECK(widths[0].first + widths[0].second <= 8 * 4);  // within two nodes each way, folded (twice)
  }
  SECTION("auto chooses the band LU for a string without fronts") {
    auto a = hanging(10, "auto", false);
    StringJacobian<2> j(*a);
    j.linearize(0.0, a->state_from_chain());
    CHECK(j.banded());
  }
}
