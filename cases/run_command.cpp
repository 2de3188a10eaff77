// `chainsim run SCENE [--out DIR] [--t-end T] [--json]`: runs a string scene with the general string solver.
//
// Sample run (the hanging chain of cases/scenes/hanging_chain.toml):
//   $ chainsim run cases/scenes/hanging_chain.toml --out results/hanging
//   scene      cases/scenes/hanging_chain.toml (2D, 41 nodes, open)
//   effects    gravity; prescribed node 0: fixed; 0 root functions, 0 junction unknowns
//   ...
//   outputs    results/hanging: nodes.csv tension.csv energy.csv string.pvd frames/ stats.json
//
// Steps: 1. parse the scene, 2. build and check the model (before any run), 3. check that the output
// directory is writable, 4. integrate, 5. write the outputs (also after a numerical failure, up to
// the failure, before the error is reported), 6. print the summary. With --json every outcome,
// failures included, prints one JSON object on stdout.
#include "cases/run_command.hpp"

#include <cmath>
#include <filesystem>
#include <ostream>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "cases/scene.hpp"
#include "solver/errors.hpp"
#include "solver/output.hpp"

namespace chainsim {

namespace {

std::string join_words(const std::vector<std::string>& words) {
  std::string out;
  for (const auto& w : words) out += (out.empty() ? "" : ", ") + w;
  return out;
}

std::string output_files(const OutputSelection& o) {
  std::string files;
  auto add = [&](bool on, const char* name) {
    if (on) files += std::string(files.empty() ? "" : " ") + name;
  };
  add(o.csv && o.nodes, "nodes.csv");
  add(o.csv && o.tension, "tension.csv");
  add(o.csv && o.energy, "energy.csv");
  add(o.vtk, "string.pvd frames/");
  add(o.stats, "stats.json");
  return files.empty() ? "(none)" : files;
}

template <int dim>
int run_scene(const SceneSpec& spec, const std::filesystem::path& dir, bool json, std::ostream& out) {
  // 2.-3. Model, checked; the output directory, before integrating.
  StringScene<dim> scene = build_string_scene<dim>(spec);
  ensure_writable_directory(dir);
  StringSolver<dim> solver(*scene.model, scene.solver);
  // 4.-5. Integrate and write.
  try {
    solver.run();
  } catch (const NumericalError& e) {
    solver.write_outputs(dir, scene.output);
    if (json) {
      nlohmann::json j = to_json(solver.summary());
      j["scene"] = spec.source;
      j["out"] = dir.string();
      j["exit_code"] = 3;
      out << j.dump() << '\n';
    }
    throw;
  }
  solver.write_outputs(dir, scene.output);
  // 6. Summary.
  const RunSummary& s = solver.summary();
  if (json) {
    nlohmann::json j = to_json(s);
    j["scene"] = spec.source;
    j["out"] = dir.string();
    out << j.dump() << '\n';
    return 0;
  }
  out << fmt::format("scene      {} ({}D, {} nodes, {})\n", spec.source, s.dimension, s.nodes,
                     scene.model->chain().closed() ? "closed" : "open");
  out << fmt::format("effects    {}; {}{} root functions, {} junction unknowns\n",
                     s.effects.empty() ? "none" : join_words(s.effects),
                     s.prescribed.empty() ? "" : "prescribed " + join_words(s.prescribed) + "; ", s.root_functions,
                     s.junction_unknowns);
  out << fmt::format("method     {} (order {}), rtol {:g}, atol {:g}, tension backend {}\n", s.stats.method,
                     s.stats.order, scene.solver.integrator.rtol, scene.solver.integrator.atol, s.tension_backend);
  out << fmt::format("run        t_end = {:g} s in {:.3f} s wall: {} steps, {} rhs evaluations, {} tension solves\n",
                     s.t_end, s.wall_s, s.stats.steps, s.stats.rhs_evals, s.tension_solves);
  out << fmt::format("ledger     energy drift {:.3e} J (max over frames; energy scale {:.3e} J)\n", s.energy_drift,
                     s.energy_scale);
  out << fmt::format("links      max | |dx| - h | / h = {:.3e} (stabilization time {:g} s)\n",
                     s.max_constraint_violation, s.stabilization_time);
  out << fmt::format("outputs    {}: {}\n", dir.string(), output_files(scene.output));
  return 0;
}

}  // namespace

int run_scene_command(const RunCommandOptions& options, std::ostream& out) {
  try {
    // 1. Scene (and the command line's overrides).
    SceneSpec spec = parse_scene(options.scene);
    if (options.t_end) {
      if (!(*options.t_end > 0 && std::isfinite(*options.t_end)))
        throw InputError(fmt::format("--t-end = {:g} is out of range: allowed t_end > 0", *options.t_end));
      spec.stop.t_end = *options.t_end;
    }
    const std::filesystem::path dir =
        options.out.empty() ? std::filesystem::path("results") / std::filesystem::path(options.scene).stem()
                            : std::filesystem::path(options.out);
    if (spec.dimension == 3) return run_scene<3>(spec, dir, options.json, out);
    return run_scene<2>(spec, dir, options.json, out);
  } catch (const NumericalError&) {
    throw;  // already reported by run_scene (with the partial summary)
  } catch (const std::exception& e) {
    if (options.json) {
      const bool input = dynamic_cast<const InputError*>(&e) != nullptr;
      out << nlohmann::json{{"status", "failed"}, {"error", e.what()}, {"scene", options.scene},
                            {"exit_code", input ? 2 : 1}}
                 .dump()
          << '\n';
    }
    throw;
  }
}

}  // namespace chainsim
