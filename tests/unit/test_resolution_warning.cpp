// The run's warning when a cylinder in node contact is thinner than the links (issue 23): its nodes are held on
// the circle and its links are chords, so such a cylinder is a polygon of one or two nodes, and its contact
// forces and lift-offs are not the cylinder's (`chainsim compare pulley --u0 0.05 --nodes 101`, links of 1 cm:
// lift-off 0.002 s late over R = 1 cm, 0.032 s early over R = 5 mm, at 0.27 s instead of 0.60 s over R = 3 mm).
#include <filesystem>
#include <string>

#include <catch2/catch.hpp>
#include <nlohmann/json.hpp>

#include "cases/scene/scene_run.hpp"

namespace {

/// The summary of cases/scenes/atwood_pulley.toml (1 m of chain over a pulley of radius 0.1 m) built with
/// `overrides`, before any step: the warning is the scene's, known before the run.
nlohmann::json atwood_summary(const std::vector<std::string>& overrides) {
  const std::filesystem::path file =
      std::filesystem::path(CHAINSIM_SOURCE_DIR) / "cases" / "scenes" / "atwood_pulley.toml";
  chainsim::SceneRun<2> run(chainsim::parse_scene(file, overrides));
  return run.summary();
}

}  // namespace

TEST_CASE("a cylinder thinner than the links warns with the nodes that resolve it", "[scene][contact][tolerance]") {
  // 101 nodes: links of 1 cm under a radius of 10 cm, resolved.
  CHECK_FALSE(atwood_summary({}).contains("resolution_warning"));
  // 5 nodes: links of 25 cm over a radius of 10 cm.
  const nlohmann::json coarse = atwood_summary({"string.nodes=5"});
  REQUIRE(coarse.contains("resolution_warning"));
  const std::string text = coarse["resolution_warning"];
  CHECK_THAT(text, Catch::Matchers::Contains("effects.cylinder[0].radius = 0.1 m is shorter than the links (0.25 m)"));
  // The advice: links no longer than R, i.e. ceil(l / R) + 1 = 11 nodes for 1 m of chain; it does not warn again.
  CHECK_THAT(text, Catch::Matchers::EndsWith("set string.nodes >= 11 (links no longer than the radius)"));
  CHECK_FALSE(atwood_summary({"string.nodes=11"}).contains("resolution_warning"));
  CHECK(atwood_summary({"string.nodes=10"}).contains("resolution_warning"));
  // Links along the arc bend over the circle exactly, on any mesh: no warning.
  CHECK_FALSE(atwood_summary({"string.nodes=5", "effects.cylinder[0].contact=\"arc\""}).contains("resolution_warning"));
}
