// `chainsim reduced`: see commands.hpp.
#include <filesystem>
#include <ostream>

#include <fmt/format.h>
#include <fmt/ostream.h>

#include "cases/cli/commands.hpp"
#include "mesh/errors.hpp"
#include "solver/output.hpp"

namespace chainsim {

namespace fs = std::filesystem;

namespace {

void write_run(const ReducedRun& run, const fs::path& dir) {
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
  const RunDirectory run_dir(dir);  // held until the outputs are written
  run_dir.clear();
  const ReducedRun run = solve_reduced(options.setup);
  write_run(run, dir);
  if (options.json) {
    out << json_text(run.summary) << '\n';
  } else {
    print_human(run.summary, out);
    fmt::print(out, "  wrote {} and {}\n", (dir / "series.csv").string(), (dir / "summary.json").string());
  }
  return 0;
}

}  // namespace chainsim
