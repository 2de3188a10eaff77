// cases/scene/scene.hpp: the TOML scene (parser and builder), the effects it builds, and `chainsim run`.
// The table of bad scenes and their messages is in test_scene_errors.cpp.
#include <cmath>
#include <filesystem>
#include <fstream>
#include <sstream>

#include <catch2/catch.hpp>
#include <nlohmann/json.hpp>

#include "cases/cli/run_command.hpp"
#include "cases/scene/scene.hpp"
#include "mesh/errors.hpp"
#include "test_scene_support.hpp"

using namespace chainsim;
using test::read;
using test::temp_dir;
using Catch::Matchers::Contains;
using Catch::Matchers::WithinAbs;
using Catch::Matchers::WithinRel;

namespace {

// The shared hanging chain, with two frames.
const std::string kHanging = test::kSceneBase + "\n[output]\ninterval = 0.1\n";

/// Builds a parsed scene in its own dimension and runs it; returns the run's summary.
template <int dim>
RunSummary run_in(const SceneSpec& spec) {
  StringScene<dim> scene = build_string_scene<dim>(spec);
  StringSolver<dim> solver(*scene.model, scene.solver);
  return solver.run();
}
RunSummary run_spec(const SceneSpec& spec) { return spec.dimension == 3 ? run_in<3>(spec) : run_in<2>(spec); }
RunSummary run_text(const std::string& text) { return run_spec(parse_scene_text(text, "s.toml")); }

}  // namespace

TEST_CASE("a scene parses into its spec and builds the model it names", "[unit][scene]") {
  const SceneSpec spec = parse_scene_text(kHanging, "hanging.toml");
  CHECK(spec.dimension == 2);
  CHECK(spec.nodes == 11);
  CHECK(spec.start.kind == "fixed");
  CHECK(spec.end.kind == "free");
  REQUIRE(spec.effects.gravity);
  CHECK(*spec.effects.gravity == std::vector<double>{0.0, -9.81});
  CHECK_FALSE(spec.effects.drag);
  CHECK(spec.stop.t_end == 0.2);
  // Every key read is located; an absent key falls back to its section, then to the file.
  CHECK(spec.where("string.nodes") == "hanging.toml:4:9");
  CHECK(spec.locations.at("shape.points[1]").text == "[0.0, -1.0]");
  CHECK(spec.where("effects.gravity.g") == "hanging.toml:14:5");
  CHECK(spec.where("ends.end") == "hanging.toml:10:1");
  CHECK(spec.where("velocity.kind") == "hanging.toml:1:1");
  StringScene<2> scene = build_string_scene<2>(spec);
  const auto& model = *scene.model;
  CHECK(model.chain().num_nodes() == 11);
  CHECK(model.is_prescribed(0));
  CHECK_FALSE(model.is_prescribed(10));
  CHECK(model.forces().size() == 1);  // gravity only: no drag effect was declared
  // Default Baumgarte time: 0.1 sqrt(l/g) = 0.0319 s (gravity sets the time scale; t_end = 0.2 s is
  // the run's length, no physical scale).
  CHECK_THAT(scene.characteristic_time, WithinRel(std::sqrt(1.0 / 9.81), 1e-12));
  CHECK_THAT(model.options().stabilization_time, WithinRel(0.1 * std::sqrt(1.0 / 9.81), 1e-12));
  CHECK(scene.solver.t_end == 0.2);
  CHECK(scene.solver.output_interval == 0.1);
}

TEST_CASE("string.link_length sets the number of links from the length", "[unit][scene]") {
  const std::string text = R"(
[string]
length = 2.0
link_length = 0.05
[shape]
kind = "polyline"
points = [[0.0, 0.0], [2.0, 0.0]]
[stop]
t_end = 1.0
)";
  const StringScene<2> scene = build_string_scene<2>(parse_scene_text(text, "s.toml"));
  CHECK(scene.model->chain().num_links() == 40);
  CHECK_THAT(scene.model->chain().link_length(0), WithinRel(0.05, 1e-12));
}

