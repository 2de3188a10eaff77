// Hard cases of the reduced models (docs/stability.md): cutoffs near the singular ends, f at and next
// to 0 and 1, the sliding chain from (almost) nothing, extreme units, a pulled fold that turns many
// times or leaves through its domain boundary, thinned series, refused cutoffs and the step budget.
// References: the exact quadratures and first integrals (cases/reduced/exact_solutions), and the
// power laws of the speed near the singular ends derived from them.
#include <cmath>
#include <limits>
#include <vector>

#include <boost/math/quadrature/tanh_sinh.hpp>
#include <boost/math/tools/roots.hpp>
#include <catch2/catch.hpp>
#include <fmt/format.h>

#include "cases/reduced/exact_solutions.hpp"
#include "cases/reduced/reduced_models.hpp"
#include "mesh/errors.hpp"

using namespace chainsim;
using Catch::Matchers::Contains;
using Catch::Matchers::WithinAbs;
using Catch::Matchers::WithinRel;

namespace {

/// A reduced problem with the default chain, integrator and outputs.
ReducedSetup make(Problem p, double f, double eps, double eta0) {
  ReducedSetup setup;
  setup.problem = p, setup.chain.dissipation = f, setup.eps = eps, setup.eta0 = eta0;
  return setup;
}

/// Every value of every column is finite.
void require_all_finite(const CsvTable& table) {
  long bad = 0;
  for (const auto& name : table.columns())
    for (double v : table.column(name)) bad += !std::isfinite(v);
  REQUIRE(bad == 0);
}

double d(const nlohmann::json& j) { return j.get<double>(); }

/// Runs a setup and checks the stop, the whole series and the ledger against the exact solution:
/// stop time to 1e-9, P/P0 and the speed η' at every row to rel_P (their exact values diverge at
/// the singular end as a power of the distance to it, so round-off of η near 1 costs digits there).
/// The energy ledger to 1e-11, plus 1e-15/ε for the folded chain: K = 2λ(ℓ − y)ẏ² stays finite
/// while ẏ² ~ 1/(ℓ − y), and ℓ − y carries an absolute round-off of ~1e-16 ℓ.
nlohmann::json check_against_exact(const ReducedSetup& s, double rel_P) {
  const ReducedRun run = solve_reduced(s);
  require_all_finite(run.series);
  const auto& j = run.summary;
  const double f = s.chain.dissipation, eta0 = s.initial_eta();
  REQUIRE(j["stop_reason"] == (s.problem == Problem::kSliding ? "chain_fully_hanging" : "cutoff"));
  const double eta_stop = d(j["eta_stop"]);
  CHECK_THAT(d(j["t_stop_over_t0"]), WithinRel(exact::xi(s.problem, f, std::min(eta_stop, 1.0), eta0), 1e-9));
  const double P_stop = exact::P(s.problem, f, std::min(eta_stop, 1.0), eta0);  // 0 for a sliding chain with f = 0
  CHECK(std::abs(d(j["P_stop_over_P0"]) - P_stop) <= rel_P * std::max(std::abs(P_stop), 1.0));
  CHECK(d(j["energy_residual"]) < 1e-11 + (s.problem == Problem::kFolded ? 1e-15 / s.eps : 0.0));
  const auto eta = run.series.column("eta"), eta_p = run.series.column("eta_p"), P = run.series.column("P_over_P0");
  // Errors relative to max(|exact|, 1): relative where the values are large (near the singular
  // end), absolute in units of the scaled problem where they pass through 0 (at the release).
  double speed_err = 0, P_err = 0;
  for (std::size_t k = 1; k < eta.size(); ++k) {
    const double e = std::min(eta[k], 1.0);
    const double s2 = exact::eta_prime_squared(s.problem, f, e, eta0), Pe = exact::P(s.problem, f, e, eta0);
    speed_err = std::max(speed_err, std::abs(eta_p[k] * eta_p[k] - s2) / std::max(std::abs(s2), 1.0));
    P_err = std::max(P_err, std::abs(P[k] - Pe) / std::max(std::abs(Pe), 1.0));
  }
  INFO("speed error " << speed_err << ", P error " << P_err);
  CHECK(speed_err < 2 * rel_P);
  CHECK(P_err < rel_P);
  return j;
}

}  // namespace

