// `chainsim compare`: the string solver against the reduced ODE, or (edge, peg, pulley) against the
// exact solution (see commands.hpp); compare_problem and run_compare_problem (compare_problem.hpp) are the
// command without its files and report, which the Python module calls too.
#include <filesystem>
#include <iostream>
#include <optional>
#include <ostream>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "cases/cli/compare_problem.hpp"
#include "mesh/errors.hpp"
#include "solver/output.hpp"

namespace chainsim {

namespace {

/// --u0 and --R belong to compare pulley alone.
void refuse_pulley_options(const CompareCommandOptions& options) {
  if (options.u0)
    throw InputError(fmt::format("--u0 = {}: only compare pulley takes --u0 (compare {})", *options.u0, options.problem));
  if (options.radius)
    throw InputError(fmt::format("--R = {}: only compare pulley takes --R (compare {})", *options.radius, options.problem));
}

/// compare edge, peg and pulley run the string over an edge or a pulley, which implicit methods do not
/// meet (as in a scene: the Newton systems know neither a link bent over a point nor contact).
void refuse_implicit_method(const StringCaseSetup& s, const std::string& name) {
  if (s.integrator.implicit_method())
    throw InputError(fmt::format("--method = {} is implicit, and implicit methods do not meet {} (their Newton systems "
                                 "know no {}): allowed an explicit method (auto, erk3, erk4, erk5, erk6, erk8, or an "
                                 "ARKODE_* explicit table)",
                                 s.integrator.method, name == "pulley" ? "the pulley" : "an edge",
                                 name == "pulley" ? "contact" : "link bent over a point"));
}

/// `compare edge`'s and `compare peg`'s setup from the command's options; the options they have no use
/// for are refused.
EdgeCaseSetup edge_setup(const CompareCommandOptions& options, PointContactProblem problem) {
  const StringCaseSetup& s = options.setup;
  const std::string& name = options.problem;
  const char* x0_range = problem == PointContactProblem::kPeg ? "the longer side's fraction (0.5 < x0 < 1)"
                                                              : "the hanging fraction (0 < x0 < 1)";
  if (s.eta0)
    throw InputError(fmt::format("--eta0 = {}: compare {} starts from --x0, {}", *s.eta0, name, x0_range));
  if (s.force != 0)
    throw InputError(fmt::format("--force = {}: only the folded chain has an end force (compare {}: 0)", s.force, name));
  if (options.eps_given)
    throw InputError(fmt::format("--eps = {}: compare {} stops at the lift-off and has no cutoff", s.eps, name));
  refuse_pulley_options(options);
  refuse_implicit_method(s, name);
  EdgeCaseSetup e;
  e.problem = problem;
  e.chain = s.chain;
  e.nodes = s.nodes;
  e.x0 = options.x0 ? *options.x0 : EdgeCaseSetup::default_x0(problem);
  e.t_max_over_t0 = s.t_max_over_t0;
  e.integrator = s.integrator;
  e.validate();
  return e;
}

/// `compare pulley`'s setup from the command's options; the options it has no use for are refused.
PulleyCaseSetup pulley_setup(const CompareCommandOptions& options) {
  const StringCaseSetup& s = options.setup;
  if (s.eta0) throw InputError(fmt::format("--eta0 = {}: compare pulley starts from --u0 (m, 0 < u0 < (l - pi R)/2)", *s.eta0));
  if (options.x0) throw InputError(fmt::format("--x0 = {}: compare pulley starts from --u0 (m, 0 < u0 < (l - pi R)/2)", *options.x0));
  if (s.force != 0)
    throw InputError(fmt::format("--force = {}: only the folded chain has an end force (compare pulley: 0)", s.force));
  if (options.eps_given)
    throw InputError(fmt::format("--eps = {}: compare pulley stops at the lift-off and has no cutoff", s.eps));
  if (options.f_given)  // even at the default value: the pulley's exact solution has no f
    throw InputError(fmt::format("--f = {}: compare pulley has no f (a smooth pulley; its touchdowns are perfectly "
                                 "inelastic node impacts, docs/model.md section 10)", s.chain.dissipation));
  refuse_implicit_method(s, "pulley");
  PulleyCaseSetup p;
  p.chain = s.chain;
  p.nodes = s.nodes;
  if (options.u0) p.u0 = *options.u0;
  if (options.radius) p.radius = *options.radius;
  p.t_max_over_t0 = s.t_max_over_t0;
  p.integrator = s.integrator;
  p.validate();
  return p;
}

/// The lines every comparison with an exact solution prints: its title, the lift-off's t and x, x(t).
void print_exact_comparison(const nlohmann::json& s, const std::string& setup, std::ostream& out) {
  auto number = [&](const char* key) { return s[key].is_number() ? fmt::format("{:.12g}", s[key].get<double>()) : "none"; };
  auto error = [&](const char* key) { return s[key].is_number() ? fmt::format("{:.3g}", s[key].get<double>()) : "none"; };
  out << fmt::format("{}, {}, {} nodes: string solver vs exact solution\n", s["problem"].get<std::string>(), setup,
                     s["nodes"].get<int>());
  // A peg with f = 1 pushes until the shorter end arrives: the exact solution has no lift-off, and its keys hold
  // that arrival (x = ℓ, t_end_at_peg_exact), which the report does not call a lift-off.
  if (s.contains("t_end_at_peg_exact") && s["t_end_at_peg_exact"] == s["t_lift_off_exact"]) {
    out << fmt::format("  lift-off         string {}   exact none: the shorter end reaches the peg at t = {:.12g} s\n",
                       number("t_lift_off"), s["t_end_at_peg_exact"].get<double>());
  } else {
    out << fmt::format("  lift-off t (s)   string {}   exact {:.12g}   abs. error {}\n", number("t_lift_off"),
                       s["t_lift_off_exact"].get<double>(), error("abs_err_t_lift_off"));
    out << fmt::format("  lift-off x (m)   string {}   exact {:.12g}   abs. error {}\n", number("x_lift_off"),
                       s["x_lift_off_exact"].get<double>(), error("abs_err_x_lift_off"));
  }
  out << fmt::format("  max |x error|    {:.3g} m (equal times)\n", s["max_abs_err_x"].get<double>());
}

void print_edge(const nlohmann::json& s, std::ostream& out) {
  const bool peg = s["problem"] == "peg";
  print_exact_comparison(s, fmt::format("f = {}, x0 = {}", s["f"].get<double>(), s["x0"].get<double>()), out);
  out << fmt::format("  max |T error|    {:.3g} N before the {}, {:.3g} N after it ({:.3g} relative to lambda g l)\n",
                     s["max_abs_err_tension"].get<double>(), peg ? "peg" : "edge",
                     s["max_abs_err_tension_plus"].get<double>(), s["max_rel_err_tension"].get<double>());
  out << fmt::format("  max |F0 error|   {:.3g} N (reaction of the {})\n", s["max_abs_err_reaction"].get<double>(),
                     peg ? "peg" : "edge");
  out << fmt::format("  dissipated       string {:.12g} J   exact {:.12g} J   abs. error {:.3g}\n",
                     s["dissipated"].get<double>(), s["dissipated_exact"].get<double>(),
                     s["abs_err_dissipated"].get<double>());
  if (peg)
    out << fmt::format("  (the shorter end would reach the peg at t = {:.12g} s)\n", s["t_end_at_peg_exact"].get<double>());
}

void print_pulley(const nlohmann::json& s, std::ostream& out) {
  print_exact_comparison(s, fmt::format("u0 = {} m, R = {} m", s["u0"].get<double>(), s["R"].get<double>()), out);
  out << fmt::format("  max |T error|    {:.3g} N where the shorter side meets the pulley, {:.3g} N where the longer "
                     "leaves it ({:.3g} relative to lambda g l); means {:.3g} N, {:.3g} N\n",
                     s["max_abs_err_tension_short"].get<double>(), s["max_abs_err_tension_long"].get<double>(),
                     s["max_rel_err_tension"].get<double>(), s["mean_abs_err_tension_short"].get<double>(),
                     s["mean_abs_err_tension_long"].get<double>());
}

}  // namespace

CompareProblem compare_problem(const CompareCommandOptions& options) {
  CompareProblem p;
  p.name = options.problem;
  if (options.problem == "pulley") {
    p.pulley = pulley_setup(options);
  } else if (options.problem == "edge" || options.problem == "peg") {
    p.edge = edge_setup(options, options.problem == "peg" ? PointContactProblem::kPeg : PointContactProblem::kEdge);
  } else {
    if (options.problem != "falling" && options.problem != "folded" && options.problem != "sliding")
      throw InputError(fmt::format(
          "problem = \"{}\" is not a known problem: allowed falling, folded, sliding, edge, peg, pulley", options.problem));
    if (options.x0)
      throw InputError(fmt::format("--x0 = {}: only compare edge takes --x0, and compare peg ({} starts from --eta0)",
                                   *options.x0, options.problem));
    refuse_pulley_options(options);
    p.reduced = options.setup;
    p.reduced->problem = parse_problem(options.problem);
    p.reduced->validate();
  }
  return p;
}

CompareOutcome run_compare_problem(const CompareProblem& p) {
  CompareOutcome o;
  if (p.pulley)
    o.exact = compare_pulley_with_exact(*p.pulley);
  else if (p.edge)
    o.exact = p.edge->problem == PointContactProblem::kPeg ? compare_peg_with_exact(*p.edge)
                                                           : compare_edge_with_exact(*p.edge);
  else
    o.reduced = compare_with_reduced(*p.reduced);
  return o;
}

int run_compare_command(const CompareCommandOptions& options, std::ostream& out) {
  const CompareProblem problem = compare_problem(options);
  const bool pulley = problem.pulley.has_value();
  const bool edge = problem.exact();  // against an exact solution
  const std::filesystem::path dir =
      options.out.empty() ? std::filesystem::path("results") / "compare" / options.problem
                          : std::filesystem::path(options.out);
  const RunDirectory run_dir(dir);  // held until the outputs are written
  run_dir.clear();
  const CompareOutcome outcome = run_compare_problem(problem);
  samples_table(outcome.run()).write(dir / "string_series.csv");
  if (edge)
    outcome.exact->exact.write(dir / "exact_series.csv");
  else
    outcome.reduced->reduced.series.write(dir / "reduced_series.csv");
  const RunSummary& run = outcome.run();
  const nlohmann::json& s = outcome.summary();
  write_json(dir / "summary.json", s);  // written last: its presence means the set is complete
  const bool failed = run.status == "failed";
  const std::string error = fmt::format("the string solver failed: {}", run.error);
  // compare pulley's warning (a pulley thinner than the links), as `chainsim run` gives a scene's: on stderr
  // beside the JSON, on the report's warning line otherwise.
  const std::string warning = s.value("resolution_warning", std::string());
  if (options.json) {
    if (!warning.empty()) std::cerr << "chainsim: warning: " << warning << '\n';
    nlohmann::json j = s;
    if (failed) {
      j["error"] = error;
      j["exit_code"] = 3;
    }
    out << json_text(j) << '\n';
  } else {
    if (pulley) {
      print_pulley(s, out);
    } else if (edge) {
      print_edge(s, out);
    } else {
      out << fmt::format("{} chain, f = {}, {} nodes: string solver vs reduced ODE\n", options.problem,
                         problem.reduced->chain.dissipation, problem.reduced->nodes);
      out << fmt::format("  t_stop/t0        string {:.12g}   reduced {:.12g}   rel. error {:.3g}\n",
                         s["t_stop_over_t0"].get<double>(), s["t_stop_over_t0_reduced"].get<double>(),
                         s["rel_err_t_stop"].get<double>());
      out << fmt::format("  max |eta error|  {:.3g} (equal times)\n", s["max_abs_err_eta"].get<double>());
      out << fmt::format("  max rel. P error {:.3g} ({})\n", s["max_rel_err_P"].get<double>(),
                         s["P_compared_at"].get<std::string>());
    }
    out << fmt::format("  energy ledger    {:.3g} (relative)   momentum ledger {:.3g}\n",
                       s["energy_residual"].get<double>(), s["momentum_residual"].get<double>());
    if (!warning.empty()) out << fmt::format("  warning          {}\n", warning);
    out << fmt::format("  stop: {} ({} crossings, {} steps, {:.3g} s)\n", s["stop_reason"].get<std::string>(),
                       s["transfers"].get<long>(), s["steps"].get<long>(), s["wall_s"].get<double>());
    out << fmt::format("  outputs in {}\n", dir.string());
  }
  if (failed) throw NumericalError(error, run.t_stop);
  return 0;
}

}  // namespace chainsim
