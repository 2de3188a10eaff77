// `chainsim run SCENE [--out DIR] [--json]`: runs a string scene with the general string solver.
//
// Sample run (the hanging chain of cases/scenes/hanging_chain.toml):
//   $ chainsim run cases/scenes/hanging_chain.toml --out results/hanging
//   scene      cases/scenes/hanging_chain.toml (2D, 41 nodes, open)
//   ...
//   outputs    results/hanging: nodes.csv tension.csv energy.csv stats.json string.pvd frames/
//
// Steps: 1. parse the scene, 2. build the model, 3. integrate, 4. write the outputs (also after a
// numerical failure, up to the failure, before the error is reported), 5. print the summary.
#include "cases/run_command.hpp"

#include <filesystem>
#include <ostream>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "cases/scene.hpp"
#include "solver/errors.hpp"
#include "solver/output.hpp"

namespace chainsim {

namespace {

template <int dim>
int run_scene(const SceneSpec& spec, const std::filesystem::path& dir, bool json, std::ostream& out) {
  // 2. Model.
  StringScene<dim> scene = build_string_scene<dim>(spec);
  ensure_directory(dir);  // fail on a bad --out before integrating
  StringSolver<dim> solver(*scene.model, scene.solver);
  // 3.-4. Integrate and write.
  try {
    solver.run();
  } catch (const NumericalError&) {
    solver.write_outputs(dir, scene.vtk);
    throw;
  }
  solver.write_outputs(dir, scene.vtk);
  // 5. Summary.
  const RunSummary& s = solver.summary();
  const auto& chain = scene.model->chain();
  if (json) {
    nlohmann::json j = to_json(s);
    j["scene"] = spec.source;
    j["out"] = dir.string();
    j["dimension"] = dim;
    j["nodes"] = chain.num_nodes();
    j["stabilization_time"] = scene.model->options().stabilization_time;
    out << j.dump() << '\n';
    return 0;
  }
  out << fmt::format("scene      {} ({}D, {} nodes, {})\n", spec.source, dim, chain.num_nodes(),
                     chain.closed() ? "closed" : "open");
  out << fmt::format("method     {} (order {}), rtol {:g}, atol {:g}, tension backend {}\n", s.stats.method,
                     s.stats.order, scene.solver.integrator.rtol, scene.solver.integrator.atol, s.tension_backend);
  out << fmt::format("run        t_end = {:g} s in {:.3f} s wall: {} steps, {} rhs evaluations, {} tension solves\n",
                     s.t_end, s.wall_s, s.stats.steps, s.stats.rhs_evals, s.tension_solves);
  out << fmt::format("ledger     energy drift {:.3e} J (max over frames; energy scale {:.3e} J)\n", s.energy_drift,
                     s.energy_scale);
  out << fmt::format("links      max | |dx| - h | / h = {:.3e} (stabilization time {:g} s)\n",
                     s.max_constraint_violation, scene.model->options().stabilization_time);
  out << fmt::format("outputs    {}: nodes.csv tension.csv energy.csv stats.json{}\n", dir.string(),
                     scene.vtk ? " string.pvd frames/" : "");
  return 0;
}

}  // namespace

int run_scene_command(const RunCommandOptions& options, std::ostream& out) {
  // 1. Scene.
  const SceneSpec spec = parse_scene(options.scene);
  const std::filesystem::path dir =
      options.out.empty() ? std::filesystem::path("results") / std::filesystem::path(options.scene).stem()
                          : std::filesystem::path(options.out);
  if (spec.dimension == 3) return run_scene<3>(spec, dir, options.json, out);
  return run_scene<2>(spec, dir, options.json, out);
}

}  // namespace chainsim
