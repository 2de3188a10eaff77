#pragma once
// What the slack tests share (docs/model.md §9): the shaken heap, a scene that goes slack beside a front.
#include <string>

#include <fmt/format.h>

namespace chainsim::test {

/// A vertical chain on a table (a heap on the plane y = 0 holds s > s0) whose top end is driven by the
/// shake path x0 + A (1 − cos ω t): it starts at rest and accelerates down at A ω² = 40 m/s² > g, so the
/// links below it go slack and the chain below falls into the heap; from t = π/(2ω) the top slows, turns
/// at t = π/ω and pulls the slack stretch taut and the chain back out of the heap. The scene's string,
/// shape, ends and effects on `nodes` nodes: each test appends its [solver] (with slack = "allow"),
/// [output] and [stop].
inline std::string shaken_heap_scene(int nodes) {
  return fmt::format(R"([string]
length = 1.0
density = 1.0
nodes = {}
[shape]
kind = "polyline"
points = [[0.0, 1.0], [0.0, 0.0]]
[ends]
start = {{ kind = "driven", path = "shake", amplitude = [0.0, -0.1], omega = 20.0 }}
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
)",
                     nodes);
}

}  // namespace chainsim::test
