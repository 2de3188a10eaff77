// Independent checks of the exact references in cases/reduced/exact_solutions.hpp (docs/model.md §4).
//
// The implementation evaluates ξ(η) by tanh-sinh quadrature after sin/cosh substitutions. Here every
// quadrature is instead written as an incomplete Beta function and evaluated with Boost's
// beta/ibeta/ibetac (used in these tests only):
//
//  (a) falling, w = (x/η0)^k, k = 3−2f, a = (2−f)/k:
//        ∫_η^η0 dx / sqrt(η0^k x^(2f−2) − x) = sqrt(η0)/k · B(a,½) (1 − I_w1(a,½)),  w1 = (η/η0)^k
//  (b) folded, z = 1−x, z0 = 1−η0, w = (z/z0)^k, k = 2−f, a = (3−f)/(2k):
//        ∫_η0^η dx / sqrt(z0^k (1−x)^(f−1) − 1 + x) = sqrt(z0)/k · B(a,½) (1 − I_w1(a,½)),  w1 = ((1−η)/z0)^k
//  (c) sliding, w = (η0/x)^p, p = 3+2f: the Beta parameter is a = −1/(2p) < 0, outside ibeta's domain;
//      one integration by parts, using d[w^a (1−w)^½] = a w^(a−1) (1−w)^½ dw − ½ w^a (1−w)^(−½) dw, gives
//        ξ = sqrt(p η (1 − w1)) − (p−1)/(2p) · sqrt(p η0) · B(b,½) (1 − I_w1(b,½)),  b = 1 − 1/(2p),  w1 = (η0/η)^p
//      (which tends to sqrt(p η) as η0 → 0, the special solution).
//
// The other checks: the classical special values, the closed forms of P/P0, the ODEs themselves
// (η'' = ½ d(η'²)/dη by central differences), dξ/dη = 1/|η'|, the inverses, and argument checking.
#include <catch2/catch.hpp>

#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

#include <boost/math/special_functions/beta.hpp>

#include "cases/reduced/exact_solutions.hpp"
#include "mesh/errors.hpp"