TEST_CASE("shape.corner_radius rounds the polyline's corners and the string takes the rounded length",
          "[unit][scene]") {
  // The U of docs/scenes.md: two fillets of 0.02 m meeting in the middle of the 0.04 m bottom, a
  // semicircle around (0.02, -0.28). No string.length: the string takes the shape's length.
  const SceneSpec spec = parse_scene_text(R"(
[string]
link_length = 0.005
[shape]
kind = "points"
points = [[0.0, 0.0], [0.0, -0.3], [0.04, -0.3], [0.04, 0.377]]
corner_radius = 0.02
[ends]
start = "fixed"
[effects.gravity]
g = [0.0, -9.81]
[stop]
t_end = 0.05
)",
                                          "u.toml");
  REQUIRE(spec.shape.corner_radius);
  CHECK(*spec.shape.corner_radius == 0.02);
  const StringScene<2> scene = build_string_scene<2>(spec);
  const Chain<2>& chain = scene.model->chain();
  const double length = 0.3 + 0.04 + 0.677 - 2 * (2 * 0.02 - 0.02 * kPi / 2);
  CHECK_THAT(chain.length(), WithinRel(length, 1e-12));
  CHECK(chain.num_links() == 200);
  // The nodes on the bottom (s in [0.28, 0.28 + 0.02 pi]) lie on the semicircle, up to the projection
  // onto the links, which pushes them out by h^2 / (24 r) = 5.2e-5 m so that chords are h long
  // (measured at most 5.5e-5 m).
  const Vec<2> center(0.02, -0.28);
  for (int i = 0; i < chain.num_nodes(); ++i) {
    const double s = length * i / chain.num_links();
    if (s < 0.28 || s > 0.28 + 0.02 * kPi) continue;
    CAPTURE(i, s);
    CHECK_THAT((chain.positions().col(i) - center).norm(), WithinAbs(0.02, 1e-4));
  }
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
[stop]
t_end = 1.0
)",
                                            "loop.toml");
  StringScene<3> scene = build_string_scene<3>(closed);
  CHECK(scene.model->chain().closed());
  CHECK_THAT(scene.model->chain().length(), WithinRel(3.14159265358979323846, 1e-12));
  const SceneSpec ends = parse_scene_text(R"(
[string]
length = 1.0
nodes = 11
[shape]
kind = "polyline"
points = [[0.0, 0.0], [0.0, -1.0]]
[ends]
start = { kind = "driven", path = "shake", amplitude = [0.05, 0.0], omega = 10.0 }
end = { kind = "loaded", force = [0.0, -1.0], amplitude = [0.5, 0.0], omega = 3.0 }
[effects.drag]
coefficient = 0.5
[stop]
t_end = 1.0
)",
                                          "ends.toml");
  StringScene<2> built = build_string_scene<2>(ends);
  CHECK(built.model->is_prescribed(0));
  CHECK(built.model->forces().size() == 2);  // drag + load, no gravity
  CHECK_THAT(built.characteristic_time, WithinRel(2 * 3.14159265358979323846 / 10.0, 1e-12));
}

