#pragma once
/// @file scene_overrides.hpp
/// Overrides of scene keys from the command line (`chainsim run SCENE --set KEY=VALUE`; internal to
/// cases/scene/). Each override is applied to the parsed TOML table before any check, so its value
/// goes through the same checks and messages as one written in the file, located at the argument
/// ("--set effects.heap[0].f=1.5: effects.heap[0].f = 1.5 is out of range: allowed 0 <= f <= 1").
///
///   KEY    a dotted key, each part optionally indexed: string.nodes, effects.heap[0].f,
///          shape.points[2]. A section, element or key the scene does not have yet is created
///          (effects.drag.coefficient=0.1 declares drag; an index one past the last element adds one).
///   VALUE  a TOML value: 201, 0.5, true, "erk8", [0.0, -9.81], { kind = "fixed" }; a bare word
///          (letters, digits, _ - . +, starting with a letter) is taken as a string: erk8.
#include <string>
#include <vector>

#include "cases/scene/toml.hpp"

#include "cases/scene/scene_text.hpp"

namespace chainsim::scene_parse {

/// Applies `overrides` ("KEY=VALUE", in order: a later one wins) to `root`; each becomes a text of
/// `text` named "--set KEY=VALUE". Throws InputError located at the argument if one is malformed,
/// its value is no TOML value, or its key runs through a value that is no table or array, or
/// indexes beyond the end of an array.
void apply_overrides(toml::table& root, const std::vector<std::string>& overrides, scene_text::SourceText& text);

}  // namespace chainsim::scene_parse
