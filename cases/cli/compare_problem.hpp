#pragma once
/// @file compare_problem.hpp
/// `chainsim compare`'s problems without the command's files and report: the setup checked from the
/// command's options, and the comparison run. The command (compare_command.cpp) and the Python module's
/// compare() (python/chainsim/_core.cpp) both go through these, so that one set of options gives one run.
#include <optional>
#include <string>

#include <nlohmann/json.hpp>

#include "cases/canonical/canonical_string.hpp"
#include "cases/canonical/edge_case.hpp"
#include "cases/canonical/pulley_case.hpp"
#include "cases/cli/commands.hpp"

namespace chainsim {

/// A checked `chainsim compare` problem: exactly one of the setups is set (falling, folded, sliding:
/// `reduced`, against the reduced ODE; edge, peg: `edge`; pulley: `pulley`, against the exact solution).
struct CompareProblem {
  std::string name;  ///< falling | folded | sliding | edge | peg | pulley
  std::optional<StringCaseSetup> reduced;
  std::optional<EdgeCaseSetup> edge;
  std::optional<PulleyCaseSetup> pulley;
  /// True for edge, peg and pulley (string_series.csv, exact_series.csv).
  bool exact() const { return !reduced; }
};

/// The problem's setup from the command's options: InputError naming an unknown problem, an option the
/// problem has no use for (--x0 for falling, --f for pulley, ...) or a value out of its range.
CompareProblem compare_problem(const CompareCommandOptions& options);

/// A comparison run: `reduced` for falling, folded and sliding, `exact` for edge, peg and pulley.
struct CompareOutcome {
  std::optional<Comparison> reduced;
  std::optional<ExactComparison> exact;
  /// The string solver's run (string_series.csv is samples_table(run())).
  const RunSummary& run() const { return exact ? exact->run : reduced->string.run; }
  /// summary.json.
  const nlohmann::json& summary() const { return exact ? exact->summary : reduced->summary; }
};

/// Runs the problem (a numerical failure of the string solver ends its run: run().status "failed").
CompareOutcome run_compare_problem(const CompareProblem& problem);

}  // namespace chainsim