namespace {

namespace exact = chainsim::exact;
using Catch::Matchers::Contains;
using Catch::Matchers::WithinAbs;
using Catch::Matchers::WithinRel;

/// The accuracy the references promise: quadrature against Boost's incomplete Beta functions.
constexpr double kBetaRelTol = 1e-12;
/// Closed forms evaluated directly (free fall, special solution): a few ulps of rounding.
constexpr double kClosedFormRelTol = 1e-14;
/// P/P0 is O(1); closed forms of P cancel near the release point, which costs a few ulps absolute.
constexpr double kPAbsTol = 1e-13;
/// Central-difference step relative to the distance d from the singular end (η'² varies on the
/// scale d): truncation ~ (h/d)² ~ 1e-10, rounding ~ ε d/h ~ 1e-11, both relative.
constexpr double kDiffStep = 1e-5;
/// ODE residual relative to the size of its terms, with η'' from such a central difference.
constexpr double kOdeResidualTol = 1e-7;
/// dξ/dη by central differences of two quadratures accurate to ~1e-15: rounding ~ 1e-15 d/h.
constexpr double kSlopeRelTol = 1e-7;
/// Inverse then forward (or forward then inverse): root finder stops at 1e-14 relative in η.
constexpr double kRoundTripAbsTol = 1e-12;
/// ξ(η(ξ)) is well conditioned everywhere (ξ is flat where η is not): rounding of two quadratures.
constexpr double kInverseXiRelTol = 1e-13;
/// η0 → 0 limit of the sliding fall time: the gap shrinks like sqrt(η0), checked to 1%.
constexpr double kRateRelTol = 1e-2;

const std::vector<double> kDissipations = {0.0, 0.25, 0.5, 0.83, 1.0};

/// Worst relative error of any ξ against its Beta form, reported at the end of that test.
double worst_beta_error = 0.0;

void record_beta_error(double value, double reference) {
  if (reference != 0.0) worst_beta_error = std::max(worst_beta_error, std::abs(value - reference) / reference);
}

/// 1 − (1 − d)^k, accurate when d is small.
double one_minus_complement_power(double d, double k) { return -std::expm1(k * std::log1p(-d)); }

/// ∫_w1^1 w^(a−1) (1−w)^(−½) dw = B(a,½) (1 − I_w1(a,½)), given w1 and w1c = 1 − w1. Next to w1 = 1
/// the reflected form I_w1c(½, a) is used, so that the small 1 − w1 enters without rounding.
double upper_beta(double a, double w1, double w1c) {
  const double tail = w1c < 0.5 ? boost::math::ibeta(0.5, a, w1c) : boost::math::ibetac(a, 0.5, w1);
  return boost::math::beta(a, 0.5) * tail;
}

double falling_xi_beta(double f, double eta, double eta0) {
  const double k = 3.0 - 2.0 * f;
  const double a = (2.0 - f) / k;
  const double w1 = std::pow(eta / eta0, k);
  const double w1c = one_minus_complement_power((eta0 - eta) / eta0, k);
  return 0.5 * std::sqrt(k) * std::sqrt(eta0) / k * upper_beta(a, w1, w1c);
}

double folded_xi_beta(double f, double eta, double eta0) {
  const double k = 2.0 - f;
  const double a = (3.0 - f) / (2.0 * k);
  const double z0 = 1.0 - eta0;
  const double w1 = std::pow((1.0 - eta) / z0, k);
  const double w1c = one_minus_complement_power((eta - eta0) / z0, k);
  return std::sqrt(1.0 - 0.5 * f) * std::sqrt(z0) / k * upper_beta(a, w1, w1c);
}

double sliding_xi_beta(double f, double eta, double eta0) {
  const double p = 3.0 + 2.0 * f;
  const double b = 1.0 - 0.5 / p;
  const double w1 = std::pow(eta0 / eta, p);
  const double w1c = one_minus_complement_power((eta - eta0) / eta, p);
  return std::sqrt(p * eta * w1c) - (p - 1.0) / (2.0 * p) * std::sqrt(p * eta0) * upper_beta(b, w1, w1c);
}

/// Points of [lo, hi] including both ends, the two points 1e-10 inside them and a spread between.
std::vector<double> grid(double lo, double hi) {
  std::vector<double> points = {lo, lo + 1e-10, hi - 1e-10, hi};
  for (double s : {1e-6, 1e-3, 0.1, 0.3, 0.5, 0.7, 0.9, 0.999}) points.push_back(lo + s * (hi - lo));
  return points;
}

/// η'' = ½ d(η'²)/dη by a central difference with step kDiffStep · d.
template <class U>
double second_derivative(const U& eta_prime_squared, double eta, double d) {
  const double h = kDiffStep * d;
  return 0.5 * (eta_prime_squared(eta + h) - eta_prime_squared(eta - h)) / (2.0 * h);
}

/// dξ/dη by a central difference with step kDiffStep · d.
template <class Xi>
double slope(const Xi& xi, double eta, double d) {
  const double h = kDiffStep * d;
  return (xi(eta + h) - xi(eta - h)) / (2.0 * h);
}

/// The call throws chainsim::InputError whose message names `what` (e.g. "f = 1.5") and `range`.
template <class Call>
void require_input_error(const Call& call, const std::string& what, const std::string& range) {
  REQUIRE_THROWS_AS(call(), chainsim::InputError);
  REQUIRE_THROWS_WITH(call(), Contains(what) && Contains(range));
}

}  // namespace

