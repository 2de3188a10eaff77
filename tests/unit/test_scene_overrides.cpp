// cases/scene/scene_overrides.cpp and scene_json.cpp: `chainsim run --set KEY=VALUE` overrides scene keys with
// the file's checks and messages, located at the argument; the effective scene as JSON ("scene_effective").
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include <catch2/catch.hpp>
#include <nlohmann/json.hpp>

#include "cases/cli/run_command.hpp"
#include "cases/scene/scene.hpp"
#include "cases/scene/scene_json.hpp"
#include "mesh/errors.hpp"
#include "test_scene_support.hpp"

using namespace chainsim;
using test::edit;
using test::read;
using test::temp_dir;
using Catch::Matchers::Contains;

namespace {

/// The message of the InputError that parsing `text` with `overrides` and building its model raises,
/// or "" if none.
std::string error_of(const std::string& text, const std::vector<std::string>& overrides) {
  try {
    check_scene(parse_scene_text(text, "s.toml", overrides));
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}

/// A JSON value as a TOML value (JSON numbers, strings, booleans and arrays are TOML as they print;
/// objects become inline tables).
std::string toml_value(const nlohmann::json& v) {
  if (v.is_object()) {
    std::string out;
    for (const auto& [key, item] : v.items())
      if (!item.is_null()) out += (out.empty() ? "" : ", ") + key + " = " + toml_value(item);
    return "{ " + out + " }";
  }
  if (v.is_array()) {
    std::string out;
    for (const auto& item : v) out += (out.empty() ? "" : ", ") + toml_value(item);
    return "[" + out + "]";
  }
  return v.dump();
}

/// A table of the effective scene as TOML text under `[name]` (sub-tables as [name.key], arrays of
/// tables as [[name.key]]); nulls and empty arrays left out.
std::string toml_table(const nlohmann::json& table, const std::string& name) {
  std::string keys, below;
  for (const auto& [key, v] : table.items()) {
    const std::string full = name.empty() ? key : name + "." + key;
    if (v.is_null() || (v.is_array() && v.empty())) continue;
    if (v.is_object() && !(name == "ends")) {
      below += toml_table(v, full);
    } else if (v.is_array() && v.front().is_object()) {
      for (const auto& item : v) below += "[[" + full + "]]\n" + toml_table(item, "");
    } else {
      keys += key + " = " + toml_value(v) + "\n";
    }
  }
  return (name.empty() ? "" : "[" + name + "]\n") + keys + "\n" + below;
}

}  // namespace

TEST_CASE("overrides (--set) are checked as the file is, and located at the argument", "[unit][scene]") {
  const std::string& H = test::kSceneBase;   // the hanging chain (11 nodes)
  const std::string& F = test::kFallingBase;  // the falling chain: a heap on a plane, one stop event
  struct Bad {
    const std::string* text;
    std::vector<std::string> overrides;
    std::string message;
  };
  const Bad cases[] = {
      {&F, {"effects.heap[0].f=1.5"}, "--set effects.heap[0].f=1.5: effects.heap[0].f = 1.5 is out of range: allowed 0 <= f <= 1"},
      {&H, {"string.nodez=21"},
       "--set string.nodez=21: unknown key 'nodez' in [string]; valid keys: length, density, nodes, link_length, closed, dimension, elements (did you mean 'nodes'?)"},
      {&H, {"strin.nodes=21"},
       "--set strin.nodes=21: unknown section [strin]; valid sections: string, shape, velocity, ends, effects, solver, output, stop; valid top-level keys: model (did you mean [string]?)"},
      {&H, {"effects.gravty.g=[0.0, -1.0]"},
       "--set effects.gravty.g=[0.0, -1.0]: unknown effect [effects.gravty]; valid effects: gravity, drag, heap, fold, plane, edge, surface, cylinder, kink (did you mean [effects.gravity]?)"},
      {&H, {"string.nodes=1"}, "--set string.nodes=1: string.nodes = 1 is out of range: allowed 2 <= nodes <= 10000000"},
      {&H, {"string.nodes=11.5"}, "--set string.nodes=11.5: string.nodes = 11.5 must be an integer"},
      {&H, {"string.density=heavy"}, "--set string.density=heavy: string.density = \"heavy\" must be a number"},
      {&H, {"shape.kind=polyine"},
       "--set shape.kind=polyine: shape.kind = \"polyine\" is not allowed; valid values: polyline, points, arc, circle, catenary (did you mean \"polyline\"?)"},
      {&H, {"effects.drag.coefficient=-1"},
       "--set effects.drag.coefficient=-1: effects.drag.coefficient = -1 is out of range: allowed coefficient >= 0"},
      // A value checked while building the model is located at the argument too.
      {&H, {"effects.gravity.g=[0.0, -9.81, 0.0]"},
       "--set effects.gravity.g=[0.0, -9.81, 0.0]: effects.gravity.g = [0.0, -9.81, 0.0] has 3 components but string.dimension = 2"},
      {&H, {"shape.points[1]=[0.0, -2.0]"},
       "s.toml:2:10: string.length = 1 m but the shape (polyline through 2 points) is 2 m long: they differ by 1 m, more than shape.length_tolerance = 1e-06 (relative)"},
      // A created section that lacks a required key: located at the argument that created it.
      {&H, {"effects.fold.f=0.5"}, "--set effects.fold.f=0.5: [effects.fold] needs s0 (m, the material coordinate of the fold at t = 0)"},
      {&F, {"stop.front[1].front=heap_end"},
       "--set stop.front[1].front=heap_end: stop.front[1] needs s0 (m, stop when that front reaches this material coordinate)"},
      // Malformed arguments.
      {&H, {"string.nodes"}, "--set string.nodes: expected KEY=VALUE, e.g. --set string.nodes=201"},
      {&H, {"=3"}, "--set =3: expected KEY=VALUE, e.g. --set string.nodes=201"},
      {&H, {"string.nodes="}, "--set string.nodes=: string.nodes has no value after '='"},
      {&H, {"string..nodes=3"},
       "--set string..nodes=3: 'string..nodes' is not a scene key: write a dotted key such as string.nodes or effects.heap[0].f"},
      {&H, {"shape.points[x]=3"},
       "--set shape.points[x]=3: 'shape.points[x]' is not a scene key: write a dotted key such as string.nodes or effects.heap[0].f"},
      {&H, {"string.nodes=[1,"},
       "--set string.nodes=[1,: [1, is not a TOML value (Error while parsing array: encountered end-of-file): write a number, true or false, a \"string\", an [array] or a { table }"},
      {&H, {"string.nodes=1 2"},
       "--set string.nodes=1 2: 1 2 is not a TOML value (Error while parsing key-value pair: expected a comment or whitespace, saw '2'): write a number, true or false, a \"string\", an [array] or a { table }"},
      {&H, {"string.nodes=1\nw = 2"}, "--set string.nodes=1\nw = 2: 1\nw = 2 is more than one TOML value"},
      // Keys through values that are no table or array, and indices past the end.
      {&H, {"string.nodes.x=1"}, "--set string.nodes.x=1: string.nodes = 11 is not a table, so it has no key 'x'"},
      {&H, {"string.nodes[0]=1"}, "--set string.nodes[0]=1: string.nodes = 11 is not an array, so it has no element [0]"},
      {&H, {"shape.points[5]=[0.0, 1.0]"},
       "--set shape.points[5]=[0.0, 1.0]: shape.points[5] does not exist: shape.points has 2 elements; --set may change [0] to [1] or add [2]"},
      {&H, {"effects.heap[1].f=0.5"}, "--set effects.heap[1].f=0.5: effects.heap[1] does not exist: effects.heap is empty; --set may add [0]"},
      {&F, {"effects.heap[0]=3"},
       "--set effects.heap[0]=3: effects.heap[0] = 3 must be a table: write [[effects.heap]] once per heap"},
      // The last override of a key wins; the first bad one in the order given is reported.
      {&H, {"string.nodes=1", "string.nodes=5", "solver.rtol=1.0", "string.density=-1"},
       "--set string.density=-1: string.density = -1 is out of range: allowed density > 0"},
      {&H, {"string.nodez=1", "string.lenght=1"},
       "--set string.nodez=1: unknown key 'nodez' in [string]; valid keys: length, density, nodes, link_length, closed, dimension, elements (did you mean 'nodes'?)"},
  };
  for (const Bad& c : cases) {
    std::string args;
    for (const auto& o : c.overrides) args += " --set " + o;
    INFO(args);
    CHECK(error_of(*c.text, c.overrides) == c.message);
  }
  // An unknown key written in the file is reported before one set on the command line.
  CHECK_THAT(error_of(edit(H, "density = 0.1", "densty = 0.1"), {"string.nodez=3"}),
             Contains("s.toml:3:1: unknown key 'densty' in [string]"));
}

TEST_CASE("an override (--set) replaces values, array elements and whole arrays, and creates sections and elements", "[unit][scene]") {
  SECTION("a value and an array element, located at the argument") {
    const SceneSpec spec = parse_scene_text(test::kSceneBase, "s.toml",
                                            {"string.nodes=21", "string.length=0.5", "shape.points[1]=[0.0, -0.5]"});
    CHECK(spec.nodes == 21);
    CHECK(spec.length == 0.5);
    CHECK(spec.shape.points == std::vector<std::vector<double>>{{0.0, 0.0}, {0.0, -0.5}});
    CHECK(spec.where("string.nodes") == "--set string.nodes=21");
    CHECK(spec.where("shape.points[1]") == "--set shape.points[1]=[0.0, -0.5]");
    CHECK(spec.locations.at("shape.points[1]").text == "[0.0, -0.5]");
    CHECK(spec.where("shape.points[0]") == "s.toml:8:11");  // the element written in the file
    CHECK(spec.where("string.density") == "s.toml:3:11");   // keys not overridden keep their place
    // The array shows its effective contents in messages, not the text of the file.
    CHECK(spec.locations.at("shape.points").text == "[ [ 0.0, 0.0 ], [ 0.0, -0.5 ] ]");
    StringScene<2> scene = build_string_scene<2>(spec);
    CHECK(scene.model->chain().num_nodes() == 21);
    CHECK(scene.model->chain().positions()(1, 20) == Approx(-0.5).margin(1e-12));
  }
  SECTION("a bare word is a string; TOML strings, booleans, arrays and inline tables are values") {
    const SceneSpec spec = parse_scene_text(test::kSceneBase, "s.toml",
                                            {"solver.method=erk5", "solver.backend=\"eigen\"", "solver.check_slack=true",
                                             "ends.end={ kind = \"loaded\", force = [0.0, -0.5] }",
                                             "output.fields=[\"energy\", \"stats\"]", "output.formats=[\"csv\"]"});
    CHECK(spec.solver.method == "erk5");
    CHECK(spec.solver.backend == "eigen");
    CHECK(spec.solver.slack == "stop");
    CHECK(spec.end.kind == "loaded");
    CHECK(spec.end.force == std::vector<double>{0.0, -0.5});
    CHECK_FALSE(spec.output.select.nodes);
    CHECK(spec.output.select.energy);
    CHECK_FALSE(spec.output.select.vtk);
  }
  SECTION("an override replaces what the file says of the same thing under another name") {
    // The example scenes write check_slack = true (slack's older form) and nodes; --set solver.slack=allow
    // and --set string.link_length=... were refused as "both say what a slack link does" and "both set
    // the resolution", the file's key against the command line's. The command line is the later one.
    const std::string file = edit(test::kSceneBase, "[stop]", "[solver]\ncheck_slack = true\n\n[stop]");
    const SceneSpec slack = parse_scene_text(file, "s.toml", {"solver.slack=allow"});
    CHECK(slack.solver.slack == "allow");
    CHECK(parse_scene_text(file, "s.toml", {"solver.check_slack=false"}).solver.slack == "ignore");
    const SceneSpec spacing = parse_scene_text(file, "s.toml", {"string.link_length=0.05"});
    CHECK_FALSE(spacing.nodes);
    CHECK(build_string_scene<2>(spacing).model->chain().num_links() == 20);
    // Two overrides that set one thing twice are still refused, at the later one.
    CHECK_THAT(error_of(file, {"solver.slack=allow", "solver.check_slack=true"}),
               Contains("--set solver.check_slack=true: solver.check_slack = true and solver.slack = \"allow\" both say"));
    CHECK_THAT(error_of(file, {"string.nodes=21", "string.link_length=0.05"}),
               Contains("--set string.link_length=0.05: string.link_length = 0.05 and string.nodes = 21 both set the "
                        "resolution"));
  }
  SECTION("a slack policy other than allow set on the command line drops the file's snap_restitution") {
    // cases/scenes/swinging_u.toml writes slack = "allow" and snap_restitution = 0.0: --set solver.slack=stop (to
    // see where the taut model ends) was refused at the file's restitution, "applies only with slack = allow",
    // and so was every point but allow of chainsim sweep --grid solver.slack=stop,warn,allow.
    const std::string file =
        edit(test::kSceneBase, "[stop]", "[solver]\nslack = \"allow\"\nsnap_restitution = 0.5\n\n[stop]");
    CHECK(parse_scene_text(file, "s.toml").solver.snap_restitution == 0.5);
    for (const char* policy : {"stop", "warn", "ignore"}) {
      const SceneSpec spec = parse_scene_text(file, "s.toml", {std::string("solver.slack=") + policy});
      CHECK(spec.solver.slack == policy);
      CHECK(spec.solver.snap_restitution == 0.0);
    }
    CHECK(parse_scene_text(file, "s.toml", {"solver.check_slack=true"}).solver.slack == "stop");
    // allow keeps the file's restitution; a restitution given on the command line with another policy is
    // still refused, as in the file.
    CHECK(parse_scene_text(file, "s.toml", {"solver.slack=allow"}).solver.snap_restitution == 0.5);
    CHECK_THAT(error_of(file, {"solver.slack=stop", "solver.snap_restitution=0.5"}),
               Contains("--set solver.snap_restitution=0.5: solver.snap_restitution = 0.5 applies only with "
                        "solver.slack = \"allow\""));
  }
  SECTION("a section the scene lacks is created: --set effects.drag.coefficient declares drag") {
    const SceneSpec plain = parse_scene_text(test::kSceneBase, "s.toml");
    REQUIRE_FALSE(plain.effects.drag);
    const SceneSpec spec = parse_scene_text(test::kSceneBase, "s.toml", {"effects.drag.coefficient=0.1"});
    REQUIRE(spec.effects.drag);
    CHECK(*spec.effects.drag == 0.1);
    CHECK(spec.where("effects.drag") == "--set effects.drag.coefficient=0.1");
    CHECK(build_string_scene<2>(spec).model->forces().size() == 2);  // gravity and the drag now declared
    CHECK(build_string_scene<2>(plain).model->forces().size() == 1);
  }
  SECTION("an element one past the end of an array of tables is added; an existing one is changed") {
    const SceneSpec spec = parse_scene_text(test::kFallingBase, "s.toml",
                                            {"effects.heap[0].f=0.25", "stop.front[1].front=heap_end", "stop.front[1].s0=0.5"});
    REQUIRE(spec.effects.heaps.size() == 1);
    CHECK(spec.effects.heaps[0].dissipation == 0.25);
    CHECK(spec.effects.heaps[0].side == "end");  // the rest of the heap is the file's
    CHECK(spec.where("effects.heap[0].f") == "--set effects.heap[0].f=0.25");
    CHECK(spec.where("effects.heap[0].side") == "s.toml:15:8");
    REQUIRE(spec.stop.fronts.size() == 2);
    CHECK(spec.stop.fronts[0].s0 == 0.01);
    CHECK(spec.stop.fronts[1].front == "heap_end");
    CHECK(spec.stop.fronts[1].s0 == 0.5);
    CHECK(spec.where("stop.front[1].s0") == "--set stop.front[1].s0=0.5");
    // A whole new array of tables, from nothing: a heap on a scene without fronts.
    const SceneSpec added = parse_scene_text(test::kSceneBase, "s.toml",
                                             {"effects.heap[0]={ side = \"end\", s0 = 0.5, point = [0.0, -0.5] }"});
    REQUIRE(added.effects.heaps.size() == 1);
    CHECK(added.effects.heaps[0].s0 == 0.5);
    CHECK(added.effects.heaps[0].point == std::vector<double>{0.0, -0.5});
  }
}

TEST_CASE("chainsim run --set changes the run as editing the file does, and --json echoes the effective scene",
          "[unit][scene][cli]") {
  const auto dir = temp_dir("run_set");
  const auto scene = dir / "hanging.toml";
  std::ofstream(scene) << test::kSceneBase;
  const auto edited = dir / "edited.toml";
  std::ofstream(edited) << edit(test::kSceneBase, "nodes = 11", "nodes = 21");
  auto run = [&](const std::string& args) {
    const std::string cmd = std::string(CHAINSIM_BINARY) + " run " + args + " > " + (dir / "stdout").string() + " 2> " +
                            (dir / "stderr").string();
    return WEXITSTATUS(std::system(cmd.c_str()));
  };
  REQUIRE(run(scene.string() + " --json --out " + (dir / "a").string()) == 0);
  const auto plain = nlohmann::json::parse(read(dir / "stdout"));
  REQUIRE(run(scene.string() + " --json --set string.nodes=21 --out " + (dir / "b").string()) == 0);
  const auto set = nlohmann::json::parse(read(dir / "stdout"));
  REQUIRE(run(edited.string() + " --json --out " + (dir / "c").string()) == 0);
  const auto file = nlohmann::json::parse(read(dir / "stdout"));
  CHECK(plain["nodes"] == 11);
  CHECK(set["nodes"] == 21);
  // The same run as the edited file: same steps, same energy ledger, same nodes.csv.
  CHECK(set["steps"] == file["steps"]);
  CHECK(set["energy_drift"] == file["energy_drift"]);
  CHECK(set["energy_scale"] == file["energy_scale"]);
  CHECK(read(dir / "b" / "nodes.csv") == read(dir / "c" / "nodes.csv"));
  CHECK(read(dir / "a" / "nodes.csv") != read(dir / "b" / "nodes.csv"));
  CHECK(set["scene_effective"]["string"]["nodes"] == 21);
  CHECK(plain["scene_effective"]["string"]["nodes"] == 11);
  CHECK(set["scene_effective"] == file["scene_effective"]);
  // --set and --t-end together: t_end after the overrides.
  REQUIRE(run(scene.string() + " --json --set stop.t_end=0.05 --t-end 0.1 --out " + (dir / "d").string()) == 0);
  const auto both = nlohmann::json::parse(read(dir / "stdout"));
  CHECK(both["t_end"] == 0.1);
  CHECK(both["scene_effective"]["stop"]["t_end"] == 0.1);
  // A bad override: exit code 2, the message located at the argument.
  CHECK(run(scene.string() + " --set string.nodez=21 --out " + (dir / "e").string()) == 2);
  CHECK_THAT(read(dir / "stderr"), Contains("chainsim: error: --set string.nodez=21: unknown key 'nodez' in [string]"));
  CHECK(run(scene.string() + " --json --set effects.drag.coefficient=-1 --out " + (dir / "e").string()) == 2);
  const auto failed = nlohmann::json::parse(read(dir / "stdout"));
  CHECK(failed["status"] == "failed");
  CHECK(failed["error"] ==
        "--set effects.drag.coefficient=-1: effects.drag.coefficient = -1 is out of range: allowed coefficient >= 0");
}

TEST_CASE("the effective scene as JSON has every key with its default, and written back is the same scene",
          "[unit][scene]") {
  const nlohmann::json j = scene_to_json(parse_scene_text(test::kSceneBase, "s.toml"));
  // The defaults of docs/scenes.md, filled in.
  CHECK(j["model"] == "string");
  CHECK(j["string"]["nodes"] == 11);
  CHECK(j["string"]["closed"] == false);
  CHECK(j["string"]["dimension"] == 2);
  CHECK(j["string"]["link_length"].is_null());
  CHECK(j["velocity"] == nlohmann::json{{"kind", "rest"}});
  CHECK(j["ends"]["end"] == "free");
  CHECK(j["solver"]["method"] == "erk8");
  CHECK(j["solver"]["rtol"] == 1e-8);
  CHECK(j["solver"]["atol"] == 1e-10);
  CHECK(j["solver"]["max_steps"] == 500000);
  CHECK(j["solver"]["stabilization_time"].is_null());  // derived when the model is built
  CHECK(j["solver"]["backend"] == "auto");
  CHECK(j["solver"]["slack"] == "stop");
  CHECK(j["solver"]["max_wall_s"].is_null());  // no limit
  CHECK_FALSE(j["solver"].contains("check_slack"));  // written as slack
  CHECK(j["output"]["interval"] == 0.05);
  CHECK(j["output"]["fields"] == nlohmann::json({"nodes", "tension", "energy", "forces", "stats"}));
  CHECK(j["output"]["formats"] == nlohmann::json({"csv", "vtk"}));
  CHECK(j["effects"] == nlohmann::json{{"gravity", {{"g", {0.0, -9.81}}}}});  // drag not declared: absent
  CHECK(j["shape"]["length_tolerance"] == 1e-6);
  // A circle's default axes in 3D, and a closed string by default.
  const nlohmann::json circle = scene_to_json(parse_scene_text(
      "[string]\ndimension = 3\n[shape]\nkind = \"circle\"\ncenter = [0.0, 0.0, 0.0]\nradius = 0.5\n[stop]\nt_end = 1.0\n",
      "c.toml"));
  CHECK(circle["shape"]["axis1"] == nlohmann::json({1.0, 0.0, 0.0}));
  CHECK(circle["shape"]["axis2"] == nlohmann::json({0.0, 1.0, 0.0}));
  CHECK(circle["string"]["closed"] == true);
  CHECK(circle["string"]["nodes"] == 41);
  CHECK_FALSE(circle["shape"].contains("points"));  // keys of other kinds are left out

  // Every example scene and every test base: the JSON written back as TOML parses into the same scene.
  std::vector<std::pair<std::string, std::string>> scenes = {{"hanging", test::kSceneBase},
                                                             {"falling", test::kFallingBase},
                                                             {"folded", test::kFoldedBase},
                                                             {"sliding", test::kSlidingBase}};
  for (const auto& entry : std::filesystem::directory_iterator(std::filesystem::path(CHAINSIM_SOURCE_DIR) / "cases/scenes"))
    scenes.emplace_back(entry.path().filename().string(), read(entry.path()));
  REQUIRE(scenes.size() >= 15);
  for (const auto& [name, text] : scenes) {
    INFO(name);
    const SceneSpec spec = parse_scene_text(text, name);
    const nlohmann::json effective = scene_to_json(spec);
    nlohmann::json top = effective;
    const std::string model = top["model"];
    top.erase("model");
    const std::string back = "model = \"" + model + "\"\n" + toml_table(top, "");
    INFO(back);
    const SceneSpec again = parse_scene_text(back, name + " (from JSON)");
    CHECK(scene_to_json(again) == effective);
    CHECK(error_of(back, {}) == "");  // and it builds: no key of another kind crept in
  }
}
