// The effective scene (cases/scene/scene_json.cpp, `scene_effective` of `chainsim run --json` and
// Python's Scene.effective) writes back every effect the scene format declares (issue 22, item 5): an
// effect added to the parser but forgotten in scene_json.cpp fails here.
#include <catch2/catch.hpp>
#include <fmt/format.h>

#include <map>
#include <string>

#include "cases/scene/scene.hpp"
#include "cases/scene/scene_json.hpp"
#include "test_scene_support.hpp"

using namespace chainsim;

namespace {
/// The object as a scene file writes it: nulls (derived defaults) and empty arrays left out.
nlohmann::json written(const nlohmann::json& j) {
  if (!j.is_object()) return j;
  nlohmann::json out = nlohmann::json::object();
  for (const auto& [key, value] : j.items())
    if (!value.is_null() && !(value.is_array() && value.empty())) out[key] = written(value);
  return out;
}
}  // namespace

TEST_CASE("every effect table of the scene format is written back to scene_effective", "[unit][scene]") {
  // The hanging chain of the scene tests without its gravity: each effect is declared alone.
  const std::string base = test::edit(test::kSceneBase, "[effects.gravity]\ng = [0.0, -9.81]\n", "");
  // One declaration of each effect, with the keys it needs (a plane lies under a heap on it).
  const std::map<std::string, std::string> samples = {
      {"gravity", "[effects.gravity]\ng = [0.0, -9.81]\n"},
      {"drag", "[effects.drag]\ncoefficient = 0.5\n"},
      {"heap", "[[effects.heap]]\nside = \"end\"\ns0 = 0.5\nf = 0.5\npoint = [0.0, -0.5]\n"},
      {"fold", "[effects.fold]\ns0 = 0.5\nf = 0.5\n"},
      {"plane", "[[effects.heap]]\nside = \"end\"\ns0 = 0.5\nf = 0.5\npoint = [0.0, -0.5]\non_plane = true\n"
                "[effects.plane]\npoint = [0.0, -0.5]\nnormal = [0.0, 1.0]\n"},
      {"edge", "[[effects.edge]]\npoint = [0.0, -0.5]\nf = 0.5\n"},
      {"surface", "[[effects.surface]]\npoint = [0.0, -2.0]\nnormal = [0.0, 1.0]\n"},
      {"cylinder", "[[effects.cylinder]]\ncenter = [0.5, -0.5]\nradius = 0.1\n"},
      {"kink", "[[effects.kink]]\ns0 = 0.5\n"},
  };
  REQUIRE(!effect_tables().empty());
  for (const EffectTable& table : effect_tables()) {
    const std::string name = table.name;
    INFO("[effects." << name << "]: give this test a sample declaration of the new effect");
    REQUIRE(samples.count(name) == 1);
    const SceneSpec spec = parse_scene_text(base + samples.at(name), "effect.toml");
    const nlohmann::json effective = scene_to_json(spec);
    INFO("scene_effective: " << effective.dump());
    REQUIRE(effective.contains("effects"));
    CHECK(effective["effects"].contains(name));
    CHECK(effective["effects"][name].is_array() == table.array);
    // Written back as TOML, the effect is read again as declared.
    const SceneSpec again = parse_scene_text(scene_toml_text(written(effective)), "again.toml");
    CHECK(scene_to_json(again)["effects"] == effective["effects"]);
  }
}

TEST_CASE("a cylinder's contact is written back where it is not the default", "[unit][scene]") {
  const std::string base = test::edit(test::kSceneBase, "[effects.gravity]\ng = [0.0, -9.81]\n", "");
  const std::string cylinder = "[[effects.cylinder]]\ncenter = [0.5, -0.5]\nradius = 0.1\n";
  // Without the key: nothing new in scene_effective (a scene without it writes what it always wrote).
  const nlohmann::json nodes = scene_to_json(parse_scene_text(base + cylinder, "nodes.toml"));
  CHECK(!nodes["effects"]["cylinder"][0].contains("contact"));
  const nlohmann::json arc = scene_to_json(parse_scene_text(base + cylinder + "contact = \"arc\"\n", "arc.toml"));
  CHECK(arc["effects"]["cylinder"][0]["contact"] == "arc");
  const SceneSpec again = parse_scene_text(scene_toml_text(written(arc)), "again.toml");
  CHECK(again.effects.cylinders.at(0).contact == "arc");
}