TEST_CASE("xi(eta) agrees with the incomplete-Beta forms", "[problems][exact]") {
  worst_beta_error = 0.0;
  for (double f : kDissipations) {
    for (double eta0 : {1.0, 0.7, 0.3}) {
      for (double eta : grid(0.0, eta0)) {
        CAPTURE(f, eta0, eta);
        const double reference = falling_xi_beta(f, eta, eta0);
        const double xi = exact::falling_xi(f, eta, eta0);
        record_beta_error(xi, reference);
        CHECK_THAT(xi, WithinRel(reference, kBetaRelTol));
      }
      CHECK_THAT(exact::falling_fall_time(f, eta0), WithinRel(falling_xi_beta(f, 0.0, eta0), kBetaRelTol));
    }
    for (double eta0 : {0.0, 0.3, 0.7}) {
      for (double eta : grid(eta0, 1.0)) {
        CAPTURE(f, eta0, eta);
        const double reference = folded_xi_beta(f, eta, eta0);
        const double xi = exact::folded_xi(f, eta, eta0);
        record_beta_error(xi, reference);
        CHECK_THAT(xi, WithinRel(reference, kBetaRelTol));
      }
      CHECK_THAT(exact::folded_fall_time(f, eta0), WithinRel(folded_xi_beta(f, 1.0, eta0), kBetaRelTol));
    }
    for (double eta0 : {1e-8, 0.01, 0.25, 0.75}) {
      for (double eta : grid(eta0, 1.0)) {
        CAPTURE(f, eta0, eta);
        const double reference = sliding_xi_beta(f, eta, eta0);
        const double xi = exact::sliding_xi(f, eta, eta0);
        record_beta_error(xi, reference);
        CHECK_THAT(xi, WithinRel(reference, kBetaRelTol));
      }
      CHECK_THAT(exact::sliding_fall_time(f, eta0), WithinRel(sliding_xi_beta(f, 1.0, eta0), kBetaRelTol));
    }
  }
  WARN("worst relative error of xi against the incomplete-Beta references: " << worst_beta_error);
}

TEST_CASE("xi vanishes at the release point", "[problems][exact]") {
  for (double f : kDissipations) {
    CHECK(exact::falling_xi(f, 0.6, 0.6) == 0.0);
    CHECK(exact::folded_xi(f, 0.4, 0.4) == 0.0);
    CHECK(exact::sliding_xi(f, 0.2, 0.2) == 0.0);
    CHECK(exact::sliding_xi(f, 0.0, 0.0) == 0.0);
    CHECK(exact::sliding_fall_time(f, 1.0) == 0.0);
  }
}

TEST_CASE("classical special values", "[problems][exact]") {
  SECTION("falling chain, f = 1: free fall, xi = sqrt(1 - eta), t_f = t0") {
    for (double eta : grid(0.0, 1.0)) {
      CAPTURE(eta);
      CHECK_THAT(exact::falling_xi(1.0, eta), WithinRel(std::sqrt(1.0 - eta), kClosedFormRelTol));
    }
    CHECK_THAT(exact::falling_fall_time(1.0), WithinRel(1.0, kClosedFormRelTol));
  }
  SECTION("folded chain, f = 1, eta0 = 0: the tip falls freely, xi = sqrt(2 eta), t_f = sqrt(2) t0") {
    for (double eta : grid(0.0, 1.0)) {
      CAPTURE(eta);
      CHECK_THAT(exact::folded_xi(1.0, eta), WithinRel(std::sqrt(2.0 * eta), kClosedFormRelTol));
    }
    CHECK_THAT(exact::folded_fall_time(1.0), WithinRel(std::sqrt(2.0), kClosedFormRelTol));
  }
  SECTION("sliding chain: eta0 = 0 is the special solution, and eta0 -> 0 tends to it like sqrt(eta0)") {
    for (double f : kDissipations) {
      CAPTURE(f);
      const double p = 3.0 + 2.0 * f;
      CHECK_THAT(exact::sliding_fall_time(f, 0.0), WithinRel(std::sqrt(p), kClosedFormRelTol));
      CHECK_THAT(exact::sliding_xi(f, 0.36, 0.0), WithinRel(std::sqrt(p * 0.36), kClosedFormRelTol));
      // From the Beta form: t_f/t0 = sqrt(p) − C sqrt(η0) + O(η0^(p−½)), C = (p−1)/(2p) sqrt(p) B(1−1/(2p), ½).
      const double C = (p - 1.0) / (2.0 * p) * std::sqrt(p) * boost::math::beta(1.0 - 0.5 / p, 0.5);
      const double gap_6 = std::sqrt(p) - exact::sliding_fall_time(f, 1e-6);
      const double gap_8 = std::sqrt(p) - exact::sliding_fall_time(f, 1e-8);
      CHECK(gap_8 > 0.0);
      CHECK(gap_8 < gap_6);
      CHECK_THAT(gap_6 / gap_8, WithinRel(10.0, kRateRelTol));
      CHECK_THAT(gap_8 / std::sqrt(1e-8), WithinRel(C, kRateRelTol));
    }
  }
  SECTION("dynamic weight: falling f = 0 gives 1 - eta, f = 1 gives 3(1 - eta); folded f = 1 gives 3 eta") {
    for (double eta : grid(0.0, 1.0)) {
      CAPTURE(eta);
      CHECK_THAT(exact::falling_P(0.0, eta), WithinAbs(1.0 - eta, kPAbsTol));
      CHECK_THAT(exact::falling_P(1.0, eta), WithinAbs(3.0 * (1.0 - eta), kPAbsTol));
      CHECK_THAT(exact::folded_P(1.0, eta), WithinAbs(3.0 * eta, kPAbsTol));
    }
  }
  SECTION("the speeds diverge at the far end for f < 1 and stay finite for f = 1") {
    for (double f : {0.0, 0.5, 0.83}) {
      CHECK(std::isinf(exact::falling_eta_prime_squared(f, 0.0)));
      CHECK(std::isinf(exact::folded_eta_prime_squared(f, 1.0)));
    }
    CHECK(std::isinf(exact::falling_P(0.5, 0.0)));
    CHECK_THAT(exact::falling_eta_prime_squared(1.0, 0.0, 0.8), WithinRel(4.0 * 0.8, kClosedFormRelTol));
    CHECK_THAT(exact::folded_eta_prime_squared(1.0, 1.0, 0.2), WithinRel(2.0 * 0.8, kClosedFormRelTol));
  }
}

