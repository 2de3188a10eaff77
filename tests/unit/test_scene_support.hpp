#pragma once
// A small good scene shared by the scene tests: a hanging chain, fixed at its top, under gravity.
// Line numbers matter: test_scene_errors.cpp checks messages that point into this text.
#include <string>

namespace chainsim::test {

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

}  // namespace chainsim::test