TEST_CASE("velocity kind = rotation gives every mesh a rigid rotation, so --set string.nodes refines it",
          "[unit][scene]") {
  // cases/scenes/thrown_chain.toml wrote its rotation node by node (kind = "nodes"), so --set string.nodes=41 was
  // refused ("velocity.values has 21 entries but the string has 41 nodes"): no mesh study of the thrown chain.
  const std::string thrown = R"([string]
length = 1.0
nodes = 21
[shape]
kind = "polyline"
points = [[0.0, 0.0], [1.0, 0.0]]
[velocity]
kind = "rotation"
omega = 7.0
center = [0.0, 0.0]
[ends]
start = "fixed"
[stop]
t_end = 1.0
)";
  for (const int nodes : {21, 41, 81}) {
    const SceneSpec spec = parse_scene_text(thrown, "thrown.toml", {"string.nodes=" + std::to_string(nodes)});
    const StringScene<2> scene = build_string_scene<2>(spec);
    const auto& v = scene.model->chain().velocities();
    REQUIRE(v.cols() == nodes);
    for (int i = 0; i < nodes; ++i) {  // v = ω s upward at s = i h: compatible with the links, kept as given
      CHECK_THAT(v(0, i), WithinAbs(0.0, 1e-14));
      CHECK_THAT(v(1, i), WithinAbs(7.0 * i / (nodes - 1), 1e-13));
    }
  }
  // 3D, a straight string turned about a point off it: ω × (x − c) is normal to ω and to x − c, and
  // |v| = |ω| |x − c| sin of their angle.
  const std::string line = R"([string]
nodes = 24
dimension = 3
[shape]
kind = "polyline"
points = [[0.0, 0.0, 0.0], [0.3, 0.4, 1.2]]
[velocity]
kind = "rotation"
omega = [1.0, -2.0, 3.0]
center = [0.1, 0.2, 0.3]
[stop]
t_end = 1.0
)";
  const StringScene<3> scene = build_string_scene<3>(parse_scene_text(line, "line.toml"));
  const Eigen::Vector3d omega(1.0, -2.0, 3.0), center(0.1, 0.2, 0.3);
  for (int i = 0; i < 24; ++i) {
    const Eigen::Vector3d r = scene.model->chain().positions().col(i) - center;
    const Eigen::Vector3d vi = scene.model->chain().velocities().col(i);
    CHECK_THAT(vi.dot(omega), WithinAbs(0.0, 1e-13));
    CHECK_THAT(vi.dot(r), WithinAbs(0.0, 1e-13));
    const double sine = std::sqrt(1 - std::pow(omega.dot(r) / (omega.norm() * r.norm()), 2));
    CHECK_THAT(vi.norm(), WithinRel(omega.norm() * r.norm() * sine, 1e-12));
  }
  // Refused before the run, located: a vector omega in 2D, no center, omega on another kind.
  auto error = [&](const std::vector<std::string>& overrides) {
    try {
      build_string_scene<2>(parse_scene_text(thrown, "thrown.toml", overrides));
    } catch (const InputError& e) {
      return std::string(e.what());
    }
    return std::string("no error");
  };
  CHECK(error({"velocity.omega=[0.0, 0.0, 7.0]"}) ==
        "--set velocity.omega=[0.0, 0.0, 7.0]: velocity.omega = [0.0, 0.0, 7.0] has 3 components but "
        "string.dimension = 2: allowed a number (rad/s about the out-of-plane axis)");
  CHECK(error({"velocity={ kind = \"rotation\", omega = 1.0 }"}) ==
        "--set velocity={ kind = \"rotation\", omega = 1.0 }: [velocity] needs center (m, the point the string turns "
        "about, for kind = \"rotation\")");
  CHECK_THAT(error({"velocity.kind=uniform", "velocity.value=[0.0, 1.0]"}),
             Contains("velocity.omega") && Contains("kind = \"uniform\""));
}