TEST_CASE("P/P0 against the closed forms of docs/model.md section 4", "[problems][exact]") {
  for (double f : kDissipations) {
    // Stay off the far ends, where the falling and folded P diverge for f < 1.
    for (double s : {0.01, 0.2, 0.5, 0.8, 0.99, 1.0}) {
      CAPTURE(f, s);
      {  // falling, η0 = 1: P/P0 = 1 + (2 f η^(2(f−1)) − 3η)/(3 − 2f)
        const double eta = s;
        const double closed = 1.0 + (2.0 * f * std::pow(eta, 2.0 * (f - 1.0)) - 3.0 * eta) / (3.0 - 2.0 * f);
        CHECK_THAT(exact::falling_P(f, eta), WithinAbs(closed, kPAbsTol * std::max(1.0, closed)));
      }
      {  // falling, η0 = 0.6: P/P0 = ½ f η'² + 1 − η with the first integral written out
        const double eta0 = 0.6;
        const double eta = s * eta0;
        const double k = 3.0 - 2.0 * f;
        const double closed =
            1.0 - eta + 2.0 * f / k * (std::pow(eta0, k) * std::pow(eta, 2.0 * f - 2.0) - eta);
        CHECK_THAT(exact::falling_P(f, eta, eta0), WithinAbs(closed, kPAbsTol * std::max(1.0, closed)));
      }
      for (double eta0 : {0.0, 0.4}) {  // folded: (1+f)/(2−f) [(1−η0)^(2−f) (1−η)^(f−1) − 1 + η] + η
        const double eta = 1.0 - s * (1.0 - eta0);
        const double closed =
            (1.0 + f) / (2.0 - f) * (std::pow(1.0 - eta0, 2.0 - f) * std::pow(1.0 - eta, f - 1.0) - 1.0 + eta) + eta;
        CHECK_THAT(exact::folded_P(f, eta, eta0), WithinAbs(closed, kPAbsTol * std::max(1.0, closed)));
      }
      for (double eta0 : {0.0, 0.3}) {  // sliding: 1 − η + 2f/(3+2f) (η − η0^(3+2f) η^(−2−2f))
        const double eta = eta0 + s * (1.0 - eta0);
        const double p = 3.0 + 2.0 * f;
        const double closed = 1.0 - eta + 2.0 * f / p * (eta - std::pow(eta0, p) * std::pow(eta, -2.0 - 2.0 * f));
        CHECK_THAT(exact::sliding_P(f, eta, eta0), WithinAbs(closed, kPAbsTol));
      }
    }
  }
}

