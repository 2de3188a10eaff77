// The reduced ODEs of the three canonical problems (cases/reduced/reduced_models) against independent
// references: the exact quadratures ξ(η) and P/P0(η) (cases/reduced/exact_solutions, checked on their own
// against incomplete Beta functions), the sliding chain's special solution, first integrals of the
// folded chain with an end force, energy conservation, and invariance under a change of units.
#include <cmath>
#include <tuple>

#include <catch2/catch.hpp>

#include "cases/reduced/exact_solutions.hpp"
#include "cases/reduced/reduced_models.hpp"
#include "mesh/errors.hpp"

using namespace chainsim;
using Catch::Matchers::WithinAbs;
using Catch::Matchers::WithinRel;

namespace {

// The acceptance levels; the default integrator (order 8, rtol 1e-13) meets them with margin.
constexpr double kStopTimeRelTol = 1e-9;
constexpr double kStopForceRelTol = 1e-7;
// The integrated ledger K + V − E0 − ∫ΣW is a time-integration error: a few rtol of the energy scale.
constexpr double kEnergyResidualTol = 1e-11;
// Scaled results of two runs in different units differ only by rounding and tolerance effects.
constexpr double kUnitsRelTol = 1e-10;

ReducedSetup make(Problem p, double f, double eta0, double eps = 0.01) {
  ReducedSetup s;
  s.problem = p;
  s.chain.dissipation = f;
  s.eta0 = eta0;
  s.eps = eps;
  return s;
}

double exact_xi(Problem p, double f, double eta, double eta0) {
  switch (p) {
    case Problem::kFalling: return exact::falling_xi(f, eta, eta0);
    case Problem::kFolded: return exact::folded_xi(f, eta, eta0);
    case Problem::kSliding: return exact::sliding_xi(f, eta, eta0);
  }
  return NAN;
}

double exact_P(Problem p, double f, double eta, double eta0) {
  switch (p) {
    case Problem::kFalling: return exact::falling_P(f, eta, eta0);
    case Problem::kFolded: return exact::folded_P(f, eta, eta0);
    case Problem::kSliding: return exact::sliding_P(f, eta, eta0);
  }
  return NAN;
}

double stop_eta(Problem p, double eps) {
  return p == Problem::kFalling ? eps : p == Problem::kFolded ? 1.0 - eps : 1.0;
}

}  // namespace

TEST_CASE("reduced ODEs meet the exact quadratures at the stop event", "[problems][reduced]") {
  const auto [problem, eta0] = GENERATE(table<Problem, double>({{Problem::kFalling, 1.0},
                                                                {Problem::kFalling, 0.6},
                                                                {Problem::kFolded, 0.0},
                                                                {Problem::kFolded, 0.3},
                                                                {Problem::kSliding, 0.0},
                                                                {Problem::kSliding, 0.25},
                                                                {Problem::kSliding, 0.75}}));
  const double f = GENERATE(0.0, 0.25, 0.5, 0.83, 1.0);
  CAPTURE(to_string(problem), eta0, f);
  const ReducedSetup setup = make(problem, f, eta0);
  const ReducedRun run = solve_reduced(setup);
  const auto& s = run.summary;

  const double eta_end = stop_eta(problem, setup.eps);
  CHECK(s["stop_reason"] != "t_max");
  CHECK_THAT(s["eta_stop"].get<double>(), WithinAbs(eta_end, 1e-10));
  CHECK_THAT(s["t_stop_over_t0"].get<double>(), WithinRel(exact_xi(problem, f, eta_end, eta0), kStopTimeRelTol));
  // P/P0 is O(1) and vanishes at the end of the sliding chain with f = 0: relative to max(|P|, P0).
  const double P_ref = exact_P(problem, f, eta_end, eta0);
  CHECK_THAT(s["P_stop_over_P0"].get<double>(), WithinAbs(P_ref, kStopForceRelTol * std::max(1.0, std::abs(P_ref))));
  CHECK(s["energy_residual"].get<double>() < kEnergyResidualTol);

  // P/P0 along the whole run against the exact P at the same η (the force is steep near the stop).
  const auto eta = run.series.column("eta");
  const auto P = run.series.column("P_over_P0");
  double worst = 0;
  for (std::size_t k = 0; k < eta.size(); ++k) {
    const double ref = exact_P(problem, f, std::clamp(eta[k], std::min(eta0, eta_end), std::max(eta0, eta_end)), eta0);
    worst = std::max(worst, std::abs(P[k] - ref) / std::max(1.0, std::abs(ref)));
  }
  CHECK(worst < kStopForceRelTol);
}

TEST_CASE("sliding chain from eta0 = 0 follows y = a t^2 / 2 with a = g / (3 + 2f)", "[problems][reduced]") {
  const double f = GENERATE(0.0, 0.5, 1.0);
  CAPTURE(f);
  const ReducedRun run = solve_reduced(make(Problem::kSliding, f, 0.0));
  const double g = 9.81, a = g / (3.0 + 2.0 * f);
  const auto t = run.series.column("t");
  const auto y = run.series.column("y");
  const auto yd = run.series.column("ydot");
  for (std::size_t k = 0; k < t.size(); ++k) {
    CHECK_THAT(y[k], WithinRel(0.5 * a * t[k] * t[k], 1e-9));
    CHECK_THAT(yd[k], WithinRel(a * t[k], 1e-9));
  }
  // t_f = t0 sqrt(3 + 2f), and P/P0 = 1 − 3/(3+2f) (t/t_f)² at the end: P/P0 = 2f/(3+2f).
  CHECK_THAT(run.summary["t_stop_over_t0"].get<double>(), WithinRel(std::sqrt(3.0 + 2.0 * f), kStopTimeRelTol));
  CHECK_THAT(run.summary["P_stop_over_P0"].get<double>() + 1.0,
             WithinRel(1.0 + 2.0 * f / (3.0 + 2.0 * f), kStopForceRelTol));
}

