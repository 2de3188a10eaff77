// Coulomb friction on rigid obstacles (solver/contact_module.hpp; docs/model.md §10, "Friction"),
// each against an independent reference:
//  - every tension backend solves the non-symmetric tridiagonal (and cyclic) system a sliding node
//    makes, against a dense LU of the same entries;
//  - a straight chain on a rough inclined plane (angle α): from rest with tan α > μ it slides down at
//    g (sin α − μ cos α) exactly; with tan α < μ it stays at rest; launched up the slope it decelerates
//    at g (sin α + μ cos α), sticks at t_s = v0/(g (sin α + μ cos α)), then stays (tan α < μ) or slides
//    back at g (sin α − μ cos α); W_friction = −μ M g cos α times the distance slid;
//  - the heavy Atwood chain over a rough pulley: the reduced ODE ẍ = F(x, ẋ) from the capstan balance
//    of the wrapped arc (derived in docs/model.md §10), integrated independently to round-off, against
//    x(t) on 25, 50, 100, 200 links (order ≈ 2 to 100); at rest the chain holds iff the heavier side is
//    within the capstan bound x1 ≤ e^{μπ} x2 + 2μR (1 + e^{μπ})/(1 + μ²), and otherwise slides as the
//    ODE says; launched towards the lighter side it stops at the ODE's time and holds;
//  - a chain landing flat on a rough table: Coulomb's impulse at the landing, then the stick at the
//    exact place; a 3D chain launched up a rough slope: the stop and the slide back;
//  - the onset of slip in 3D (the minimum of Φ, docs/model.md §10): a straight chain at 45° to 90° to the
//    line of steepest slope slides rigidly straight downhill at g (sin α − μ cos α) with no tension, and a
//    half circle pulled at an end slips, closes its ledgers and converges on refinement;
//  - the energy ledger with W_friction, and the momentum ledger with the friction's impulse, closed.
#include <cmath>
#include <cstdio>
#include <random>
#include <vector>

#include <Eigen/Dense>
#include <fmt/format.h>
#include <catch2/catch.hpp>

#include "mesh/errors.hpp"
#include "solver/contact_module.hpp"
#include "solver/string_solver.hpp"
#include "solver/tension_system.hpp"
#include "tests/convergence/contact_test_support.hpp"

using namespace chainsim;

namespace {

constexpr double kG = 9.81;

}  // namespace

TEST_CASE("friction: every tension backend solves the non-symmetric system of a sliding node", "[contact][friction]") {
  // One open arc of 7 links and one closed arc of 5: random diagonally dominant entries, A(u, v) ≠ A(v, u).
  const std::vector<int> links = {7, 5};
  const std::vector<bool> closed = {false, true};
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> U(-1.0, 1.0);
  const int n = 12;
  Eigen::MatrixXd dense = Eigen::MatrixXd::Zero(n, n);
  Eigen::VectorXd b(n);
  std::vector<double> diag(n), upper(n), lower(n);
  for (int u = 0; u < n; ++u) {
    diag[u] = -3 - U(rng);
    upper[u] = U(rng);
    lower[u] = U(rng);
    b[u] = U(rng);
  }
  auto next_of = [](int u) { return u < 6 ? u + 1 : (u == 6 ? -1 : (u < 11 ? u + 1 : 7)); };
  for (int u = 0; u < n; ++u) {
    dense(u, u) = diag[u];
    const int v = next_of(u);
    if (v < 0) continue;
    dense(u, v) += upper[u];
    dense(v, u) += lower[u];
  }
  const Eigen::VectorXd exact = dense.partialPivLu().solve(b);
  for (const std::string& backend : tension_backend_names()) {
    TensionSystem system(links, closed, backend);
    system.zero();
    for (int u = 0; u < n; ++u) {
      system.add_diagonal(u, diag[u]);
      if (next_of(u) >= 0) system.add_couplings(u, upper[u], lower[u]);
      system.rhs(u) = b[u];
    }
    const Eigen::VectorXd T = system.solve(0.0);
    const double error = (T - exact).cwiseAbs().maxCoeff() / exact.cwiseAbs().maxCoeff();
    std::printf("\nnon-symmetric tension system, backend %s: relative error %.3g\n", backend.c_str(), error);
    CHECK(error < 1e-13);
  }
}

