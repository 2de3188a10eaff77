#pragma once
/// @file commands.hpp
/// The chainsim subcommands as plain functions (cases/cli/main.cpp only parses the command line).
/// Each returns the process exit code and throws InputError / NumericalError on failure.
#include <iosfwd>
#include <optional>
#include <string>
#include <vector>

#include "cases/canonical/canonical_string.hpp"
#include "cases/reduced/reduced_models.hpp"

namespace chainsim {

/// `chainsim reduced falling|folded|sliding ...`
struct ReducedCommandOptions {
  std::string problem;   ///< "falling" | "folded" | "sliding"
  ReducedSetup setup;    ///< problem is filled in from `problem`
  std::string out;       ///< output directory; "" = results/reduced/<problem>
  bool json = false;     ///< print the summary as one JSON object on stdout
};
int run_reduced_command(ReducedCommandOptions options, std::ostream& out);

/// `chainsim canonical --out DIR`: the main job. Each of the paper's three problems (falling η0 = 1,
/// folded η0 = 0, sliding η0 = 0.25) at f = 0, 0.5, 0.83, 1 three ways: the string solver with front
/// tracking (compare_with_reduced, `nodes` nodes), the reduced ODE and the exact quadrature; the stop
/// times, their differences, the string run's ledgers and the wall times in DIR/summary.{csv,json}; the
/// curves of the figures in DIR/figure_data/ (profiles, and the fall time against f with the string
/// solver's points); each problem's reduced run with default parameters in DIR/<problem>/.
/// Defined in canonical_command.cpp.
struct CanonicalCommandOptions {
  std::string out = "results";
  int nodes = 41;       ///< nodes of the string runs (the straight problems are exact on any mesh)
  bool quick = false;   ///< f = 0, 0.83 only, and the string's fall time at f = 0, 0.5, 1 (for tests)
  bool json = false;    ///< print the summary rows as one JSON array
};
int run_canonical_command(const CanonicalCommandOptions& options, std::ostream& out);

/// `chainsim compare falling|folded|sliding --nodes N ...`: the string solver (front tracking) and the
/// reduced ODE on the same problem; writes string_series.csv, reduced_series.csv and summary.json.
/// `chainsim compare edge --x0 X0 ...`: the chain sliding off a table over an edge against its exact
/// solution (edge_case.hpp); `chainsim compare peg --x0 X0 ...` the heavy Atwood chain over a sharp peg;
/// `chainsim compare pulley --u0 U0 --R R ...` the heavy Atwood chain over a smooth pulley (pulley_case.hpp);
/// all three write string_series.csv, exact_series.csv and summary.json.
struct CompareCommandOptions {
  std::string problem;
  StringCaseSetup setup;  ///< problem is filled in from `problem` (edge: its chain, nodes, t_max, integrator)
  std::optional<double> x0;  ///< edge: the hanging fraction at release (default 0.2); peg: the longer side's (0.6)
  std::optional<double> u0;      ///< pulley: the offset at release (m; default 0.05)
  std::optional<double> radius;  ///< pulley: the pulley's radius R (m; default 0.1)
  /// --f and --eps were given (whatever their value: setup holds their defaults otherwise). The command sets them from
  /// the options' counts, compare() from its keywords; compare pulley refuses both, edge and peg --eps.
  bool f_given = false, eps_given = false;
  std::string out;        ///< output directory; "" = results/compare/<problem>
  bool json = false;
};
int run_compare_command(const CompareCommandOptions& options, std::ostream& out);

/// `chainsim plot RUN_DIR ...`: draws a run directory with the Python package python/chainsim_plot
/// (docs/plotting.md). The option values are passed on as written (the package checks them);
/// "" = not given.
struct PlotCommandOptions {
  std::string run_dir;
  bool animate = false;
  bool html = false;  ///< --html: the animation as one self-contained HTML page
  std::string speed, fps, times, format;
};
/// Runs /usr/bin/python3 (else python3 on PATH) -m chainsim_plot (run_python_module, python_command.hpp);
/// returns its exit code (1 if it cannot be started).
int run_plot_command(const PlotCommandOptions& options);

/// `chainsim fit TARGET DATA.csv... [...]`: fits scene keys (f, ...) to measured series with the Python
/// module chainsim.fitting (docs/fit.md). The option values are passed on as written (the module checks
/// them); "" = not given. Defined in fit_command.cpp; returns the module's exit code.
struct FitCommandOptions {
  std::string target;                  ///< falling | folded | sliding, or a scene file
  std::vector<std::string> data;       ///< CSV files, each FILE[@KEY=VALUE...]
  std::string observable, column, time_column, sigma, profile, jobs, max_nfev, out;
  std::vector<std::string> free;       ///< NAME=START[:LOWER:UPPER]
  std::vector<std::string> per_run;    ///< names of free parameters fitted once per data file
  std::vector<std::string> overrides;  ///< --set KEY=VALUE
  bool absolute_sigma = false, no_figures = false, json = false;
};
int run_fit_command(const FitCommandOptions& options);

/// `chainsim sweep SCENE --grid KEY=V1,V2,... --out DIR`: the scene at every point of the grid, on
/// `jobs` threads, one row per point in DIR/sweep.csv (cases/scene/scene_sweep.hpp; docs/python.md).
/// Defined in sweep_command.cpp.
struct SweepCommandOptions {
  std::string scene;
  std::vector<std::string> grid;       ///< "KEY=V1,V2,..." per axis
  std::vector<std::string> overrides;  ///< --set KEY=VALUE for every point
  std::optional<double> t_end;         ///< replaces [stop] t_end (s)
  int jobs = 0;                        ///< threads; 0 = every core
  std::string out;                     ///< "" = results/sweep/<scene stem>
  bool json = false;
};
int run_sweep_command(const SweepCommandOptions& options, std::ostream& out);

}  // namespace chainsim
