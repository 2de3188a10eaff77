#pragma once
/// @file run_command.hpp
/// `chainsim run SCENE`: run a scene (docs/scenes.md) on the model it asks for: the string solver,
/// with front tracking if the scene declares a heap or a fold, or the reduced ODE (model = "reduced").
#include <iosfwd>
#include <optional>
#include <string>
#include <vector>

namespace chainsim {

struct SceneSpec;

/// Builds the model the scene runs on (string, string with fronts, or reduced) and checks it, without
/// running anything. Throws InputError located at the key at fault (the checks of `chainsim run`).
void check_scene(const SceneSpec& spec);

struct RunCommandOptions {
  std::string scene;  ///< path of the scene file
  std::string out;    ///< output directory ("" = "results/<scene stem>")
  std::optional<double> t_end;  ///< replaces the scene's [stop] t_end (s)
  std::optional<double> max_wall;  ///< replaces the scene's [solver] max_wall_s (s of wall-clock time)
  std::vector<std::string> overrides;  ///< --set KEY=VALUE, applied to the scene in order
  bool json = false;  ///< print the summary object on stdout
  bool quiet = false;  ///< no progress line on stderr (there is none when stderr is not a terminal)
};

/// Runs the scene, writes the outputs, prints a human summary (or JSON) to `out`.
/// Returns the process exit code. Throws InputError / NumericalError on failure; with `json`, it
/// first prints {"status": "failed", "error": …, "exit_code": …} (after a numerical failure: the
/// whole summary up to the failure) on `out`.
int run_scene_command(const RunCommandOptions& options, std::ostream& out);

}  // namespace chainsim