namespace {

/// A straight chain of ℓ = 1 m, λ = 0.7 kg/m on a rough plane through the origin inclined at α (its
/// upslope direction s = (cos α, sin α), normal (−sin α, cos α)), nodes from the origin up the slope,
/// all moving at v0 along s.
struct Incline {
  double alpha = 0.5, mu = 0.3, v0 = 0, ell = 1.0, lambda = 0.7;
  int links = 10;
  Vec<2> up() const { return Vec<2>(std::cos(alpha), std::sin(alpha)); }
  double a_down() const { return kG * (std::sin(alpha) - mu * std::cos(alpha)); }
  double a_up() const { return kG * (std::sin(alpha) + mu * std::cos(alpha)); }
  double t_stop() const { return v0 / a_up(); }
  /// The displacement up the slope at t (the exact motion with stick–slip).
  double s(double t) const {
    if (v0 <= 0) return a_down() > 0 ? -0.5 * a_down() * t * t : 0.0;
    if (t <= t_stop()) return v0 * t - 0.5 * a_up() * t * t;
    const double top = v0 * t_stop() - 0.5 * a_up() * t_stop() * t_stop(), dt = t - t_stop();
    return a_down() > 0 ? top - 0.5 * a_down() * dt * dt : top;
  }
  double speed(double t) const {  // along s
    if (v0 <= 0) return a_down() > 0 ? -a_down() * t : 0.0;
    if (t <= t_stop()) return v0 - a_up() * t;
    return a_down() > 0 ? -a_down() * (t - t_stop()) : 0.0;
  }
  /// The distance slid to t (for W_friction).
  double path(double t) const {
    if (v0 <= 0) return std::abs(s(t));
    if (t <= t_stop()) return s(t);
    return 2 * s(t_stop()) - s(t);
  }
};

struct InclineRun {
  double position_error = 0, speed_error = 0, w_friction = 0, drift = 0, momentum = 0;
  double sticks = 0, slips = 0;
};

InclineRun incline_run(const Incline& c, double t_end) {
  Chain<2> chain = Chain<2>::uniform(c.lambda, c.ell, c.links, false);
  for (int i = 0; i <= c.links; ++i) {
    chain.positions().col(i) = (i * c.ell / c.links) * c.up();
    chain.velocities().col(i) = c.v0 * c.up();
  }
  std::vector<std::unique_ptr<Force<2>>> forces;
  forces.push_back(std::make_unique<Gravity<2>>(Vec<2>(0.0, -kG)));
  Obstacle<2> plane;
  plane.kind = Obstacle<2>::Kind::kPlane;
  plane.point = Vec<2>::Zero();
  plane.normal = Vec<2>(-std::sin(c.alpha), std::cos(c.alpha));
  plane.mu = c.mu;
  plane.name = "slope";
  StringModel<2> model(std::move(chain), std::move(forces), {}, test::contact_options(), make_contact_module<2>({plane}));
  StringSolver<2> solver(model, test::contact_run(t_end, t_end / 4));
  const RunSummary& s = solver.run();
  REQUIRE(s.status == "completed");
  InclineRun r;
  const auto& last = solver.frames().back();
  REQUIRE(last.t == Approx(t_end));
  for (int i = 0; i <= c.links; ++i) {
    const Vec<2> x = (i * c.ell / c.links + c.s(t_end)) * c.up();
    r.position_error = std::max(r.position_error, (last.x.col(i) - x).norm());
    r.speed_error = std::max(r.speed_error, (last.v.col(i) - c.speed(t_end) * c.up()).norm());
  }
  r.w_friction = last.terms["W_friction"];
  r.sticks = last.terms["sticks"];
  r.slips = last.terms["slips"];
  r.drift = s.relative_energy_drift();
  r.momentum = s.relative_momentum_residual();
  return r;
}

}  // namespace

