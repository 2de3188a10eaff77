// `chainsim plot RUN_DIR [...]`: draws a run with the Python package python/chainsim_plot (matplotlib).
// The C++ side only passes the options on (run_python_module finds the interpreter and the package); the
// package checks them, reads the run and draws it, and its exit code is the command's (2: bad input, see
// docs/plotting.md).
#include <string>
#include <vector>

#include "cases/cli/commands.hpp"
#include "cases/cli/python_command.hpp"

namespace chainsim {

namespace {

/// The module's arguments: RUN_DIR [--option=value ...].
std::vector<std::string> plot_arguments(const PlotCommandOptions& options) {
  std::vector<std::string> args = {options.run_dir};
  if (options.animate) args.emplace_back("--animate");
  if (options.html) args.emplace_back("--html");
  const std::pair<const char*, const std::string*> values[] = {
      {"--speed", &options.speed}, {"--fps", &options.fps}, {"--times", &options.times}, {"--format", &options.format}};
  for (const auto& [name, value] : values)
    if (!value->empty()) args.push_back(std::string(name) + "=" + *value);
  return args;
}

}  // namespace

int run_plot_command(const PlotCommandOptions& options) {
  return run_python_module("plot", "chainsim_plot", "chainsim_plot/__main__.py", plot_arguments(options));
}

}  // namespace chainsim
