// `chainsim run SCENE [--out DIR] [--t-end T] [--json]`: runs a scene on the model it asks for:
//   - no heap and no fold: the string solver (StringModel; no fronts, no root functions);
//   - a heap or a fold:    the string solver with front tracking (FrontModel, cases/scene/front_scene.hpp);
//   - model = "reduced":   the reduced ODE of the canonical problem the scene is (cases/scene/reduced_scene.hpp).
//
// Sample runs:
//   $ chainsim run cases/scenes/hanging_chain.toml --out results/hanging
//   scene      cases/scenes/hanging_chain.toml (2D, 41 nodes, open)
//   effects    gravity; prescribed node 0: fixed; 0 root functions, 0 junction unknowns
//   ...
//   outputs    results/hanging: nodes.csv tension.csv energy.csv string.pvd frames/ stats.json
//
//   $ chainsim run cases/scenes/falling_chain.toml --out results/falling
//   scene      cases/scenes/falling_chain.toml (2D, 101 nodes, open)
//   fronts     heap_end (f = 0.5, on a plane); 3 root functions (2 per front + 1 stop event)
//   ...
//   stop       the heap_end front reached s0 = 0.01 m at t = 0.38232 s
//
// Steps: 1. parse the scene, 2. build and check the model (before any run), 3. check that the output
// directory is writable, 4. integrate, 5. write the outputs (also after a numerical failure, up to
// the failure, before the error is reported; stats.json last), 6. print the summary. With --json
// every outcome, failures included, prints one JSON object on stdout.
#include "cases/cli/run_command.hpp"

#include <cmath>
#include <filesystem>
#include <ostream>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "cases/scene/front_scene.hpp"
#include "cases/scene/reduced_scene.hpp"
#include "cases/scene/scene_json.hpp"
#include "cases/scene/scene.hpp"
#include "mesh/errors.hpp"
#include "solver/output.hpp"