TEST_CASE("friction: a chain on a rough incline slides, stays or sticks and slides back as a block", "[contact][friction]") {
  const double M = 0.7;
  SECTION("from rest, tan α > μ: it slides down at g (sin α − μ cos α)") {
    Incline c;
    c.alpha = 0.5;
    c.mu = 0.3;
    const double T = 0.4;
    const InclineRun r = incline_run(c, T);
    const double W = -c.mu * M * kG * std::cos(c.alpha) * c.path(T);
    std::printf("\nincline from rest (tan a = %.3f > mu = %.2f): position error %.3g m, speed error %.3g m/s, "
                "W_friction %.9g J (exact %.9g), energy %.3g, momentum %.3g\n",
                std::tan(c.alpha), c.mu, r.position_error, r.speed_error, r.w_friction, W, r.drift, r.momentum);
    CHECK(r.position_error < 1e-9);
    CHECK(r.speed_error < 1e-9);
    CHECK(std::abs(r.w_friction - W) < 1e-9 * std::abs(W));
    CHECK(r.drift < 1e-9);
    CHECK(r.momentum < 1e-9);
  }
  SECTION("from rest, tan α < μ: it stays") {
    Incline c;
    c.alpha = 0.25;
    c.mu = 0.4;
    const InclineRun r = incline_run(c, 0.4);
    std::printf("\nincline from rest (tan a = %.3f < mu = %.2f): position error %.3g m, speed error %.3g m/s, "
                "sticks %g, slips %g\n",
                std::tan(c.alpha), c.mu, r.position_error, r.speed_error, r.sticks, r.slips);
    CHECK(r.position_error == 0);
    CHECK(r.speed_error == 0);
    CHECK(r.sticks == c.links + 1);
    CHECK(r.slips == 0);
    CHECK(r.w_friction == 0);
  }
  for (const double alpha : {0.25, 0.5}) {
    DYNAMIC_SECTION("launched up the slope at tan α = " << std::tan(alpha)) {
      Incline c;
      c.alpha = alpha;
      c.mu = 0.4;
      c.v0 = 1.5;
      // just before and just after the stop, and well after it
      for (const double f : {0.999, 1.001, 2.0}) {
        const double T = f * c.t_stop();
        const InclineRun r = incline_run(c, T);
        const double W = -c.mu * M * kG * std::cos(c.alpha) * c.path(T);
        std::printf("\nincline launched up (tan a = %.3f, mu = %.2f), t = %.4f t_stop (t_stop = %.9f s): position "
                    "error %.3g m, speed error %.3g m/s, W_friction %.9g J (exact %.9g), sticks %g, slips %g, "
                    "energy %.3g, momentum %.3g\n",
                    std::tan(c.alpha), c.mu, f, c.t_stop(), r.position_error, r.speed_error, r.w_friction, W,
                    r.sticks, r.slips, r.drift, r.momentum);
        CHECK(r.position_error < 1e-9);
        CHECK(r.speed_error < 1e-8);
        CHECK(std::abs(r.w_friction - W) < 1e-8 * std::abs(W));
        CHECK(r.drift < 1e-8);
        CHECK(r.momentum < 1e-8);
        CHECK(r.sticks == (f < 1 ? 0 : c.links + 1));
        CHECK(r.slips == (f < 1 || c.a_down() < 0 ? 0 : c.links + 1));
      }
    }
  }
}

