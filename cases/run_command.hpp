#pragma once
/// @file run_command.hpp
/// `chainsim run SCENE`: run a general string scene with the string solver (docs/scenes.md).
#include <iosfwd>
#include <optional>
#include <string>

namespace chainsim {

struct RunCommandOptions {
  std::string scene;  ///< path of the scene file
  std::string out;    ///< output directory ("" = "results/<scene stem>")
  std::optional<double> t_end;  ///< replaces the scene's [stop] t_end (s)
  bool json = false;  ///< print the summary object on stdout
};

/// Runs the scene, writes the outputs, prints a human summary (or JSON) to `out`.
/// Returns the process exit code. Throws InputError / NumericalError on failure; with `json`, it
/// first prints {"status": "failed", "error": …, "exit_code": …} (after a numerical failure: the
/// whole summary up to the failure) on `out`.
int run_scene_command(const RunCommandOptions& options, std::ostream& out);

}  // namespace chainsim