TEST_CASE("falling chain, f = 0 and 0.1, down to eps = 1e-6: stop, P and the speed law against the quadrature",
          "[hard][reduced]") {
  for (double f : {0.0, 0.1}) {
    for (double eps : {1e-3, 1e-5, 1e-6}) {
      INFO("f = " << f << ", eps = " << eps);
      const auto j = check_against_exact(make(Problem::kFalling, f, eps, 1.0), 1e-7);
      // The stop lies on the cutoff; near it the speed follows η'² = 4/(3−2f) η^(2f−2) (1 − η^(3−2f)).
      CHECK_THAT(d(j["eta_stop"]), WithinRel(eps, 1e-2));
      const double eta = d(j["eta_stop"]);
      CHECK_THAT(exact::falling_eta_prime_squared(f, eta),
                 WithinRel(4.0 / (3 - 2 * f) * std::pow(eta, 2 * f - 2) * (1 - std::pow(eta, 3 - 2 * f)), 1e-12));
    }
  }
}

TEST_CASE("folded chain, f = 0 (the tip speed diverges), down to eps = 1e-6", "[hard][reduced]") {
  for (double eps : {1e-3, 1e-5, 1e-6}) {
    INFO("eps = " << eps);
    // P/P0 = ½η'² + η ~ 1/(2ε): η near 1 carries an absolute round-off of ~1e-16, so P loses
    // about 1e-16/ε of relative accuracy; 1e-7 holds down to 1e-6 with margin.
    const auto j = check_against_exact(make(Problem::kFolded, 0.0, eps, 0.0), 1e-7);
    const double z = 1 - d(j["eta_stop"]);
    CHECK_THAT(z, WithinRel(eps, 1e-2));
    // Tip speed 2η' against the power law η'² = 1/z − 1 (f = 0, η0 = 0).
    const double tip = 2 * std::sqrt(exact::folded_eta_prime_squared(0.0, 1 - z));
    CHECK_THAT(tip, WithinRel(2 * std::sqrt(1 / z - z), 1e-9));
    CHECK(tip > 1.9 / std::sqrt(eps));
  }
}

TEST_CASE("f exactly 0 and 1, and within 1e-12 of each: all three problems against the quadrature",
          "[hard][reduced]") {
  const double fs[] = {0.0, 1e-12, 1 - 1e-12, 1.0};
  for (Problem p : {Problem::kFalling, Problem::kFolded, Problem::kSliding}) {
    std::vector<double> stop;
    for (double f : fs) {
      INFO(to_string(p) << ", f = " << f);
      const auto j = check_against_exact(make(p, f, 1e-4, p == Problem::kFalling ? 1.0 : 0.0), 1e-7);
      stop.push_back(d(j["t_stop_over_t0"]));
    }
    // The motion depends smoothly on f: 1e-12 away, the stop time moves by O(1e-12) (plus the stop's
    // own error, 1e-9 at most); the limits f = 0, 1 are not special numerically.
    CHECK_THAT(stop[1], WithinRel(stop[0], 2e-9));
    CHECK_THAT(stop[2], WithinRel(stop[3], 2e-9));
  }
}

