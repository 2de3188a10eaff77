// The static catenary as the rest state of a damped string (docs/model.md §7.3).
//
// A string of length ℓ = 1 m between the fixed points (0, 0) and (0.8, 0.2) starts at rest as a V
// (two straight legs) and relaxes under gravity with linear drag. Its rest state is compared with the
// catenary y = a cosh((x − x_m)/a) + c through the same points, a found here from the length
// constraint 2 a sinh(d / 2a) = sqrt(ℓ² − Δy²) with Boost's bracket-and-solve (independently of the
// solver's own catenary shape), node by node at the same material coordinate s_i. The error must
// fall at second order in the mesh size.
#include <cmath>

#include <boost/math/tools/roots.hpp>
#include <catch2/catch.hpp>

#include "../problems/string_test_support.hpp"
#include "solver/integrator.hpp"

using namespace chainsim;
using namespace chainsim::testing;

namespace {
constexpr double kOrder = 2.0;       ///< lumped masses, central differences
constexpr double kRateMargin = 0.1;  ///< STYLE.md: rate > p − 0.1
/// Drag (1/s): every mode faster than c/2 decays like e^{−ct/2}; the first mode (≈ 5 rad/s) is near
/// critical damping.
constexpr double kDrag = 10.0;
/// Long enough for e^{−c t / 2} ≈ 1e-13: the remaining motion is far below the mesh error.
constexpr double kRelaxTime = 6.0;
/// At rest: the largest node speed left after the relaxation (m/s).
constexpr double kAtRest = 1e-8;

struct Catenary {
  double a, x_m, c;
  Vec<2> at(double s) const {  // point at arc length s from (0, 0)
    const double x = x_m + a * std::asinh(s / a + std::sinh(-x_m / a));
    return {x, a * std::cosh((x - x_m) / a) + c};
  }
};

Catenary reference(double d, double dy, double length) {
  const double chord = std::sqrt(length * length - dy * dy);
  auto f = [&](double a) { return 2 * a * std::sinh(d / (2 * a)) - chord; };  // decreasing in a
  boost::uintmax_t iterations = 200;
  const auto r = boost::math::tools::bracket_and_solve_root(f, 1.0, 2.0, false,
                                                           boost::math::tools::eps_tolerance<double>(50), iterations);
  Catenary cat;
  cat.a = 0.5 * (r.first + r.second);
  // y(0) = 0, y(d) = dy:  x_m = d/2 − a asinh(dy / chord), c = −a cosh(x_m / a).
  cat.x_m = 0.5 * d - cat.a * std::asinh(dy / chord);
  cat.c = -cat.a * std::cosh(cat.x_m / cat.a);
  return cat;
}

double relaxed_error(int links, const std::string& elements = "links") {
  const double length = 1.0;
  const Vec<2> p0(0.0, 0.0), p1(0.8, 0.2);
  // The V: apex at x = 0.4 below the chord, with legs adding up to ℓ (bisection on its height).
  double lo = -2.0, hi = 0.1;
  for (int k = 0; k < 200; ++k) {
    const double y = 0.5 * (lo + hi);
    const double legs = Vec<2>(0.4, y).norm() + (p1 - Vec<2>(0.4, y)).norm();
    (legs > length ? lo : hi) = y;
  }
  Points<2> v(2, 3);
  v << 0.0, 0.4, 0.8, 0.0, 0.5 * (lo + hi), 0.2;
  Chain<2> chain = discretize(*polyline_curve<2>(v), length, 1.0, links, false, 1e-12);
  std::vector<std::unique_ptr<Force<2>>> forces;
  forces.push_back(std::make_unique<Gravity<2>>(Vec<2>(0.0, -kG)));
  forces.push_back(std::make_unique<Drag<2>>(kDrag));
  std::vector<PrescribedNode<2>> ends = {{0, std::make_shared<FixedPoint<2>>(p0)},
                                         {links, std::make_shared<FixedPoint<2>>(p1)}};
  StringModelOptions mo;
  mo.stabilization_time = 0.03;
  mo.elements = elements;
  StringModel<2> model(std::move(chain), std::move(forces), ends, mo);
  model.make_consistent(0.0);
  IntegratorOptions io;
  io.rtol = 1e-10;
  io.atol = 1e-13;
  Integrator integrator(model, 0.0, model.state_from_chain(), io);
  integrator.advance(kRelaxTime);
  Points<2> x, vel;
  model.unpack(kRelaxTime, integrator.state(), x, vel);
  CHECK(vel.colwise().norm().maxCoeff() < kAtRest);
  const Catenary cat = reference(0.8, 0.2, length);
  double error = 0;
  for (int i = 0; i <= links; ++i)
    error = std::max(error, (x.col(i) - cat.at(model.chain().node_coordinate(i))).norm());
  return error;
}

}  // namespace

TEST_CASE("a damped string relaxes to the catenary, at second order in the mesh size", "[convergence][string]") {
  const std::vector<int> links = {10, 20, 40, 80};
  std::vector<double> error;
  for (int n : links) error.push_back(relaxed_error(n));
  const auto rates = rate_table("static catenary: max node distance to y = a cosh((x - x_m)/a) + c (m)", "links",
                                links, error);
  for (double r : rates) CHECK(r > kOrder - kRateMargin);
}

TEST_CASE("with quadratic elements the damped string relaxes to the catenary at fourth order",
          "[convergence][string][quadratic]") {
  // The same rest state with [string] elements = "quadratic" (two links per element): a smooth arc.
  const std::vector<int> links = {4, 8, 16, 32};
  std::vector<double> error;
  for (int n : links) error.push_back(relaxed_error(n, "quadratic"));
  const auto rates = rate_table("static catenary, quadratic elements: max node distance to the catenary (m)", "links",
                                links, error);
  for (double r : rates) CHECK(r > 4.0 - 0.2);
}