namespace chainsim {

namespace {

std::string join_words(const std::vector<std::string>& words) {
  std::string out;
  for (const auto& w : words) out += (out.empty() ? "" : ", ") + w;
  return out;
}

std::string output_files(const OutputSelection& o, bool fronts = false) {
  std::string files;
  auto add = [&](bool on, const char* name) {
    if (on) files += std::string(files.empty() ? "" : " ") + name;
  };
  add(o.csv && o.nodes, "nodes.csv");
  add(o.csv && o.tension && !fronts, "tension.csv");
  add(o.csv && o.energy, fronts ? "series.csv" : "energy.csv");
  add(o.vtk && o.nodes, "string.pvd frames/");
  add(o.stats, "stats.json");
  return files.empty() ? "(none)" : files;
}

/// Removes every file a run of any model writes, so that a directory never mixes two runs.
void clear_outputs(const std::filesystem::path& dir) {
  std::error_code ec;
  for (const char* name : {"stats.json", "nodes.csv", "tension.csv", "energy.csv", "series.csv", "string.pvd"})
    std::filesystem::remove(dir / name, ec);
  std::filesystem::remove_all(dir / "frames", ec);
}

void print_json(std::ostream& out, nlohmann::json j, const SceneSpec& spec, const std::filesystem::path& dir) {
  j["scene"] = spec.source;
  j["scene_effective"] = scene_to_json(spec);
  j["out"] = dir.string();
  out << j.dump() << '\n';
}

template <int dim>
int run_string_scene(const SceneSpec& spec, const std::filesystem::path& dir, bool json, std::ostream& out) {
  // 2.-3. Model, checked; the output directory, before integrating.
  StringScene<dim> scene = build_string_scene<dim>(spec);
  ensure_writable_directory(dir);
  StringSolver<dim> solver(*scene.model, scene.solver);
  auto summary_json = [&] {
    nlohmann::json j = to_json(solver.summary());
    j["model"] = "string";
    j["fronts"] = nlohmann::json::array();  // none built: no front unknowns, no root functions
    j["num_fronts"] = 0;
    return j;
  };
  // 4.-5. Integrate and write.
  try {
    solver.run();
  } catch (const NumericalError& e) {
    clear_outputs(dir);
    solver.write_outputs(dir, scene.output);
    if (json) {
      nlohmann::json j = summary_json();
      j["exit_code"] = 3;
      print_json(out, j, spec, dir);
    }
    throw;
  }
  clear_outputs(dir);
  solver.write_outputs(dir, scene.output);
  // 6. Summary.
  const RunSummary& s = solver.summary();
  if (json) {
    print_json(out, summary_json(), spec, dir);
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

template <int dim>
int run_front_scene(const SceneSpec& spec, const std::filesystem::path& dir, bool json, std::ostream& out) {
  // 2.-3. Model, checked; the output directory, before integrating.
  FrontScene<dim> scene = build_front_scene<dim>(spec);
  ensure_writable_directory(dir);
  // 4.-5. Integrate (a numerical failure ends the run with status "failed"), write, summary last.
  const FrontRun run = run_fronts(*scene.model, scene.run);
  const nlohmann::json summary = front_summary(scene, run);
  clear_outputs(dir);
  write_front_outputs(dir, scene, run, summary);
  const bool failed = run.status == "failed";
  // 6. Summary.
  if (json) {
    nlohmann::json j = summary;
    if (failed) j["exit_code"] = 3;
    print_json(out, j, spec, dir);
  } else {
    const nlohmann::json& d = scene.description;
    std::vector<std::string> fronts;
    for (const nlohmann::json& f : d["fronts"]) {
      std::string where;
      if (f.contains("on_plane")) where = f["on_plane"].get<bool>() ? ", on a plane" : ", pinned";
      fronts.push_back(fmt::format("{} (f = {:g}, s0 = {:g} m{})", f["name"].get<std::string>(), f["f"].get<double>(),
                                   f["s0"].get<double>(), where));
    }
    const int stops = static_cast<int>(d["stop_events"].size());
    std::vector<std::string> effects = d["effects"].get<std::vector<std::string>>();
    const auto prescribed = d["prescribed"].get<std::vector<std::string>>();
    out << fmt::format("scene      {} ({}D, {} nodes, open)\n", spec.source, dim, d["nodes"].get<int>());
    out << fmt::format("fronts     {}; {} root functions (2 per front + {} stop event{})\n", join_words(fronts),
                       d["root_functions"].get<int>(), stops, stops == 1 ? "" : "s");
    out << fmt::format("effects    {}{}\n", effects.empty() ? "none" : join_words(effects),
                       prescribed.empty() ? "" : "; prescribed " + join_words(prescribed));
    out << fmt::format("method     {} (order {}), rtol {:g}, atol {:g}\n", run.stats.method, run.stats.order,
                       scene.run.integrator.rtol, scene.run.integrator.atol);
    out << fmt::format("run        {} at t = {:.6g} s (t_end = {:g} s) in {:.3f} s wall: {} steps, {} rhs "
                       "evaluations, {} crossings\n",
                       run.status, run.t_stop, scene.run.t_end, run.wall_s, run.stats.steps, run.stats.rhs_evals,
                       run.transfers);
    out << fmt::format("stop       {}\n", failed ? run.error : summary["stop_reason"].get<std::string>());
    out << fmt::format("ledger     energy residual {:.3e}, momentum residual {:.3e} (relative)\n",
                       run.relative_energy_residual(), run.relative_momentum_residual());
    out << fmt::format("links      max | |dx| - h | / h = {:.3e} (stabilization time {:g} s)\n", run.max_violation,
                       d["stabilization_time"].get<double>());
    out << fmt::format("outputs    {}: {}\n", dir.string(), output_files(scene.output, true));
  }
  if (failed) throw NumericalError(fmt::format("the string solver with fronts failed: {}", run.error), run.t_stop);
  return 0;
}

int run_reduced_scene(const SceneSpec& spec, const std::filesystem::path& dir, bool json, std::ostream& out) {
  // 2.-3. The canonical problem the scene is (or the reason it is none); the output directory.
  const ReducedSetup setup = match_canonical_problem(spec);
  ensure_writable_directory(dir);
  // 4.-5. Integrate, write the series and the summary (last).
  ReducedRun run{CsvTable(series_columns()), {}};
  try {
    run = solve_reduced(setup);
  } catch (const NumericalError& e) {
    if (json)
      print_json(out, {{"status", "failed"}, {"model", "reduced"}, {"error", e.what()}, {"exit_code", 3}}, spec, dir);
    throw;
  }
  run.summary["t_end"] = spec.stop.t_end;
  clear_outputs(dir);
  run.series.write(dir / "series.csv");
  write_json(dir / "stats.json", run.summary);
  // 6. Summary.
  if (json) {
    print_json(out, run.summary, spec, dir);
    return 0;
  }
  const auto& s = run.summary;
  const auto& p = s["parameters"];
  auto exact = [](const nlohmann::json& v) { return v.is_number() ? fmt::format("{:.12g}", v.get<double>()) : "-"; };
  out << fmt::format("scene      {}: the {} chain (reduced model)\n", spec.source, s["problem"].get<std::string>());
  out << fmt::format("parameters l = {:g} m, lambda = {:g} kg/m, g = {:g} m/s^2, f = {:g}, eta0 = {:g}, eps = {:g}, "
                     "F = {:g} N\n",
                     p["length"].get<double>(), p["density"].get<double>(), p["gravity"].get<double>(),
                     p["f"].get<double>(), p["eta0"].get<double>(), p["eps"].get<double>(), p["force"].get<double>());
  out << fmt::format("stop       {} at t = {:.12g} s (t/t0 = {:.12g}, exact {})\n", s["stop_reason"].get<std::string>(),
                     s["t_stop"].get<double>(), s["t_stop_over_t0"].get<double>(), exact(s["t_stop_over_t0_exact"]));
  out << fmt::format("outputs    {}: series.csv stats.json\n", dir.string());
  return 0;
}

template <int dim>
int run_scene(const SceneSpec& spec, const std::filesystem::path& dir, bool json, std::ostream& out) {
  if (spec.model == "reduced") return run_reduced_scene(spec, dir, json, out);
  if (spec.has_fronts()) return run_front_scene<dim>(spec, dir, json, out);
  return run_string_scene<dim>(spec, dir, json, out);
}

template <int dim>
void check_in(const SceneSpec& spec) {
  if (spec.model == "reduced")
    match_canonical_problem(spec);
  else if (spec.has_fronts())
    build_front_scene<dim>(spec);
  else
    build_string_scene<dim>(spec);
}

}  // namespace

void check_scene(const SceneSpec& spec) {
  if (spec.dimension == 3)
    check_in<3>(spec);
  else
    check_in<2>(spec);
}

int run_scene_command(const RunCommandOptions& options, std::ostream& out) {
  try {
    // 1. Scene (and the command line's overrides).
    SceneSpec spec = parse_scene(options.scene, options.overrides);
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
