// Quadratic elements (solver/quadratic_string.hpp) at single states, against independent references:
// the block-tridiagonal solve against Eigen's dense LU, and the hanging chain's tension λ g (ℓ − s),
// which the elements (tension linear per element, at the Gauss points) must give exactly.
#include <fstream>
#include <random>
#include <regex>
#include <sstream>

#include <Eigen/Dense>
#include <catch2/catch.hpp>

#include "../problems/string_test_support.hpp"
#include "cases/scene/scene.hpp"
#include "cases/scene/scene_run.hpp"
#include "solver/quadratic_string.hpp"

using namespace chainsim;
using namespace chainsim::testing;

namespace {
/// A random block-tridiagonal system with saddle-like blocks (zero diagonal entries in the last rows,
/// which need the pivoting), its neighbours coupled through the window O..O+W−1, solved by
/// BlockTridiagonal and by Eigen's dense LU.
template <int K, int O, int W>
void check_against_dense(int blocks) {
  const int n = K * blocks;
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  BlockTridiagonal<K, O, W> bt;
  bt.resize(blocks);
  bt.set_zero();
  Eigen::MatrixXd dense = Eigen::MatrixXd::Zero(n, n);
  for (int i = 0; i < blocks; ++i) {
    for (int r = 0; r < K; ++r)
      for (int c = 0; c < K; ++c) {
        bt.diag[i](r, c) = (r >= K - 2 && c >= K - 2) ? 0.0 : u(rng) + (r == c ? 4.0 : 0.0);
        if (i > 0 && c >= O && c < O + W) bt.lower[i](r, c) = u(rng);
        if (i + 1 < blocks && r >= O && r < O + W) bt.upper[i](r, c) = u(rng);
      }
    dense.block(K * i, K * i, K, K) = bt.diag[i];
    if (i > 0) dense.block(K * i, K * (i - 1), K, K) = bt.lower[i];
    if (i + 1 < blocks) dense.block(K * i, K * (i + 1), K, K) = bt.upper[i];
  }
  Eigen::VectorXd b(n);
  for (int k = 0; k < n; ++k) b[k] = u(rng);
  const Eigen::VectorXd exact = dense.partialPivLu().solve(b);
  std::vector<typename BlockTridiagonal<K, O, W>::Column> rhs(static_cast<std::size_t>(blocks));
  for (int i = 0; i < blocks; ++i) rhs[static_cast<std::size_t>(i)] = b.template segment<K>(K * i);
  bt.factor();
  REQUIRE_FALSE(bt.singular());
  bt.solve(rhs);
  for (int i = 0; i < blocks; ++i)
    CHECK((rhs[static_cast<std::size_t>(i)] - exact.template segment<K>(K * i)).cwiseAbs().maxCoeff() <
          1e-12 * exact.cwiseAbs().maxCoeff());
}
}  // namespace

TEST_CASE("BlockTridiagonal solves as a dense LU does", "[unit][quadratic]") {
  check_against_dense<6, 0, 6>(7);
  check_against_dense<6, 2, 2>(9);  // the 2D quadratic elements' layout
  check_against_dense<8, 3, 3>(5);  // the 3D one
}

TEST_CASE("quadratic elements: a chain hanging at rest has the tension lambda g (l - s) at every Gauss point",
          "[unit][quadratic]") {
  for (int elements : {1, 3, 10}) {
    auto model = hanging_chain(2 * elements, 1.0, [](double) { return 0.0; }, 0.1, 0.0, "quadratic");
    const Eigen::VectorXd y = model->state_from_chain();
    const auto snap = model->snapshot(0.0, y);
    const QuadraticString<2>& q = *model->quadratic();
    for (int e = 0; e < elements; ++e)
      for (int k = 0; k < 2; ++k)
        CHECK(std::abs(q.tensions()[2 * e + k] - kG * (1.0 - q.gauss_coordinate(e, k))) < 1e-12 * kG);
    // tension.csv's values: the element's linear tension at each link's midpoint.
    for (int j = 0; j < 2 * elements; ++j)
      CHECK(std::abs(snap.tension[j] - kG * (1.0 - model->chain().link_midpoint(j))) < 1e-12 * kG);
    // At rest: no acceleration, the support carries the weight λ g ℓ.
    CHECK(model->accelerations().cwiseAbs().maxCoeff() < 1e-12 * kG);  // of the snapshot's state
    CHECK(std::abs(snap.end_reactions[0].y() - kG) < 1e-12 * kG);
    CHECK(std::abs(snap.moving_mass - 1.0) < 1e-14);
  }
}

