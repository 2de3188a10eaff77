// chainsim: the command-line front end. Only parses arguments (CLI11 is slow to compile, so it is
// confined to this file) and maps errors to exit codes; every command lives in cases/*_command.cpp.
//
// Exit codes: 0 success, 1 internal error, 2 bad input (option, value, scene), 3 numerical failure.
#include <iostream>
#include <sstream>

#include <CLI/CLI.hpp>
#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "cases/cli/commands.hpp"
#include "cases/cli/fit_options.hpp"
#include "cases/cli/run_command.hpp"
#include "mesh/errors.hpp"
#include "solver/output.hpp"

namespace {

using chainsim::IntegratorOptions;

void add_integrator_options(CLI::App& cmd, IntegratorOptions& o) {
  std::string methods;
  for (const auto& [name, what] : chainsim::method_aliases()) methods += "\n  " + name + ": " + what;
  cmd.add_option("--method", o.method, "ARKODE method: an alias or an ARKODE_* table name" + methods)
      ->capture_default_str();
  cmd.add_option("--rtol", o.rtol, "relative tolerance, 1e-14 <= rtol <= 1e-2")->capture_default_str();
  cmd.add_option("--atol", o.atol, "absolute tolerance, relative to the state's natural scale")->capture_default_str();
  cmd.add_option("--max-step", o.max_step, "largest time step (s); 0 = the command's default")->capture_default_str();
}

/// The subcommand the command line entered (nullptr before one).
const CLI::App* entered_subcommand(const CLI::App& app) {
  for (const CLI::App* sub : app.get_subcommands([](const CLI::App* c) { return c->parsed(); })) return sub;
  return nullptr;
}

std::string command_names(const CLI::App& app) {
  std::string names;
  for (const CLI::App* sub : app.get_subcommands([](const CLI::App*) { return true; }))
    names += (names.empty() ? "" : ", ") + sub->get_name();
  return names;
}

/// A CLI11 parse error in chainsim's words: the option, the value as written, and what is allowed (the
/// option's help text carries its range).
std::string describe_parse_error(const CLI::App& app, const CLI::ParseError& e, const std::string& first_argument) {
  const CLI::App* sub = entered_subcommand(app);
  const CLI::App& where = sub ? *sub : app;
  const std::string command = sub ? "chainsim " + sub->get_name() : "chainsim";
  const std::string what = e.what();
  auto help_of = [&](const std::string& name) -> std::string {
    for (const CLI::Option* o : where.get_options())
      if (o->check_name(name) || o->get_name() == name) return o->get_description();
    return "";
  };
  auto valid_options = [&] {
    std::string names;
    for (const CLI::Option* o : where.get_options())
      if (!o->get_lnames().empty()) names += (names.empty() ? "--" : ", --") + o->get_lnames().front();
    return names;
  };
  const std::string hint = fmt::format(" (see '{} --help')", command);
  const auto code = static_cast<CLI::ExitCodes>(e.get_exit_code());
  if (code == CLI::ExitCodes::ConversionError) {
    // "Could not convert: --f = abc"
    const auto colon = what.find(": "), eq = what.find(" = ");
    if (colon != std::string::npos && eq != std::string::npos && eq > colon) {
      const std::string name = what.substr(colon + 2, eq - colon - 2), value = what.substr(eq + 3);
      const CLI::Option* o = nullptr;
      for (const CLI::Option* c : where.get_options())
        if (c->check_name(name)) o = c;
      const std::string kind = o && o->get_type_name() == "INT" ? "an integer" : "a number";
      return fmt::format("{} = '{}' is not {}: allowed {}", name, value, kind, help_of(name));
    }
  }
  if (!sub && !first_argument.empty() && first_argument[0] != '-')
    return fmt::format("unknown command '{}': allowed {}{}", first_argument, command_names(app), hint);
  if (code == CLI::ExitCodes::ExtrasError) {
    // "The following argument(s) was/were not expected: --bogus"
    const std::string extras = what.substr(what.find(": ") + 2);
    return fmt::format("unknown or extra argument{} {} for {}; valid options: {}", extras.find(' ') == std::string::npos ? "" : "s",
                       extras, command, valid_options());
  }
  if (code == CLI::ExitCodes::RequiredError) {
    if (!sub) return fmt::format("a command is required: {}{}", command_names(app), hint);
    const std::string name = what.substr(0, what.find(" is required"));
    return fmt::format("{} needs the argument '{}' ({}){}", command, name, help_of(name), hint);
  }
  if (code == CLI::ExitCodes::ArgumentMismatch) {
    // "--f: 1 required FLOAT missing" or "Expected exactly 1 arguments to --f, got 0"
    std::string name = what.substr(0, what.find(':'));
    if (what.rfind("Expected", 0) == 0) name = what.substr(what.find(" to ") + 4, what.rfind(',') - what.find(" to ") - 4);
    return fmt::format("{} needs a value: {}{}", name, help_of(name), hint);
  }
  return what + hint;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"chainsim: dynamics of inextensible strings and chains with shocks"};
  app.require_subcommand(1);
  app.set_version_flag("--version", CHAINSIM_VERSION_TEXT);  // cases/CMakeLists.txt