TEST_CASE("the first integrals satisfy the reduced ODEs and the initial conditions", "[problems][exact]") {
  for (double f : kDissipations) {
    CAPTURE(f);
    SECTION("falling: (1-f) eta'^2 + (eta'' + 2) eta = 0, eta'(eta0) = 0") {
      for (double eta0 : {1.0, 0.5}) {
        CHECK(exact::falling_eta_prime_squared(f, eta0, eta0) == 0.0);
        auto u = [&](double eta) { return exact::falling_eta_prime_squared(f, eta, eta0); };
        for (double s : {0.05, 0.3, 0.6, 0.95}) {
          const double eta = s * eta0;
          CAPTURE(eta0, eta);
          const double acceleration = second_derivative(u, eta, std::min(eta, eta0 - eta));
          const double scale = (1.0 - f) * u(eta) + (std::abs(acceleration) + 2.0) * eta;
          const double residual = (1.0 - f) * u(eta) + (acceleration + 2.0) * eta;
          CHECK_THAT(residual / scale, WithinAbs(0.0, kOdeResidualTol));
        }
      }
    }
    SECTION("folded: (1-f) eta'^2 + 2 (1 - eta'')(1 - eta) = 0, eta'(eta0) = 0") {
      for (double eta0 : {0.0, 0.5}) {
        CHECK(exact::folded_eta_prime_squared(f, eta0, eta0) == 0.0);
        auto u = [&](double eta) { return exact::folded_eta_prime_squared(f, eta, eta0); };
        for (double s : {0.05, 0.3, 0.6, 0.95}) {
          const double eta = eta0 + s * (1.0 - eta0);
          CAPTURE(eta0, eta);
          const double acceleration = second_derivative(u, eta, std::min(1.0 - eta, eta - eta0));
          const double scale = (1.0 - f) * u(eta) + 2.0 * (1.0 + std::abs(acceleration)) * (1.0 - eta);
          const double residual = (1.0 - f) * u(eta) + 2.0 * (1.0 - acceleration) * (1.0 - eta);
          CHECK_THAT(residual / scale, WithinAbs(0.0, kOdeResidualTol));
        }
      }
    }
    SECTION("sliding: (1+f) eta'^2 + (eta'' - 2) eta = 0, eta'(eta0) = 0") {
      for (double eta0 : {0.0, 0.1, 0.5}) {
        CHECK(exact::sliding_eta_prime_squared(f, eta0, eta0) == 0.0);
        auto u = [&](double eta) { return exact::sliding_eta_prime_squared(f, eta, eta0); };
        for (double s : {0.05, 0.3, 0.6, 0.95}) {
          const double eta = eta0 + s * (1.0 - eta0);
          CAPTURE(eta0, eta);
          const double acceleration = second_derivative(u, eta, std::min(eta, eta - eta0));
          const double scale = (1.0 + f) * u(eta) + (std::abs(acceleration) + 2.0) * eta;
          const double residual = (1.0 + f) * u(eta) + (acceleration - 2.0) * eta;
          CHECK_THAT(residual / scale, WithinAbs(0.0, kOdeResidualTol));
        }
      }
    }
  }
}