TEST_CASE("sliding chain from eta0 = 1e-8 and exactly 0: the special solution and the quadrature",
          "[hard][reduced]") {
  for (double f : {0.0, 0.5, 1.0}) {
    INFO("f = " << f);
    const auto j0 = check_against_exact(make(Problem::kSliding, f, 0.01, 0.0), 1e-7);
    CHECK_THAT(d(j0["t_stop_over_t0"]), WithinRel(std::sqrt(3 + 2 * f), 1e-9));  // ξ = sqrt((3+2f)η), η = 1
    const auto j8 = check_against_exact(make(Problem::kSliding, f, 0.01, 1e-8), 1e-7);
    // Released from 1e-8, the chain joins the special branch: the deviation decays like η^−2(1+f).
    CHECK_THAT(d(j8["t_stop_over_t0"]), WithinRel(d(j0["t_stop_over_t0"]), 1e-3));
  }
}

TEST_CASE("extreme but valid units give the same scaled answer to 1e-9 (reduced models)", "[hard][reduced]") {
  for (Problem p : {Problem::kFalling, Problem::kFolded, Problem::kSliding}) {
    ReducedSetup base = make(p, 0.5, 1e-3, p == Problem::kFalling ? 1.0 : 0.25);
    const auto ref = solve_reduced(base).summary;
    struct Units {
      double length, density, gravity;
    };
    for (Units u : {Units{1e-3, 1, 9.81}, Units{1e3, 1, 9.81}, Units{1, 1e-6, 9.81}, Units{1, 1e6, 9.81},
                    Units{1, 1, 1e-3}, Units{1, 1, 1e3}, Units{1e-3, 1e6, 1e3}, Units{1e3, 1e-6, 1e-3}}) {
      INFO(to_string(p) << ": length " << u.length << ", density " << u.density << ", gravity " << u.gravity);
      ReducedSetup s = base;
      s.chain.length = u.length;
      s.chain.density = u.density;
      s.chain.gravity = u.gravity;
      const ReducedRun run = solve_reduced(s);
      require_all_finite(run.series);
      for (const char* key : {"t_stop_over_t0", "eta_stop", "P_stop_over_P0", "t_fall_over_t0"})
        CHECK_THAT(d(run.summary[key]), WithinRel(d(ref[key]), 1e-9));
    }
  }
}

TEST_CASE("a cutoff the run cannot resolve is refused naming the allowed range, and the smallest allowed one runs",
          "[hard][reduced]") {
  for (Problem p : {Problem::kFalling, Problem::kFolded}) {
    for (double f : {0.0, 0.1, 0.5}) {
      INFO(to_string(p) << ", f = " << f);
      ReducedSetup s = make(p, f, 1e-14, p == Problem::kFalling ? 1.0 : 0.0);
      const double eps_min = s.min_cutoff();
      CHECK_THROWS_WITH(s.validate(), Contains("--eps = 1e-14 is out of range") && Contains("allowed") &&
                                          Contains(fmt::format("{:g} <= eps", eps_min)));
      // At the limit the exact time left to the singular end is >= 2e-13 t0 (the power law, checked
      // here against the quadrature's own fall time): the run ends at the cutoff, accurately.
      s.eps = eps_min;
      const double eta_cut = p == Problem::kFalling ? eps_min : 1 - eps_min;
      const double left = p == Problem::kFalling ? exact::falling_fall_time(f) - exact::falling_xi(f, eta_cut)
                                                 : exact::folded_fall_time(f) - exact::folded_xi(f, eta_cut);
      CHECK(left > 0.5 * ReducedSetup::kMinTimeToEnd);  // the quadratures' own error is ~1e-14
      const ReducedRun run = solve_reduced(s);
      require_all_finite(run.series);
      CHECK(run.summary["stop_reason"] == "cutoff");
      CHECK(d(run.summary["rel_err_t_stop"]) < 1e-12);
      // P diverges at the end: at the limit it is accurate to the round-off of η there.
      CHECK(d(run.summary["rel_err_P_stop"]) < 1e-5);
    }
  }
}