  // --- chainsim reduced ------------------------------------------------------------------------
  chainsim::ReducedCommandOptions reduced;
  auto* cmd_reduced = app.add_subcommand(
      "reduced", "Solve a canonical chain problem from its reduced ODE (ARKODE) and compare it with the exact quadrature");
  cmd_reduced->add_option("problem", reduced.problem, "falling | folded | sliding")->required();
  auto& rs = reduced.setup;
  cmd_reduced->add_option("--f", rs.chain.dissipation, "shock dissipation parameter f, 0 <= f <= 1")->capture_default_str();
  cmd_reduced->add_option("--eps", rs.eps, "cutoff eps, 0 < eps < 1 (falling stops at eta = eps, folded at 1 - eps)")
      ->capture_default_str();
  cmd_reduced->add_option("--eta0", rs.eta0,
                          "initial y/l, released from rest (default: falling 1, folded 0, sliding 0)");
  cmd_reduced->add_option("--force", rs.force, "upward force F on the free end of the folded chain (N), F >= 0")
      ->capture_default_str();
  cmd_reduced->add_option("--length", rs.chain.length, "chain length l (m), > 0")->capture_default_str();
  cmd_reduced->add_option("--density", rs.chain.density, "linear density lambda (kg/m), > 0")->capture_default_str();
  cmd_reduced->add_option("--gravity", rs.chain.gravity, "gravitational acceleration g (m/s^2), > 0")->capture_default_str();
  cmd_reduced->add_option("--t-max", rs.t_max_over_t0, "safety stop time, in units of t0 = sqrt(2 l / g)")->capture_default_str();
  add_integrator_options(*cmd_reduced, rs.integrator);
  cmd_reduced->add_option("--out", reduced.out, "output directory (default results/reduced/<problem>)");
  cmd_reduced->add_flag("--json", reduced.json, "print the summary as one JSON object on stdout");

  // --- chainsim canonical ----------------------------------------------------------------------
  chainsim::CanonicalCommandOptions canonical;
  auto* cmd_canonical = app.add_subcommand(
      "canonical", "The main job: the three canonical problems, each on the string solver with front tracking, as the "
                   "reduced ODE and as the exact quadrature; a summary table and the data of the paper's figures (plot "
                   "with scripts/plot_canonical.py)");
  cmd_canonical->add_option("--out", canonical.out, "output directory")->capture_default_str();
  cmd_canonical->add_option("--nodes", canonical.nodes, "nodes of the string runs, 4 <= N <= 200001")
      ->capture_default_str();
  cmd_canonical->add_flag("--quick", canonical.quick,
                          "fewer values of f: profiles at f = 0, 0.83, the string's fall time at f = 0, 0.5, 1");
  cmd_canonical->add_flag("--json", canonical.json, "print the summary rows (one per problem and f) as a JSON array");

