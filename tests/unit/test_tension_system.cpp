// solver/tension_system.hpp: every backend gives the same tensions, the tensions reproduce the
// constraint's second derivative, the pattern is assembled once (several arcs), and a
// singular system is reported with the link and the time.
#include <cmath>
#include <memory>
#include <random>

#include <Eigen/Dense>
#include <catch2/catch.hpp>

#include "mesh/errors.hpp"
#include "solver/string_model.hpp"
#include "solver/tension_system.hpp"

using namespace chainsim;
using Catch::Matchers::Contains;
using Catch::Matchers::WithinAbs;

namespace {

/// Backends must agree to round-off: the systems have condition numbers of at most ~1e3 here.
constexpr double kBackendAgreement = 1e-12;
/// Residual of the differentiated constraint relative to its largest term.
constexpr double kConstraintResidual = 1e-12;

/// A random open or closed chain with random masses, positions, velocities, gravity, drag and loads,
/// possibly with a fixed start and a driven end.
template <int dim>
std::unique_ptr<StringModel<dim>> random_model(std::mt19937& rng, bool closed, bool prescribe,
                                               const std::string& backend, double tau_b) {
  std::uniform_real_distribution<double> u(-1.0, 1.0), pos(0.05, 0.3);
  const int links = closed ? 23 : 19;
  std::vector<double> h(static_cast<std::size_t>(links));
  for (double& x : h) x = pos(rng);
  Chain<dim> chain(0.7, h, closed);
  // A random walk with steps of length h_j (so the constraints hold), the closed loop perturbed.
  chain.positions().col(0).setZero();
  for (int j = 0; j + 1 < chain.num_nodes(); ++j) {
    Vec<dim> d;
    for (int k = 0; k < dim; ++k) d[k] = u(rng);
    chain.positions().col(j + 1) = chain.positions().col(j) + h[static_cast<std::size_t>(j)] * d.normalized();
  }
  for (int i = 0; i < chain.num_nodes(); ++i)
    for (int k = 0; k < dim; ++k) chain.velocities()(k, i) = u(rng);
  Vec<dim> g, f;
  for (int k = 0; k < dim; ++k) g[k] = 5 * u(rng), f[k] = u(rng);
  std::vector<std::unique_ptr<Force<dim>>> forces;
  forces.push_back(std::make_unique<Gravity<dim>>(g));
  forces.push_back(std::make_unique<Drag<dim>>(0.3));
  std::vector<PrescribedNode<dim>> prescribed;
  if (!closed) {
    if (prescribe) {
      prescribed.push_back({0, std::make_shared<FixedPoint<dim>>(chain.positions().col(0))});
      prescribed.push_back({chain.num_nodes() - 1, std::make_shared<HarmonicPath<dim>>(
                                                       chain.positions().col(chain.num_nodes() - 1), f, 3.0, false)});
    } else {
      forces.push_back(std::make_unique<EndLoad<dim>>(chain.num_nodes() - 1, f, f, 2.0));
    }
  }
  StringModelOptions options;
  options.backend = backend;
  options.stabilization_time = tau_b;
  return std::make_unique<StringModel<dim>>(std::move(chain), std::move(forces), std::move(prescribed), options);
}

template <int dim>
void check_backends_agree() {
  for (bool closed : {false, true}) {
    for (bool prescribe : {false, true}) {
      if (closed && prescribe) continue;
      for (int trial = 0; trial < 5; ++trial) {
        Eigen::VectorXd reference;
        for (const std::string& backend : tension_backend_names()) {
          std::mt19937 rng(100 + trial);  // same configuration for every backend
          auto model = random_model<dim>(rng, closed, prescribe, backend, 0.05);
          CHECK(model->tension_system().backend_name() == backend);
          const auto& chain = model->chain();
          model->evaluate(0.3, chain.positions(), chain.velocities());
          const Eigen::VectorXd T = model->tensions();
          if (reference.size() == 0) {
            reference = T;
            continue;
          }
          INFO("backend " << backend << ", closed " << closed << ", prescribed " << prescribe);
          CHECK((T - reference).cwiseAbs().maxCoeff() <= kBackendAgreement * reference.cwiseAbs().maxCoeff());
        }
      }
    }
  }
}

/// C_j = (|Δx_j|² − h_j²)/2: checks C'' + 2α C' + β² C = 0 with C'' = Δx·Δa + |Δv|².
template <int dim>
void check_constraint_second_derivative(double tau_b) {
  for (bool closed : {false, true}) {
    for (bool prescribe : {false, true}) {
      if (closed && prescribe) continue;
      std::mt19937 rng(42);
      auto model = random_model<dim>(rng, closed, prescribe, "auto", tau_b);
      auto& chain = model->chain();
      // Perturb the link lengths so the stabilisation term is active.
      const Points<dim> x = 1.001 * chain.positions();
      Points<dim> v = chain.velocities();
      for (const auto& p : model->prescribed()) v.col(p.node) = p.path->velocity(0.7);
      model->evaluate(0.7, x, v);
      const Points<dim>& a = model->accelerations();
      for (int j = 0; j < chain.num_links(); ++j) {
        const int i0 = chain.link_start(j), i1 = chain.link_end(j);
        const Vec<dim> dx = x.col(i1) - x.col(i0), dv = v.col(i1) - v.col(i0), da = a.col(i1) - a.col(i0);
        const double h = chain.link_length(j);
        const double c = 0.5 * (dx.squaredNorm() - h * h), cdot = dx.dot(dv), cddot = dx.dot(da) + dv.squaredNorm();
        const double residual = cddot + 2 * model->alpha() * cdot + model->beta() * model->beta() * c;
        const double scale = std::abs(dx.dot(da)) + dv.squaredNorm() + std::abs(2 * model->alpha() * cdot) +
                             std::abs(model->beta() * model->beta() * c);
        INFO("link " << j << ", closed " << closed << ", prescribed " << prescribe << ", tau_b " << tau_b);
        CHECK(std::abs(residual) <= kConstraintResidual * scale);
      }
      // Prescribed nodes move as told; free nodes obey m a = F + T_i e_i − T_{i−1} e_{i−1}.
      for (const auto& p : model->prescribed())
        CHECK((a.col(p.node) - p.path->acceleration(0.7)).norm() <= 1e-14 * (1 + p.path->acceleration(0.7).norm()));
    }
  }
}

/// Dense copy of the assembled system.
Eigen::MatrixXd dense(const TensionSystem& s) {
  Eigen::MatrixXd A = Eigen::MatrixXd::Zero(s.size(), s.size());
  const auto& p = s.pattern();
  for (int c = 0; c < p.n; ++c)
    for (int k = p.col_ptr[c]; k < p.col_ptr[c + 1]; ++k) A(p.row_index[k], c) = s.values()[k];
  return A;
}

void fill_arcs(TensionSystem& s, std::mt19937& rng) {
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  s.zero();
  for (const ArcBlock& arc : s.arcs()) {
    for (int i = 0; i < arc.num_links; ++i) {
      const int j = arc.first_unknown + i;
      s.add_diagonal(j, -2.5 + 0.5 * u(rng));
      if (i + 1 < arc.num_links || arc.closed) s.set_coupling(j, u(rng));
      s.rhs(j) = u(rng);
    }
  }
}

}  // namespace