namespace {

/// The heavy Atwood chain over a rough pulley of radius R at the origin (λ = 1 kg/m): the side of
/// length x2 hangs at x = −R, the side x1 at x = +R, the half circle πR between; s from the x2 side's
/// end. X is the displacement of the chain towards the x1 side (x1 + X, x2 − X).
///
/// The reduced ODE (docs/model.md §10). Moving towards x1 (Ẋ > 0), on the wrapped arc (φ from the x2
/// side's contact point, s = Rφ) the tangential balance λẌ = ∂τ/∂s − λg cos φ − μN and the normal
/// one N = (τ − λẊ²)/R + λg sin φ give, for u = τ − λẊ², u' − μu = λR (Ẍ + g cos φ + μg sin φ), so
///   u(π) = E u(0) + λRẌ (E − 1)/μ + λRg c (1 + E),   E = e^{μπ},  c = 2μ/(1 + μ²),
/// and the hanging sides give u(0) = λ x2 (g + Ẍ) − λẊ², u(π) = λ x1 (g − Ẍ) − λẊ²:
///   Ẍ = [g (x1 − E x2 − R c (1 + E)) + (E − 1) Ẋ²] / (x1 + E x2 + R (E − 1)/μ).
/// At rest it holds iff x1 ≤ E x2 + R c (1 + E) (and the mirror inequality), the capstan bound of a
/// heavy chain.
struct RoughAtwood {
  double ell = 1.0, R = 0.1, mu = 0.1, x1 = 0, x2 = 0, v0 = 0;
  double E() const { return std::exp(mu * kPi); }
  double c() const { return 2 * mu / (1 + mu * mu); }
  double free() const { return x1 + x2; }
  /// The largest x1 that the pulley holds at rest against x2 = free − x1.
  double x1_bound() const { return (E() * free() + R * c() * (1 + E())) / (1 + E()); }
  /// Ẍ at (X, Ẋ) while it slides towards x1 (sign > 0) or towards x2 (sign < 0).
  double acc(double X, double V, double sign) const {
    const double a1 = x1 + X, a2 = x2 - X, e = E(), k = R * c() * (1 + e), d = R * (e - 1) / mu;
    if (sign > 0) return (kG * (a1 - e * a2 - k) + (e - 1) * V * V) / (a1 + e * a2 + d);
    return -(kG * (a2 - e * a1 - k) + (e - 1) * V * V) / (a2 + e * a1 + d);
  }
  /// u(0)/λ = x2 (g + Ẍ) − Ẋ², the contact force per length at the x2 side's contact point times R
  /// (sliding towards x1): the chain stays on the pulley while it is positive.
  double lift_margin(double X, double V) const { return (x2 - X) * (kG + acc(X, V, 1)) - V * V; }
  /// X and Ẋ at t by the classical Runge–Kutta method on `steps` steps (to round-off at 20000), from
  /// X = 0, Ẋ = v0, sliding in the direction of v0 (towards x1 from rest); if it stops first, the stop
  /// time in `t_stop` (bisected on the last step) and the state there.
  std::pair<double, double> solve(double t, int steps, double* t_stop = nullptr, double* min_margin = nullptr) const {
    const double sign = v0 < 0 ? -1.0 : 1.0;
    double X = 0, V = v0;
    const double dt = t / steps;
    if (min_margin) *min_margin = lift_margin(X, V);
    for (int k = 0; k < steps; ++k) {
      const auto next = step(X, V, dt, sign);
      if (t_stop && V != 0 && next.second * sign <= 0) {
        double lo = 0, hi = dt;
        for (int it = 0; it < 200; ++it) {
          const double h = 0.5 * (lo + hi);
          (step(X, V, h, sign).second * sign > 0 ? lo : hi) = h;
        }
        *t_stop = k * dt + 0.5 * (lo + hi);
        return step(X, V, 0.5 * (lo + hi), sign);
      }
      X = next.first;
      V = next.second;
      if (min_margin) *min_margin = std::min(*min_margin, lift_margin(X, V));
    }
    return {X, V};
  }
  std::pair<double, double> step(double X, double V, double dt, double sign) const {
    auto f = [&](double x, double v) { return std::make_pair(v, acc(x, v, sign)); };
    const auto k1 = f(X, V), k2 = f(X + 0.5 * dt * k1.first, V + 0.5 * dt * k1.second);
    const auto k3 = f(X + 0.5 * dt * k2.first, V + 0.5 * dt * k2.second), k4 = f(X + dt * k3.first, V + dt * k3.second);
    return {X + dt / 6 * (k1.first + 2 * k2.first + 2 * k3.first + k4.first),
            V + dt / 6 * (k1.second + 2 * k2.second + 2 * k3.second + k4.second)};
  }
  Vec<2> at(double s) const { return test::pulley_path_point(R, x2, s); }
  Vec<2> tangent(double s) const { return test::pulley_path_tangent(R, x2, s); }
};

RoughAtwood rough_atwood(double x1, double v0) {
  RoughAtwood a;
  a.x1 = x1;
  a.x2 = a.ell - kPi * a.R - x1;
  a.v0 = v0;
  return a;
}

struct RoughAtwoodRun {
  double X = 0, max_speed_end = 0, drift = 0, momentum = 0, w_friction = 0, sticks = 0, slips = 0, lift_offs = 0;
};

RoughAtwoodRun rough_atwood_run(const RoughAtwood& a, int links, double t_end) {
  Chain<2> chain = test::pulley_chain(1.0, a.ell, a.R, a.x2, a.v0, links);
  std::vector<std::unique_ptr<Force<2>>> forces;
  forces.push_back(std::make_unique<Gravity<2>>(Vec<2>(0.0, -kG)));
  StringModel<2> model(std::move(chain), std::move(forces), {}, test::contact_options(),
                       make_contact_module<2>({test::pulley(a.R, a.mu)}));
  StringSolver<2> solver(model, test::contact_run(t_end, t_end / 4, 1e-11));
  const RunSummary& s = solver.run();
  REQUIRE(s.status == "completed");
  const auto& first = solver.frames().front();
  const auto& last = solver.frames().back();
  RoughAtwoodRun r;
  r.X = 0.5 * ((last.x(1, 0) - last.x(1, links)) - (first.x(1, 0) - first.x(1, links)));
  for (int i = 0; i <= links; ++i) r.max_speed_end = std::max(r.max_speed_end, last.v.col(i).norm());
  r.drift = s.relative_energy_drift();
  r.momentum = s.relative_momentum_residual();
  r.w_friction = last.terms["W_friction"];
  r.sticks = last.terms["sticks"];
  r.slips = last.terms["slips"];
  r.lift_offs = last.terms["lift_offs"];
  return r;
}

}  // namespace