  // --- chainsim compare ------------------------------------------------------------------------
  chainsim::CompareCommandOptions compare;
  auto* cmd_compare = app.add_subcommand(
      "compare", "Solve a canonical problem with the string solver (front tracking) and with its reduced ODE (edge, peg, "
                 "pulley: its exact solution), and compare them");
  cmd_compare->add_option("problem", compare.problem, "falling | folded | sliding | edge | peg | pulley")->required();
  auto& cs = compare.setup;
  cmd_compare->add_option("--nodes", cs.nodes, "nodes of the string, 4 <= N <= 200001")->capture_default_str();
  auto* opt_compare_f =
      cmd_compare->add_option("--f", cs.chain.dissipation, "shock dissipation parameter f, 0 <= f <= 1")->capture_default_str();
  auto* opt_compare_eps = cmd_compare->add_option("--eps", cs.eps, "cutoff eps, 0 < eps < 1")->capture_default_str();
  cmd_compare->add_option("--eta0", cs.eta0, "initial eta = y(0)/l (defaults: falling 1, folded 0, sliding 0)");
  cmd_compare->add_option("--force", cs.force, "upward force F on the free end of the folded chain (N), F >= 0")
      ->capture_default_str();
  cmd_compare->add_option("--length", cs.chain.length, "chain length l (m), > 0")->capture_default_str();
  cmd_compare->add_option("--density", cs.chain.density, "linear density lambda (kg/m), > 0")->capture_default_str();
  cmd_compare->add_option("--gravity", cs.chain.gravity, "gravitational acceleration g (m/s^2), > 0")->capture_default_str();
  cmd_compare->add_option("--t-max", cs.t_max_over_t0, "safety stop time, in units of t0")->capture_default_str();
  cmd_compare->add_option("--x0", compare.x0, "edge: hanging fraction at release, 0 < x0 < 1 (default 0.2); peg: the longer side's fraction, 0.5 < x0 < 1 (default 0.6)");
  cmd_compare->add_option("--u0", compare.u0, "pulley: the offset at release (m), 0 < u0 < (l - pi R)/2 (default 0.05)");
  cmd_compare->add_option("--R", compare.radius, "pulley: the pulley's radius (m), 0 < pi R < l (default 0.1)");
  add_integrator_options(*cmd_compare, cs.integrator);
  cmd_compare->add_option("--out", compare.out, "output directory (default results/compare/<problem>)");
  cmd_compare->add_flag("--json", compare.json, "print the summary as one JSON object on stdout");

  // --- chainsim run ----------------------------------------------------------------------------
  chainsim::RunCommandOptions run;
  auto* cmd_run = app.add_subcommand("run", "Run a string scene (a TOML file): the string solver, with front tracking when the scene has heaps or a "
                      "fold, or the reduced ODE (model = \"reduced\")");
  cmd_run->add_option("scene", run.scene, "scene file")->required();
  cmd_run->add_option("--out", run.out, "output directory (default results/<scene name>)");
  double run_t_end = 0;
  auto* opt_t_end = cmd_run->add_option("--t-end", run_t_end, "end time (s), > 0: replaces the scene's [stop] t_end");
  double run_max_wall = 0;
  auto* opt_max_wall = cmd_run->add_option(
      "--max-wall", run_max_wall, "wall-clock budget (s), > 0: replaces the scene's [solver] max_wall_s");
  cmd_run->add_flag("--quiet", run.quiet, "no progress line on stderr (there is none when stderr is not a terminal)");
  cmd_run->add_option("--set", run.overrides,
                      "KEY=VALUE: sets a scene key, checked as in the file (repeatable; a later one wins), e.g. "
                      "--set string.nodes=201 --set effects.heap[0].f=0.5 --set effects.drag.coefficient=0.1; VALUE is "
                      "a TOML value (a bare word is a string); a missing section or element is created")
      ->allow_extra_args(false);
  cmd_run->add_flag("--json", run.json,
                    "print the run summary as one JSON object on stdout (on failure: status \"failed\" and the error)");

  // --- chainsim plot -----------------------------------------------------------------------------
  chainsim::PlotCommandOptions plot;
  auto* cmd_plot = app.add_subcommand(
      "plot", "Draw a run directory (written by run, compare, reduced or canonical) into RUN_DIR/figures/ with "
              "matplotlib, and print the paths of the files written");
  cmd_plot->add_option("run_dir", plot.run_dir, "the run directory")->required();
  cmd_plot->add_flag("--animate", plot.animate,
                     "also write RUN_DIR/figures/animation.mp4 (ffmpeg), or .gif without ffmpeg, of the string moving");
  cmd_plot->add_option("--speed", plot.speed, "animation speed in units of real time, > 0 (default 1)");
  cmd_plot->add_option("--fps", plot.fps, "animation frames per second, an integer >= 1 (default 25)");
  cmd_plot->add_option("--times", plot.times, "times of the snapshots and tension profiles (s), e.g. 0,0.1,0.2");
  cmd_plot->add_option("--format", plot.format,
                       "animation format: mp4 | gif | html (default mp4 if ffmpeg is installed, else gif)");
  cmd_plot->add_flag("--html", plot.html,
                     "with --animate: RUN_DIR/figures/animation.html, one self-contained page with play and scrub "
                     "controls (the frames embedded) that any browser opens");