TEST_CASE("effects a scene does not declare are not built, as the run statistics show", "[unit][scene]") {
  // A string at rest in free space: no effects at all.
  const std::string bare = R"(
[string]
nodes = 9
[shape]
kind = "polyline"
points = [[0.0, 0.0], [1.0, 0.0]]
[output]
interval = 0.1
[stop]
t_end = 0.1
)";
  const RunSummary none = run_text(bare);
  CHECK(none.effects.empty());
  CHECK(none.prescribed.empty());
  CHECK(none.root_functions == 0);
  CHECK(none.tension_unknowns == 8);
  CHECK(none.links == 8);
  CHECK(none.dimension == 2);
  CHECK(none.tension_backend == "tridiagonal");
  CHECK(none.stop_reason == "t_end");

  // Each declared effect is built, even at zero strength (declared means built), and only those.
  const RunSummary gravity = run_text(bare + "[effects.gravity]\ng = [0.0, -9.81]\n[ends]\nstart = \"fixed\"\n");
  CHECK(gravity.effects == std::vector<std::string>{"gravity"});
  CHECK(gravity.prescribed == std::vector<std::string>{"node 0: fixed"});
  const RunSummary zero = run_text(bare + "[effects.drag]\ncoefficient = 0.0\n[ends]\nend = { kind = \"loaded\", force = [0.0, 0.0] }\n");
  CHECK(zero.effects == std::vector<std::string>{"drag", "load on node 8"});
  CHECK(zero.root_functions == 0);

  // A 3D scene runs the 3D instantiation, with the same (absent) machinery.
  const RunSummary three = run_text(R"(
[string]
nodes = 9
dimension = 3
[shape]
kind = "polyline"
points = [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0]]
[effects.gravity]
g = [0.0, 0.0, -9.81]
[output]
interval = 0.1
[stop]
t_end = 0.1
)");
  CHECK(three.dimension == 3);
  CHECK(three.effects == std::vector<std::string>{"gravity"});
  CHECK(three.root_functions == 0);
}

TEST_CASE("the example scenes parse, run and close their energy ledger", "[unit][scene]") {
  // Every scene in cases/scenes/, shortened to at most 1 s of simulated time, on the model it asks for.
  int count = 0, with_fronts = 0;
  for (const auto& entry : std::filesystem::directory_iterator(std::filesystem::path(CHAINSIM_SOURCE_DIR) / "cases" / "scenes")) {
    if (entry.path().extension() != ".toml") continue;
    ++count;
    SceneSpec spec = parse_scene(entry.path());
    spec.stop.t_end = std::min(spec.stop.t_end, 1.0);
    CHECK(spec.model == "string");
    if (spec.has_fronts()) {
      ++with_fronts;
      const RunSummary run = test::run_front_spec(spec);
      INFO(entry.path().filename().string() << ": " << run.stop_reason << run.error << ", relative energy residual "
                                            << run.relative_energy_residual() << ", momentum "
                                            << run.relative_momentum_residual() << ", violation " << run.max_constraint_violation);
      // Each front scene ends on its own (a cutoff, or the heap running empty) within 1 s.
      CHECK(run.status == "stopped");
      // Measured relative ledgers: energy <= 2.9e-9 for the straight motions (tilted_falling_chain, at
      // rtol 1e-8) and 1.2e-5 for the swinging hanging part (first order in h, docs/shocks.md);
      // momentum <= 1.6e-9; links <= 2.1e-10. The bounds sit about ten times above.
      CHECK(run.relative_energy_residual() < 2e-4);
      CHECK(run.relative_momentum_residual() < 2e-8);
      CHECK(run.max_constraint_violation < 3e-9);
      continue;
    }
    const RunSummary s = run_spec(spec);
    INFO(entry.path().filename().string() << ": relative energy drift " << s.relative_energy_drift() << ", violation "
                                          << s.max_constraint_violation);
    CHECK(s.status == "completed");
    if (spec.solver.slack == "allow") {
      // Unilateral links (docs/model.md §9): two root functions (the snaps, the releases), W_snap and W_links booked.
      // Measured relative drift 1.9e-9 (thrown_chain), 2.1e-10 (swinging_u), 3.8e-11 (pendulum_whip;
      // 1.9e-7 and 4.4e-8 before W_links booked the released links that came back), momentum ledger
      // <= 1e-14.
      // With obstacles (chain_landing_at_angle) the contact module's two root functions come first.
      CHECK(s.root_functions == (spec.has_obstacles() ? 4 : 2));
      CHECK(s.relative_energy_drift() < 2e-8);
      CHECK(s.relative_momentum_residual() < 1e-12);
      continue;
    }
    if (spec.has_obstacles()) {
      // Contact along arcs (docs/model.md §10): two root functions (landing, lift-off), W_impacts booked;
      // with friction two more (stop, slip), W_friction booked. Measured relative drift 1.3e-10
      // (atwood_pulley), 9e-17 (chain_landing_on_table), 3.3e-11 (atwood_rough_pulley); momentum <= 3e-15.
      bool rough = false;
      for (const SurfaceEntry& e : spec.effects.surfaces) rough = rough || e.mu > 0;
      for (const CylinderEntry& e : spec.effects.cylinders) rough = rough || e.mu > 0;
      CHECK(s.root_functions == (rough ? 4 : 2));
      CHECK(s.relative_energy_drift() < 2e-9);
      CHECK(s.relative_momentum_residual() < 1e-12);
      CHECK(s.max_constraint_violation < 1e-8);
      continue;
    }
    CHECK(s.root_functions == 0);
    // The example scenes run at rtol 1e-8; measured relative drift <= 1.2e-10 (whip_crack) and link
    // error <= 3.7e-9 (whip_crack): the bounds sit about ten times above.
    CHECK(s.relative_energy_drift() < 1e-9);
    CHECK(s.max_constraint_violation < 1e-8);
  }
  CHECK(count >= 11);
  CHECK(with_fronts >= 5);
}