TEST_CASE("friction: the heavy Atwood chain over a rough pulley follows the capstan ODE at second order",
          "[contact][friction][convergence]") {
  // Beyond the capstan bound (x1 = 0.45 m > 0.4162 m for μ = 0.1), moving towards the heavier side.
  const RoughAtwood a = rough_atwood(0.45, 0.5);
  const double T = 0.2;
  double margin = 0;
  const double X = a.solve(T, 20000, nullptr, &margin).first;
  REQUIRE(a.x1 > a.x1_bound());
  REQUIRE(margin > 0.1);  // the reference stays on the pulley: no lift-off before T
  REQUIRE(std::abs(X - a.solve(T, 10000).first) < 1e-14);
  std::vector<double> errors;
  for (const int links : {25, 50, 100, 200}) {
    const RoughAtwoodRun r = rough_atwood_run(a, links, T);
    errors.push_back(std::abs(r.X - X));
    std::printf("\nrough Atwood (mu = %.2f), %d links: X(%.2f) = %.9f m (exact %.9f), error %.3g m%s, W_friction %.6g J, "
                "energy %.3g, momentum %.3g, sticks %g\n",
                a.mu, links, T, r.X, X, errors.back(),
                errors.size() > 1 ? fmt::format(", order {:.2f}", std::log2(errors[errors.size() - 2] / errors.back())).c_str() : "",
                r.w_friction, r.drift, r.momentum, r.sticks);
    CHECK(r.drift < 1e-8);
    CHECK(r.momentum < 1e-8);
    CHECK(r.w_friction < 0);
    CHECK(r.sticks == 0);
  }
  // Measured: 1.08e-3, 2.03e-4, 3.25e-5, 5.1e-6 m (orders 2.4, 2.65, 2.7; the error changes sign between
  // 100 and 200 links); past that a part of about 5e-5 of X, first order, remains (9.0e-6 and 5.3e-6 m on
  // 400 and 800 links; docs/model.md §10, "Friction"). Without the landings' Coulomb impulse the error
  // was 1.4e-4 m on 50 links and 1.8e-5 m on 200 (first order past 100).
  CHECK(std::log2(errors[0] / errors[1]) > 2);
  CHECK(std::log2(errors[1] / errors[2]) > 2);
  CHECK(errors[2] < 5e-5);
  CHECK(errors[3] < 1e-5);
}

TEST_CASE("friction: the heavy Atwood chain at rest on a rough pulley holds iff within the capstan bound",
          "[contact][friction]") {
  const int links = 50;
  const double T = 0.3;
  SECTION("within the bound it stays") {
    const RoughAtwood a = rough_atwood(0.97 * rough_atwood(0.4, 0).x1_bound(), 0.0);
    const RoughAtwoodRun r = rough_atwood_run(a, links, T);
    std::printf("\nrough Atwood at rest, x1 = %.4f m (bound %.4f m): X = %.3g m, max speed %.3g m/s, sticks %g, slips %g\n",
                a.x1, a.x1_bound(), r.X, r.max_speed_end, r.sticks, r.slips);
    CHECK(std::abs(r.X) < 1e-5);  // the hanging sides settle under their stuck tops (chords, not tangents)
    CHECK(r.sticks > 0);
    CHECK(r.slips == 0);
  }
  SECTION("beyond it, it slides at the capstan ODE's acceleration") {
    const RoughAtwood a = rough_atwood(1.03 * rough_atwood(0.4, 0).x1_bound(), 0.0);
    const double X = a.solve(T, 20000).first;
    const RoughAtwoodRun r = rough_atwood_run(a, links, T);
    std::printf("\nrough Atwood at rest, x1 = %.4f m (bound %.4f m): X = %.6g m (capstan ODE %.6g m), sticks %g, slips %g\n",
                a.x1, a.x1_bound(), r.X, X, r.sticks, r.slips);
    // From rest the convergence is slower (as over the smooth pulley): 5.7% on 50 links.
    CHECK(r.slips > 0);
    CHECK(std::abs(r.X - X) < 0.1 * X);
  }
  SECTION("launched towards the lighter side within the bound, it stops at the ODE's time and holds") {
    const RoughAtwood a = rough_atwood(0.38, -0.4);
    REQUIRE(a.x1 < a.x1_bound());
    double t_stop = 0;
    const double X_stop = a.solve(1.0, 20000, &t_stop).first;
    REQUIRE(t_stop > 0);
    const RoughAtwoodRun before = rough_atwood_run(a, links, 0.98 * t_stop);
    const RoughAtwoodRun after = rough_atwood_run(a, links, 1.5 * t_stop);
    std::printf("\nrough Atwood launched at 0.4 m/s towards x2, x1 = %.4f m (bound %.4f m): stops at %.6f s at X = %.6g m; "
                "X(1.5 t_stop) = %.6g m, max speed %.3g m/s, sticks %g, slips %g, energy %.3g; before: sticks %g\n",
                a.x1, a.x1_bound(), t_stop, X_stop, after.X, after.max_speed_end, after.sticks, after.slips, after.drift,
                before.sticks);
    CHECK(before.sticks == 0);
    CHECK(after.sticks > 0);
    CHECK(std::abs(after.X - X_stop) < 1e-2 * std::abs(X_stop));
    CHECK(after.slips == 0);
    CHECK(after.drift < 1e-8);
  }
}

