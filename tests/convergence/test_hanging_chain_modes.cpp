// Small oscillations of a heavy chain hanging from a fixed point (docs/model.md §7.1):
//   ω_n = (j_{0,n} / 2) sqrt(g/ℓ),  mode shape J0(2 ω_n sqrt(σ/g)) = J0(j_{0,n} sqrt(σ/ℓ)),
// σ the distance from the free end. The chain starts at rest in the mode shape with a small amplitude;
// the frequency is measured from the zero crossings of the modal projection
//   q(t) = Σ_i m_i u_i(t) φ_n(σ_i)   (u: lateral displacement),
// (a least-squares fit of the crossing times), and its error must fall under mesh refinement at the
// order p of the lumped-mass discretization (p = 2: central differences with the exact link tensions).
#include <cmath>

#include <boost/math/special_functions/bessel.hpp>
#include <catch2/catch.hpp>

#include "../problems/string_test_support.hpp"

using namespace chainsim;
using namespace chainsim::testing;

namespace {
/// Order of the lumped-mass scheme: second-order central differences in s.
constexpr double kOrder = 2.0;
/// Margin for the observed rate (STYLE.md: rate > p − 0.1).
constexpr double kRateMargin = 0.1;
/// Lateral amplitude relative to ℓ: the nonlinear frequency shift O(ε²) = 1e-10 stays far below
/// the discretization error of the finest mesh (~1e-5).
constexpr double kAmplitude = 1e-5;
/// Tight time integration: its error (~1e-10 relative) is negligible against the mesh error.
constexpr double kRtol = 1e-11;

struct Measured {
  double omega;
  int crossings;
};

Measured measure(int links, int mode, double periods) {
  IntegratorOptions options;
  options.rtol = kRtol;
  options.atol = 1e-15;
  const ModeMeasurement m = measure_mode(links, mode, periods, options, kAmplitude);
  REQUIRE(m.crossings >= 4);
  return {m.omega, m.crossings};
}

void check_mode(int mode, const std::vector<int>& links, double periods) {
  const double omega = 0.5 * boost::math::cyl_bessel_j_zero(0.0, mode) * std::sqrt(kG);
  std::vector<double> error;
  for (int n : links) {
    const Measured m = measure(n, mode, periods);
    error.push_back(std::abs(m.omega - omega) / omega);
  }
  const auto rates =
      rate_table("hanging chain, mode " + std::to_string(mode) + ": relative frequency error", "links", links, error);
  for (double r : rates) CHECK(r > kOrder - kRateMargin);
}

}  // namespace

TEST_CASE("hanging chain: first-mode frequency converges at second order", "[convergence][string]") {
  check_mode(1, {10, 20, 40, 80}, 5.0);
}

TEST_CASE("hanging chain: second-mode frequency converges at second order", "[convergence][string]") {
  check_mode(2, {20, 40, 80, 160}, 8.0);
}

TEST_CASE("hanging chain: third mode, finer meshes", "[convergence][string][.long]") {
  check_mode(3, {20, 40, 80, 160, 320}, 10.0);
}
