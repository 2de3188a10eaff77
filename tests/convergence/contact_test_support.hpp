#pragma once
// What the contact tests share (solver/contact_module.hpp; docs/model.md §10): the smooth table, the
// model's options and the run's, so that each test file builds its chains on the same obstacles.
#include <cmath>

#include "solver/contact_module.hpp"
#include "solver/string_solver.hpp"

namespace chainsim::test {

/// The smooth table y = 0, the string above it (normal +y).
inline Obstacle<2> table() {
  Obstacle<2> o;
  o.kind = Obstacle<2>::Kind::kPlane;
  o.point = Vec<2>(0.0, 0.0);
  o.normal = Vec<2>(0.0, 1.0);
  o.name = "table";
  return o;
}

/// erk5 to t_end, frames every `interval`, atol = 10⁻³ rtol.
inline StringSolverOptions contact_run(double t_end, double interval, double rtol = 1e-10) {
  StringSolverOptions so;
  so.integrator.rtol = rtol;
  so.integrator.atol = 1e-3 * rtol;
  so.integrator.method = "erk5";
  so.t_end = t_end;
  so.output_interval = interval;
  return so;
}

/// The drift control's time 0.05 s and the slack policy (bilateral links unless told).
inline StringModelOptions contact_options(SlackPolicy slack = StringModelOptions{}.slack) {
  StringModelOptions mo;
  mo.stabilization_time = 0.05;
  mo.slack = slack;
  return mo;
}

/// A chain over a pulley of radius R about the origin (2D), by arc length s from its left end: up the
/// left side (x = −R) for x2, over the half circle πR, down the right side (x = +R). Its point and unit
/// tangent at s.
inline Vec<2> pulley_path_point(double R, double x2, double s) {
  if (s <= x2) return Vec<2>(-R, s - x2);
  if (s <= x2 + kPi * R) {
    const double phi = (s - x2) / R;
    return Vec<2>(-R * std::cos(phi), R * std::sin(phi));
  }
  return Vec<2>(R, -(s - x2 - kPi * R));
}
inline Vec<2> pulley_path_tangent(double R, double x2, double s) {
  if (s <= x2) return Vec<2>(0.0, 1.0);
  if (s <= x2 + kPi * R) {
    const double phi = (s - x2) / R;
    return Vec<2>(std::sin(phi), std::cos(phi));
  }
  return Vec<2>(0.0, -1.0);
}

/// The chain of density λ and length ℓ on that path, `links` links, moving along itself at v0.
inline Chain<2> pulley_chain(double lambda, double ell, double R, double x2, double v0, int links) {
  Chain<2> chain = Chain<2>::uniform(lambda, ell, links, false);
  for (int i = 0; i <= links; ++i) {
    chain.positions().col(i) = pulley_path_point(R, x2, i * ell / links);
    chain.velocities().col(i) = v0 * pulley_path_tangent(R, x2, i * ell / links);
  }
  return chain;
}

/// The pulley of that path: a cylinder of radius R about the origin, Coulomb's mu (0: smooth).
inline Obstacle<2> pulley(double R, double mu = 0) {
  Obstacle<2> o;
  o.kind = Obstacle<2>::Kind::kCylinder;
  o.point = Vec<2>::Zero();
  o.radius = R;
  o.mu = mu;
  o.name = "pulley";
  return o;
}

}  // namespace chainsim::test