TEST_CASE("every example scene is named in docs/scenes.md, and every figure it shows exists", "[unit][scene]") {
  const std::filesystem::path source(CHAINSIM_SOURCE_DIR);
  const std::string doc = read(source / "docs" / "scenes.md");
  int scenes = 0;
  for (const auto& entry : std::filesystem::directory_iterator(source / "cases" / "scenes")) {
    if (entry.path().extension() != ".toml") continue;
    ++scenes;
    INFO(entry.path().filename().string() << " is not named in docs/scenes.md");
    CHECK(doc.find(entry.path().filename().string()) != std::string::npos);
  }
  CHECK(scenes >= 11);
  // Each image and link into figures/: "](figures/NAME)".
  int figures = 0;
  for (std::size_t at = doc.find("](figures/"); at != std::string::npos; at = doc.find("](figures/", at + 1)) {
    const std::size_t start = at + 2, end = doc.find(')', start);
    REQUIRE(end != std::string::npos);
    const std::string file = doc.substr(start, end - start);
    INFO("docs/scenes.md shows docs/" << file);
    CHECK(std::filesystem::exists(source / "docs" / file));
    ++figures;
  }
  CHECK(figures >= 10);
}

TEST_CASE("chainsim run writes every output and prints the JSON summary", "[unit][scene]") {
  const auto dir = temp_dir("run_scene");
  const auto scene = dir / "hanging.toml";
  std::ofstream(scene) << kHanging;
  RunCommandOptions options;
  options.scene = scene.string();
  options.out = (dir / "out").string();
  options.json = true;
  std::ostringstream out;
  CHECK(run_scene_command(options, out) == 0);
  const auto j = nlohmann::json::parse(out.str());
  for (const char* key : {"t_end", "steps", "rhs_evals", "wall_s", "energy_drift", "max_constraint_violation", "stats",
                          "effects", "root_functions", "tension_unknowns", "dimension"})
    CHECK(j.contains(key));
  CHECK(j["status"] == "completed");
  CHECK(j["t_end"] == 0.2);
  CHECK(j["effects"] == nlohmann::json::array({"gravity"}));
  CHECK(j["root_functions"] == 0);
  for (const char* file : {"nodes.csv", "tension.csv", "energy.csv", "stats.json", "string.pvd",
                           "frames/frame_0000.vtp", "frames/frame_0002.vtp"})
    CHECK(std::filesystem::exists(dir / "out" / file));
  CHECK(nlohmann::json::parse(read(dir / "out" / "stats.json"))["effects"] == j["effects"]);
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

  // The command line's end time replaces the scene's.
  options.t_end = 0.1;
  std::ostringstream shorter;
  CHECK(run_scene_command(options, shorter) == 0);
  CHECK(nlohmann::json::parse(shorter.str())["t_end"] == 0.1);
}