TEST_CASE("folded chain with an end force: first integrals between turning points", "[problems][reduced]") {
  // With F > 0 the chain oscillates about y* = l − F/(λg). On a phase of constant s = sgn ẏ,
  // z = l − y and k = 1 − f s, the equation of motion is linear in u = ẏ²:
  //   du/dz + k u / z = F/(λ z) − g   ⇒   u = F/(λ k) − g z/(k + 1) + C z^(−k),
  // with C fixed by u = 0 at the phase's turning point z_a.
  const double f = GENERATE(0.3, 0.83);
  // Turning needs C < 0 at release, F > λ g k/(k+1) with k = 1 − f (4.04 N for f = 0.3).
  const double force = 5.0;  // N: y* = l − F/(λg) ≈ 0.49 m
  CAPTURE(f);
  ReducedSetup setup = make(Problem::kFolded, f, 0.0);
  setup.force = force;
  setup.t_max_over_t0 = 15.0;
  const ReducedRun run = solve_reduced(setup);
  const auto& s = run.summary;
  REQUIRE(s["turning_points"].get<int>() >= 4);
  CHECK(s["energy_residual"].get<double>() < kEnergyResidualTol);

  const double l = 1.0, lam = 1.0, g = 9.81;
  const auto y = run.series.column("y");
  const auto yd = run.series.column("ydot");
  double z_a = l - y[0];
  double sgn = 1.0;
  double worst = 0;
  for (std::size_t k = 1; k < y.size(); ++k) {
    if (std::abs(yd[k]) < 1e-12) continue;  // the turning point itself (ẏ = 0 up to rounding)
    if ((yd[k] > 0) != (sgn > 0)) {          // first sample of a new phase: the previous one is its turning point
      z_a = l - y[k - 1];
      sgn = -sgn;
    }
    const double kk = 1.0 - f * sgn, z = l - y[k];
    const double C = std::pow(z_a, kk) * (g * z_a / (kk + 1.0) - force / (lam * kk));
    const double u = force / (lam * kk) - g * z / (kk + 1.0) + C * std::pow(z, -kk);
    worst = std::max(worst, std::abs(yd[k] * yd[k] - u) / (g * l));
  }
  CHECK(worst < 1e-9);
  // Damped oscillation about y*: the late samples stay near it.
  CHECK_THAT(y.back(), WithinAbs(l - force / (lam * g), 0.25));
}

TEST_CASE("folded chain with f = 0 and an end force conserves K + V + 2 F y", "[problems][reduced]") {
  ReducedSetup setup = make(Problem::kFolded, 0.0, 0.0);
  setup.force = 6.0;
  setup.t_max_over_t0 = 5.0;
  const ReducedRun run = solve_reduced(setup);
  REQUIRE(run.summary["turning_points"].get<int>() >= 2);
  const auto K = run.series.column("K"), V = run.series.column("V"), y = run.series.column("y");
  const double E0 = K[0] + V[0] + 2.0 * setup.force * y[0];
  for (std::size_t k = 0; k < K.size(); ++k) CHECK_THAT(K[k] + V[k] + 2.0 * setup.force * y[k], WithinAbs(E0, 1e-10));
}

TEST_CASE("scaled results do not depend on the units", "[problems][reduced]") {
  const Problem problem = GENERATE(Problem::kFalling, Problem::kFolded, Problem::kSliding);
  CAPTURE(to_string(problem));
  ReducedSetup a = make(problem, 0.83, problem == Problem::kFalling ? 1.0 : 0.2);
  ReducedSetup b = a;
  b.chain.length = 3.7;
  b.chain.density = 0.21;
  b.chain.gravity = 1.62;
  const auto sa = solve_reduced(a).summary, sb = solve_reduced(b).summary;
  for (const char* key : {"t_stop_over_t0", "eta_stop", "P_stop_over_P0"})
    CHECK_THAT(sb[key].get<double>(), WithinRel(sa[key].get<double>(), kUnitsRelTol));
  CHECK_THAT(sb["t_stop"].get<double>() / sa["t_stop"].get<double>(),
             WithinRel(std::sqrt((3.7 / 1.62) / (1.0 / 9.81)), kUnitsRelTol));
}

TEST_CASE("bad reduced setups are refused with the option, the value and the range", "[problems][reduced]") {
  auto message = [](ReducedSetup s) -> std::string {
    try {
      s.validate();
    } catch (const InputError& e) {
      return e.what();
    }
    return "";
  };
  ReducedSetup s;
  s.chain.dissipation = 1.5;
  CHECK(message(s) == "--f = 1.5 is out of range: allowed 0 <= f <= 1");
  s = ReducedSetup{};
  s.chain.length = -1;
  CHECK(message(s) == "--length = -1 is out of range: allowed length > 0");
  s = ReducedSetup{};
  s.eps = 1.0;
  CHECK(message(s) == "--eps = 1 is out of range: allowed 0 < eps < 1");
  s = ReducedSetup{};
  s.problem = Problem::kSliding;
  s.eta0 = 1.0;
  CHECK(message(s) == "--eta0 = 1 is out of range: allowed 0 <= eta0 < 1");
  s = ReducedSetup{};
  s.force = 2.0;
  CHECK(message(s).find("--force = 2 applies to the folded chain only") == 0);
  CHECK_THROWS_WITH(parse_problem("hanging"),
                    "problem = \"hanging\" is not a known problem: allowed falling, folded, sliding");
}
