#pragma once
/// @file commands.hpp
/// The chainsim subcommands as plain functions (cases/cli/main.cpp only parses the command line).
/// Each returns the process exit code and throws InputError / NumericalError on failure.
#include <iosfwd>
#include <string>

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

/// `chainsim canonical --out DIR`: the main job. The three canonical problems with default
/// parameters (series + summary), a summary table, and the data behind the paper's figures
/// (fall time against f, η(ξ) and P/P0(ξ) for several f, each with its exact reference).
struct CanonicalCommandOptions {
  std::string out = "results";
  bool json = false;
};
int run_canonical_command(const CanonicalCommandOptions& options, std::ostream& out);

/// `chainsim compare falling|folded|sliding --nodes N ...`: the string solver (front tracking) and the
/// reduced ODE on the same problem; writes string_series.csv, reduced_series.csv and summary.json.
struct CompareCommandOptions {
  std::string problem;
  StringCaseSetup setup;  ///< problem is filled in from `problem`
  std::string out;        ///< output directory; "" = results/compare/<problem>
  bool json = false;
};
int run_compare_command(CompareCommandOptions options, std::ostream& out);

/// `chainsim plot RUN_DIR ...`: draws a run directory with the Python package python/chainsim_plot
/// (docs/plotting.md). The option values are passed on as written (the package checks them);
/// "" = not given.
struct PlotCommandOptions {
  std::string run_dir;
  bool animate = false;
  std::string speed, fps, times, format;
};
/// Runs /usr/bin/python3 (else python3 on PATH) -m chainsim_plot with PYTHONPATH set to the source
/// tree's python/; returns its exit code (1 if it cannot be started).
int run_plot_command(const PlotCommandOptions& options);

}  // namespace chainsim
