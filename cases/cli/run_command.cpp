// `chainsim run SCENE [--out DIR] [--t-end T] [--json]`: runs a scene on the model it asks for:
//   - no heap and no fold: the string solver (StringModel; no fronts, no root functions);
//   - a heap or a fold:    the same string solver with front tracking (cases/scene/front_scene.hpp);
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
//   fronts     heap_end (f = 0.5, on a plane); 3 root functions, 1 of them stop event
//   ...
//   stop       the heap_end front reached s0 = 0.01 m at t = 0.38232 s
//
// Steps: 1. parse the scene, 2. build and check the model (before any run), 3. lock the output
// directory (refused if another run holds it), check that it is writable and remove what any chainsim
// command wrote there before, 4. integrate (SIGINT or SIGTERM: stop at the next accepted step), 5. write the outputs (also after a numerical failure, up to
// the failure, before the error is reported; stats.json last), 6. print the summary. With --json
// every outcome, failures included, prints one JSON object on stdout.
#include "cases/cli/run_command.hpp"

#include <cmath>
#include <filesystem>
#include <iostream>
#include <optional>
#include <ostream>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "cases/scene/front_scene.hpp"
#include "cases/scene/reduced_scene.hpp"
#include "cases/scene/scene_json.hpp"
#include "cases/scene/scene.hpp"
#include "cases/scene/scene_run.hpp"
#include "cases/cli/progress.hpp"
#include "solver/interrupt.hpp"
#include "mesh/errors.hpp"
#include "solver/output.hpp"