TEST_CASE("the folded chain stops where the fold reaches the fixed end (eta = 0, its domain boundary)",
          "[hard][reduced]") {
  // Released at η0 = 0.5 and pulled by F = 1e6 N >> λgℓ: the fold runs up to the fixed end at once.
  const double f = 0.5, F = 1e6, eta0 = 0.5;
  ReducedSetup s = make(Problem::kFolded, f, 0.01, eta0);
  s.force = F;
  const ReducedRun run = solve_reduced(s);
  require_all_finite(run.series);
  const auto& j = run.summary;
  REQUIRE(j["stop_reason"] == "front_reached_fixed_end");
  CHECK_THAT(j["stop_detail"].get<std::string>(), Contains("eta = 0"));
  CHECK_THAT(d(j["eta_stop"]), WithinAbs(0.0, 1e-12));
  for (double eta : run.series.column("eta")) CHECK(eta >= -1e-12);
  // Independent reference: on the rising phase (k = 1 + f) the first integral of model.md §4.2'
  // gives u(z) = ẏ² = F/(λk) − g z/(k+1) + C z^−k, with u = 0 at z_t = ℓ − y0; the time to reach
  // z = ℓ is ∫ dz / sqrt(u), integrated by tanh-sinh over w = z − z_t (the end point singularity
  // is integrable). With r = z_t/z, u = A(1 − r^k) − B z (1 − r^(k+1)), A = F/(λk), B = g/(k+1):
  // the differences are evaluated by expm1/log1p, accurate as z → z_t.
  const double l = 1, lam = 1, g = 9.81, k = 1 + f, zt = l - eta0 * l, A = F / (lam * k), B = g / (k + 1);
  auto u_of_w = [&](double w) {
    const double log_r = -std::log1p(w / zt);
    return -A * std::expm1(k * log_r) + B * (zt + w) * std::expm1((k + 1) * log_r);
  };
  const double speed = std::sqrt(u_of_w(l - zt));
  CHECK_THAT(d(j["P_stop"]), WithinRel(lam * (1 - f) * speed * speed, 1e-9));  // P = λ(1 + f sgn ẏ)ẏ² + λgy
  boost::math::quadrature::tanh_sinh<double> rule;
  const double t_exact = rule.integrate([&](double w) { return 1 / std::sqrt(u_of_w(w)); }, 0.0, l - zt);
  CHECK_THAT(d(j["t_stop"]), WithinRel(t_exact, 1e-9));
  CHECK(d(j["energy_residual"]) < 1e-11);

  // From η0 = 0 such a force would leave the domain at once: refused, naming the allowed range.
  ReducedSetup bad = make(Problem::kFolded, f, 0.01, 0.0);
  bad.force = 20;
  CHECK_THROWS_WITH(solve_reduced(bad), Contains("--force = 20 N") && Contains("allowed 0 <= force <= 9.81 N"));
  bad.force = 1e6;
  CHECK_THROWS_AS(solve_reduced(bad), InputError);
}

