// `chainsim fit TARGET DATA.csv... [...]`: fits f (and other scene keys) to measured series with the Python
// module chainsim.fitting (run as `python3 -m chainsim fit ...`; SciPy's least_squares; docs/fit.md). One
// implementation: the C++ side only passes the options on; the module checks them, fits, writes the output
// directory and prints the table, and its exit code is the command's (2: bad input or a fit that does not
// converge, 3: the model failed).
#include <string>
#include <vector>

#include "cases/cli/commands.hpp"
#include "cases/cli/python_command.hpp"

namespace chainsim {

int run_fit_command(const FitCommandOptions& options) {
  std::vector<std::string> args = {"fit", options.target};
  args.insert(args.end(), options.data.begin(), options.data.end());
  const std::pair<const char*, const std::string*> values[] = {
      {"--observable", &options.observable}, {"--column", &options.column},     {"--time-column", &options.time_column},
      {"--sigma", &options.sigma},           {"--profile", &options.profile},   {"--jobs", &options.jobs},
      {"--max-nfev", &options.max_nfev},     {"--out", &options.out}};
  for (const auto& [name, value] : values)
    if (!value->empty()) args.push_back(std::string(name) + "=" + *value);
  const std::pair<const char*, const std::vector<std::string>*> lists[] = {
      {"--free", &options.free}, {"--per-run", &options.per_run}, {"--set", &options.overrides}};
  for (const auto& [name, list] : lists)
    for (const std::string& value : *list) args.push_back(std::string(name) + "=" + value);
  if (options.absolute_sigma) args.emplace_back("--absolute-sigma");
  if (options.no_figures) args.emplace_back("--no-figures");
  if (options.json) args.emplace_back("--json");
  return run_python_module("fit", "chainsim", "chainsim/fitting.py", args);
}

}  // namespace chainsim
