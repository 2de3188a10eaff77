// `chainsim compare`: the string solver against the reduced ODE (see commands.hpp).
#include <filesystem>
#include <ostream>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "cases/cli/commands.hpp"
#include "mesh/errors.hpp"
#include "solver/output.hpp"

namespace chainsim {

int run_compare_command(CompareCommandOptions options, std::ostream& out) {
  options.setup.problem = parse_problem(options.problem);
  options.setup.validate();
  const std::filesystem::path dir =
      options.out.empty() ? std::filesystem::path("results") / "compare" / options.problem
                          : std::filesystem::path(options.out);
  const RunDirectory run_dir(dir);  // held until the outputs are written
  run_dir.clear();
  const Comparison c = compare_with_reduced(options.setup);
  samples_table(c.string.run).write(dir / "string_series.csv");
  c.reduced.series.write(dir / "reduced_series.csv");
  write_json(dir / "summary.json", c.summary);  // written last: its presence means the set is complete
  const bool failed = c.string.run.status == "failed";
  const std::string error = fmt::format("the string solver failed: {}", c.string.run.error);
  if (options.json) {
    nlohmann::json j = c.summary;
    if (failed) {
      j["error"] = error;
      j["exit_code"] = 3;
    }
    out << json_text(j) << '\n';
  } else {
    const auto& s = c.summary;
    out << fmt::format("{} chain, f = {}, {} nodes: string solver vs reduced ODE\n", options.problem,
                       options.setup.chain.dissipation, options.setup.nodes);
    out << fmt::format("  t_stop/t0        string {:.12g}   reduced {:.12g}   rel. error {:.3g}\n",
                       s["t_stop_over_t0"].get<double>(), s["t_stop_over_t0_reduced"].get<double>(),
                       s["rel_err_t_stop"].get<double>());
    out << fmt::format("  max |eta error|  {:.3g} (equal times)\n", s["max_abs_err_eta"].get<double>());
    out << fmt::format("  max rel. P error {:.3g} ({})\n", s["max_rel_err_P"].get<double>(),
                       s["P_compared_at"].get<std::string>());
    out << fmt::format("  energy ledger    {:.3g} (relative)   momentum ledger {:.3g}\n",
                       s["energy_residual"].get<double>(), s["momentum_residual"].get<double>());
    out << fmt::format("  stop: {} ({} crossings, {} steps, {:.3g} s)\n", s["stop_reason"].get<std::string>(),
                       s["transfers"].get<long>(), s["steps"].get<long>(), s["wall_s"].get<double>());
    out << fmt::format("  outputs in {}\n", dir.string());
  }
  if (failed) throw NumericalError(error, c.string.run.t_stop);
  return 0;
}

}  // namespace chainsim
