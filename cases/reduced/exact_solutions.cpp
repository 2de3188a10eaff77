// Exact references for the reduced chain models of docs/model.md §4; see exact_solutions.hpp.
//
// @sect{The first integrals}
// With u = η'² we have η'' = ½ du/dη, and each reduced equation becomes linear in u:
//
//   falling  (1−f) u + (½ u_η + 2) η = 0       u_η + 2(1−f) u/η = −4,   integrating factor η^(2−2f)
//   folded   (1−f) u + (2 − u_η)(1 − η) = 0    with z = 1 − η:  u_z + (1−f) u/z = −2,   factor z^(1−f)
//   sliding  (1+f) u + (½ u_η − 2) η = 0       u_η + 2(1+f) u/η = 4,    integrating factor η^(2+2f)
//
// and u = 0 at the release point η0 gives the η'² formulas of the header. In terms of the ratio r of
// the distance to the singular end (η for the falling chain, 1 − η for the folded one) to its
// initial value, and of ρ = η0/η for the sliding chain,
//
//   falling  u = 4 η0 / k · r^(2f−2) (1 − r^k),    k = 3 − 2f,  r = η/η0
//   folded   u = 2 z0 / k · r^(f−1)  (1 − r^k),    k = 2 − f,   r = (1−η)/(1−η0), z0 = 1 − η0
//   sliding  u = 4 η / p · (1 − ρ^p),              p = 3 + 2f,  ρ = η0/η
//
// The factors 1 − r^k vanish at the release point and are evaluated from 1 − r (which the callers
// form without cancellation) as −expm1(k log1p(−(1 − r))).
//
// @sect{Removing the singularity of the quadratures}
// Scaling x = η0 s (falling) or 1 − x = z0 s (folded) turns both quadratures into
//
//   ∫_r^1 s^α ds / sqrt(1 − s^k)   with  α = 1−f (falling), (1−f)/2 (folded),
//
// and in both cases (2α + 2)/k − 1 = 1/k. The substitution s^(k/2) = cos φ then removes the
// inverse square root at s = 1 and leaves the bounded integrand
//
//   ∫_r^1 s^α ds / sqrt(1 − s^k) = 2/k ∫_0^φ1 cos(φ)^(1/k) dφ,   cos φ1 = r^(k/2),  sin φ1 = sqrt(1 − r^k),
//
// so that
//
//   falling  ξ = sqrt(η0 / k)     ∫_0^φ1 cos^(1/k) φ dφ
//   folded   ξ = sqrt(2 z0 / k)   ∫_0^φ1 cos^(1/k) φ dφ
//
// (for f = 1, k = 1 and this is sin φ1 = sqrt(1 − r): free fall). For the sliding chain, x = η0 s and
// s^(p/2) = cosh v give x^(1+f) dx / sqrt(x^p − η0^p) = sqrt(η0) · 2/p · cosh(v)^(1/p) dv, so
//
//   sliding  ξ = sqrt(η0 / p)     ∫_0^V cosh^(1/p) v dv,    cosh V = (η/η0)^(p/2),
//
// an entire integrand on a finite interval that also behaves as η0 → 0 (V grows like ½ p ln(η/η0)).
// The only non-smoothness left is cos^(1/k) at φ = π/2 (the falling chain reaching the table, the
// folded chain straightening), a bounded algebraic endpoint singularity that the tanh-sinh rule
// integrates at its usual double-exponential rate. Near that end the integrand is evaluated from
// the distance to the endpoint (the two-argument functor form), so cos φ carries no cancellation.
#include "cases/reduced/exact_solutions.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <string>
#include <utility>

#include <boost/math/quadrature/tanh_sinh.hpp>
#include <boost/math/tools/toms748_solve.hpp>

#include "mesh/chain.hpp"
#include "mesh/errors.hpp"