  chainsim::FitCommandOptions fit;  // chainsim fit (cases/cli/fit_options.hpp)
  auto* cmd_fit = chainsim::add_fit_command(app, fit);

  // --- chainsim sweep --------------------------------------------------------------------------
  chainsim::SweepCommandOptions sweep;
  auto* cmd_sweep = app.add_subcommand(
      "sweep", "Run a scene at every point of a grid of scene keys (one row per point in OUT/sweep.csv; a failed "
               "point is a row with its error) on local cores");
  cmd_sweep->add_option("scene", sweep.scene, "scene file")->required();
  cmd_sweep->add_option("--grid", sweep.grid,
                        "KEY=V1,V2,...: an axis of the grid (repeatable; the points are all combinations); KEY as for "
                        "run --set, or f (the dissipation of the scene's only front), e.g. --grid f=0,0.5,1 --grid "
                        "string.nodes=51,101")
      ->required()
      ->allow_extra_args(false);
  cmd_sweep->add_option("--set", sweep.overrides, "KEY=VALUE: sets a scene key for every point (as run --set)")
      ->allow_extra_args(false);
  double sweep_t_end = 0;
  auto* opt_sweep_t_end = cmd_sweep->add_option("--t-end", sweep_t_end, "end time (s), > 0: replaces [stop] t_end");
  cmd_sweep->add_option("--jobs", sweep.jobs, "threads, >= 1 (default: every core)");
  cmd_sweep->add_option("--out", sweep.out, "output directory (default results/sweep/<scene name>)");
  cmd_sweep->add_flag("--json", sweep.json, "print the sweep's counts as one JSON object on stdout");

  // With --json, every failure also prints one JSON object on stdout: the command's own (run, and
  // compare after a numerical failure, print their summary), else {"status": "failed", "error", ...}.
  const bool json = [&] {
    for (int k = 1; k < argc; ++k)
      if (std::string(argv[k]) == "--json") return true;
    return false;
  }();
  // `printed`: the command has printed its own JSON object for this failure.
  auto fail = [&](const std::string& command, const std::string& message, int code, bool printed = false) {
    std::cerr << "chainsim: " << (code == 3 ? "numerical failure: " : "error: ") << message << '\n';
    if (json && !printed) {
      nlohmann::json j = {{"status", "failed"}, {"error", message}, {"exit_code", code}};
      if (!command.empty()) j["command"] = command;
      std::cout << chainsim::json_text(j) << '\n';
    }
    return code;
  };

  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    if (e.get_exit_code() == 0) return app.exit(e);  // --help, --version
    const CLI::App* sub = entered_subcommand(app);
    return fail(sub ? sub->get_name() : "", describe_parse_error(app, e, argc > 1 ? argv[1] : ""), 2);
  }
  if (*cmd_plot) return chainsim::run_plot_command(plot);
  if (*cmd_fit) return chainsim::run_fit_command(fit);

  const CLI::App* sub = entered_subcommand(app);
  const std::string command = sub ? sub->get_name() : "";
  std::ostringstream buffered;  // with --json, the command's output, to know whether it printed its own
  std::ostream& out = json ? static_cast<std::ostream&>(buffered) : std::cout;
  auto failed = [&](const std::exception& e, int code) {
    std::cout << buffered.str();
    return fail(command, e.what(), code, !buffered.str().empty());
  };
  try {
    int code = 1;
    if (*cmd_reduced) code = chainsim::run_reduced_command(reduced, out);
    if (*cmd_canonical) code = chainsim::run_canonical_command(canonical, out);
    if (*cmd_compare) {
      compare.f_given = opt_compare_f->count() > 0;
      compare.eps_given = opt_compare_eps->count() > 0;
      code = chainsim::run_compare_command(compare, out);
    }
    if (*cmd_run) {
      if (opt_t_end->count() > 0) run.t_end = run_t_end;
      if (opt_max_wall->count() > 0) run.max_wall = run_max_wall;
      code = chainsim::run_scene_command(run, out);
    }
    if (*cmd_sweep) {
      if (opt_sweep_t_end->count() > 0) sweep.t_end = sweep_t_end;
      code = chainsim::run_sweep_command(sweep, out);
    }
    std::cout << buffered.str();
    return code;
  } catch (const chainsim::InputError& e) {
    return failed(e, 2);
  } catch (const chainsim::NumericalError& e) {
    return failed(e, 3);
  } catch (const std::exception& e) {
    return failed(e, 1);
  }
}