namespace chainsim {

namespace {

/// The exit code of a run stopped by Ctrl-C (128 + SIGINT, as a shell reports it).
constexpr int kInterruptedExit = 130;

std::string join_words(const std::vector<std::string>& words) {
  std::string out;
  for (const auto& w : words) out += (out.empty() ? "" : ", ") + w;
  return out;
}

/// What the run wrote: the outputs present in its directory (cleared before the run and locked).
std::string output_files(const std::filesystem::path& dir) {
  std::string files;
  for (const std::string& name : outputs_present(dir)) files += (files.empty() ? "" : " ") + name;
  return files.empty() ? "(none)" : files;
}

void print_json(std::ostream& out, nlohmann::json j, const SceneSpec& spec, const std::filesystem::path& dir) {
  j["scene"] = spec.source;
  j["scene_effective"] = scene_to_json(spec);
  j["out"] = dir.string();
  out << json_text(j) << '\n';
}

template <int dim>
int run_string_scene(const SceneSpec& spec, const std::filesystem::path& dir, bool json, bool quiet,
                     std::ostream& out) {
  // Ctrl-C and SIGTERM from here on stop the run at its next accepted step (none taken yet: at t = 0).
  install_sigint_handler();
  // 2.-3. Model, checked; the output directory, locked for the whole run, before integrating (what
  //       any chainsim command wrote there before removed).
  SceneRun<dim> scene(spec);
  const RunDirectory run_dir(dir);
  run_dir.clear();
  scene.stream(run_dir);  // the frames' files written while the run goes on
  const StringSolver<dim>& solver = scene.solver();
  const bool fronts = scene.has_fronts();
  // 4.-5. Integrate (a numerical failure, or a signal, still writes what was done), write, summary last.
  std::optional<NumericalError> failure;
  {
    ProgressLine progress(scene.solver_options().t_end, progress_wanted(quiet));
    failure = scene.run([&](double t) { progress.update(t); });
  }
  const bool interrupted = solver.summary().status == "interrupted";
  nlohmann::json summary = scene.summary();
  scene.write(run_dir, summary);
  if (failure && json) summary["exit_code"] = 3;
  if (interrupted && json) summary["exit_code"] = kInterruptedExit;
  // 6. Summary.
  const RunSummary& s = solver.summary();
  // The JSON summary is for a program: the warning also goes to stderr, for the person who ran it
  // (the text report has it on its 'warning' line).
  if (json && !s.tolerance_warning.empty()) std::cerr << "chainsim: warning: " << s.tolerance_warning << '\n';
  const std::string resolution_warning = summary.value("resolution_warning", std::string());
  if (json && !resolution_warning.empty()) std::cerr << "chainsim: warning: " << resolution_warning << '\n';
  if (json) {
    print_json(out, summary, spec, dir);
  } else if (!failure) {  // a failure is reported by its message (outputs written up to it)
    out << fmt::format("scene      {} ({}D, {} nodes, {})\n", spec.source, s.dimension, s.nodes,
                       scene.model().chain().closed() ? "closed" : "open");
    if (fronts) {
      // description() returns a copy: keep it alive for the loop (a range over a member of the
      // temporary would dangle).
      const nlohmann::json description = scene.description();
      std::vector<std::string> names;
      for (const nlohmann::json& f : description["fronts"]) {
        std::string where;
        if (f.contains("on_plane")) where = f["on_plane"].get<bool>() ? ", on a plane" : ", pinned";
        if (f.contains("inserted")) {  // [solver] kinks = "insert": not in the string until a kink forms
          names.push_back(fmt::format("{} (f = {:g}, inserted where the tangent turns by {:g} deg over {:g} m)",
                                      f["name"].get<std::string>(), f["f"].get<double>(), f["turn"].get<double>(),
                                      f["window"].get<double>()));
          continue;
        }
        names.push_back(fmt::format("{} (f = {:g}, s0 = {:g} m{})", f["name"].get<std::string>(),
                                    f["f"].get<double>(), f["s0"].get<double>(), where));
      }
      const int stops = static_cast<int>(description["stop_events"].size());
      // The count is the run's (each kind of front has its own, and obstacles and slack links add theirs).
      out << fmt::format("fronts     {}; {} root functions, {} of them stop event{}\n", join_words(names),
                         s.root_functions, stops, stops == 1 ? "" : "s");
    }
    out << fmt::format("effects    {}; {}{} root functions\n", s.effects.empty() ? "none" : join_words(s.effects),
                       s.prescribed.empty() ? "" : "prescribed " + join_words(s.prescribed) + "; ", s.root_functions);
    out << fmt::format("method     {} (order {}), rtol {:g}, atol {:g}, tension backend {}\n", s.stats.method,
                       s.stats.order, scene.solver_options().integrator.rtol,
                       scene.solver_options().integrator.atol, s.tension_backend);
    out << fmt::format("run        {} at t = {:.6g} s (t_end = {:g} s) in {:.3f} s wall: {} steps, {} rhs "
                       "evaluations, {} tension solves{}\n",
                       s.status, s.t_stop, s.t_end, s.wall_s, s.stats.steps, s.stats.rhs_evals, s.tension_solves,
                       fronts ? fmt::format(", {} crossings", s.transfers) : "");
    if (s.status != "completed") out << fmt::format("stop       {}\n", summary["stop_reason"].get<std::string>());
    if (s.impulsive_start)
      out << fmt::format("start      {}\n", summary["impulsive_start"]["message"].get<std::string>());
    out << fmt::format("ledger     energy drift {:.3e} J (max over frames{}; energy scale {:.3e} J){}\n",
                       s.energy_drift, fronts ? " and steps" : "", s.energy_scale,
                       fronts ? fmt::format(", momentum residual {:.3e} (relative)", s.relative_momentum_residual())
                              : "");
    out << fmt::format("links      max | |dx| - h | / h = {:.3e} (stabilization time {:g} s)\n",
                       s.max_constraint_violation, s.stabilization_time);
    const nlohmann::json& slack = summary["slack"];
    out << fmt::format("slack      {} (policy {})\n",
                       s.slack                                   ? s.slack->message()
                       : s.slack_policy == SlackPolicy::kIgnore ? "not checked"
                       : s.slack_policy == SlackPolicy::kAllow && slack.contains("snaps")
                           ? fmt::format("allowed: {} snap{} taut by t = {:g} s, W_snap = {:.4g} J, W_snap_supports = "
                                         "{:.4g} J (W_snap, W_snap_supports, W_links in energy.csv)",
                                         slack["snaps"].get<long long>(), slack["snaps"] == 1 ? "" : "s",
                                         slack["ledger_t"].get<double>(), slack["W_snap"].get<double>(),
                                         slack["W_snap_supports"].get<double>())
                       : s.slack_policy == SlackPolicy::kAllow
                           ? "allowed: links go slack and snap taut (W_snap, W_snap_supports, W_links in energy.csv)"
                           : "none at any accepted step",
                       to_string(s.slack_policy));
    if (!s.tolerance_warning.empty()) out << fmt::format("warning    {}\n", s.tolerance_warning);
    if (!resolution_warning.empty()) out << fmt::format("warning    {}\n", resolution_warning);
    out << fmt::format("outputs    {}: {}\n", dir.string(), output_files(dir));
  }
  if (failure) throw *failure;
  return interrupted ? kInterruptedExit : 0;
}

int run_reduced_scene(const SceneSpec& spec, const std::filesystem::path& dir, bool json, std::ostream& out) {
  // 2.-3. The canonical problem the scene is (or the reason it is none); the output directory.
  const ReducedSetup setup = match_canonical_problem(spec);
  const RunDirectory run_dir(dir);
  run_dir.clear();
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
  out << fmt::format("outputs    {}: {}\n", dir.string(), output_files(dir));
  return 0;
}

template <int dim>
int run_scene(const SceneSpec& spec, const std::filesystem::path& dir, bool json, bool quiet, std::ostream& out) {
  if (spec.model == "reduced") return run_reduced_scene(spec, dir, json, out);
  return run_string_scene<dim>(spec, dir, json, quiet, out);
}

template <int dim>
void check_in(const SceneSpec& spec) {
  if (spec.model == "reduced")
    match_canonical_problem(spec);
  else
    SceneRun<dim>{spec};
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
    if (options.t_end) replace_t_end(spec, *options.t_end, "--t-end");
    if (options.max_wall) {
      if (!(*options.max_wall > 0 && std::isfinite(*options.max_wall)))
        throw InputError(fmt::format("--max-wall = {:g} is out of range: allowed max_wall > 0 (s)", *options.max_wall));
      spec.solver.max_wall_s = *options.max_wall;
    }
    const std::filesystem::path dir =
        options.out.empty() ? std::filesystem::path("results") / std::filesystem::path(options.scene).stem()
                            : std::filesystem::path(options.out);
    if (spec.dimension == 3) return run_scene<3>(spec, dir, options.json, options.quiet, out);
    return run_scene<2>(spec, dir, options.json, options.quiet, out);
  } catch (const NumericalError&) {
    throw;  // already reported by run_scene (with the partial summary)
  } catch (const std::exception& e) {
    if (options.json) {
      const bool input = dynamic_cast<const InputError*>(&e) != nullptr;
      out << json_text({{"status", "failed"}, {"error", e.what()}, {"scene", options.scene},
                        {"exit_code", input ? 2 : 1}})
          << '\n';
    }
    throw;
  }
}

}  // namespace chainsim