TEST_CASE("friction: in 3D a chain launched up a rough slope stops at the exact time and slides back", "[contact][friction]") {
  // The incline of the 2D case tilted about the line of steepest slope's normal: the slope rises along
  // s = (cos α, 0, sin α) in a plane with normal (−sin α, 0, cos α), the chain lies along s, gravity −g z.
  Incline c;
  c.alpha = 0.5;
  c.mu = 0.4;
  c.v0 = 1.5;
  const Vec<3> up(std::cos(c.alpha), 0.0, std::sin(c.alpha));
  for (const double f : {0.999, 2.0}) {
    const double T = f * c.t_stop();
    Chain<3> chain = Chain<3>::uniform(c.lambda, c.ell, c.links, false);
    for (int i = 0; i <= c.links; ++i) {
      chain.positions().col(i) = (i * c.ell / c.links) * up + Vec<3>(0.0, 0.3, 0.0);
      chain.velocities().col(i) = c.v0 * up;
    }
    std::vector<std::unique_ptr<Force<3>>> forces;
    forces.push_back(std::make_unique<Gravity<3>>(Vec<3>(0.0, 0.0, -kG)));
    Obstacle<3> plane;
    plane.kind = Obstacle<3>::Kind::kPlane;
    plane.point = Vec<3>::Zero();
    plane.normal = Vec<3>(-std::sin(c.alpha), 0.0, std::cos(c.alpha));
    plane.mu = c.mu;
    plane.name = "slope";
    StringModel<3> model(std::move(chain), std::move(forces), {}, test::contact_options(), make_contact_module<3>({plane}));
    StringSolver<3> solver(model, test::contact_run(T, T / 4));
    const RunSummary& s = solver.run();
    REQUIRE(s.status == "completed");
    const auto& last = solver.frames().back();
    double position_error = 0;
    for (int i = 0; i <= c.links; ++i)
      position_error = std::max(position_error, (last.x.col(i) - ((i * c.ell / c.links + c.s(T)) * up + Vec<3>(0.0, 0.3, 0.0))).norm());
    std::printf("\n3D incline launched up (tan a = %.3f, mu = %.2f), t = %.3f t_stop: position error %.3g m, sticks %g, "
                "slips %g, energy %.3g, momentum %.3g\n",
                std::tan(c.alpha), c.mu, f, position_error, last.terms["sticks"], last.terms["slips"],
                s.relative_energy_drift(), s.relative_momentum_residual());
    CHECK(position_error < 1e-9);
    CHECK(last.terms["sticks"] == (f < 1 ? 0 : c.links + 1));
    CHECK(last.terms["slips"] == (f < 1 ? 0 : c.links + 1));
    CHECK(s.relative_energy_drift() < 1e-8);
    CHECK(s.relative_momentum_residual() < 1e-8);
  }
}

