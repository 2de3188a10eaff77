#pragma once
// What the contact tests share (solver/contact_module.hpp; docs/model.md §10): the smooth table, the
// model's options and the run's, so that each test file builds its chains on the same obstacles.
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

}  // namespace chainsim::test
