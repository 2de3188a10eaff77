// mesh/chain.hpp and mesh/discretize.hpp: masses, lengths and the initial shapes.
#include <cmath>
#include <random>

#include <catch2/catch.hpp>

#include "mesh/chain.hpp"
#include "mesh/discretize.hpp"
#include "solver/errors.hpp"

using namespace chainsim;
using Catch::Matchers::Contains;
using Catch::Matchers::WithinAbs;
using Catch::Matchers::WithinRel;

namespace {
/// Sums of a few dozen positive terms: exact up to a few ulps.
constexpr double kRoundOff = 1e-13;
/// Nodes placed on an analytic curve: the curve's own evaluation error.
constexpr double kOnCurve = 1e-12;
}  // namespace

TEST_CASE("lumped masses sum to the chain's mass", "[unit][mesh]") {
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> u(0.01, 0.2);
  for (bool closed : {false, true}) {
    std::vector<double> h(17);
    double length = 0;
    for (double& x : h) length += (x = u(rng));
    const double density = 0.37;
    Chain<3> chain(density, h, closed);
    CHECK(chain.num_links() == 17);
    CHECK(chain.num_nodes() == (closed ? 17 : 18));
    CHECK_THAT(chain.length(), WithinRel(length, kRoundOff));
    CHECK_THAT(chain.total_mass(), WithinRel(density * length, kRoundOff));
    // End nodes of an open chain carry half their link; interior nodes half of each neighbour.
    if (!closed) CHECK_THAT(chain.mass(0), WithinRel(0.5 * density * h[0], kRoundOff));
    CHECK_THAT(chain.mass(1), WithinRel(0.5 * density * (h[0] + h[1]), kRoundOff));
    CHECK(chain.link_end(16) == (closed ? 0 : 17));
    CHECK_THAT(chain.link_midpoint(2), WithinRel(h[0] + h[1] + 0.5 * h[2], kRoundOff));
  }
}

TEST_CASE("a 2D chain stores no third component", "[unit][mesh]") {
  STATIC_REQUIRE(Chain<2>::Vector::RowsAtCompileTime == 2);
  Chain<2> chain = Chain<2>::uniform(1.0, 1.0, 4, false);
  CHECK(chain.positions().rows() == 2);
  CHECK(sizeof(Vec<2>) == 2 * sizeof(double));
}

TEST_CASE("bad chains are refused", "[unit][mesh]") {
  CHECK_THROWS_AS(Chain<2>(1.0, {0.5, 0.5}, true), InputError);  // closed needs 3 links
  CHECK_THROWS_AS(Chain<2>(0.0, {0.5}, false), InputError);
  CHECK_THROWS_AS(Chain<2>(1.0, {0.5, -0.1}, false), InputError);
}

TEST_CASE("polyline: nodes at equal arc length, the length checked", "[unit][mesh]") {
  Points<2> p(2, 3);
  p << 0.0, 1.0, 1.0,  //
      0.0, 0.0, 1.0;
  auto curve = polyline_curve<2>(p);
  CHECK_THAT(curve->length(), WithinRel(2.0, kRoundOff));
  Chain<2> chain = discretize(*curve, 2.0, 0.5, 8, false);
  CHECK(chain.num_nodes() == 9);
  CHECK_THAT(chain.link_length(3), WithinRel(0.25, kRoundOff));
  CHECK_THAT(chain.total_mass(), WithinRel(1.0, kRoundOff));
  CHECK_THAT(chain.positions()(0, 4), WithinAbs(1.0, kRoundOff));  // the corner is at s = 1
  CHECK_THAT(chain.positions()(1, 6), WithinAbs(0.5, kRoundOff));
  // A shape of the wrong length is an error that names both lengths.
  CHECK_THROWS_WITH(discretize(*curve, 2.5, 0.5, 8, false), Contains("2 m long") && Contains("2.5 m"));
  // ... unless the tolerance allows it.
  CHECK_NOTHROW(discretize(*curve, 2.0 * (1 + 1e-4), 0.5, 8, false, 1e-3));
  // An open curve cannot make a closed string.
  CHECK_THROWS_AS(discretize(*curve, 2.0, 0.5, 8, true), InputError);
}