TEST_CASE("a pulled fold that turns back and forth more than 10 times stays in its domain and follows the "
          "first integrals from turning point to turning point",
          "[hard][reduced]") {
  // f = 0.5, F = 6 N (λgℓ = 9.81 N): the force stops the first fall (F > λgℓ k/(k+1) = 3.27 N) and the
  // chain oscillates about y* = ℓ − F/(λg) with a decaying amplitude, never reaching η = 0 or 1.
  const double f = 0.5, F = 6, l = 1, lam = 1, g = 9.81;
  ReducedSetup s = make(Problem::kFolded, f, 0.01, 0.0);
  s.force = F;
  const ReducedRun run = solve_reduced(s);
  require_all_finite(run.series);
  REQUIRE(run.summary["stop_reason"] == "t_max");
  REQUIRE(run.summary["turning_points"].get<int>() >= 10);
  const auto eta = run.series.column("eta");
  for (double e : eta) CHECK((e >= 0 && e < 1));
  // Turning points: the rows where η has a local extremum (the event rows, polished to ẏ ≈ 0).
  std::vector<double> z_turn = {l};  // released at y = 0
  for (std::size_t k = 1; k + 1 < eta.size(); ++k)
    if ((eta[k] - eta[k - 1]) * (eta[k + 1] - eta[k]) < 0) z_turn.push_back(l - eta[k] * l);
  REQUIRE(z_turn.size() >= 11);
  // Next turning point from the first integral u(z) = F/(λk) − g z/(k+1) + C z^−k = 0 of the phase
  // that starts at rest at z_t, found by TOMS 748 between z* = F/(λg) and z_t.
  const double z_star = F / (lam * g);
  for (std::size_t i = 0; i + 1 < 11; ++i) {
    const double zt = z_turn[i];
    const double k = zt > z_star ? 1 - f : 1 + f;  // falling (ẏ > 0) above z*, rising below
    const double C = std::pow(zt, k) * (g * zt / (k + 1) - F / (lam * k));
    auto u = [&](double z) { return F / (lam * k) - g * z / (k + 1) + C * std::pow(z, -k); };
    // Bracket on the other side of z*: from z* (u > 0) out to where u < 0 (or the domain's end).
    double a = z_star, b = l;
    if (zt > z_star) {
      b = z_star;
      while (u(b) > 0 && b > 1e-12) b *= 0.5;
    }
    std::uintmax_t iters = 200;
    const auto root = boost::math::tools::toms748_solve(
        u, std::min(a, b), std::max(a, b), boost::math::tools::eps_tolerance<double>(50), iters);
    INFO("turning point " << i + 1);
    CHECK_THAT(z_turn[i + 1], WithinRel(0.5 * (root.first + root.second), 1e-8));
  }
}

TEST_CASE("the recorded series is bounded before the run and keeps the last state", "[hard][reduced]") {
  ReducedSetup s = make(Problem::kFolded, 0.5, 0.01, 0.0);
  s.force = 6;
  s.max_rows = 64;
  const ReducedRun thin = solve_reduced(s);
  s.max_rows = 100000;
  const ReducedRun full = solve_reduced(s);
  REQUIRE(thin.series.rows() <= 64);
  REQUIRE(full.series.rows() > 20000);  // every step: t_max = 50 t0 with steps <= t0/500
  CHECK(thin.summary["sample_stride"].get<std::size_t>() >= full.series.rows() / 64);
  const auto t_thin = thin.series.column("t"), t_full = full.series.column("t");
  CHECK(t_thin.front() == t_full.front());
  CHECK(t_thin.back() == t_full.back());  // the last state, whatever the stride
  CHECK(thin.series.column("eta").back() == full.series.column("eta").back());
  for (std::size_t k = 1; k < t_thin.size(); ++k) CHECK(t_thin[k] > t_thin[k - 1]);
  CHECK(thin.summary["t_stop"] == full.summary["t_stop"]);
}

TEST_CASE("an order-2 method at the default rtol = 1e-13 ends at the step budget, in bounded time",
          "[hard][reduced]") {
  // SDIRK 2 would need ~1e7 steps for this fall (it ran 833 s and wrote 5.7 GB before the budget
  // was enforced): the run now ends after max_steps accepted steps with a diagnostic.
  ReducedSetup s = make(Problem::kFalling, 0.83, 0.01, 1.0);
  s.integrator.method = "dirk2";
  s.integrator.max_steps = 20000;
  try {
    solve_reduced(s);
    FAIL("expected the step budget to end the run");
  } catch (const NumericalError& e) {
    const std::string what = e.what();
    CHECK_THAT(what, Contains("ARK_TOO_MUCH_WORK") && Contains("max_steps = 20000") &&
                         Contains("ARKODE_SDIRK_2_1_2") && Contains("higher-order method"));
    CHECK(e.time() > 0);
    CHECK(e.time() < exact::falling_fall_time(0.83) * s.chain.t0());
  }
}

