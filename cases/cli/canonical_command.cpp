// `chainsim canonical`, the main job (see commands.hpp): each of the paper's three problems solved three
// ways — the string solver with front tracking (cases/canonical), the reduced ODE and the exact
// quadrature (cases/reduced) — with a summary table and the data of the figures.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <filesystem>
#include <ostream>
#include <string>
#include <vector>

#include <fmt/format.h>
#include <fmt/ostream.h>
#include <nlohmann/json.hpp>

#include "cases/cli/commands.hpp"
#include "cases/reduced/exact_solutions.hpp"
#include "mesh/errors.hpp"
#include "solver/output.hpp"

namespace chainsim {

namespace fs = std::filesystem;

namespace {

using Clock = std::chrono::steady_clock;

double seconds_since(Clock::time_point start) {
  return std::chrono::duration<double>(Clock::now() - start).count();
}

const Problem kProblems[] = {Problem::kFalling, Problem::kFolded, Problem::kSliding};

/// Where the paper's profile figures start: falling η0 = 1, folded η0 = 0, sliding η0 = 0.25.
double profile_eta0(Problem p) {
  switch (p) {
    case Problem::kFalling: return 1.0;
    case Problem::kFolded: return 0.0;
    case Problem::kSliding: return 0.25;
  }
  return 0.0;
}

/// The η at which a run stops: the falling chain at ε, the folded chain at 1 − ε, the sliding chain at 1.
double stop_eta(Problem p, double eps) {
  switch (p) {
    case Problem::kFalling: return eps;
    case Problem::kFolded: return 1.0 - eps;
    case Problem::kSliding: return 1.0;
  }
  return 0.0;
}

/// The exact quadrature of a problem at η: ξ = t/t0 and P/P0.
struct ExactPoint {
  double xi = 0, P = 0;
};
ExactPoint exact_at(Problem p, double f, double eta, double eta0) {
  switch (p) {
    case Problem::kFalling: return {exact::falling_xi(f, eta, eta0), exact::falling_P(f, eta, eta0)};
    case Problem::kFolded: return {exact::folded_xi(f, eta, eta0), exact::folded_P(f, eta, eta0)};
    case Problem::kSliding: return {exact::sliding_xi(f, eta, eta0), exact::sliding_P(f, eta, eta0)};
  }
  return {};
}

/// The exact η(ξ), P/P0 curve from η0 to the stop (for drawing beside the ODE and the string).
CsvTable exact_curve(Problem p, double f, double eta0, double eps) {
  CsvTable table({"eta", "xi", "P_over_P0"});
  const int n = 400;
  const double eta_end = stop_eta(p, eps);
  for (int k = 0; k <= n; ++k) {
    // Cluster the points towards the stop, where η and P are steep.
    const double s = 1.0 - std::pow(1.0 - static_cast<double>(k) / n, 2.0);
    const double eta = eta0 + (eta_end - eta0) * s;
    const ExactPoint q = exact_at(p, f, eta, eta0);
    table.add_row({eta, q.xi, q.P});
  }
  return table;
}

/// The string run in the scaled variables of the reduced series: ξ = t/t0, η, η' = dη/dξ, P/P0.
CsvTable string_curve(const StringCaseRun& run, const ChainParameters& chain) {
  CsvTable table({"t", "xi", "eta", "eta_p", "P_over_P0"});
  const double t0 = chain.t0(), P0 = chain.P0();
  for (std::size_t k = 0; k < run.t.size(); ++k)
    table.add_row({run.t[k], run.t[k] / t0, run.eta[k], run.eta_dot[k] * t0, run.P[k] / P0});
  return table;
}

/// The reduced series (recorded at every step of at most t0/5000) thinned to what a figure resolves: a
/// row is kept when ξ, η or P/P0 has moved by 1/500 (of 1, or of |P/P0| if larger) since the last
/// row kept; the first and last rows are always kept.
CsvTable thin_for_figure(const CsvTable& series) {
  const std::vector<std::string>& names = series.columns();
  std::vector<std::vector<double>> cols;
  for (const std::string& name : names) cols.push_back(series.column(name));
  const std::vector<double> xi = series.column("xi"), eta = series.column("eta"), P = series.column("P_over_P0");
  CsvTable thin(names);
  const std::size_t n = series.rows();
  std::size_t last = 0;
  for (std::size_t k = 0; k < n; ++k) {
    const double d = 1.0 / 500;
    const bool keep = k == 0 || k + 1 == n || std::abs(xi[k] - xi[last]) >= d || std::abs(eta[k] - eta[last]) >= d ||
                      std::abs(P[k] - P[last]) >= d * std::max(1.0, std::abs(P[k]));
    if (!keep) continue;
    std::vector<double> row;
    for (const auto& c : cols) row.push_back(c[k]);
    thin.add_row(row);
    last = k;
  }
  return thin;
}

/// A string run must end at its stop event, at the η where the problem stops; a failure, the safety
/// stop or an earlier end (a falling chain whose last node meets the heap before the cutoff, when the
/// cutoff is shorter than about 1e-3 of a link) is a numerical failure.
void require_stopped(const StringCaseRun& run, Problem p, double eps, const std::string& what) {
  if (run.run.status == "failed")
    throw NumericalError(fmt::format("{}: the string solver failed: {}", what, run.run.error), run.run.t_stop);
  if (run.run.status != "stopped")
    throw NumericalError(fmt::format("{}: the string solver did not reach the stop event ({}: {})", what,
                                     run.run.status, run.run.stop_reason),
                         run.run.t_stop);
  const double eta_end = stop_eta(p, eps);
  if (run.eta.empty() || std::abs(run.eta.back() - eta_end) > 1e-9)
    throw NumericalError(fmt::format("{}: the string run stopped at eta = {:.9g} instead of {:g} ({}); with eps = {:g} "
                                     "it needs more nodes",
                                     what, run.eta.empty() ? NAN : run.eta.back(), eta_end, run.run.stop_reason, eps),
                         run.run.t_stop);
}

double rel_diff(double a, double b) { return std::abs(a - b) / std::abs(b); }

const std::vector<std::string> kSummaryColumns = {
    "f", "eta0", "eps", "nodes",
    "t_stop_over_t0_string", "t_stop_over_t0_reduced", "t_stop_over_t0_quadrature",
    "rel_diff_string_reduced", "rel_diff_reduced_quadrature", "rel_diff_string_quadrature",
    "max_abs_diff_eta", "max_rel_diff_P",
    "P_stop_over_P0_string", "P_stop_over_P0_reduced", "P_stop_over_P0_quadrature",
    "energy_residual_string", "momentum_residual_string", "energy_residual_reduced",
    "wall_s_string", "wall_s_reduced", "wall_s_quadrature"};

/// One problem at one f, three ways. Writes the three curves into `fig` and returns the summary row
/// (the keys of kSummaryColumns, "problem", and the string and reduced runs' own summaries).
nlohmann::json three_way(Problem p, double f, int nodes, const fs::path& fig) {
  StringCaseSetup setup;
  setup.problem = p;
  setup.chain.dissipation = f;
  setup.eta0 = profile_eta0(p);
  setup.nodes = nodes;
  setup.frame_interval = 0.05 * setup.chain.t0();  // the nodes for the snapshot figures
  const Comparison c = compare_with_reduced(setup);
  const std::string stem = fmt::format("{}_f{:.2f}", to_string(p), f);
  require_stopped(c.string, p, setup.eps, stem);
  const double eta0 = *setup.eta0;
  const auto start = Clock::now();
  const ExactPoint q = exact_at(p, f, stop_eta(p, setup.eps), eta0);
  const double wall_quadrature = seconds_since(start);

  thin_for_figure(c.reduced.series).write(fig / (stem + "_ode.csv"));
  exact_curve(p, f, eta0, setup.eps).write(fig / (stem + "_exact.csv"));
  string_curve(c.string, setup.chain).write(fig / (stem + "_string.csv"));
  samples_table(c.string.run).write(fig / (stem + "_string_series.csv"));
  // The string's own nodes at its frames (times on the reduced solution's clock, as in _string.csv).
  CsvTable positions({"t", "node", "s", "x", "y"});
  for (const Frame<2>& frame : c.string.frames)
    for (int i : frame.moving)
      positions.add_row({frame.t + c.string.t_offset, static_cast<double>(i), i * setup.chain.length / (setup.nodes - 1),
                     frame.x(0, i), frame.x(1, i)});
  positions.write(fig / (stem + "_string_nodes.csv"));

  const double ts = c.summary["t_stop_over_t0"].get<double>();
  const double tr = c.reduced.summary["t_stop_over_t0"].get<double>();
  const double Ps = c.string.P.back() / setup.chain.P0();
  nlohmann::json row;
  row["problem"] = to_string(p);
  row["f"] = f;
  row["eta0"] = eta0;
  row["eps"] = setup.eps;
  row["nodes"] = nodes;
  row["t_stop_over_t0_string"] = ts;
  row["t_stop_over_t0_reduced"] = tr;
  row["t_stop_over_t0_quadrature"] = q.xi;
  row["rel_diff_string_reduced"] = rel_diff(ts, tr);
  row["rel_diff_reduced_quadrature"] = rel_diff(tr, q.xi);
  row["rel_diff_string_quadrature"] = rel_diff(ts, q.xi);
  row["max_abs_diff_eta"] = c.summary["max_abs_err_eta"];
  row["max_rel_diff_P"] = c.summary["max_rel_err_P"];
  row["P_stop_over_P0_string"] = Ps;
  row["P_stop_over_P0_reduced"] = c.reduced.summary["P_stop_over_P0"];
  row["P_stop_over_P0_quadrature"] = q.P;
  row["energy_residual_string"] = c.summary["energy_residual"];
  row["momentum_residual_string"] = c.summary["momentum_residual"];
  row["energy_residual_reduced"] = c.reduced.summary["energy_residual"];
  row["wall_s_string"] = c.summary["wall_s"];
  row["wall_s_reduced"] = c.summary["wall_s_reduced"];
  row["wall_s_quadrature"] = wall_quadrature;
  row["string"] = c.summary;
  row["reduced"] = c.reduced.summary;
  return row;
}

/// The fall time against f (the paper's Figs. 3b, 4b, 5b): the reduced ODE stopped at ε = 1e-6 beside the
/// quadrature of the full fall (falling η0 = 1, folded η0 = 0, sliding η0 = 0, 0.25, 0.75), 21 values of f.
CsvTable fall_time_reduced() {
  CsvTable tf({"f", "falling_ode", "falling_exact", "folded_ode", "folded_exact", "sliding0_ode", "sliding0_exact",
               "sliding25_ode", "sliding25_exact", "sliding75_ode", "sliding75_exact"});
  auto stop_time = [](Problem p, double f, double eta0, double eps) {
    ReducedSetup s;
    s.problem = p;
    s.chain.dissipation = f;
    s.eta0 = eta0;
    s.eps = eps;
    s.integrator.max_step = s.chain.t0();  // only the stop time is needed here
    return solve_reduced(s).summary["t_stop_over_t0"].get<double>();
  };
  for (int k = 0; k <= 20; ++k) {
    const double f = k / 20.0;
    // The ODE runs down to ε = 1e-6 so the stop time is close to the full fall it is drawn beside.
    const double eps = 1e-6;
    tf.add_row({f, stop_time(Problem::kFalling, f, 1.0, eps), exact::falling_fall_time(f, 1.0),
                stop_time(Problem::kFolded, f, 0.0, eps), exact::folded_fall_time(f, 0.0),
                stop_time(Problem::kSliding, f, 0.0, eps), exact::sliding_fall_time(f, 0.0),
                stop_time(Problem::kSliding, f, 0.25, eps), exact::sliding_fall_time(f, 0.25),
                stop_time(Problem::kSliding, f, 0.75, eps), exact::sliding_fall_time(f, 0.75)});
  }
  return tf;
}

/// The string solver's points of the fall-time figure: falling η0 = 1, folded η0 = 0 (both stopped at
/// ε = kFallTimeEps, where the quadrature is taken too) and sliding from η0 = 0 (to η = 1).
/// Returns the largest relative difference from the quadrature per problem.
constexpr double kFallTimeEps = 1e-4;
std::vector<double> fall_time_string(const std::vector<double>& fs_list, int nodes, const fs::path& path) {
  CsvTable table({"f", "falling_string", "falling_exact", "folded_string", "folded_exact", "sliding0_string",
                  "sliding0_exact", "falling_energy_residual", "folded_energy_residual", "sliding0_energy_residual"});
  std::vector<double> worst(3, 0.0);
  for (double f : fs_list) {
    std::vector<double> times, residuals;
    for (int k = 0; k < 3; ++k) {
      const Problem p = kProblems[k];
      StringCaseSetup setup;
      setup.problem = p;
      setup.chain.dissipation = f;
      setup.eps = kFallTimeEps;
      setup.eta0 = p == Problem::kFalling ? 1.0 : 0.0;
      setup.nodes = nodes;
      const StringCaseRun run = solve_string_case(setup);
      require_stopped(run, p, setup.eps, fmt::format("fall time of the {} chain, f = {:g}", to_string(p), f));
      const double ts = run.summary["t_stop_over_t0"].get<double>();
      const double tq = exact_at(p, f, stop_eta(p, setup.eps), *setup.eta0).xi;
      worst[k] = std::max(worst[k], rel_diff(ts, tq));
      times.push_back(ts);
      times.push_back(tq);
      residuals.push_back(run.summary["energy_residual"].get<double>());
    }
    std::vector<double> row = {f};
    row.insert(row.end(), times.begin(), times.end());
    row.insert(row.end(), residuals.begin(), residuals.end());
    table.add_row(row);
  }
  table.write(path);
  return worst;
}

void print_table(const nlohmann::json& rows, std::ostream& out) {
  fmt::print(out, "{:<8} {:>4} {:>4}  {:>15} {:>15} {:>15}  {:>8} {:>8}  {:>8}  {:>21}\n", "problem", "f", "eta0",
             "t/t0 string", "reduced ODE", "quadrature", "|s-r|/r", "|r-q|/q", "ledger", "wall ms string/ODE/quad");
  for (const auto& r : rows)
    fmt::print(out, "{:<8} {:>4.2f} {:>4.2f}  {:>15.12f} {:>15.12f} {:>15.12f}  {:>8.1e} {:>8.1e}  {:>8.1e}  {:>7.1f} {:>6.1f} {:>6.2f}\n",
               r["problem"].get<std::string>(), r["f"].get<double>(), r["eta0"].get<double>(),
               r["t_stop_over_t0_string"].get<double>(), r["t_stop_over_t0_reduced"].get<double>(),
               r["t_stop_over_t0_quadrature"].get<double>(), r["rel_diff_string_reduced"].get<double>(),
               r["rel_diff_reduced_quadrature"].get<double>(), r["energy_residual_string"].get<double>(),
               1e3 * r["wall_s_string"].get<double>(), 1e3 * r["wall_s_reduced"].get<double>(),
               1e3 * r["wall_s_quadrature"].get<double>());
}

}  // namespace

int run_canonical_command(const CanonicalCommandOptions& options, std::ostream& out) {
  const auto start = Clock::now();
  {
    StringCaseSetup check;  // the node count, checked before anything runs
    check.nodes = options.nodes;
    check.validate();
  }
  const fs::path root(options.out);
  const RunDirectory run_dir(root);  // held until summary.json is written
  run_dir.clear();
  const fs::path fig = root / "figure_data";
  ensure_directory(fig);

  // 1. Each problem with default parameters on the reduced model (its series and summary, as
  //    `chainsim reduced` writes them).
  for (Problem p : kProblems) {
    ReducedSetup setup;
    setup.problem = p;
    const ReducedRun run = solve_reduced(setup);
    const RunDirectory problem_dir(root / to_string(p));  // a run directory of its own (cleared above)
    run.series.write(root / to_string(p) / "series.csv");
    write_json(root / to_string(p) / "summary.json", run.summary);
  }

  // 2. Each problem at each f three ways: the summary table and the profile curves.
  const std::vector<double> profile_fs =
      options.quick ? std::vector<double>{0.0, 0.83} : std::vector<double>{0.0, 0.5, 0.83, 1.0};
  CsvTable table(kSummaryColumns, "problem");
  nlohmann::json rows = nlohmann::json::array();
  for (Problem p : kProblems) {
    for (double f : profile_fs) {
      nlohmann::json row = three_way(p, f, options.nodes, fig);
      std::vector<double> values;
      for (const std::string& key : kSummaryColumns) values.push_back(row[key].get<double>());
      table.add_row(to_string(p), values);
      rows.push_back(std::move(row));
    }
  }

  // 3. The fall time against f: the reduced ODE and the quadrature at 21 values of f, the string
  //    solver at every other one (three with --quick).
  fall_time_reduced().write(fig / "fall_time_vs_f.csv");
  std::vector<double> string_fs;
  for (int k = 0; k <= 10; k += options.quick ? 5 : 1) string_fs.push_back(k / 10.0);
  const std::vector<double> worst = fall_time_string(string_fs, options.nodes, fig / "fall_time_string.csv");

  table.write(root / "summary.csv");
  write_json(root / "summary.json", rows);  // written last
  if (options.json) {
    out << json_text(rows) << '\n';
    return 0;
  }
  fmt::print(out, "The paper's three chain problems, each three ways: the string solver with front tracking ({} nodes),\n"
                  "the reduced ODE (ARKODE) and the exact quadrature. Stop time t/t0 at the cutoff (eps = 0.01):\n",
             options.nodes);
  print_table(rows, out);
  fmt::print(out, "Fall time against f (string solver at {} values of f, eps = {:g}), max rel. diff. from the quadrature: "
                  "falling {:.1e}, folded {:.1e}, sliding {:.1e}\n",
             string_fs.size(), kFallTimeEps, worst[0], worst[1], worst[2]);
  fmt::print(out, "computed in {:.2f} s\n", seconds_since(start));
  fmt::print(out, "results  {}/summary.csv and summary.json (one row per problem and f), {}/{{falling,folded,sliding}}/ "
                  "(reduced model, default parameters), figure data in {}\n",
             root.string(), root.string(), fig.string());
  fmt::print(out, "figures  /usr/bin/python3 scripts/plot_canonical.py {} draws them into {}\n", root.string(),
             (root / "figures").string());
  return 0;
}

}  // namespace chainsim