TEST_CASE("output fields and formats select the files, and no file of an earlier run survives", "[unit][scene]") {
  const auto dir = temp_dir("run_select");
  RunCommandOptions options;
  options.scene = (dir / "full.toml").string();
  options.out = (dir / "out").string();
  std::ofstream(options.scene) << kHanging;
  std::ostringstream out;
  REQUIRE(run_scene_command(options, out) == 0);
  REQUIRE(std::filesystem::exists(dir / "out" / "frames"));
  // Second run in the same directory: energy and stats only, CSV only.
  std::string selective = kHanging;
  const std::string output = "[output]\ninterval = 0.1\n";
  selective.replace(selective.find(output), output.size(), output + "fields = [\"energy\", \"stats\"]\nformats = [\"csv\"]\n");
  options.scene = (dir / "select.toml").string();
  std::ofstream(options.scene) << selective;
  REQUIRE(run_scene_command(options, out) == 0);
  std::vector<std::string> files;
  for (const auto& entry : std::filesystem::directory_iterator(dir / "out")) files.push_back(entry.path().filename().string());
  std::sort(files.begin(), files.end());
  CHECK(files == std::vector<std::string>{"energy.csv", "stats.json"});
}

TEST_CASE("chainsim run: exit codes, JSON on failure and the output directory check", "[unit][scene][cli]") {
  const auto dir = temp_dir("run_cli");
  auto run = [&](const std::string& args) {
    const std::string cmd = std::string(CHAINSIM_BINARY) + " run " + args + " > " + (dir / "stdout").string() + " 2> " +
                            (dir / "stderr").string();
    const int status = std::system(cmd.c_str());
    return WEXITSTATUS(status);
  };
  // A bad scene: exit 2, the located message on stderr, and with --json a failed status on stdout.
  const auto typo = dir / "typo.toml";
  std::ofstream(typo) << kHanging << "[solver_extra]\n";
  CHECK(run(typo.string() + " --out " + (dir / "o").string()) == 2);
  CHECK_THAT(read(dir / "stderr"), Contains("typo.toml:21:2: unknown section [solver_extra]"));
  CHECK(run(typo.string() + " --json --out " + (dir / "o").string()) == 2);
  const auto failed = nlohmann::json::parse(read(dir / "stdout"));
  CHECK(failed["status"] == "failed");
  CHECK(failed["exit_code"] == 2);
  CHECK_THAT(failed["error"].get<std::string>(), Contains("typo.toml:21:2: unknown section [solver_extra]"));
  // An output directory that cannot be written is refused before the run (root may write almost
  // anywhere, but not into /proc).
  const auto good = dir / "good.toml";
  std::ofstream(good) << kHanging;
  CHECK(run(good.string() + " --json --out /proc") == 2);
  const auto unwritable = nlohmann::json::parse(read(dir / "stdout"));
  CHECK(unwritable["status"] == "failed");
  CHECK_THAT(unwritable["error"].get<std::string>(), Contains("--out = '/proc' is not writable"));
  // A good run with --t-end from the command line.
  CHECK(run(good.string() + " --json --t-end 0.1 --out " + (dir / "o").string()) == 0);
  CHECK(nlohmann::json::parse(read(dir / "stdout"))["t_end"] == 0.1);
  CHECK(run(good.string() + " --t-end -1 --out " + (dir / "o").string()) == 2);
  CHECK_THAT(read(dir / "stderr"), Contains("--t-end = -1 is out of range: allowed t_end > 0"));
}