TEST_CASE("a reduced run honours t_max exactly, whatever its size relative to t0 (issue #21)", "[hard][reduced]") {
  // `chainsim reduced falling --t-max 1e-7` exited 3 "stalled" (the step floor 1e-14 t0 was above
  // the steps such a run takes); `chainsim reduced sliding --t-max 1e-6` stopped at t/t0 = 0.00216,
  // 2000 times past t_max (the sliding branch starts at eta = 1e-6, and t_max counted from there).
  const double f = 0.5;
  for (double tau : {1e-12, 1e-7, 1e-3, 0.5}) {
    CAPTURE(tau);
    ReducedSetup s = make(Problem::kFalling, f, 0.01, 1.0);
    s.t_max_over_t0 = tau;
    const ReducedRun run = solve_reduced(s);
    require_all_finite(run.series);
    REQUIRE(run.summary["stop_reason"] == "t_max");
    CHECK(d(run.summary["t_stop_over_t0"]) == tau);
    CHECK_THAT(d(run.summary["t_stop"]), WithinRel(tau * s.chain.t0(), 1e-15));
    // Released from rest, y = l - g t^2/2 (1 + O(tau^2)): the speed at the stop, |ydot| = g t, to the
    // O((1+f) tau^2) of the next term; and eta against the exact solution where 1 - eta is resolved.
    const double t = tau * s.chain.t0(), ydot = run.series.column("ydot").back();
    CHECK_THAT(ydot, WithinRel(-s.chain.gravity * t, 1e-9 + 2 * tau * tau));
    if (tau >= 1e-3) CHECK_THAT(d(run.summary["eta_stop"]), WithinAbs(exact::falling_eta(f, tau), 1e-12));
  }
  // The sliding chain from eta0 = 0 on its exact branch eta = tau^2/(3 + 2f) (y = a t^2/2, a = g/(3+2f)),
  // before the branch's start at eta = 1e-6 (tau = 0.00224) and after it (integrated).
  for (double tau : {1e-9, 1e-6, 1e-3, 0.01}) {
    CAPTURE(tau);
    ReducedSetup s = make(Problem::kSliding, f, 0.01, 0.0);
    s.t_max_over_t0 = tau;
    const ReducedRun run = solve_reduced(s);
    require_all_finite(run.series);
    REQUIRE(run.summary["stop_reason"] == "t_max");
    CHECK(d(run.summary["t_stop_over_t0"]) == tau);
    CHECK_THAT(d(run.summary["t_stop"]), WithinRel(tau * s.chain.t0(), 1e-15));
    CHECK_THAT(d(run.summary["eta_stop"]), WithinRel(tau * tau / (3 + 2 * f), 1e-9));
    CHECK(run.series.column("t").back() <= tau * s.chain.t0());
  }
  // Where the branch's hanging length would underflow (t_max = 2.2e-162 escaped as an internal
  // "y <= 0"), t_max is refused with its smallest value, and that value runs.
  ReducedSetup tiny = make(Problem::kSliding, f, 0.01, 0.0);
  tiny.t_max_over_t0 = 2.2227587494850775e-162;
  CHECK_THROWS_WITH(solve_reduced(tiny), Contains("--t-max = 2.2227587494850775e-162 is out of range for the sliding "
                                                  "chain from eta0 = 0: allowed t_max >= 2e-75"));
  tiny.t_max_over_t0 = 2e-75;
  CHECK_THAT(d(solve_reduced(tiny).summary["eta_stop"]), WithinRel(4e-150 / (3 + 2 * f), 1e-9));
  // The folded chain too.
  ReducedSetup folded = make(Problem::kFolded, f, 0.01, 0.0);
  folded.t_max_over_t0 = 1e-7;
  const ReducedRun fr = solve_reduced(folded);
  CHECK(fr.summary["stop_reason"] == "t_max");
  CHECK(d(fr.summary["t_stop_over_t0"]) == 1e-7);
}

