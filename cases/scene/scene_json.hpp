#pragma once
/// @file scene_json.hpp
/// The effective scene as JSON (`chainsim run --json` prints it as "scene_effective"): every key of
/// the format that applies to the scene, by section as in the file, with the value the run uses —
/// after the command line's overrides, with the defaults filled in (docs/scenes.md). Keys whose
/// default is derived when the model is built are null: string.length (the shape's length),
/// solver.stabilization_time (0.1 t_char; the run summary reports the value used), and
/// shape.corner_radius when the corners are not rounded; solver.max_wall_s is null without a limit.
/// solver.check_slack is written as solver.slack. Keys that do not apply to the chosen kind
/// (of shape, velocity, end) are left out, and so are effects the scene does not declare: written
/// back as TOML (nulls and empty arrays left out), the object is the same scene.
#include <nlohmann/json.hpp>

#include "cases/scene/scene.hpp"

namespace chainsim {

nlohmann::json scene_to_json(const SceneSpec& spec);

}  // namespace chainsim

namespace chainsim {

/// The TOML text of a scene given as a JSON object (sections as objects, [[arrays of tables]] as
/// arrays of objects; the Python module's Scene.from_dict), to be read by parse_scene_text, which
/// checks it like a file. Throws InputError for a value TOML cannot hold (null, an array that mixes
/// tables and values, a top-level value that is not an object).
std::string scene_toml_text(const nlohmann::json& scene);

}  // namespace chainsim
