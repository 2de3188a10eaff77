#pragma once
// Small good scenes shared by the scene tests: a hanging chain, fixed at its top, under gravity, and
// the three canonical problems with fronts (falling, folded, sliding chain, 21 nodes, f = 0.5).
// Line numbers matter: test_scene_errors.cpp checks messages that point into these texts.
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

#include <catch2/catch.hpp>
#include <fmt/format.h>

#include <unistd.h>

#include "cases/scene/front_scene.hpp"
#include "cases/scene/scene.hpp"

namespace chainsim::test {

/// The prefix of this process's temporary paths: the process id is in it, so two test runs at once
/// (two build trees, CI stages) never share a directory.
inline std::string temp_prefix() { return "chainsim_test_" + std::to_string(static_cast<long>(::getpid())) + "_"; }

/// A path for one test's files under the system's temporary directory, removed if it exists.
inline std::filesystem::path temp_path(const std::string& name) {
  auto dir = std::filesystem::temp_directory_path() / (temp_prefix() + name);
  std::filesystem::remove_all(dir);
  return dir;
}

/// Removes every temp_path of this process (tests/test_main.cpp, after a run that passed).
inline void remove_temp_paths() {
  std::error_code ignored;
  const std::string prefix = temp_prefix();
  for (const auto& entry : std::filesystem::directory_iterator(std::filesystem::temp_directory_path(), ignored))
    if (entry.path().filename().string().rfind(prefix, 0) == 0) std::filesystem::remove_all(entry.path(), ignored);
}

/// An empty directory for one test's files (temp_path, created).
inline std::filesystem::path temp_dir(const std::string& name) {
  auto dir = temp_path(name);
  std::filesystem::create_directories(dir);
  return dir;
}

/// The whole text of a file.
inline std::string read(const std::filesystem::path& file) {
  std::ifstream in(file);
  std::stringstream text;
  text << in.rdbuf();
  return text.str();
}

/// `text` with its first `from` replaced by `to` (which must be there).
inline std::string edit(const std::string& text, const std::string& from, const std::string& to) {
  const auto at = text.find(from);
  REQUIRE(at != std::string::npos);
  std::string out = text;
  out.replace(at, from.size(), to);
  return out;
}

/// Builds a scene with fronts in its own dimension and runs it (no outputs written).
inline RunSummary run_front_spec(const SceneSpec& spec) {
  return spec.dimension == 3 ? run_front_scene<3>(spec) : run_front_scene<2>(spec);
}

inline const std::string kSceneBase = R"([string]
length = 1.0
density = 0.1
nodes = 11

[shape]
kind = "polyline"
points = [[0.0, 0.0], [0.0, -1.0]]

[ends]
start = "fixed"

[effects.gravity]
g = [0.0, -9.81]

[stop]
t_end = 0.2
)";

// The falling chain: a heap at the end on a table, a cutoff at s0 = 0.01 m.
inline const std::string kFallingBase = R"(model = "string"

[string]
length = 1.0
nodes = 21

[shape]
kind = "polyline"
points = [[0.0, 1.0], [0.0, 0.0]]

[effects.gravity]
g = [0.0, -9.81]

[[effects.heap]]
side = "end"
s0 = 1.0
f = 0.5
point = [0.0, 0.0]
on_plane = true

[effects.plane]
point = [0.0, 0.0]
normal = [0.0, 1.0]

[stop]
t_end = 1.0
[[stop.front]]
front = "heap_end"
s0 = 0.01
)";

// The folded chain: start fixed, a resting arm of 0.2 m, the fold, the free arm back up; cutoff 0.99 m.
inline const std::string kFoldedBase = R"(model = "string"

[string]
length = 1.0
nodes = 21

[shape]
kind = "polyline"
points = [[0.0, 0.0], [0.0, -0.2], [0.0, 0.6]]

[ends]
start = "fixed"

[effects.gravity]
g = [0.0, -9.81]

[effects.fold]
s0 = 0.2
f = 0.5

[stop]
t_end = 1.0
[[stop.front]]
front = "fold"
s0 = 0.99
)";

// The sliding chain: a heap at the start feeding a hole at the origin, 0.2 m hanging.
inline const std::string kSlidingBase = R"(model = "string"

[string]
length = 1.0
nodes = 21

[shape]
kind = "polyline"
points = [[-0.8, 0.0], [0.0, 0.0], [0.0, -0.2]]

[effects.gravity]
g = [0.0, -9.81]

[[effects.heap]]
side = "start"
s0 = 0.8
f = 0.5
point = [0.0, 0.0]

[stop]
t_end = 1.0
)";

/// A chain pulled up at `speed` by its driven end out of a heap on a table: 0.8 m in the heap, 0.2 m
/// lifted and at rest, `nodes` nodes, output frames every `interval`.
inline std::string pick_up(int nodes, double speed, double interval, bool on_plane) {
  return fmt::format(R"(model = "string"
[string]
length = 1.0
density = 0.25
nodes = {}
[shape]
kind = "polyline"
points = [[-0.8, 0.0], [0.0, 0.0], [0.0, 0.2]]
[ends]
end = {{ kind = "driven", path = "linear", velocity = [0.0, {:g}] }}
[effects.gravity]
g = [0.0, -9.81]
[[effects.heap]]
side = "start"
s0 = 0.8
f = 0.0
point = [0.0, 0.0]
{}
[output]
interval = {:g}
[stop]
t_end = 1.0
)",
                     nodes, speed,
                     on_plane ? "on_plane = true\n[effects.plane]\npoint = [0.0, 0.0]\nnormal = [0.0, 1.0]" : "on_plane = false",
                     interval);
}

}  // namespace chainsim::test