TEST_CASE("a t_max whose run length t_max t0 is out of the scale range is refused before the run, with its bounds",
          "[hard][reduced]") {
  // `chainsim reduced falling --t-max 1e-200` exited 3 with ARK_ILL_INPUT ("tstop is behind current t"):
  // t_max t0 = 4.5e-201 s rounds onto the start. The run's length is a scale, in [1e-100, 1e100] s.
  for (Problem p : {Problem::kFalling, Problem::kFolded}) {
    for (double tau : {1e-200, 1e-300, 5e-324, 1e101}) {
      CAPTURE(to_string(p), tau);
      ReducedSetup s = make(p, 0.5, 0.01, p == Problem::kFalling ? 1.0 : 0.5);
      s.t_max_over_t0 = tau;
      try {
        solve_reduced(s);
        FAIL("accepted");
      } catch (const InputError& e) {
        const std::string m = e.what();
        CHECK_THAT(m, Catch::Matchers::StartsWith("--t-max = "));
        CHECK_THAT(m, Catch::Matchers::Contains("allowed "));
        CHECK_THAT(m, Catch::Matchers::Contains(" <= t_max <= "));
      }
    }
    // Just inside the range: the run ends at t_max exactly.
    ReducedSetup s = make(p, 0.5, 0.01, p == Problem::kFalling ? 1.0 : 0.5);
    s.t_max_over_t0 = 1e-99;
    const ReducedRun run = solve_reduced(s);
    CHECK(run.summary["stop_reason"] == "t_max");
    CHECK(d(run.summary["t_stop_over_t0"]) == 1e-99);
  }
}

TEST_CASE("a reduced run at g = 1e-100 or l = 1e90 stops at its t_max, a tiny fraction of t0 (issue #21)",
          "[hard][reduced]") {
  // A scene's t_end = 2 s is 1.4e-50 t0 at g = 1e-100 (t0 = 1.4e50 s): it stalled at the step floor 1e-14 t0.
  for (auto [g, l] : {std::pair{1e-100, 1.0}, std::pair{9.81, 1e90}}) {
    CAPTURE(g, l);
    ReducedSetup s = make(Problem::kFalling, 0.5, 0.01, 1.0);
    s.chain.gravity = g;
    s.chain.length = l;
    s.t_max_over_t0 = 2.0 / s.chain.t0();
    const ReducedRun run = solve_reduced(s);
    require_all_finite(run.series);
    REQUIRE(run.summary["stop_reason"] == "t_max");
    CHECK_THAT(d(run.summary["t_stop"]), WithinRel(2.0, 1e-15));
    CHECK_THAT(run.series.column("ydot").back(), WithinRel(-g * 2.0, 1e-9));  // free fall from rest, |ydot| = g t
  }
  // A t_max whose time t_max t0 overflows is refused with the allowed range.
  ReducedSetup huge = make(Problem::kFalling, 0.5, 0.01, 1.0);
  huge.chain.gravity = 1e-100;
  huge.chain.length = 1e100;  // t0 = 1.4e100 s
  huge.t_max_over_t0 = 1e300;
  CHECK_THROWS_WITH(solve_reduced(huge), Contains("--t-max = 1e+300 is out of range") && Contains(" <= t_max <= 0.7071067811865476"));
  // Scales beyond the solver's range are refused with it (l = 5e-324 made the energy scale 0: an internal error).
  ReducedSetup tiny = make(Problem::kFalling, 0.5, 0.01, 1.0);
  tiny.chain.length = 5e-324;
  CHECK_THROWS_WITH(solve_reduced(tiny), "--length = 5e-324 is out of range: allowed 1e-100 <= length <= 1e+100");
  tiny.chain.length = 1e-60;  // each scale in range, but lambda g l^2 = 9.81e-220 J is not
  tiny.chain.density = 1e-100;
  CHECK_THROWS_WITH(solve_reduced(tiny), Contains("the energy scale lambda g l^2 = 9.81") &&
                                             Contains("e-220 J is out of the range the solver can represent"));
}
