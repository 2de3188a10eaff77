// Uses the installed chainsim: the falling chain's reduced ODE against its exact quadrature, and a
// scene (a double pendulum of two links, a scene given as text) through the same runner as `chainsim run`,
// against the conservation of energy. Exit 0 when both agree.
#include <cmath>
#include <cstdio>

#include "cases/reduced/reduced_models.hpp"
#include "cases/scene/scene.hpp"
#include "cases/scene/scene_run.hpp"

int main() {
  chainsim::ReducedSetup setup;
  setup.problem = chainsim::Problem::kFalling;
  setup.chain.dissipation = 0.5;
  const chainsim::ReducedRun run = chainsim::solve_reduced(setup);
  const double t = run.summary["t_stop_over_t0"].get<double>(), exact = run.summary["t_stop_over_t0_exact"].get<double>();
  std::printf("falling chain, f = 0.5: t_stop/t0 = %.15g, exact %.15g\n", t, exact);

  const char* text = "[string]\nlength = 2.0\nnodes = 3\n"
                     "[shape]\nkind = \"polyline\"\npoints = [[0.0, 0.0], [1.2, -1.6]]\n"
                     "[ends]\nstart = \"fixed\"\n[effects.gravity]\ng = [0.0, -9.81]\n[stop]\nt_end = 0.4\n";
  chainsim::SceneRun<2> pendulum(chainsim::parse_scene_text(text, "pendulum"));
  const bool failed = pendulum.run().has_value();
  const double drift = pendulum.solver().summary().relative_energy_drift();
  std::printf("pendulum: %s, relative energy drift %.3g\n", pendulum.solver().summary().status.c_str(), drift);
  return std::abs(t - exact) <= 1e-9 * exact && !failed && drift < 1e-6 ? 0 : 1;
}