TEST_CASE("a surface's and a cylinder's mu are written back where they are not the default, and read again",
          "[unit][scene]") {
  const std::string base = test::edit(test::kSceneBase, "[effects.gravity]\ng = [0.0, -9.81]\n", "");
  const std::string obstacles = "[[effects.surface]]\npoint = [0.0, -2.0]\nnormal = [0.0, 1.0]\n{}"
                                "[[effects.cylinder]]\ncenter = [0.5, -0.5]\nradius = 0.1\n{}";
  const auto scene = [&](const std::string& surface_mu, const std::string& cylinder_mu) {
    std::string text = obstacles;
    text.replace(text.find("{}"), 2, surface_mu);
    text.replace(text.find("{}"), 2, cylinder_mu);
    return base + text;
  };
  // Without the key: no mu in scene_effective (a scene without it writes what it always wrote).
  const nlohmann::json smooth = scene_to_json(parse_scene_text(scene("", ""), "smooth.toml"));
  CHECK(!smooth["effects"]["surface"][0].contains("mu"));
  CHECK(!smooth["effects"]["cylinder"][0].contains("mu"));
  // With it: written as given, and the scene written back as TOML reads the same coefficients.
  const SceneSpec rough = parse_scene_text(scene("mu = 0.35\n", "mu = 0.2\n"), "rough.toml");
  const nlohmann::json effective = scene_to_json(rough);
  INFO("scene_effective: " << effective.dump());
  CHECK(effective["effects"]["surface"][0].value("mu", 0.0) == 0.35);
  CHECK(effective["effects"]["cylinder"][0].value("mu", 0.0) == 0.2);
  const SceneSpec again = parse_scene_text(scene_toml_text(written(effective)), "again.toml");
  CHECK(again.effects.surfaces.at(0).mu == rough.effects.surfaces.at(0).mu);
  CHECK(again.effects.cylinders.at(0).mu == rough.effects.cylinders.at(0).mu);
  CHECK(scene_to_json(again)["effects"] == effective["effects"]);
}

TEST_CASE("a surface's f is written back where it is given, and read again", "[unit][scene]") {
  const std::string base = test::edit(test::kSceneBase, "[effects.gravity]\ng = [0.0, -9.81]\n", "");
  const std::string surface = "[[effects.surface]]\npoint = [0.0, -2.0]\nnormal = [0.0, 1.0]\n";
  // Without the key: no f in scene_effective (node contact).
  CHECK(!scene_to_json(parse_scene_text(base + surface, "contact.toml"))["effects"]["surface"][0].contains("f"));
  // With it (f = 0 too: a touchdown front without dissipation, not node contact): written as given, read the same.
  for (const double f : {0.0, 0.35}) {
    CAPTURE(f);
    const SceneSpec front = parse_scene_text(base + surface + fmt::format("f = {}\n", f), "front.toml");
    const nlohmann::json effective = scene_to_json(front);
    INFO("scene_effective: " << effective.dump());
    REQUIRE(effective["effects"]["surface"][0].contains("f"));
    CHECK(effective["effects"]["surface"][0]["f"] == f);
    const SceneSpec again = parse_scene_text(scene_toml_text(written(effective)), "again.toml");
    REQUIRE(again.effects.surfaces.at(0).f.has_value());
    CHECK(*again.effects.surfaces.at(0).f == f);
    CHECK(scene_to_json(again)["effects"] == effective["effects"]);
  }
}