TEST_CASE("xi(eta) and eta'^2 describe the same motion: d xi / d eta = 1/|eta'|", "[problems][exact]") {
  for (double f : kDissipations) {
    for (double s : {0.1, 0.5, 0.9}) {
      CAPTURE(f, s);
      {
        const double eta0 = 0.8;
        const double eta = s * eta0;
        auto xi = [&](double e) { return exact::falling_xi(f, e, eta0); };
        const double expected = -1.0 / std::sqrt(exact::falling_eta_prime_squared(f, eta, eta0));
        CHECK_THAT(slope(xi, eta, std::min(eta, eta0 - eta)), WithinRel(expected, kSlopeRelTol));
      }
      {
        const double eta0 = 0.2;
        const double eta = eta0 + s * (1.0 - eta0);
        auto xi = [&](double e) { return exact::folded_xi(f, e, eta0); };
        const double expected = 1.0 / std::sqrt(exact::folded_eta_prime_squared(f, eta, eta0));
        CHECK_THAT(slope(xi, eta, std::min(1.0 - eta, eta - eta0)), WithinRel(expected, kSlopeRelTol));
      }
      {
        const double eta0 = 0.2;
        const double eta = eta0 + s * (1.0 - eta0);
        auto xi = [&](double e) { return exact::sliding_xi(f, e, eta0); };
        const double expected = 1.0 / std::sqrt(exact::sliding_eta_prime_squared(f, eta, eta0));
        CHECK_THAT(slope(xi, eta, eta - eta0), WithinRel(expected, kSlopeRelTol));
      }
    }
  }
}

TEST_CASE("the inverses eta(xi) round-trip", "[problems][exact]") {
  // Away from the far ends of the falling and folded chains, where η'² diverges for f < 1 and an
  // ulp of ξ moves η by |η'| ulps.
  const std::vector<double> fractions = {0.0, 1e-10, 0.01, 0.2, 0.5, 0.8, 0.99};
  for (double f : kDissipations) {
    for (double s : fractions) {
      CAPTURE(f, s);
      {
        const double eta0 = 0.9;
        const double eta = eta0 * (1.0 - s);
        CHECK_THAT(exact::falling_eta(f, exact::falling_xi(f, eta, eta0), eta0), WithinAbs(eta, kRoundTripAbsTol));
      }
      for (double eta0 : {0.0, 0.3}) {
        const double eta = eta0 + s * (1.0 - eta0);
        CHECK_THAT(exact::folded_eta(f, exact::folded_xi(f, eta, eta0), eta0), WithinAbs(eta, kRoundTripAbsTol));
      }
      for (double eta0 : {0.0, 0.05, 0.6}) {
        const double eta = eta0 + s * (1.0 - eta0);
        CHECK_THAT(exact::sliding_eta(f, exact::sliding_xi(f, eta, eta0), eta0), WithinAbs(eta, kRoundTripAbsTol));
      }
    }
    // The ends of the ξ range map to the ends of the η range exactly.
    CHECK(exact::falling_eta(f, 0.0, 0.9) == 0.9);
    CHECK(exact::falling_eta(f, exact::falling_fall_time(f, 0.9), 0.9) == 0.0);
    CHECK(exact::folded_eta(f, exact::folded_fall_time(f, 0.3), 0.3) == 1.0);
    CHECK(exact::sliding_eta(f, exact::sliding_fall_time(f, 0.6), 0.6) == 1.0);
    // ξ(η(ξ)) = ξ, including the ill-conditioned far end (there ξ is flat in η).
    for (double s : {0.1, 0.5, 0.9, 0.999}) {
      const double T = exact::falling_fall_time(f);
      CHECK_THAT(exact::falling_xi(f, exact::falling_eta(f, s * T)), WithinRel(s * T, kInverseXiRelTol));
      const double Tf = exact::folded_fall_time(f);
      CHECK_THAT(exact::folded_xi(f, exact::folded_eta(f, s * Tf)), WithinRel(s * Tf, kInverseXiRelTol));
    }
  }
}