TEST_CASE("friction: a chain landing flat on a rough table takes Coulomb's impulse and stops at the exact place",
          "[contact][friction]") {
  // Dropped flat from H while moving at v0 along the table: it lands at t_l = √(2H/g) with the normal
  // impulse M v_n (v_n = √(2gH)), and Coulomb's impulse takes μ M v_n of its tangential momentum:
  // v1 = v0 − μ v_n; then it decelerates at μ g and sticks at t_l + v1/(μ g). W_impacts = −½ M v_n²,
  // W_friction = −½ M v0² (all the tangential motion).
  const double ell = 1.0, lambda = 1.0, H = 0.05, v0 = 0.5, mu = 0.3, T = 0.4;
  const int links = 20;
  Chain<2> chain = Chain<2>::uniform(lambda, ell, links, false);
  for (int i = 0; i <= links; ++i) {
    chain.positions().col(i) = Vec<2>(i * ell / links, H);
    chain.velocities().col(i) = Vec<2>(v0, 0.0);
  }
  std::vector<std::unique_ptr<Force<2>>> forces;
  forces.push_back(std::make_unique<Gravity<2>>(Vec<2>(0.0, -kG)));
  Obstacle<2> table;
  table.kind = Obstacle<2>::Kind::kPlane;
  table.point = Vec<2>::Zero();
  table.normal = Vec<2>(0.0, 1.0);
  table.mu = mu;
  table.name = "table";
  StringModel<2> model(std::move(chain), std::move(forces), {}, test::contact_options(), make_contact_module<2>({table}));
  StringSolver<2> solver(model, test::contact_run(T, T / 4));
  const RunSummary& s = solver.run();
  REQUIRE(s.status == "completed");
  const auto& last = solver.frames().back();
  const double t_land = std::sqrt(2 * H / kG), vn = std::sqrt(2 * kG * H), v1 = v0 - mu * vn, t_slide = v1 / (mu * kG);
  const double shift = v0 * t_land + v1 * t_slide - 0.5 * mu * kG * t_slide * t_slide, M = lambda * ell;
  REQUIRE(t_land + t_slide < T);
  double position_error = 0, speed = 0;
  for (int i = 0; i <= links; ++i) {
    position_error = std::max(position_error, (last.x.col(i) - Vec<2>(i * ell / links + shift, 0.0)).norm());
    speed = std::max(speed, last.v.col(i).norm());
  }
  std::printf("\nflat landing on a rough table (mu = %.2f): position error %.3g m (shift %.9f m), speed %.3g m/s, "
              "W_impacts %.12g J (exact %.12g), W_friction %.12g J (exact %.12g), energy %.3g, momentum %.3g\n",
              mu, position_error, shift, speed, last.terms["W_impacts"], -0.5 * M * vn * vn, last.terms["W_friction"],
              -0.5 * M * v0 * v0, s.relative_energy_drift(), s.relative_momentum_residual());
  CHECK(position_error < 1e-12);
  CHECK(speed == 0);
  CHECK(std::abs(last.terms["W_impacts"] + 0.5 * M * vn * vn) < 1e-12);
  CHECK(std::abs(last.terms["W_friction"] + 0.5 * M * v0 * v0) < 1e-12);
  CHECK(last.terms["sticks"] == links + 1);
  CHECK(s.relative_energy_drift() < 1e-12);
  CHECK(s.relative_momentum_residual() < 1e-12);
}

TEST_CASE("friction: in 3D a straight chain at any angle to a rough slope slips from rest straight downhill",
          "[contact][friction]") {
  // docs/model.md §10, *The onset of slip in 3D*. A straight chain at angle φ to the line of steepest
  // slope of a plane (angle α, normal (0, cos α, sin α), gravity −g y): every node carries the same
  // tangential load m g sin α downhill, so at rest with tan α > μ the chain slides rigidly straight
  // downhill (across itself unless φ = 0) at g (sin α − μ cos α), its tension zero; W_friction =
  // −μ M g cos α × (distance slid). Independent of φ: 90° is the chain lying across the slope.
  const double alpha = kPi / 6, mu = 0.2, ell = 0.8, lambda = 1.0, T = 0.5, M = lambda * ell;
  const Vec<3> n(0.0, std::cos(alpha), std::sin(alpha)), down = Vec<3>(0.0, -std::sin(alpha), std::cos(alpha)).normalized();
  const Vec<3> level = n.cross(down);  // horizontal, in the plane
  const double acc = kG * (std::sin(alpha) - mu * std::cos(alpha)), path = 0.5 * acc * T * T;
  for (const double phi_deg : {90.0, 89.99, 80.0, 45.0}) {
    for (const int links : {5, 20, 40}) {
      const double phi = phi_deg * kPi / 180;
      const Vec<3> along = std::cos(phi) * down + std::sin(phi) * level;
      Chain<3> chain = Chain<3>::uniform(lambda, ell, links, false);
      for (int i = 0; i <= links; ++i) chain.positions().col(i) = (i * ell / links) * along;
      std::vector<std::unique_ptr<Force<3>>> forces;
      forces.push_back(std::make_unique<Gravity<3>>(Vec<3>(0.0, -kG, 0.0)));
      Obstacle<3> plane;
      plane.kind = Obstacle<3>::Kind::kPlane;
      plane.point = Vec<3>::Zero();
      plane.normal = n;
      plane.mu = mu;
      plane.name = "slope";
      StringModel<3> model(std::move(chain), std::move(forces), {}, test::contact_options(), make_contact_module<3>({plane}));
      StringSolver<3> solver(model, test::contact_run(T, T / 5));
      const RunSummary& s = solver.run();
      REQUIRE(s.status == "completed");
      double position_error = 0, tension = 0;
      for (const auto& frame : solver.frames()) {
        for (int i = 0; i <= links; ++i)
          position_error = std::max(position_error, (frame.x.col(i) - ((i * ell / links) * along + 0.5 * acc * frame.t * frame.t * down)).norm());
        tension = std::max(tension, frame.tension.cwiseAbs().maxCoeff());
      }
      const auto& last = solver.frames().back();
      const double W = -mu * M * kG * std::cos(alpha) * path;
      std::printf("\n3D chain at %.2f deg to a rough slope, %d links: position error %.3g m, max |T| %.3g N, "
                  "W_friction %.12g J (relative error %.3g), slips %g, energy %.3g, momentum %.3g\n",
                  phi_deg, links, position_error, tension, last.terms["W_friction"], std::abs(last.terms["W_friction"] / W - 1), last.terms["slips"],
                  s.relative_energy_drift(), s.relative_momentum_residual());
      CHECK(position_error < 5e-14);
      CHECK(tension < 4e-12);
      CHECK(std::abs(last.terms["W_friction"] - W) < 5e-14 * std::abs(W));
      CHECK(last.terms["slips"] == links + 1);
      CHECK(s.relative_energy_drift() < 5e-14);
      CHECK(s.relative_momentum_residual() < 2.5e-13);
    }
  }
}