namespace {
std::string scene_with_quadratic_elements(const std::string& name) {
  std::ifstream file(std::string(CHAINSIM_SOURCE_DIR) + "/cases/scenes/" + name);
  std::stringstream text;
  text << file.rdbuf();
  return std::regex_replace(text.str(), std::regex("\\[string\\]\n"), "[string]\nelements = \"quadratic\"\n");
}
}  // namespace

TEST_CASE("quadratic elements: the energy ledger closes with a driven end and with drag", "[unit][quadratic]") {
  // K + V − K0 − V0 − W_applied = 0 for the exact solution, W_applied the work of the driver (its
  // reaction M a − F − f at the node) and of the drag: a conservation law the run does not impose.
  for (const char* name : {"shaken_chain.toml", "damped_catenary.toml"}) {
    SceneRun<2> run(parse_scene_text(scene_with_quadratic_elements(name), name));
    REQUIRE_FALSE(run.run().has_value());
    const RunSummary& s = run.solver().summary();
    double work = 0;
    for (const auto& frame : run.solver().frames()) work = std::max(work, std::abs(frame.work));
    INFO(name << ": relative energy drift " << s.relative_energy_drift() << ", max |W_applied| " << work);
    CHECK(s.tension_backend == "quadratic elements (block tridiagonal)");
    CHECK(work > 1e-3 * s.energy_scale);  // the driver or the drag did work
    CHECK(s.relative_energy_drift() < 1e-10);
    CHECK(s.max_constraint_violation < 1e-9);
  }
}

TEST_CASE("quadratic elements: the Newton solve inverts I - gamma J, J from central differences of the rhs",
          "[unit][quadratic][implicit]") {
  // A hanging chain off equilibrium and moving (so every term of the linearisation has work), the
  // Newton system (I − γ J) z = r solved by the elements, checked with J z from central differences
  // of the right-hand side (an independent computation).
  auto model = hanging_chain(8, 1.0, [](double sigma) { return 0.05 * sigma * sigma; }, 0.03, 0.0, "quadratic");
  Eigen::VectorXd y = model->state_from_chain();
  const int n = model->size(), nv = n / 2;  // [x | v | W]: n = 2 nv + 1
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  // moving: a rigid rotation about the fixed top, v = ω ẑ × x (compatible with the constraints)
  for (int k = 0; k < nv / 2; ++k) {
    y[nv + 2 * k] = -0.7 * y[2 * k + 1];
    y[nv + 2 * k + 1] = 0.7 * y[2 * k];
  }
  REQUIRE(model->has_newton_solver());
  REQUIRE(model->newton_solver_exact());
  Eigen::VectorXd r(n), z(n), f1(n), f2(n);
  for (int k = 0; k < n; ++k) r[k] = u(rng);
  for (double gamma : {1e-4, 1e-2, 1e-1}) {
    model->newton_setup(0.0, y, true, gamma);
    model->newton_solve(r, z);
    const double eps = 1e-6 / z.cwiseAbs().maxCoeff();  // central differences: 1e-4 .. 1e-7 give 2e-6 .. 9e-11 at γ = 1e-4
    model->rhs(0.0, y + eps * z, f1);
    model->rhs(0.0, y - eps * z, f2);
    const Eigen::VectorXd Jz = (f1 - f2) / (2 * eps);
    const Eigen::VectorXd residual = z - gamma * Jz - r;
    INFO("gamma " << gamma << ": |z - gamma J z - r| " << residual.cwiseAbs().maxCoeff());
    CHECK(residual.cwiseAbs().maxCoeff() < 1e-6 * r.cwiseAbs().maxCoeff());
  }
}
