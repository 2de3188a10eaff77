#pragma once
// One scene text through the parser and the builders, up to the start of integration: the input of
// the scene fuzzer (fuzz_scene.cpp) and of its regression tests (tests/hard/test_fuzz_regressions.cpp).
#include <string>
#include <string_view>

#include "cases/cli/run_command.hpp"
#include "cases/scene/scene.hpp"
#include "mesh/errors.hpp"

namespace chainsim::fuzz {

/// Parses `text` as a scene and builds its model (string, fronts or reduced, as the scene says),
/// exactly as `chainsim run` does before it integrates. Returns "" if the scene was accepted, else
/// the InputError's message: a refusal with a message is the expected outcome of bad input. Any
/// other exception (an internal invariant, a NumericalError while building) propagates: the
/// fuzzer reports it as a crash, and so does a sanitizer's finding.
inline std::string check_scene_text(std::string_view text) {
  try {
    const SceneSpec spec = parse_scene_text(text, "fuzz.toml");
    check_scene(spec);
    return "";
  } catch (const InputError& e) {
    return e.what();
  }
}

}  // namespace chainsim::fuzz