TEST_CASE("all tension backends give the same tensions on random configurations", "[unit][tension]") {
  check_backends_agree<2>();
  check_backends_agree<3>();
}

TEST_CASE("the solved tensions reproduce the constraint's second derivative", "[unit][tension]") {
  check_constraint_second_derivative<2>(0.0);   // exact: e_j·Δa_j + |Δv_j|²/l_j = 0
  check_constraint_second_derivative<3>(0.0);
  check_constraint_second_derivative<2>(0.05);  // Baumgarte: C'' + 2αC' + β²C = 0
  check_constraint_second_derivative<3>(0.05);
}

TEST_CASE("several arcs: cyclic and open blocks solved per arc, equal to a dense solve", "[unit][tension]") {
  std::mt19937 rng(3);
  for (const std::string& backend : tension_backend_names()) {
    TensionSystem s({5, 3, 1, 7}, {false, true, false, true}, backend);
    CHECK(s.size() == 16);
    CHECK(s.pattern().nnz() == (5 + 8) + (3 + 6) + 1 + (7 + 14));
    for (int repeat = 0; repeat < 3; ++repeat) {  // same pattern, new values: refactor
      fill_arcs(s, rng);
      const Eigen::VectorXd expected = dense(s).fullPivLu().solve(s.rhs_vector());
      const Eigen::VectorXd T = s.solve(0.0);
      INFO("backend " << backend);
      CHECK((T - expected).cwiseAbs().maxCoeff() <= kBackendAgreement * expected.cwiseAbs().maxCoeff());
    }
    CHECK(s.num_solves() == 3);
  }
}