TEST_CASE("friction: in 3D a half circle on a rough table pulled at an end slips and converges on refinement",
          "[contact][friction][convergence]") {
  // docs/model.md §10, *The onset of slip in 3D*: a half circle (radius about 0.2 m, length 0.2π m,
  // λ = 1) at rest on a rough table (μ = 0.3, gravity −g z), its last node pulled by 5 N (> μ M g =
  // 1.85 N) along the chain's tangent, away from it. At t = 0 the pulled end slips with the nodes
  // whose cones the tension leaves, each in the direction of its own unheld load (not along the
  // chain: the tension's curvature pulls the arc inwards); no closed form: the energy ledger with
  // W_friction and the momentum ledger close, and the node positions at 0.5 s converge on refinement.
  const double ell = 0.2 * kPi, lambda = 1.0, mu = 0.3, T = 0.5;
  std::vector<Points<3>> x;
  for (const int links : {10, 20, 40, 80}) {
    const double dtheta = kPi / links, R = (ell / links) / (2 * std::sin(dtheta / 2));
    Chain<3> chain = Chain<3>::uniform(lambda, ell, links, false);
    for (int i = 0; i <= links; ++i) {
      const double theta = -kPi / 2 + i * dtheta;
      chain.positions().col(i) = Vec<3>(R * std::cos(theta), R * std::sin(theta), 0.0);
    }
    std::vector<std::unique_ptr<Force<3>>> forces;
    forces.push_back(std::make_unique<Gravity<3>>(Vec<3>(0.0, 0.0, -kG)));
    forces.push_back(std::make_unique<EndLoad<3>>(links, Vec<3>(-5.0, 0.0, 0.0)));
    Obstacle<3> table;
    table.kind = Obstacle<3>::Kind::kPlane;
    table.point = Vec<3>::Zero();
    table.normal = Vec<3>(0.0, 0.0, 1.0);
    table.mu = mu;
    table.name = "table";
    StringModel<3> model(std::move(chain), std::move(forces), {}, test::contact_options(), make_contact_module<3>({table}));
    StringSolver<3> solver(model, test::contact_run(T, T / 5, 1e-9));
    const RunSummary& s = solver.run();
    REQUIRE(s.status == "completed");
    const auto& last = solver.frames().back();
    std::printf("\nhalf circle pulled on a rough table, %d links: W_friction %.9g J, slips %g, sticks %g, energy %.3g, "
                "momentum %.3g\n",
                links, last.terms["W_friction"], last.terms["slips"], last.terms["sticks"], s.relative_energy_drift(),
                s.relative_momentum_residual());
    CHECK(last.terms["slips"] > 0);
    CHECK(s.relative_energy_drift() < 8e-11);
    CHECK(s.relative_momentum_residual() < 5e-15);
    x.push_back(last.x);
  }
  std::vector<double> difference;
  for (std::size_t k = 0; k + 1 < x.size(); ++k) {
    double d = 0;
    for (int i = 0; i < x[k].cols(); ++i) d = std::max(d, (x[k].col(i) - x[k + 1].col(2 * i)).norm());
    difference.push_back(d);
  }
  for (std::size_t k = 0; k + 1 < difference.size(); ++k) {
    const double order = std::log2(difference[k] / difference[k + 1]);
    std::printf("half circle: max node difference %.3g m -> %.3g m on refinement: order %.2f\n", difference[k], difference[k + 1], order);
    CHECK(order > 1.2);
  }
}
