// cases/scene.hpp: the minimal TOML scene (parser and builder) and `chainsim run`.
#include <filesystem>
#include <fstream>
#include <sstream>

#include <catch2/catch.hpp>
#include <nlohmann/json.hpp>

#include "cases/run_command.hpp"
#include "cases/scene.hpp"
#include "solver/errors.hpp"

using namespace chainsim;
using Catch::Matchers::Contains;
using Catch::Matchers::WithinRel;

namespace {

const char* kHanging = R"(
[string]
length = 1.0
density = 0.1
nodes = 11

[shape]
kind = "polyline"
points = [[0.0, 0.0], [0.0, -1.0]]

[ends]
start = "fixed"

[gravity]
g = [0.0, -9.81]

[solver]
t_end = 0.2
output_interval = 0.1
)";

std::string with(const std::string& base, const std::string& extra) { return base + extra; }

std::filesystem::path temp_dir(const std::string& name) {
  auto dir = std::filesystem::temp_directory_path() / ("chainsim_test_" + name);
  std::filesystem::remove_all(dir);
  return dir;
}

}  // namespace

TEST_CASE("a scene parses into its spec and builds the model it names", "[unit][scene]") {
  const SceneSpec spec = parse_scene_text(kHanging, "hanging.toml");
  CHECK(spec.dimension == 2);
  CHECK(spec.nodes == 11);
  CHECK(spec.start.kind == "fixed");
  CHECK(spec.end.kind == "free");
  CHECK(spec.gravity == std::vector<double>{0.0, -9.81});
  StringScene<2> scene = build_string_scene<2>(spec);
  const auto& model = *scene.model;
  CHECK(model.chain().num_nodes() == 11);
  CHECK(model.is_prescribed(0));
  CHECK_FALSE(model.is_prescribed(10));
  CHECK(model.forces().size() == 1);  // gravity only: no drag effect was declared
  // Default Baumgarte time: 0.1 min(sqrt(l/g) = 0.319 s, t_end = 0.2 s).
  CHECK_THAT(scene.characteristic_time, WithinRel(0.2, 1e-12));
  CHECK_THAT(model.options().stabilization_time, WithinRel(0.02, 1e-12));
  CHECK(scene.solver.t_end == 0.2);
}

TEST_CASE("unknown keys and sections are rejected with file:line:column and the valid keys", "[unit][scene]") {
  const std::string text = "[string]\nlength = 1.0\nlenght = 2.0\n";
  CHECK_THROWS_WITH(parse_scene_text(text, "s.toml"),
                    Contains("s.toml:3:1") && Contains("'lenght'") && Contains("[string]") &&
                        Contains("valid keys: length, density, nodes, closed, dimension"));
  CHECK_THROWS_WITH(parse_scene_text(with(kHanging, "[graviti]\ng = [0.0, 1.0]\n"), "s.toml"),
                    Contains("unknown section [graviti]") && Contains("gravity"));
  CHECK_THROWS_WITH(parse_scene_text(with(kHanging, "[drag]\ncoef = 1.0\n"), "s.toml"),
                    Contains("'coef'") && Contains("valid keys: coefficient"));
  // A TOML syntax error carries its position too.
  CHECK_THROWS_WITH(parse_scene_text("[string]\nlength = = 1\n", "bad.toml"), Contains("bad.toml:2:"));
}

TEST_CASE("bad values name the key, the value and what is allowed", "[unit][scene]") {
  CHECK_THROWS_WITH(parse_scene_text(with(kHanging, "[velocity]\nkind = \"spin\"\n"), "s.toml"),
                    Contains("velocity.kind = \"spin\"") && Contains("rest, uniform, tangential, nodes"));
  CHECK_THROWS_WITH(parse_scene_text("[string]\nnodes = 1.5\n[shape]\nkind = \"circle\"\n", "s.toml"),
                    Contains("string.nodes must be an integer"));
  CHECK_THROWS_WITH(parse_scene_text("[string]\nnodes = 11\n", "s.toml"), Contains("[shape]"));
  // Vectors must match the dimension.
  const SceneSpec spec = parse_scene_text(
      "[string]\nlength = 1.0\n[shape]\nkind = \"polyline\"\npoints = [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0]]\n", "s.toml");
  CHECK_THROWS_WITH(build_string_scene<2>(spec), Contains("shape.points[0] has 3 components") &&
                                                     Contains("string.dimension = 2"));
  // The shape's length must match the string's.
  const SceneSpec longer = parse_scene_text(
      "[string]\nlength = 1.5\n[shape]\nkind = \"polyline\"\npoints = [[0.0, 0.0], [1.0, 0.0]]\n", "s.toml");
  CHECK_THROWS_WITH(build_string_scene<2>(longer), Contains("1 m long") && Contains("string.length = 1.5 m"));
  // An end kind that needs parameters.
  CHECK_THROWS_WITH(parse_scene_text("[shape]\nkind = \"circle\"\ncenter = [0.0, 0.0]\nradius = 1.0\n"
                                     "[ends]\nend = \"driven\"\n", "s.toml"),
                    Contains("ends.end = \"driven\" needs parameters"));
  // A string pulled straight between two fixed points cannot move: reported before the run.
  const SceneSpec taut = parse_scene_text(
      "[string]\nlength = 1.0\nnodes = 5\n[shape]\nkind = \"polyline\"\npoints = [[0.0, 0.0], [1.0, 0.0]]\n"
      "[ends]\nstart = \"fixed\"\nend = \"fixed\"\n",
      "s.toml");
  StringScene<2> scene = build_string_scene<2>(taut);
  CHECK_THROWS_AS(scene.model->make_consistent(0.0), InputError);
}

