// A closed loop travelling along its own tangent without gravity (docs/model.md §7.2): a curve moving
// with uniform speed v along itself under the tension τ = λ v² keeps its shape.
//
// Discrete check: the regular polygon with side h, node masses λh and every node moving with speed v
// perpendicular to its radius R' = h / (2 sin(π/n)) rotates rigidly with Ω = v / R': each node needs
// the centripetal force λ h v² / R' = 2 T sin(π/n), i.e. T = λ v² exactly, in the discrete model too.
#include <cmath>

#include <catch2/catch.hpp>

#include "mesh/discretize.hpp"
#include "solver/string_solver.hpp"
#include "string_test_support.hpp"

using namespace chainsim;
using namespace chainsim::testing;
using Catch::Matchers::WithinAbs;
using Catch::Matchers::WithinRel;

namespace {
/// The discrete identity T = λ v² at t = 0: a tridiagonal solve of 64 unknowns, round-off only.
constexpr double kIdentity = 1e-12;
/// After three revolutions at rtol = 1e-10 (~1000 steps): radii and tensions stay at the
/// integrator's tolerance level.
constexpr double kShape = 1e-8;
/// Node positions against the exact rigid rotation: phase error ~ rtol · Ω t · steps.
constexpr double kRotation = 1e-6;

template <int dim>
void run_loop(const Vec<dim>& axis1, const Vec<dim>& axis2) {
  const int n = 64;
  const double radius = 0.5, density = 0.1, speed = 2.0;
  const double length = 2 * kPi * radius;
  Chain<dim> chain = discretize(*circle_curve<dim>(Vec<dim>::Zero(), radius, axis1, axis2), length, density, n, true);
  set_tangential_velocity(chain, speed);
  StringModelOptions mo;
  mo.stabilization_time = 0.1 * length / speed;
  StringModel<dim> model(std::move(chain), {}, {}, mo);
  model.make_consistent(0.0);
  const double h = length / n, r_polygon = h / (2 * std::sin(kPi / n));
  const Points<dim> x0 = model.chain().positions();
  const Vec<dim> e1 = axis1.normalized();
  const Vec<dim> e2 = (axis2 - axis2.dot(e1) * e1).normalized();

  StringSolverOptions so;
  so.integrator.rtol = 1e-10;
  so.integrator.atol = 1e-12;
  const double revolution = 2 * kPi * r_polygon / speed;
  so.t_end = 3 * revolution;
  so.output_interval = revolution / 8;
  StringSolver<dim> solver(model, so);
  solver.run();
  // t = 0: the discrete identity.
  const auto& first = solver.frames().front();
  for (int j = 0; j < n; ++j) CHECK_THAT(first.tension[j], WithinRel(density * speed * speed, kIdentity));
  const double omega = speed / r_polygon;
  double worst_radius = 0, worst_tension = 0, worst_position = 0;
  for (const auto& f : solver.frames()) {
    const double c = std::cos(omega * f.t), s = std::sin(omega * f.t);
    for (int i = 0; i < n; ++i) {
      worst_radius = std::max(worst_radius, std::abs(f.x.col(i).norm() / r_polygon - 1));
      // Rigid rotation by Ωt in the plane of the loop (counter-clockwise from e1 to e2).
      const double p = x0.col(i).dot(e1), q = x0.col(i).dot(e2);
      const Vec<dim> expected = (c * p - s * q) * e1 + (s * p + c * q) * e2;
      worst_position = std::max(worst_position, (f.x.col(i) - expected).norm() / r_polygon);
    }
    for (int j = 0; j < n; ++j)
      worst_tension = std::max(worst_tension, std::abs(f.tension[j] / (density * speed * speed) - 1));
  }
  INFO("max |r/R' - 1| = " << worst_radius << ", max |T/(lambda v^2) - 1| = " << worst_tension
                           << ", max position error / R' = " << worst_position);
  CHECK(worst_radius < kShape);
  CHECK(worst_tension < kShape);
  CHECK(worst_position < kRotation);
  CHECK(solver.summary().relative_energy_drift() < kShape);
}

}  // namespace

TEST_CASE("a closed loop travels along itself keeping its circle, with T = lambda v^2", "[problems][string]") {
  run_loop<2>(Vec<2>(1, 0), Vec<2>(0, 1));
}

TEST_CASE("the travelling loop in 3D, in a tilted plane", "[problems][string]") {
  run_loop<3>(Vec<3>(1, 1, 0), Vec<3>(0, 1, 1));
}
