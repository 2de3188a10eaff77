// chainsim: the command-line front end. Only parses arguments (CLI11 is slow to compile, so it is
// confined to this file) and maps errors to exit codes; every command lives in cases/*_command.cpp.
//
// Exit codes: 0 success, 1 internal error, 2 bad input (option, value, scene), 3 numerical failure.
#include <iostream>

#include <CLI/CLI.hpp>
#include <fmt/format.h>

#include "cases/cli/commands.hpp"
#include "cases/cli/run_command.hpp"
#include "mesh/errors.hpp"

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

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"chainsim: dynamics of inextensible strings and chains with shocks"};
  app.require_subcommand(1);
  app.set_version_flag("--version", "chainsim 0.1.0");

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
      "compare", "Solve a canonical problem with the string solver (front tracking) and with its reduced ODE, and "
                 "compare them");
  cmd_compare->add_option("problem", compare.problem, "falling | folded | sliding")->required();
  auto& cs = compare.setup;
  cmd_compare->add_option("--nodes", cs.nodes, "nodes of the string, 4 <= N <= 200001")->capture_default_str();
  cmd_compare->add_option("--f", cs.chain.dissipation, "shock dissipation parameter f, 0 <= f <= 1")->capture_default_str();
  cmd_compare->add_option("--eps", cs.eps, "cutoff eps, 0 < eps < 1")->capture_default_str();
  cmd_compare->add_option("--eta0", cs.eta0, "initial eta = y(0)/l (defaults: falling 1, folded 0, sliding 0)");
  cmd_compare->add_option("--force", cs.force, "upward force F on the free end of the folded chain (N), F >= 0")
      ->capture_default_str();
  cmd_compare->add_option("--length", cs.chain.length, "chain length l (m), > 0")->capture_default_str();
  cmd_compare->add_option("--density", cs.chain.density, "linear density lambda (kg/m), > 0")->capture_default_str();
  cmd_compare->add_option("--gravity", cs.chain.gravity, "gravitational acceleration g (m/s^2), > 0")->capture_default_str();
  cmd_compare->add_option("--t-max", cs.t_max_over_t0, "safety stop time, in units of t0")->capture_default_str();
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
  cmd_run->add_flag("--quiet", run.quiet, "no progress line on stderr (there is none when stderr is not a terminal)");
  cmd_run->add_option("--set", run.overrides,
                      "KEY=VALUE: sets a scene key, checked as in the file (repeatable; a later one wins), e.g. "
                      "--set string.nodes=201 --set effects.heap[0].f=0.5 --set effects.drag.coefficient=0.1; VALUE is "
                      "a TOML value (a bare word is a string); a missing section or element is created")
      ->allow_extra_args(false);
  cmd_run->add_flag("--json", run.json,
                    "print the run summary as one JSON object on stdout (on failure: status \"failed\" and the error)");

  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    return app.exit(e);
  }

  try {
    if (*cmd_reduced) return chainsim::run_reduced_command(reduced, std::cout);
    if (*cmd_canonical) return chainsim::run_canonical_command(canonical, std::cout);
    if (*cmd_compare) return chainsim::run_compare_command(compare, std::cout);
    if (*cmd_run) {
      if (opt_t_end->count() > 0) run.t_end = run_t_end;
      return chainsim::run_scene_command(run, std::cout);
    }
  } catch (const chainsim::InputError& e) {
    std::cerr << "chainsim: error: " << e.what() << '\n';
    return 2;
  } catch (const chainsim::NumericalError& e) {
    std::cerr << "chainsim: numerical failure: " << e.what() << '\n';
    return 3;
  } catch (const std::exception& e) {
    std::cerr << "chainsim: " << e.what() << '\n';
    return 1;
  }
  return 1;
}