TEST_CASE("circle and arc shapes", "[unit][mesh]") {
  const Vec<3> center(1.0, 2.0, 3.0);
  const Vec<3> a1(0.0, 0.0, 2.0), a2(1.0, 0.0, 1.0);  // orthonormalised: e1 = z, e2 = x
  auto circle = circle_curve<3>(center, 0.5, a1, a2);
  CHECK(circle->closed());
  CHECK_THAT(circle->length(), WithinRel(kPi, kRoundOff));
  Chain<3> chain = discretize(*circle, kPi, 1.0, 12, true);
  CHECK(chain.num_nodes() == 12);
  for (int i = 0; i < 12; ++i) {
    CHECK_THAT((chain.positions().col(i) - center).norm(), WithinRel(0.5, kOnCurve));
    CHECK_THAT(chain.positions()(1, i), WithinAbs(2.0, kOnCurve));  // in the plane y = 2
  }
  // Tangential velocity on a regular polygon: perpendicular to the radius, speed v.
  set_tangential_velocity(chain, 3.0);
  for (int i = 0; i < 12; ++i) {
    CHECK_THAT(chain.velocities().col(i).norm(), WithinRel(3.0, kRoundOff));
    CHECK_THAT(chain.velocities().col(i).dot(chain.positions().col(i) - center), WithinAbs(0.0, kOnCurve));
  }
  auto arc = circle_arc_curve<2>(Vec<2>(0, 0), 2.0, 0.0, -kPi / 2, Vec<2>(1, 0), Vec<2>(0, 1));
  CHECK_THAT(arc->length(), WithinRel(kPi, kRoundOff));
  CHECK_THAT(arc->point(arc->length())[1], WithinAbs(-2.0, kOnCurve));  // clockwise to (0, -2)
  CHECK_THROWS_AS(circle_curve<2>(Vec<2>(0, 0), -1.0, Vec<2>(1, 0), Vec<2>(0, 1)), InputError);
  CHECK_THROWS_AS(circle_curve<2>(Vec<2>(0, 0), 1.0, Vec<2>(1, 0), Vec<2>(2, 0)), InputError);
}

TEST_CASE("catenary shape: end points, length, and the cosh law", "[unit][mesh]") {
  const Vec<2> p0(0.0, 0.0), p1(1.0, 0.3);
  const double length = 1.6;
  auto curve = catenary_curve<2>(p0, p1, length, Vec<2>(0.0, -9.81));
  CHECK_THAT((curve->point(0) - p0).norm(), WithinAbs(0.0, kOnCurve));
  CHECK_THAT((curve->point(length) - p1).norm(), WithinAbs(0.0, kOnCurve));
  // Arc length by a fine polyline (error O(1/n²) ≈ 1e-9 for n = 20000).
  double arc = 0;
  const int n = 20000;
  for (int k = 0; k < n; ++k) arc += (curve->point(length * (k + 1) / n) - curve->point(length * k / n)).norm();
  CHECK_THAT(arc, WithinRel(length, 1e-8));
  const CatenaryParameters c = solve_catenary(1.0, 0.3, length);
  for (double s : {0.1, 0.5, 0.9, 1.3}) {
    const Vec<2> x = curve->point(s);
    CHECK_THAT(x[1], WithinAbs(c.a * std::cosh((x[0] - c.x_m) / c.a) + c.c, kOnCurve));
  }
  // Too short a string, or a vertical chord, is an input error naming the lengths.
  CHECK_THROWS_WITH(catenary_curve<2>(p0, p1, 1.0, Vec<2>(0, -1)), Contains("string.length = 1 m"));
  CHECK_THROWS_AS(catenary_curve<2>(p0, Vec<2>(0.0, -0.5), 1.0, Vec<2>(0, -1)), InputError);
}

TEST_CASE("initial velocity fields", "[unit][mesh]") {
  Chain<2> chain = Chain<2>::uniform(1.0, 1.0, 4, false);
  for (int i = 0; i < 5; ++i) chain.positions().col(i) = Vec<2>(0.25 * i, 0.0);
  set_uniform_velocity(chain, Vec<2>(1.0, -2.0));
  CHECK(chain.velocities().col(3) == Vec<2>(1.0, -2.0));
  set_tangential_velocity(chain, 2.0);
  CHECK(chain.velocities().col(0) == Vec<2>(2.0, 0.0));
  CHECK(chain.velocities().col(4) == Vec<2>(2.0, 0.0));
  CHECK_THROWS_AS(set_node_velocities<2>(chain, Points<2>::Zero(2, 3)), InputError);
}