namespace chainsim::exact {

namespace {

/// The tanh-sinh rule stops refining once two successive levels differ by less than this, relative
/// to ∫|integrand|; the rule converges double-exponentially, so the last level is far more accurate.
constexpr double kQuadratureTolerance = 1e-13;
/// A level difference above this (relative to ∫|integrand|) after all refinements means the rule
/// did not converge: a bug in the substitutions, never the user's input.
constexpr double kQuadratureFailure = 1e-10;
/// The inverses stop when the bracket around η is this narrow relative to η.
constexpr double kRootTolerance = 1e-14;
/// TOMS 748 needs about a dozen evaluations; bisection alone would need ~50 to reach kRootTolerance.
constexpr std::uintmax_t kMaxRootIterations = 200;

/// One tanh-sinh rule for all quadratures: its abscissas and weights are computed once. (Boost
/// 1.74 declares integrate() non-const by a misplaced qualifier, so the object cannot be const.)
boost::math::quadrature::tanh_sinh<double>& tanh_sinh_rule() {
  static boost::math::quadrature::tanh_sinh<double> rule;
  return rule;
}

// @sect{Argument checks}

void check_dissipation(double f) { require_in_range("f", f, 0.0, 1.0); }

void check_falling(double f, double eta0) {
  check_dissipation(f);
  require_in_range("eta0", eta0, 0.0, 1.0, Bound::kOpen, Bound::kClosed);
}

void check_folded(double f, double eta0) {
  check_dissipation(f);
  require_in_range("eta0", eta0, 0.0, 1.0, Bound::kClosed, Bound::kOpen);
}

void check_sliding(double f, double eta0) {
  check_dissipation(f);
  require_in_range("eta0", eta0, 0.0, 1.0);
}

// @sect{Building blocks}

/// 1 − r^k for 0 <= r <= 1, given rc = 1 − r formed by the caller without cancellation.
double one_minus_power(double r, double rc, double k) {
  if (rc < 0.5) return -std::expm1(k * std::log1p(-rc));
  return 1.0 - std::pow(r, k);
}

/// ∫_0^1 g(t, tc) dt by the tanh-sinh rule, where tc is the signed distance to the nearer end
/// (−t near 0, 1 − t near 1). Callers scale their interval to [0, 1] so that the error estimate and
/// ∫|g| that Boost reports refer to the same interval (Boost 1.74 scales one but not the other).
template <class G>
double integrate_unit_interval(const G& g, const char* what) {
  double error = 0.0;
  double l1 = 0.0;
  const double value = tanh_sinh_rule().integrate(g, 0.0, 1.0, kQuadratureTolerance, &error, &l1);
  CHAINSIM_VERIFY(error <= kQuadratureFailure * l1, std::string("tanh-sinh quadrature of ") + what +
                                                        " did not converge");
  return value;
}

/// W = ∫_0^φ1 cos(φ)^(1/k) dφ (k >= 1), where φ1 = π/2 − θ1 is given by its sine and cosine:
/// sin φ1 = sin_phi1 = sqrt(1 − r^k) and cos φ1 = cos_phi1 = r^(k/2).
double cos_power_integral(double k, double sin_phi1, double cos_phi1) {
  if (sin_phi1 == 0.0) return 0.0;
  const double phi1 = std::atan2(sin_phi1, cos_phi1);
  const double theta1 = std::atan2(cos_phi1, sin_phi1);  // π/2 − φ1, without cancellation
  const double exponent = 1.0 / k;
  // φ = φ1 t. Near t = 1, φ1 − φ = φ1 tc and cos φ = sin(θ1 + φ1 tc) stays accurate even when
  // φ1 = π/2, where the integrand vanishes.
  auto integrand = [&](double t, double tc) {
    const double cos_phi = tc > 0.0 ? std::sin(theta1 + phi1 * tc) : std::cos(phi1 * t);
    return std::pow(std::max(cos_phi, 0.0), exponent);
  };
  return phi1 * integrate_unit_interval(integrand, "cos^(1/k)");
}

/// ∫_0^V cosh(v)^(1/p) dv for V >= 0, without overflow for large V.
double cosh_power_integral(double p, double v_end) {
  if (v_end == 0.0) return 0.0;
  const double exponent = 1.0 / p;
  const double ln2 = std::log(2.0);
  // v = V t and log cosh v = v + log(1 + e^(−2v)) − log 2.
  auto integrand = [&](double t, double /*tc*/) {
    const double v = v_end * t;
    return std::exp(exponent * (v + std::log1p(std::exp(-2.0 * v)) - ln2));
  };
  return v_end * integrate_unit_interval(integrand, "cosh^(1/p)");
}

/// ξ-part shared by the falling and folded chains: ∫_0^φ1 cos^(1/k) φ dφ with cos φ1 = r^(k/2),
/// given r and rc = 1 − r.
double release_integral(double k, double r, double rc) {
  return cos_power_integral(k, std::sqrt(one_minus_power(r, rc, k)), std::pow(r, 0.5 * k));
}

/// Solves ξ(η) = xi for η in [eta_lo, eta_hi], where xi_lo = ξ(eta_lo) and xi_hi = ξ(eta_hi) bracket xi
/// (ξ monotone, in either direction).
template <class XiOfEta>
double solve_for_eta(const XiOfEta& xi_of_eta, double xi, double eta_lo, double xi_lo, double eta_hi,
                     double xi_hi) {
  if (xi == xi_lo) return eta_lo;
  if (xi == xi_hi) return eta_hi;
  auto residual = [&](double eta) { return xi_of_eta(eta) - xi; };
  auto narrow_enough = [](double a, double b) {
    return std::abs(b - a) <= kRootTolerance * std::max(std::abs(a), std::abs(b));
  };
  std::uintmax_t iterations = kMaxRootIterations;
  const std::pair<double, double> bracket = boost::math::tools::toms748_solve(
      residual, eta_lo, eta_hi, xi_lo - xi, xi_hi - xi, narrow_enough, iterations);
  CHAINSIM_VERIFY(iterations < kMaxRootIterations, "TOMS 748 did not bracket eta(xi) to 1e-14");
  return 0.5 * (bracket.first + bracket.second);
}

}  // namespace

// @sect{(a) Falling chain}

double falling_eta_prime_squared(double f, double eta, double eta0) {
  check_falling(f, eta0);
  require_in_range("eta", eta, 0.0, eta0);
  const double k = 3.0 - 2.0 * f;
  const double r = eta / eta0;
  const double rc = (eta0 - eta) / eta0;
  // 4 η0/k · r^(2f−2) (1 − r^k); r^0 = 1 also at r = 0 for f = 1, and +inf there for f < 1.
  return 4.0 * eta0 / k * std::pow(r, 2.0 * f - 2.0) * one_minus_power(r, rc, k);
}

double falling_xi(double f, double eta, double eta0) {
  check_falling(f, eta0);
  require_in_range("eta", eta, 0.0, eta0);
  const double k = 3.0 - 2.0 * f;
  return std::sqrt(eta0 / k) * release_integral(k, eta / eta0, (eta0 - eta) / eta0);
}

double falling_fall_time(double f, double eta0) { return falling_xi(f, 0.0, eta0); }

double falling_P(double f, double eta, double eta0) {
  const double u = falling_eta_prime_squared(f, eta, eta0);
  const double table_reaction = f == 0.0 ? 0.0 : 0.5 * f * u;  // f = 0: no reaction even where u = inf
  return table_reaction + 1.0 - eta;
}

double falling_eta(double f, double xi, double eta0) {
  const double fall_time = falling_fall_time(f, eta0);  // also checks f and eta0
  require_in_range("xi", xi, 0.0, fall_time);
  // ξ decreases from the fall time at η = 0 to 0 at η = η0.
  return solve_for_eta([&](double eta) { return falling_xi(f, eta, eta0); }, xi, 0.0, fall_time, eta0, 0.0);
}

// @sect{(b) Folded chain}

double folded_eta_prime_squared(double f, double eta, double eta0) {
  check_folded(f, eta0);
  require_in_range("eta", eta, eta0, 1.0);
  const double k = 2.0 - f;
  const double z0 = 1.0 - eta0;
  const double r = (1.0 - eta) / z0;
  const double rc = (eta - eta0) / z0;
  // 2 z0/k · r^(f−1) (1 − r^k); r^0 = 1 also at r = 0 for f = 1, and +inf there for f < 1.
  return 2.0 * z0 / k * std::pow(r, f - 1.0) * one_minus_power(r, rc, k);
}

double folded_xi(double f, double eta, double eta0) {
  check_folded(f, eta0);
  require_in_range("eta", eta, eta0, 1.0);
  const double k = 2.0 - f;
  const double z0 = 1.0 - eta0;
  return std::sqrt(2.0 * z0 / k) * release_integral(k, (1.0 - eta) / z0, (eta - eta0) / z0);
}

double folded_fall_time(double f, double eta0) { return folded_xi(f, 1.0, eta0); }

double folded_P(double f, double eta, double eta0) {
  return 0.5 * (1.0 + f) * folded_eta_prime_squared(f, eta, eta0) + eta;
}

double folded_eta(double f, double xi, double eta0) {
  const double fall_time = folded_fall_time(f, eta0);  // also checks f and eta0
  require_in_range("xi", xi, 0.0, fall_time);
  return solve_for_eta([&](double eta) { return folded_xi(f, eta, eta0); }, xi, eta0, 0.0, 1.0, fall_time);
}

// @sect{(c) Sliding chain}

double sliding_eta_prime_squared(double f, double eta, double eta0) {
  check_sliding(f, eta0);
  require_in_range("eta", eta, eta0, 1.0);
  if (eta == 0.0) return 0.0;  // η0 = 0 and the chain has not started
  const double p = 3.0 + 2.0 * f;
  // 4 η/p · (1 − ρ^p), ρ = η0/η; η0 = 0 gives the special solution's 4 η/p.
  return 4.0 * eta / p * one_minus_power(eta0 / eta, (eta - eta0) / eta, p);
}

double sliding_xi(double f, double eta, double eta0) {
  check_sliding(f, eta0);
  require_in_range("eta", eta, eta0, 1.0);
  const double p = 3.0 + 2.0 * f;
  if (eta0 == 0.0) return std::sqrt(p * eta);  // y = ½ g t²/(3+2f)
  // c = ½ p ln(η/η0) >= 0 and V = acosh(e^c) = c + ln(1 + sqrt(1 − e^(−2c))), both without
  // cancellation near η = η0 and without overflow for tiny η0.
  const double log_ratio = eta < 2.0 * eta0 ? std::log1p((eta - eta0) / eta0) : std::log(eta) - std::log(eta0);
  const double c = 0.5 * p * log_ratio;
  const double v_end = c + std::log1p(std::sqrt(-std::expm1(-2.0 * c)));
  return std::sqrt(eta0 / p) * cosh_power_integral(p, v_end);
}

double sliding_fall_time(double f, double eta0) { return sliding_xi(f, 1.0, eta0); }

double sliding_P(double f, double eta, double eta0) {
  return 0.5 * f * sliding_eta_prime_squared(f, eta, eta0) + 1.0 - eta;
}

double sliding_eta(double f, double xi, double eta0) {
  const double fall_time = sliding_fall_time(f, eta0);  // also checks f and eta0
  require_in_range("xi", xi, 0.0, fall_time);
  const double p = 3.0 + 2.0 * f;
  if (eta0 == 0.0) return std::min(xi * xi / p, 1.0);  // the special solution, inverted exactly
  return solve_for_eta([&](double eta) { return sliding_xi(f, eta, eta0); }, xi, eta0, 0.0, 1.0, fall_time);
}

// @sect{A chain sliding off a table over an edge}
// With u = ẋ², ℓ ẍ = g x − f u becomes u_x + (2f/ℓ) u = 2 g x/ℓ, integrating factor e^(2fx/ℓ); with
// u(x0) = 0 this is the header's form. ψ1 and ψ2 are evaluated from their series below z = 0.1
// (z + expm1(−z) loses digits there). The time t = ∫ dx/√u with x = x0 + w² is
// t = ∫_0^√(x−x0) 2 dw / √(g (2 Δ ψ2 + 2 X0 ψ1)): a bounded, smooth integrand for x0 > 0.

namespace {

void check_edge(double f, double x0, double ell, double g) {
  check_dissipation(f);
  require_in_range("ell", ell, 0.0, 1e100, Bound::kOpen, Bound::kClosed);
  require_in_range("g", g, 0.0, 1e100, Bound::kOpen, Bound::kClosed);
  require_in_range("x0", x0, 0.0, ell, Bound::kOpen, Bound::kOpen);
}

double psi1(double z) {
  if (z < 0.1) return 1 - z / 2 * (1 - z / 3 * (1 - z / 4 * (1 - z / 5 * (1 - z / 6 * (1 - z / 7 * (1 - z / 8))))));
  return -std::expm1(-z) / z;
}

double psi2(double z) {
  if (z < 0.1)
    return 0.5 * (1 - z / 3 * (1 - z / 4 * (1 - z / 5 * (1 - z / 6 * (1 - z / 7 * (1 - z / 8 * (1 - z / 9)))))));
  return (z + std::expm1(-z)) / (z * z);
}

/// ẋ² / w² with w² = x − x0: g (2 Δ ψ2 + 2 X0 ψ1), Δ = w²/ℓ.
double edge_speed_squared_over_w2(double f, double w2, double x0, double ell, double g) {
  const double d = w2 / ell, z = 2 * f * d;
  return g * (2 * d * psi2(z) + 2 * (x0 / ell) * psi1(z));
}

}  // namespace

double edge_speed_squared(double f, double x, double x0, double ell, double g) {
  check_edge(f, x0, ell, g);
  require_in_range("x", x, x0, ell);
  return (x - x0) * edge_speed_squared_over_w2(f, x - x0, x0, ell, g);
}

namespace {

/// The time a motion released at rest takes to travel d = x - x0, given its squared speed u as u / w2 of
/// w2 = x - x0 (finite at the start): t = ∫ dx / sqrt(u) = ∫_0^sqrt(d) 2 dw / sqrt(u / w²), which has no
/// singularity at the release.
template <class SpeedOverW2>
double time_from_rest(double d, SpeedOverW2 speed_squared_over_w2, const char* what) {
  const double w_end = std::sqrt(d);
  if (w_end == 0.0) return 0.0;
  auto integrand = [&](double t, double /*tc*/) {
    const double w = w_end * t;
    return 2 / std::sqrt(speed_squared_over_w2(w * w));
  };
  return w_end * integrate_unit_interval(integrand, what);
}

}  // namespace

double edge_acceleration(double f, double x, double x0, double ell, double g) {
  return (g * x - f * edge_speed_squared(f, x, x0, ell, g)) / ell;
}

double edge_time(double f, double x, double x0, double ell, double g) {
  check_edge(f, x0, ell, g);
  require_in_range("x", x, x0, ell);
  return time_from_rest(x - x0, [&](double w2) { return edge_speed_squared_over_w2(f, w2, x0, ell, g); },
                        "the edge's 1/sqrt(u)");
}

double edge_x(double f, double t, double x0, double ell, double g) {
  const double t_end = edge_time(f, ell, x0, ell, g);
  require_in_range("t", t, 0.0, t_end);
  return solve_for_eta([&](double x) { return edge_time(f, x, x0, ell, g); }, t, x0, 0.0, ell, t_end);
}

namespace {

/// The zero of a lift-off margin in [x0, ℓ] (positive at x0, not positive at ℓ), by TOMS 748 to 1e-14.
template <class Margin>
double lift_off_root(const Margin& margin, double x0, double ell) {
  auto narrow_enough = [](double a, double b) {
    return std::abs(b - a) <= kRootTolerance * std::max(std::abs(a), std::abs(b));
  };
  std::uintmax_t iterations = kMaxRootIterations;
  const std::pair<double, double> bracket =
      boost::math::tools::toms748_solve(margin, x0, ell, margin(x0), margin(ell), narrow_enough, iterations);
  CHAINSIM_VERIFY(iterations < kMaxRootIterations, "TOMS 748 did not bracket the lift-off point to 1e-14");
  return 0.5 * (bracket.first + bracket.second);
}

}  // namespace

double edge_lift_off_x(double f, double x0, double ell, double g) {
  check_edge(f, x0, ell, g);
  // g x (ℓ − x) − ẋ² (ℓ + f (ℓ − x)): g x0 (ℓ − x0) > 0 at x0, −ẋ² ℓ < 0 at ℓ.
  return lift_off_root(
      [&](double x) { return g * x * (ell - x) - edge_speed_squared(f, x, x0, ell, g) * (ell + f * (ell - x)); }, x0,
      ell);
}

// @sect{The heavy Atwood chain over a peg}
// With u = ẋ², ℓ ẍ = g (2x − ℓ) − 2 f u becomes u_x + (4f/ℓ) u = 2 g (2x − ℓ)/ℓ, integrating factor
// e^(4fx/ℓ); with u(x0) = 0 and 2ξ − ℓ = (2 x0 − ℓ) + 2 (ξ − x0) under the integral, the two integrals
// are those of the edge: Δ ψ1(z) and Δ² ψ2(z), z = 4 f Δ/ℓ. The time is the edge's quadrature, with
// x = x0 + w²: u/w² = (2g/ℓ) ((2 x0 − ℓ) ψ1 + 2 Δ ψ2) is smooth and positive for x0 > ℓ/2.

namespace {

void check_peg(double f, double x0, double ell, double g) {
  check_dissipation(f);
  require_in_range("ell", ell, 0.0, 1e100, Bound::kOpen, Bound::kClosed);
  require_in_range("g", g, 0.0, 1e100, Bound::kOpen, Bound::kClosed);
  require_in_range("x0", x0, 0.5 * ell, ell, Bound::kOpen, Bound::kOpen);
}

/// ẋ² / w² with w² = x − x0.
double peg_speed_squared_over_w2(double f, double w2, double x0, double ell, double g) {
  const double z = 4 * f * w2 / ell;
  return 2 * g / ell * ((2 * x0 - ell) * psi1(z) + 2 * w2 * psi2(z));
}

}  // namespace

double peg_speed_squared(double f, double x, double x0, double ell, double g) {
  check_peg(f, x0, ell, g);
  require_in_range("x", x, x0, ell);
  return (x - x0) * peg_speed_squared_over_w2(f, x - x0, x0, ell, g);
}

double peg_acceleration(double f, double x, double x0, double ell, double g) {
  return (g * (2 * x - ell) - 2 * f * peg_speed_squared(f, x, x0, ell, g)) / ell;
}

double peg_time(double f, double x, double x0, double ell, double g) {
  check_peg(f, x0, ell, g);
  require_in_range("x", x, x0, ell);
  return time_from_rest(x - x0, [&](double w2) { return peg_speed_squared_over_w2(f, w2, x0, ell, g); },
                        "the peg's 1/sqrt(u)");
}

double peg_x(double f, double t, double x0, double ell, double g) {
  const double t_end = peg_time(f, ell, x0, ell, g);
  require_in_range("t", t, 0.0, t_end);
  return solve_for_eta([&](double x) { return peg_time(f, x, x0, ell, g); }, t, x0, 0.0, ell, t_end);
}

double peg_lift_off_x(double f, double x0, double ell, double g) {
  check_peg(f, x0, ell, g);
  // (ℓ − x)(g + ẍ) − (1 − f) ẋ², half the reaction per λ: 2 g x0 (ℓ − x0)/ℓ > 0 at x0, −(1 − f) ẋ² at ℓ.
  auto margin = [&](double x) {
    return (ell - x) * (g + peg_acceleration(f, x, x0, ell, g)) - (1 - f) * peg_speed_squared(f, x, x0, ell, g);
  };
  if (margin(ell) >= 0) return ell;  // f = 1: the peg still pushes when the shorter end arrives (g x > ẋ²)
  return lift_off_root(margin, x0, ell);
}

double pulley_u(double t, double u0, double ell, double g) { return u0 * std::cosh(std::sqrt(2 * g / ell) * t); }

double pulley_u_dot(double t, double u0, double ell, double g) {
  const double omega = std::sqrt(2 * g / ell);
  return u0 * omega * std::sinh(omega * t);
}

double pulley_time(double u, double u0, double ell, double g) {
  CHAINSIM_VERIFY(u0 > 0 && u >= u0, "pulley_time needs u >= u0 > 0");
  return std::acosh(u / u0) / std::sqrt(2 * g / ell);
}

double pulley_lift_off_u(double u0, double radius, double ell) {
  const double free = ell - kPi * radius;
  CHAINSIM_VERIFY(radius > 0 && free > 0 && u0 > 0 && u0 < 0.5 * free, "pulley_lift_off_u: out of range");
  const double b = kPi * radius, c = 0.5 * ell * free + 2 * u0 * u0;
  // 4 u² + b u − c = 0, c > 0: the positive root, written without cancellation.
  return 2 * c / (b + std::sqrt(b * b + 16 * c));
}

}  // namespace chainsim::exact
