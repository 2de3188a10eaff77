// `chainsim reduced` and `chainsim canonical`: see commands.hpp.
#include <cmath>
#include <filesystem>
#include <ostream>

#include <fmt/format.h>
#include <fmt/ostream.h>

#include "cases/cli/commands.hpp"
#include "cases/reduced/exact_solutions.hpp"
#include "mesh/errors.hpp"

namespace chainsim {

namespace fs = std::filesystem;

namespace {

void write_run(const ReducedRun& run, const fs::path& dir) {
  ensure_directory(dir);
  run.series.write(dir / "series.csv");
  write_json(dir / "summary.json", run.summary);
}

std::string fmt_or_dash(const nlohmann::json& v, const char* spec = "{:.12g}") {
  return v.is_number() ? fmt::format(fmt::runtime(spec), v.get<double>()) : std::string("-");
}

void print_human(const nlohmann::json& s, std::ostream& out) {
  fmt::print(out, "{} chain (reduced model): f = {:g}, eta0 = {:g}, eps = {:g}, F = {:g} N\n", s["problem"].get<std::string>(),
             s["parameters"]["f"].get<double>(), s["parameters"]["eta0"].get<double>(),
             s["parameters"]["eps"].get<double>(), s["parameters"]["force"].get<double>());
  fmt::print(out, "  stop: {} at t = {:.12g} s  (t/t0 = {:.12g}, exact {})\n", s["stop_reason"].get<std::string>(),
             s["t_stop"].get<double>(), s["t_stop_over_t0"].get<double>(), fmt_or_dash(s["t_stop_over_t0_exact"]));
  fmt::print(out, "  eta = {:.12g}   P/P0 = {:.12g} (exact {})\n", s["eta_stop"].get<double>(),
             s["P_stop_over_P0"].get<double>(), fmt_or_dash(s["P_stop_over_P0_exact"]));
  fmt::print(out, "  full fall t_f/t0 (quadrature) = {}   energy residual = {:.2e}   turning points = {}\n",
             fmt_or_dash(s["t_fall_over_t0"]), s["energy_residual"].get<double>(), s["turning_points"].get<int>());
  const auto& st = s["integrator"];
  fmt::print(out, "  {} (order {}): {} steps, {} rhs evals, {} rejected, wall {:.3f} s\n",
             st["method"].get<std::string>(), st["order"].get<int>(), st["steps"].get<long>(),
             st["rhs_evals"].get<long>(), st["error_test_fails"].get<long>(), s["wall_s"].get<double>());
}

}  // namespace

int run_reduced_command(ReducedCommandOptions options, std::ostream& out) {
  options.setup.problem = parse_problem(options.problem);
  const fs::path dir = options.out.empty() ? fs::path("results") / "reduced" / options.problem : fs::path(options.out);
  const ReducedRun run = solve_reduced(options.setup);
  write_run(run, dir);
  if (options.json) {
    out << run.summary.dump() << '\n';
  } else {
    print_human(run.summary, out);
    fmt::print(out, "  wrote {} and {}\n", (dir / "series.csv").string(), (dir / "summary.json").string());
  }
  return 0;
}

namespace {

/// The exact η(ξ), P/P0 curve of a problem on a grid of η (for drawing beside the ODE solution).
CsvTable exact_curve(Problem problem, double f, double eta0, double eps) {
  CsvTable table({"eta", "xi", "P_over_P0"});
  const int n = 400;
  for (int k = 0; k <= n; ++k) {
    // Cluster the points towards the stop, where η and P are steep.
    const double s = 1.0 - std::pow(1.0 - static_cast<double>(k) / n, 2.0);
    double eta = 0, xi = 0, P = 0;
    switch (problem) {
      case Problem::kFalling:
        eta = eta0 + (eps - eta0) * s;
        xi = exact::falling_xi(f, eta, eta0);
        P = exact::falling_P(f, eta, eta0);
        break;
      case Problem::kFolded:
        eta = eta0 + (1.0 - eps - eta0) * s;
        xi = exact::folded_xi(f, eta, eta0);
        P = exact::folded_P(f, eta, eta0);
        break;
      case Problem::kSliding:
        eta = eta0 + (1.0 - eta0) * s;
        xi = exact::sliding_xi(f, eta, eta0);
        P = exact::sliding_P(f, eta, eta0);
        break;
    }
    table.add_row({eta, xi, P});
  }
  return table;
}

}  // namespace

int run_canonical_command(const CanonicalCommandOptions& options, std::ostream& out) {
  const fs::path root(options.out);
  ensure_directory(root);

  // 1. The three problems with default parameters: series, summaries, and one table.
  CsvTable table({"f", "eta0", "eps", "t_stop_over_t0", "t_stop_over_t0_exact", "rel_err_t_stop",
                  "eta_stop", "P_stop_over_P0", "P_stop_over_P0_exact", "rel_err_P_stop", "t_fall_over_t0",
                  "energy_residual", "steps", "wall_s"},
                 "problem");
  nlohmann::json summaries = nlohmann::json::array();
  const Problem problems[] = {Problem::kFalling, Problem::kFolded, Problem::kSliding};
  for (Problem p : problems) {
    ReducedSetup setup;
    setup.problem = p;
    const ReducedRun run = solve_reduced(setup);
    write_run(run, root / to_string(p));
    const auto& s = run.summary;
    auto num = [](const nlohmann::json& v) { return v.is_number() ? v.get<double>() : NAN; };
    table.add_row(to_string(p), {setup.chain.dissipation, setup.initial_eta(), setup.eps,
                   num(s["t_stop_over_t0"]), num(s["t_stop_over_t0_exact"]), num(s["rel_err_t_stop"]),
                   num(s["eta_stop"]), num(s["P_stop_over_P0"]), num(s["P_stop_over_P0_exact"]),
                   num(s["rel_err_P_stop"]), num(s["t_fall_over_t0"]), num(s["energy_residual"]),
                   static_cast<double>(s["integrator"]["steps"].get<long>()), num(s["wall_s"])});
    summaries.push_back(s);
    if (!options.json) print_human(s, out);
  }
  table.write(root / "summary.csv");
  write_json(root / "summary.json", summaries);

  // 2. Figure data. Fall time against f: ODE stop time at the cutoff and the quadrature of the
  //    full fall (falling η0 = 1, folded η0 = 0, sliding η0 = 0, 0.25, 0.75).
  const fs::path fig = root / "figure_data";
  ensure_directory(fig);
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
  tf.write(fig / "fall_time_vs_f.csv");

  //    η(ξ) and P/P0(ξ) for the values of f in the paper's figures (ε = 0.01).
  const double fs_falling[] = {0.0, 0.5, 0.75, 0.85, 0.95, 1.0};
  const double fs_folded[] = {0.0, 0.5, 0.75, 1.0};
  const double fs_sliding[] = {0.0, 0.5, 1.0};
  auto curves = [&](Problem p, const double* values, int count, double eta0) {
    for (int k = 0; k < count; ++k) {
      ReducedSetup s;
      s.problem = p;
      s.chain.dissipation = values[k];
      s.eta0 = eta0;
      const std::string stem = fmt::format("{}_f{:.2f}", to_string(p), values[k]);
      solve_reduced(s).series.write(fig / (stem + "_ode.csv"));
      exact_curve(p, values[k], eta0, s.eps).write(fig / (stem + "_exact.csv"));
    }
  };
  curves(Problem::kFalling, fs_falling, 6, 1.0);
  curves(Problem::kFolded, fs_folded, 4, 0.0);
  curves(Problem::kSliding, fs_sliding, 3, 0.25);

  if (options.json) {
    out << summaries.dump() << '\n';
  } else {
    fmt::print(out, "wrote {}/{{falling,folded,sliding}}/, {}/summary.csv and figure data in {}\n", root.string(),
               root.string(), fig.string());
  }
  return 0;
}

}  // namespace chainsim
