// mesh/chain.hpp and mesh/discretize.hpp: masses, lengths and the initial shapes.
#include <algorithm>
#include <cmath>
#include <random>
#include <string>
#include <vector>

#include <Eigen/Geometry>
#include <catch2/catch.hpp>

#include "mesh/chain.hpp"
#include "mesh/discretize.hpp"
#include "mesh/errors.hpp"

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

// ------------------------------------------------------------------------------------------------
// rounded_polyline_curve: a polyline whose interior points are rounded by fillets of radius r.
// Every expectation below is computed by hand from the vertices (turn θ from acos of the unit
// directions, fillet centre on the bisector at r / cos(θ/2) from the vertex), not by the curve.
namespace {
/// Tangents by Richardson-extrapolated one-sided differences (step 1e-5), normalised: on a circle the
/// truncation error lies along the tangent and drops out, so what is left is round-off,
/// ~ 4 eps |x| / 1e-5 ≈ 1e-10; a kink of angle α would show as α.
constexpr double kTangentJump = 1e-9;
/// Arc-length parametrisation: a chord of δ = 1e-5 on an arc of radius r is shorter than δ by the
/// relative δ²/(24 r²) <= 1e-8 for r >= 0.02; round-off 2 eps |x| / δ ≈ 1e-10.
constexpr double kSpeed = 2e-8;
constexpr double kChord = 1e-5;

/// The hand-made fillets of an open polyline: per interior vertex, its turn, tangent length,
/// centre, and where the arc starts (arc length along the rounded curve).
template <int dim>
struct Fillet {
  int vertex;
  double turn, tangent, start;
  Vec<dim> center;
};
template <int dim>
std::vector<Fillet<dim>> fillets_by_hand(const Points<dim>& x, double r, double* length) {
  std::vector<Fillet<dim>> out;
  double s = 0;  // arc length of the rounded curve at the current vertex's incoming tangent point
  double previous_tangent = 0;
  for (int k = 1; k < x.cols(); ++k) {
    const Vec<dim> a = (x.col(k) - x.col(k - 1)).normalized();
    const double segment = (x.col(k) - x.col(k - 1)).norm();
    double turn = 0, tangent = 0;
    Vec<dim> center = Vec<dim>::Zero();
    if (k + 1 < x.cols()) {
      const Vec<dim> b = (x.col(k + 1) - x.col(k)).normalized();
      turn = std::acos(std::clamp(a.dot(b), -1.0, 1.0));
      tangent = r * std::tan(turn / 2);
      center = Vec<dim>(x.col(k)) + r / std::cos(turn / 2) * (b - a).normalized();
    }
    s += segment - previous_tangent - tangent;
    if (turn > 0) out.push_back({k, turn, tangent, s, center});
    s += r * turn;
    previous_tangent = tangent;
  }
  *length = s;
  return out;
}

/// The unit tangent just before (side = -1) or just after (+1) arc length s, by Richardson.
template <int dim>
Vec<dim> one_sided_tangent(const Curve<dim>& c, double s, int side) {
  const double d = 1e-5 * side;
  const Vec<dim> coarse = (c.point(s + d) - c.point(s)) / d;
  const Vec<dim> fine = (c.point(s + d / 2) - c.point(s)) / (d / 2);
  return (2 * fine - coarse).normalized();
}

/// Checks a rounded polyline against the hand-made fillets: the length, every arc at distance r
/// from its centre, the tangent continuous at both ends of each arc, and unit speed everywhere.
template <int dim>
void check_rounded(const Points<dim>& x, double r) {
  auto curve = rounded_polyline_curve<dim>(x, r);
  double length = 0;
  const auto fillets = fillets_by_hand<dim>(x, r, &length);
  // The closed form Σ segments − Σ (2 r tan(θ/2) − r θ).
  double closed_form = 0;
  for (int k = 1; k < x.cols(); ++k) closed_form += (x.col(k) - x.col(k - 1)).norm();
  for (const auto& f : fillets) closed_form -= 2 * r * std::tan(f.turn / 2) - r * f.turn;
  CHECK_THAT(curve->length(), WithinRel(closed_form, kRoundOff));
  CHECK_THAT(curve->length(), WithinRel(length, kRoundOff));
  CHECK_THAT((curve->point(0) - x.col(0)).norm(), WithinAbs(0.0, kRoundOff));
  CHECK_THAT((curve->point(curve->length()) - x.col(x.cols() - 1)).norm(), WithinAbs(0.0, kOnCurve));
  for (const auto& f : fillets) {
    CAPTURE(f.vertex);
    const double arc = r * f.turn;
    for (int q = 0; q <= 16; ++q)
      CHECK_THAT((curve->point(f.start + arc * q / 16) - f.center).norm(), WithinAbs(r, kOnCurve));
    // The arc starts and ends at the tangent points, t = r tan(θ/2) from the vertex along the segments.
    const Vec<dim> in = x.col(f.vertex) - (x.col(f.vertex) - x.col(f.vertex - 1)).normalized() * f.tangent;
    const Vec<dim> out = x.col(f.vertex) + (x.col(f.vertex + 1) - x.col(f.vertex)).normalized() * f.tangent;
    CHECK_THAT((curve->point(f.start) - in).norm(), WithinAbs(0.0, kOnCurve));
    CHECK_THAT((curve->point(f.start + arc) - out).norm(), WithinAbs(0.0, kOnCurve));
    for (double s : {f.start, f.start + arc}) {
      const Vec<dim> before = one_sided_tangent(*curve, s, -1), after = one_sided_tangent(*curve, s, +1);
      CHECK_THAT((after - before).norm(), WithinAbs(0.0, kTangentJump));
    }
  }
  const int samples = 997;
  for (int q = 0; q < samples; ++q) {
    const double s = (curve->length() - kChord) * q / (samples - 1);
    CHECK_THAT((curve->point(s + kChord) - curve->point(s)).norm(), WithinRel(kChord, kSpeed));
  }
}

/// The number after `label` in `message`.
double number_after(const std::string& message, const std::string& label) {
  const auto at = message.find(label);
  REQUIRE(at != std::string::npos);
  return std::stod(message.substr(at + label.size()));
}

/// The message of the InputError that rounded_polyline_curve throws, or "".
template <int dim>
std::string rounding_error(const Points<dim>& x, double r) {
  try {
    rounded_polyline_curve<dim>(x, r);
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}
}  // namespace

TEST_CASE("rounded polyline: length by the closed form, fillets on their circles, tangent continuous",
          "[unit][mesh]") {
  // Turns of 90, 153 and 117 deg, left and right; and a straight-through vertex (no arc).
  Points<2> x(2, 6);
  x << 0.0, 1.0, 1.5, 0.7, 0.7, 0.7,  //
      0.0, 0.0, 0.8, 1.2, 2.0, 3.0;
  check_rounded<2>(x, 0.1);
  check_rounded<2>(x, 0.02);
  auto curve = rounded_polyline_curve<2>(x, 0.1);
  CHECK(curve->description() == "polyline through 6 points with corners rounded to radius 0.1 m");
  CHECK_FALSE(curve->closed());
  // Two points: a plain segment.
  Points<2> segment(2, 2);
  segment << 0.0, 0.3, 0.0, 0.4;
  CHECK_THAT(rounded_polyline_curve<2>(segment, 1.0)->length(), WithinRel(0.5, kRoundOff));
}

TEST_CASE("rounded polyline: the U of two fillets meeting mid-segment has an exact semicircle for its bottom",
          "[unit][mesh]") {
  Points<2> x(2, 4);
  x << 0.0, 0.0, 0.04, 0.04,  //
      0.0, -0.3, -0.3, 0.377;
  const double r = 0.02;
  check_rounded<2>(x, r);  // the tangent lengths fill the 0.04 m segment exactly: accepted
  auto curve = rounded_polyline_curve<2>(x, r);
  CHECK_THAT(curve->length(), WithinRel(0.3 + 0.04 + 0.677 - 2 * (2 * r - r * kPi / 2), kRoundOff));
  // The arms are straight down to y = -0.28; the bottom, s in [0.28, 0.28 + π r], is one half circle.
  const Vec<2> center(0.02, -0.28);
  double worst = 0;
  for (int q = 0; q <= 400; ++q) {
    const double s = 0.28 + kPi * r * q / 400;
    worst = std::max(worst, std::abs((curve->point(s) - center).norm() - r));
  }
  CHECK_THAT(worst, WithinAbs(0.0, kOnCurve));
  CHECK_THAT((curve->point(0.28 + kPi * r / 2) - Vec<2>(0.02, -0.3)).norm(), WithinAbs(0.0, kOnCurve));
  CHECK_THAT(curve->point(0.1)[0], WithinAbs(0.0, kRoundOff));
  CHECK_THAT(curve->point(0.28 + kPi * r + 0.1)[0], WithinAbs(0.04, kRoundOff));
}

TEST_CASE("rounded polyline in 3D: corners in a tilted plane stay in it", "[unit][mesh]") {
  const Vec<3> e1 = Vec<3>(1.0, 1.0, 1.0).normalized(), e2 = Vec<3>(1.0, -1.0, 0.0).normalized();
  const Vec<3> origin(0.2, -0.1, 0.5);
  // In plane coordinates: (0, 0) -> (1, 0) -> (1.3, 0.9) -> (0.4, 1.1).
  const double u[] = {0.0, 1.0, 1.3, 0.4}, v[] = {0.0, 0.0, 0.9, 1.1};
  Points<3> x(3, 4);
  for (int k = 0; k < 4; ++k) x.col(k) = origin + u[k] * e1 + v[k] * e2;
  check_rounded<3>(x, 0.15);
  auto curve = rounded_polyline_curve<3>(x, 0.15);
  const Vec<3> normal = e1.cross(e2);
  for (int q = 0; q <= 100; ++q)
    CHECK_THAT((curve->point(curve->length() * q / 100) - origin).dot(normal), WithinAbs(0.0, kOnCurve));
}

TEST_CASE("rounded polyline: a turn back and a segment too short for its fillets are refused", "[unit][mesh]") {
  // A turn back on itself cannot be rounded, however small the radius.
  Points<2> back(2, 3);
  back << 0.0, 0.0, 0.0,  //
      0.0, -1.0, -0.5;
  const std::string turn = rounding_error<2>(back, 0.01);
  CHECK(turn == "shape.corner_radius = 0.01 m cannot round point 1 = [0, -1]: the polyline turns back on itself "
                "there (it turns by 180 deg, to within 1e-09 rad of 180 deg), and no arc is tangent to both of its "
                "segments");
  // Nearly back (1e-10 rad short of it) is refused too; 1e-6 rad short is a segment question.
  Points<2> nearly = back;
  nearly(0, 2) = 0.5 * std::sin(1e-10);
  CHECK_THAT(rounding_error<2>(nearly, 0.01), Contains("turns back on itself"));
  nearly(0, 2) = 0.5 * std::sin(1e-6);
  CHECK_THAT(rounding_error<2>(nearly, 0.01), Contains("is too large for the segment"));
  // The U with too large a radius: the 0.04 m bottom holds two tangent lengths of r each.
  Points<2> x(2, 4);
  x << 0.0, 0.0, 0.04, 0.04,  //
      0.0, -0.3, -0.3, 0.377;
  const std::string large = rounding_error<2>(x, 0.03);
  CHECK(large == "shape.corner_radius = 0.03 m is too large for the segment from point 1 = [0, -0.3] to point 2 = "
                 "[0.04, -0.3]: it is 0.04 m long but the fillets at its ends need 0.06 m of it (tangent lengths "
                 "0.03 m + 0.03 m); the largest corner_radius that fits every segment is 0.02 m");
  // Unequal turns (90 and 60 deg) around a 0.5 m segment: r_max = 0.5 / (tan 45° + tan 30°), and the
  // tighter first segment (0.2 m, one 90 deg fillet: r_max = 0.2) is the one named when it decides.
  Points<2> y(2, 4);
  y << 0.0, 1.0, 1.0, 1.0 - std::sin(kPi / 3),  //
      0.0, 0.0, 0.5, 0.5 + std::cos(kPi / 3);
  const double r_max = 0.5 / (1 + std::tan(kPi / 6));
  const std::string too_large = rounding_error<2>(y, 0.4);
  CAPTURE(too_large);
  CHECK_THAT(too_large, Contains("segment from point 1 = [1, 0] to point 2 = [1, 0.5]: it is 0.5 m long"));
  const double reported = number_after(too_large, "fits every segment is ");
  CHECK_THAT(reported, WithinRel(r_max, 1e-8));  // printed to 9 digits
  CHECK(rounding_error<2>(y, r_max).empty());    // an exact fit passes
  CHECK_FALSE(rounding_error<2>(y, r_max * (1 + 1e-9)).empty());
  check_rounded<2>(y, r_max);
  y(0, 0) = 0.8;  // the first segment is now 0.2 m long: r_max = 0.2 < 0.3185
  const std::string first = rounding_error<2>(y, 0.25);
  CHECK_THAT(first, Contains("segment from point 0 = [0.8, 0] to point 1 = [1, 0]: it is 0.2 m long"));
  CHECK_THAT(number_after(first, "fits every segment is "), WithinRel(0.2, 1e-8));
  // The vertices are checked as for a plain polyline, and the radius must be positive.
  Points<2> repeated(2, 3);
  repeated << 0.0, 1.0, 1.0, 0.0, 0.0, 0.0;
  CHECK_THAT(rounding_error<2>(repeated, 0.1), Contains("points 1 and 2 coincide"));
  CHECK_THAT(rounding_error<2>(x, 0.0), Contains("shape.corner_radius = 0 is out of range"));
}