TEST_CASE("an open arc eliminated from both ends or from the top: the dense solve's tensions on every length",
          "[unit][tension]") {
  // Every length from 1 (no chain: the middle row alone) to 12 (even and odd: the top half one row longer or
  // not), and 1000; symmetric couplings and the non-symmetric ones of a sliding node's friction.
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  std::vector<int> lengths = {1000};
  for (int m = 1; m <= 12; ++m) lengths.push_back(m);
  for (const int m : lengths) {
    for (const bool symmetric : {true, false}) {
      TensionSystem s({m}, {false}, "tridiagonal");
      fill_arcs(s, rng);
      if (!symmetric)
        for (int j = 0; j + 1 < m; ++j) s.add_couplings(j, 0.3 * u(rng), -0.3 * u(rng));
      const Eigen::VectorXd expected = dense(s).fullPivLu().solve(s.rhs_vector());
      s.set_two_ended(true);
      const Eigen::VectorXd both = s.solve(0.0);
      s.set_two_ended(false);
      const Eigen::VectorXd top = s.solve(0.0);
      INFO(m << " links, " << (symmetric ? "symmetric" : "friction's couplings"));
      CHECK((both - expected).cwiseAbs().maxCoeff() <= kBackendAgreement * expected.cwiseAbs().maxCoeff());
      CHECK((top - expected).cwiseAbs().maxCoeff() <= kBackendAgreement * expected.cwiseAbs().maxCoeff());
    }
  }
}

TEST_CASE("a singular tension system names the link, the pivot and the time", "[unit][tension]") {
  for (const std::string& backend : tension_backend_names()) {
    TensionSystem s({4}, {false}, backend);
    s.zero();
    for (int j = 0; j < 4; ++j) s.add_diagonal(j, -1.0);
    s.set_coupling(0, 1.0);  // rows 0 and 1 equal up to sign: singular at link 1
    s.set_coupling(1, 0.0);
    s.rhs(0) = 1.0;
    INFO("backend " << backend);
    try {
      s.solve(2.5);
      FAIL("no exception");
    } catch (const NumericalError& e) {
      CHECK(e.time() == 2.5);
      CHECK_THAT(e.what(), Contains("singular") && Contains("t = 2.5 s"));
      if (backend != "eigen") CHECK_THAT(e.what(), Contains("link"));
    }
  }
  CHECK_THROWS_WITH(make_tension_backend("lapack"), Contains("allowed auto") && Contains("tridiagonal"));
}

TEST_CASE("a string taut between two fixed points is reported, not solved", "[unit][tension]") {
  // Two links, both ends fixed, straight: the middle node can only move sideways, e0 = e1 and the
  // tension matrix [[−w, w], [w, −w]] is singular.
  Chain<2> chain = Chain<2>::uniform(1.0, 1.0, 2, false);
  chain.positions() << 0.0, 0.5, 1.0, 0.0, 0.0, 0.0;
  std::vector<PrescribedNode<2>> ends = {{0, std::make_shared<FixedPoint<2>>(Vec<2>(0, 0))},
                                         {2, std::make_shared<FixedPoint<2>>(Vec<2>(1, 0))}};
  std::vector<std::unique_ptr<Force<2>>> forces;
  forces.push_back(std::make_unique<Gravity<2>>(Vec<2>(0, -9.81)));
  StringModel<2> model(chain, std::move(forces), ends, {});
  CHECK_THROWS_WITH(model.evaluate(0.125, model.chain().positions(), model.chain().velocities()),
                    Contains("link") && Contains("t = 0.125 s"));
}