TEST_CASE("bad arguments throw InputError naming the argument, its value and the range", "[problems][exact]") {
  require_input_error([] { return exact::falling_xi(-0.1, 0.5); }, "f = -0.1", "0 <= f <= 1");
  require_input_error([] { return exact::falling_xi(1.5, 0.5); }, "f = 1.5", "0 <= f <= 1");
  require_input_error([] { return exact::folded_P(-0.1, 0.5); }, "f = -0.1", "0 <= f <= 1");
  require_input_error([] { return exact::sliding_eta_prime_squared(1.5, 0.5, 0.1); }, "f = 1.5", "0 <= f <= 1");
  require_input_error([] { return exact::falling_fall_time(std::nan("")); }, "f = nan", "0 <= f <= 1");

  require_input_error([] { return exact::falling_xi(0.5, 1.2); }, "eta = 1.2", "0 <= eta <= 1");
  require_input_error([] { return exact::falling_P(0.5, 0.8, 0.5); }, "eta = 0.8", "0 <= eta <= 0.5");
  require_input_error([] { return exact::falling_eta_prime_squared(0.5, -0.1); }, "eta = -0.1", "0 <= eta <= 1");
  require_input_error([] { return exact::folded_xi(0.5, 0.1, 0.2); }, "eta = 0.1", "0.2 <= eta <= 1");
  require_input_error([] { return exact::folded_eta_prime_squared(0.5, 1.1); }, "eta = 1.1", "0 <= eta <= 1");
  require_input_error([] { return exact::sliding_xi(0.5, 0.1, 0.5); }, "eta = 0.1", "0.5 <= eta <= 1");
  require_input_error([] { return exact::sliding_P(0.5, 1.01, 0.5); }, "eta = 1.01", "0.5 <= eta <= 1");

  require_input_error([] { return exact::falling_xi(0.5, 0.0, 0.0); }, "eta0 = 0", "0 < eta0 <= 1");
  require_input_error([] { return exact::falling_fall_time(0.5, 1.5); }, "eta0 = 1.5", "0 < eta0 <= 1");
  require_input_error([] { return exact::folded_fall_time(0.5, 1.0); }, "eta0 = 1", "0 <= eta0 < 1");
  require_input_error([] { return exact::folded_xi(0.5, 0.5, -0.2); }, "eta0 = -0.2", "0 <= eta0 < 1");
  require_input_error([] { return exact::sliding_fall_time(0.5, -0.1); }, "eta0 = -0.1", "0 <= eta0 <= 1");
  require_input_error([] { return exact::sliding_xi(0.5, 1.0, 1.5); }, "eta0 = 1.5", "0 <= eta0 <= 1");

  require_input_error([] { return exact::falling_eta(0.5, 5.0); }, "xi = 5", "0 <= xi <= ");
  require_input_error([] { return exact::folded_eta(0.5, -0.5); }, "xi = -0.5", "0 <= xi <= ");
  require_input_error([] { return exact::sliding_eta(0.5, 3.0, 0.0); }, "xi = 3", "0 <= xi <= ");
}

// --- The chain sliding off a table over an edge (docs/model.md §8) -----------------------------------

namespace {
/// ℓ ẍ = g x − f ẋ², integrated by classical RK4 with step dt from rest at x0 (independent of the
/// first integral and the quadrature): calls visit(t, x, ẋ) after every step until x reaches ℓ.
template <class Visit>
void integrate_edge_ode(double f, double x0, double ell, double g, double dt, const Visit& visit) {
  auto rhs = [&](double x, double v) { return (g * x - f * v * v) / ell; };
  double t = 0, x = x0, v = 0;
  while (x < ell) {
    const double k1x = v, k1v = rhs(x, v);
    const double k2x = v + 0.5 * dt * k1v, k2v = rhs(x + 0.5 * dt * k1x, v + 0.5 * dt * k1v);
    const double k3x = v + 0.5 * dt * k2v, k3v = rhs(x + 0.5 * dt * k2x, v + 0.5 * dt * k2v);
    const double k4x = v + dt * k3v, k4v = rhs(x + dt * k3x, v + dt * k3v);
    x += dt / 6 * (k1x + 2 * k2x + 2 * k3x + k4x);
    v += dt / 6 * (k1v + 2 * k2v + 2 * k3v + k4v);
    t += dt;
    visit(t, x, v);
  }
}
}  // namespace