TEST_CASE("driven, loaded and closed scenes build, and a closed string has no ends", "[unit][scene]") {
  const SceneSpec closed = parse_scene_text(R"(
[string]
density = 0.1
nodes = 16
dimension = 3
[shape]
kind = "circle"
center = [0.0, 0.0, 1.0]
radius = 0.5
axis1 = [1.0, 0.0, 0.0]
axis2 = [0.0, 0.0, 1.0]
[velocity]
kind = "tangential"
speed = 2.0
)",
                                            "loop.toml");
  StringScene<3> scene = build_string_scene<3>(closed);
  CHECK(scene.model->chain().closed());
  CHECK_THAT(scene.model->chain().length(), WithinRel(3.14159265358979323846, 1e-12));
  const SceneSpec ends = parse_scene_text(
      std::string(R"(
[string]
length = 1.0
nodes = 11
[shape]
kind = "polyline"
points = [[0.0, 0.0], [0.0, -1.0]]
[ends]
start = { kind = "driven", path = "shake", amplitude = [0.05, 0.0], omega = 10.0 }
end = { kind = "loaded", force = [0.0, -1.0], amplitude = [0.5, 0.0], omega = 3.0 }
[drag]
coefficient = 0.5
)"),
      "ends.toml");
  StringScene<2> built = build_string_scene<2>(ends);
  CHECK(built.model->is_prescribed(0));
  CHECK(built.model->forces().size() == 2);  // load + drag, no gravity
  CHECK_THAT(built.characteristic_time, WithinRel(2 * 3.14159265358979323846 / 10.0, 1e-12));
  const SceneSpec bad = parse_scene_text(R"(
[string]
density = 0.1
nodes = 16
[shape]
kind = "circle"
center = [0.0, 0.0]
radius = 0.5
[ends]
start = "fixed"
)",
                                         "bad.toml");
  CHECK_THROWS_WITH(build_string_scene<2>(bad), Contains("closed string has no ends"));
}

TEST_CASE("chainsim run writes every output and prints the JSON summary", "[unit][scene]") {
  const auto dir = temp_dir("run_scene");
  std::filesystem::create_directories(dir);
  const auto scene = dir / "hanging.toml";
  std::ofstream(scene) << kHanging;
  RunCommandOptions options;
  options.scene = scene.string();
  options.out = (dir / "out").string();
  options.json = true;
  std::ostringstream out;
  CHECK(run_scene_command(options, out) == 0);
  const auto j = nlohmann::json::parse(out.str());
  for (const char* key : {"t_end", "steps", "rhs_evals", "wall_s", "energy_drift", "max_constraint_violation", "stats"})
    CHECK(j.contains(key));
  CHECK(j["t_end"] == 0.2);
  for (const char* file : {"nodes.csv", "tension.csv", "energy.csv", "stats.json", "string.pvd",
                           "frames/frame_0000.vtp", "frames/frame_0002.vtp"})
    CHECK(std::filesystem::exists(dir / "out" / file));
  // nodes.csv: 3 output times x 11 nodes, columns t,node,x,y,vx,vy.
  std::ifstream nodes(dir / "out" / "nodes.csv");
  std::string header;
  std::getline(nodes, header);
  CHECK(header == "t,node,x,y,vx,vy");
  int rows = 0;
  for (std::string line; std::getline(nodes, line);) ++rows;
  CHECK(rows == 33);
  // No temporary files left behind.
  for (const auto& entry : std::filesystem::recursive_directory_iterator(dir / "out"))
    CHECK(entry.path().extension() != ".tmp");
}

TEST_CASE("the example scenes run", "[unit][scene]") {
  // Each example scene, shortened to 0.5 s: it parses, builds, runs and closes its ledger.
  for (const char* name : {"hanging_chain", "travelling_loop", "shaken_chain", "damped_catenary"}) {
    const auto file = std::filesystem::path(CHAINSIM_SOURCE_DIR) / "cases" / "scenes" / (std::string(name) + ".toml");
    SceneSpec spec = parse_scene(file);
    spec.solver.t_end = 0.5;
    StringScene<2> scene = build_string_scene<2>(spec);
    StringSolver<2> solver(*scene.model, scene.solver);
    const RunSummary& s = solver.run();
    INFO(name << ": relative energy drift " << s.relative_energy_drift() << ", violation "
              << s.max_constraint_violation);
    CHECK(s.status == "completed");
    /// rtol = 1e-8 in the example scenes: the ledger and the links hold to ~rtol.
    // The example scenes run at rtol 1e-8; measured drift <= 8e-11 and link error <= 1e-9 relative.
    CHECK(s.relative_energy_drift() < 1e-9);
    CHECK(s.max_constraint_violation < 1e-8);
  }
}

TEST_CASE("chainsim run: exit codes and messages from the executable", "[unit][scene][cli]") {
  const auto dir = temp_dir("run_cli");
  std::filesystem::create_directories(dir);
  const auto scene = dir / "typo.toml";
  std::ofstream(scene) << kHanging << "[solver_extra]\n";
  const std::string cmd = std::string(CHAINSIM_BINARY) + " run " + scene.string() + " --out " + (dir / "o").string() +
                          " > " + (dir / "log").string() + " 2>&1";
  const int status = std::system(cmd.c_str());
  CHECK(WEXITSTATUS(status) == 2);
  std::ifstream log(dir / "log");
  std::stringstream text;
  text << log.rdbuf();
  CHECK_THAT(text.str(), Contains("typo.toml:20:2") && Contains("unknown section [solver_extra]"));
}
