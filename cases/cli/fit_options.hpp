#pragma once
/// @file fit_options.hpp
/// The options of `chainsim fit` for CLI11. Included by main.cpp only (the one file that compiles CLI11);
/// the command itself is fit_command.cpp, the fit the Python module chainsim.fitting (docs/fit.md).
#include <CLI/CLI.hpp>

#include "cases/cli/commands.hpp"

namespace chainsim {

inline CLI::App* add_fit_command(CLI::App& app, FitCommandOptions& fit) {
  auto* cmd = app.add_subcommand(
      "fit", "Fit f (and other scene keys) to measured series given as CSV: weighted nonlinear least squares with "
             "bounds on the reduced ODE or the string solver; 95% intervals from the covariance and the profile "
             "likelihood; a table, OUT/fit.json and figures (docs/fit.md)");
  cmd->add_option("target", fit.target,
                  "falling | folded | sliding (the reduced ODE), or a scene file (model = \"reduced\": the reduced "
                  "ODE; otherwise the string solver)")
      ->required();
  cmd->add_option("data", fit.data,
                  "CSV files: a header row, a time column, one observable column [, sigma]; lines starting with # "
                  "are comments. FILE@KEY=VALUE@... sets keys for that file's run (e.g. drop2.csv@eta0=0.8), FILE@run=NAME "
                  "puts files of one drop (e.g. its height and its force) in one run. "
                  "Several files: a joint fit (shared parameters fitted to all)")
      ->required();
  cmd->add_option("--observable", fit.observable,
                  "the column of values, named as the model output it is: y, P, ... (reduced), s0_0, support_y, "
                  "node[K].y, ... (string), t_stop (default: the only column that is neither time nor sigma)");
  cmd->add_option("--column", fit.column,
                  "the CSV column of the values, when it is not named as the observable (e.g. --observable s0_0 "
                  "--column y: the string solver's front coordinate against a column of heights)");
  cmd->add_option("--time-column", fit.time_column, "the time column (s) (default t)");
  cmd->add_option("--sigma", fit.sigma,
                  "the data's standard deviation, > 0 (a number), or the name of a column of them (default: the "
                  "column sigma if present, else estimated from the residuals)");
  cmd->add_option("--free", fit.free,
                  "NAME=START or NAME=START:LOWER:UPPER: a free parameter (repeatable; default f=0.5): f, t_offset "
                  "(the release time on the data's clock, s), the reduced keywords eta0, eps, force, length, "
                  "density, gravity, or a scene key; f and eta0 are bounded to [0, 1]")
      ->allow_extra_args(false);
  cmd->add_option("--per-run", fit.per_run,
                  "NAME: fit this free parameter once per data file, e.g. t_offset (repeatable)")
      ->allow_extra_args(false);
  cmd->add_option("--set", fit.overrides,
                  "KEY=VALUE: a fixed key for every run (a reduced keyword, e.g. eps=0.01, or a scene key, e.g. "
                  "string.nodes=41; repeatable)")
      ->allow_extra_args(false);
  cmd->add_option("--profile", fit.profile, "the parameter whose profile likelihood is computed (default f; none)");
  cmd->add_flag("--absolute-sigma", fit.absolute_sigma,
                "the given sigmas are the data's true standard deviations: no scaling by chi2/(N-p)");
  cmd->add_option("--jobs", fit.jobs, "threads for the model runs, >= 1 (default: every core)");
  cmd->add_option("--max-nfev", fit.max_nfev,
                  "most evaluations of the optimizer, >= 1 (default 200): a fit that needs more ends with exit 2");
  cmd->add_option("--out", fit.out,
                  "output directory (default results/fit): fit_table.txt, fit_series.csv, fit.png, profile.png, "
                  "fit.json (last)");
  cmd->add_flag("--no-figures", fit.no_figures, "write no figures");
  cmd->add_flag("--json", fit.json, "print the result (or the error) as one JSON object on stdout");
  return cmd;
}

}  // namespace chainsim