TEST_CASE("chain off a table edge, f = 0: x0 cosh(sqrt(g/l) t), lift-off at (l + sqrt(l^2 + 8 x0^2))/4",
          "[problems][exact][edge]") {
  using namespace chainsim::exact;
  const double ell = 1.7, g = 9.81;
  for (double x0 : {0.05, 0.3, 1.0}) {
    CAPTURE(x0);
    const double w = std::sqrt(g / ell);
    for (double x : {x0, 0.5 * (x0 + ell), ell}) {
      CHECK_THAT(edge_speed_squared(0, x, x0, ell, g), WithinRel(g / ell * (x * x - x0 * x0), 1e-14));
      CHECK_THAT(edge_time(0, x, x0, ell, g), WithinAbs(std::acosh(x / x0) / w, 1e-13));
    }
    for (double t : {0.1, 0.4}) {
      if (x0 * std::cosh(w * t) < ell) CHECK_THAT(edge_x(0, t, x0, ell, g), WithinRel(x0 * std::cosh(w * t), 1e-13));
    }
    CHECK_THAT(edge_lift_off_x(0, x0, ell, g), WithinRel((ell + std::sqrt(ell * ell + 8 * x0 * x0)) / 4, 1e-13));
  }
}

TEST_CASE("chain off a table edge, f > 0: the first integral and the quadrature against RK4 of l x'' = g x - f x'^2",
          "[problems][exact][edge]") {
  using namespace chainsim::exact;
  const double ell = 1.7, g = 9.81, lam = 0.8;
  for (double f : {0.2, 0.7, 1.0}) {
    for (double x0 : {0.1, 0.5}) {
      CAPTURE(f, x0);
      const double xs = edge_lift_off_x(f, x0, ell, g);
      const double ts = edge_time(f, xs, x0, ell, g);
      // RK4 at dt = 2e-4 (error ~1e-13 here): x(t) (every 50th step) and ẋ² against the reference; the lift-off
      // (τ⁻ = λ(ℓ − x)ẍ falls to λẋ²) located by linear interpolation of the margin between steps.
      double max_x = 0, max_u = 0, t_prev = 0, m_prev = g * x0 * (ell - x0) / ell, t_lift = -1;
      long step = 0;
      integrate_edge_ode(f, x0, ell, g, 2e-4, [&](double t, double x, double v) {
        if (x >= ell) return;
        if (++step % 50 == 0) max_x = std::max(max_x, std::abs(edge_x(f, t, x0, ell, g) - x));
        max_u = std::max(max_u, std::abs(edge_speed_squared(f, x, x0, ell, g) - v * v));
        const double m = (ell - x) * (g * x - f * v * v) / ell - v * v;
        if (t_lift < 0 && m <= 0) t_lift = t_prev + (t - t_prev) * m_prev / (m_prev - m);
        t_prev = t;
        m_prev = m;
      });
      CHECK(max_x < 1e-10);
      CHECK(max_u < 1e-9);
      CHECK_THAT(t_lift, WithinAbs(ts, 1e-6));  // linear interpolation: O(dt²) in the root
      // At x*: the tension at the edge on the table side equals λẋ² (the margin's zero), and f > 0
      // lifts off earlier in x than f = 0 (the kink's loss slows the chain, its tension jump
      // raises τ⁺ and not τ⁻ — ẍ is smaller, so τ⁻ meets λẋ² sooner).
      const double u = edge_speed_squared(f, xs, x0, ell, g);
      CHECK_THAT(lam * (ell - xs) * edge_acceleration(f, xs, x0, ell, g), WithinRel(lam * u, 1e-12));
      CHECK(xs < edge_lift_off_x(0, x0, ell, g));
      // Energy: ½ λ ℓ ẋ² − ½ λ g (x² − x0²) = −∫ f λ ẋ³ dt = −f λ ∫_x0^x ẋ² dx (Simpson, 2000 panels).
      const int n = 2000;
      double integral = 0;
      for (int i = 0; i <= n; ++i) {
        const double x = x0 + (xs - x0) * i / n;
        integral += (i == 0 || i == n ? 1 : (i % 2 ? 4 : 2)) * edge_speed_squared(f, x, x0, ell, g);
      }
      integral *= (xs - x0) / (3 * n);
      CHECK_THAT(0.5 * lam * ell * u - 0.5 * lam * g * (xs * xs - x0 * x0), WithinAbs(-f * lam * integral, 1e-12));
    }
  }
}
