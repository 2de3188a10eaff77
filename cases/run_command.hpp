#pragma once
/// @file run_command.hpp
/// `chainsim run SCENE`: run a general string scene with the string solver.
#include <iosfwd>
#include <string>

namespace chainsim {

struct RunCommandOptions {
  std::string scene;  ///< path of the scene file
  std::string out;    ///< output directory ("" = "results/<scene stem>")
  bool json = false;  ///< print the summary object on stdout
};

/// Runs the scene, writes the outputs, prints a human summary (or JSON) to `out`.
/// Returns the process exit code. Throws InputError / NumericalError on failure.
int run_scene_command(const RunCommandOptions& options, std::ostream& out);

}  // namespace chainsim
