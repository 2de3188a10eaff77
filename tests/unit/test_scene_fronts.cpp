// Scenes with shocks (cases/scene/front_scene.hpp) and the model choice (cases/scene/reduced_scene.hpp), checked
// against references that do not use the scene code: the exact quadratures of docs/model.md §4
// (cases/reduced/exact_solutions.hpp), `chainsim compare` on the same problem set up in C++, and the
// closed-form free fall of a tilted chain with f = 1. The table of bad scenes is in
// test_scene_errors.cpp.
#include <cmath>
#include <filesystem>
#include <fstream>
#include <memory>
#include <sstream>

#include <catch2/catch.hpp>
#include <nlohmann/json.hpp>
#include <fmt/format.h>

#include "cases/canonical/canonical_string.hpp"
#include "cases/reduced/exact_solutions.hpp"
#include "cases/scene/reduced_scene.hpp"
#include "cases/cli/run_command.hpp"
#include "mesh/errors.hpp"
#include "solver/string_solver.hpp"
#include "shocks/front_kind.hpp"
#include "solver/tension_system.hpp"
#include "test_scene_support.hpp"

using namespace chainsim;
using test::read;
using test::temp_dir;
using Catch::Matchers::Contains;
using Catch::Matchers::WithinAbs;
using Catch::Matchers::WithinRel;

namespace {

constexpr double kG = 9.81;
const double kT0 = std::sqrt(2.0 / kG);  // t0 = sqrt(2 l / g) for l = 1 m

/// The string solver is exact for the canonical geometries up to its tolerance (the scenes run at
/// rtol 1e-9): measured against the quadratures, t_stop to 5.1e-12 (relative) and η(t) to 2.5e-11
/// (folded_chain); against `chainsim compare`'s string run, t_stop to 8.8e-13. Bounds ten times above.
constexpr double kStopTolerance = 1e-10;
constexpr double kEtaTolerance = 3e-10;
/// Frames interpolated inside the steps carry the error of ARKODE's Hermite interpolant (degree 4 for
/// erk5), not the step's: measured max |η − η*| 6.4e-9 (folded chain, near its stop, where η'
/// grows without bound), 8.0e-10 (falling), 3.0e-11 (sliding), and |η'| to 1.2e-7, 2.0e-8 and
/// 1.2e-10. Bounds three to four times above.
constexpr double kFrameEtaTolerance = 2e-8;
constexpr double kFrameRateTolerance = 5e-7;
/// The reduced ODE (rtol 1e-13) against its quadrature: ~1e-12 (docs/reduced.md).
constexpr double kReducedTolerance = 1e-10;

std::filesystem::path scene_file(const std::string& name) {
  return std::filesystem::path(CHAINSIM_SOURCE_DIR) / "cases" / "scenes" / (name + ".toml");
}

std::string first_line(const std::filesystem::path& file) {
  std::ifstream in(file);
  std::string line;
  std::getline(in, line);
  return line;
}

/// Runs `text` (written to dir/name.toml) with `chainsim run --json`; returns the printed summary.
nlohmann::json run_json(const std::filesystem::path& dir, const std::string& name, const std::string& text) {
  const auto scene = dir / (name + ".toml");
  std::ofstream(scene) << text;
  RunCommandOptions options;
  options.scene = scene.string();
  options.out = (dir / "out").string();
  options.json = true;
  std::ostringstream out;
  REQUIRE(run_scene_command(options, out) == 0);
  return nlohmann::json::parse(out.str());
}

std::string with_model(std::string text, const std::string& model) {
  const std::string from = "model = \"string\"";
  const auto at = text.find(from);
  REQUIRE(at != std::string::npos);
  return text.replace(at, from.size(), "model = \"" + model + "\"");
}

/// A canonical problem as an example scene states it (the literal values of its file).
struct Canonical {
  const char* scene;
  Problem problem;
  double eta0, eps;
  double exact_t_stop;  ///< t_stop/t0 from the quadrature at the stop
  double exact_eta(double xi) const {
    switch (problem) {
      case Problem::kFalling: return exact::falling_eta(0.5, xi, eta0);
      case Problem::kFolded: return exact::folded_eta(0.5, xi, eta0);
      case Problem::kSliding: return exact::sliding_eta(0.5, xi, eta0);
    }
    return NAN;
  }
};

const Canonical kCanonical[] = {
    {"falling_chain", Problem::kFalling, 1.0, 0.01, exact::falling_xi(0.5, 0.01, 1.0)},
    {"folded_chain", Problem::kFolded, 0.0, 0.01, exact::folded_xi(0.5, 0.99, 0.0)},
    {"sliding_chain", Problem::kSliding, 0.2, 0.01, exact::sliding_fall_time(0.5, 0.2)},
};

}  // namespace

TEST_CASE("a scene with fronts parses its heaps, fold, plane and stop events, each located", "[unit][scene]") {
  const SceneSpec falling = parse_scene_text(test::kFallingBase, "f.toml");
  CHECK(falling.model == "string");
  CHECK(falling.has_fronts());
  REQUIRE(falling.effects.heaps.size() == 1);
  const HeapEntry& heap = falling.effects.heaps[0];
  CHECK(heap.side == "end");
  CHECK(heap.front_name() == "heap_end");
  CHECK(heap.s0 == 1.0);
  CHECK(heap.dissipation == 0.5);
  CHECK(heap.point == std::vector<double>{0.0, 0.0});
  CHECK(heap.on_plane);
  REQUIRE(falling.effects.plane);
  CHECK(falling.effects.plane->normal == std::vector<double>{0.0, 1.0});
  CHECK_FALSE(falling.effects.fold);
  REQUIRE(falling.stop.fronts.size() == 1);
  CHECK(falling.stop.fronts[0].front == "heap_end");
  CHECK(falling.stop.fronts[0].s0 == 0.01);
  CHECK(falling.where("model") == "f.toml:1:9");
  CHECK(falling.where("effects.heap[0]") == "f.toml:14:1");
  CHECK(falling.where("effects.heap[0].s0") == "f.toml:16:6");
  CHECK(falling.where("effects.heap[0].side") == "f.toml:15:8");
  CHECK(falling.where("stop.front[0].front") == "f.toml:28:9");

  const SceneSpec folded = parse_scene_text(test::kFoldedBase, "d.toml");
  REQUIRE(folded.effects.fold);
  CHECK(folded.effects.fold->s0 == 0.2);
  CHECK(folded.effects.fold->dissipation == 0.5);
  CHECK(folded.effects.heaps.empty());
  // A scene that writes no model and no fronts is a string scene.
  const SceneSpec plain = parse_scene_text(test::kSceneBase, "p.toml");
  CHECK(plain.model == "string");
  CHECK_FALSE(plain.has_fronts());
}

TEST_CASE("fronts are built only when declared: root functions and fronts in the run statistics", "[unit][scene]") {
  const auto dir = temp_dir("scene_fronts_stats");
  // No heap, no fold: the string solver, no fronts, no root functions, no junction unknowns.
  const nlohmann::json none = run_json(dir, "plain", test::kSceneBase);
  CHECK(none["model"] == "string");
  CHECK(none["fronts"] == nlohmann::json::array());
  CHECK(none["num_fronts"] == 0);
  CHECK(none["root_functions"] == 0);

  // Two root functions per front (take a node in, give one out), one per stop event, and one per fold
  // (it stops the run when the fold opens).
  auto built = [](const std::string& text) {
    const SceneSpec spec = parse_scene_text(text, "s.toml");
    const FrontScene<2> scene = build_front_scene<2>(spec);
    CHECK(scene.description["root_functions"] == scene.model->num_events());
    return scene.description;
  };
  const nlohmann::json falling = built(test::kFallingBase);  // one heap, one stop event
  CHECK(falling["root_functions"] == 3);
  CHECK(falling["num_fronts"] == 1);
  REQUIRE(falling["fronts"].size() == 1);
  CHECK(falling["fronts"][0]["name"] == "heap_end");
  CHECK(falling["fronts"][0]["on_plane"] == true);
  CHECK(falling["fronts"][0]["plane_normal"] == nlohmann::json::array({0.0, 1.0}));
  CHECK(falling["effects"] == nlohmann::json::array({"gravity"}));
  const nlohmann::json sliding = built(test::kSlidingBase);  // one heap, no stop event
  CHECK(sliding["root_functions"] == 2);
  CHECK(sliding["fronts"][0]["name"] == "heap_start");
  CHECK(sliding["fronts"][0]["on_plane"] == false);
  const nlohmann::json folded = built(test::kFoldedBase);  // a fold, its cutoff, and its opening
  CHECK(folded["root_functions"] == 4);
  CHECK(folded["fronts"][0]["kind"] == "fold");
  CHECK(folded["prescribed"] == nlohmann::json::array({"node 0: fixed"}));
  // A chain fed from a shelf through a hole, falling onto a table: two heaps, and a stop event.
  const nlohmann::json two = built(R"(
[string]
length = 1.0
nodes = 21
[shape]
kind = "polyline"
points = [[-0.3, 0.0], [0.0, 0.0], [0.0, -0.5], [0.2, -0.5]]
[effects.gravity]
g = [0.0, -9.81]
[[effects.heap]]
side = "end"
s0 = 0.8
point = [0.0, -0.5]
on_plane = true
[[effects.heap]]
side = "start"
s0 = 0.3
point = [0.0, 0.0]
[effects.plane]
point = [0.0, -0.5]
normal = [0.0, 1.0]
[stop]
t_end = 1.0
[[stop.front]]
front = "heap_start"
s0 = 0.5
)");
  CHECK(two["root_functions"] == 5);
  CHECK(two["num_fronts"] == 2);
  REQUIRE(two["fronts"].size() == 2);
  CHECK(two["fronts"][0]["name"] == "heap_start");
  CHECK(two["fronts"][1]["name"] == "heap_end");
  CHECK(two["stop_events"] == nlohmann::json::array({{{"front", "heap_start"}, {"s0", 0.5}}}));
}

TEST_CASE("the canonical scenes on the string solver agree with chainsim compare and the exact quadratures",
          "[unit][scene]") {
  for (const Canonical& c : kCanonical) {
    CAPTURE(c.scene);
    const SceneSpec spec = parse_scene(scene_file(c.scene));
    // The scene is recognised as the problem its file describes.
    const ReducedSetup rs = match_canonical_problem(spec);
    CHECK(rs.problem == c.problem);
    CHECK(rs.chain.dissipation == 0.5);
    CHECK_THAT(rs.initial_eta(), WithinAbs(c.eta0, 1e-15));
    if (c.problem != Problem::kSliding) CHECK_THAT(rs.eps, WithinAbs(c.eps, 1e-15));

    // The scene's run, and `chainsim compare` on the same problem built in C++ (same nodes, f, ε, η0).
    const RunSummary run = test::run_front_spec(spec);
    REQUIRE(run.status == "stopped");
    StringCaseSetup setup;
    setup.problem = c.problem;
    setup.nodes = 101;
    setup.chain.dissipation = 0.5;
    setup.eps = c.eps;
    setup.eta0 = c.eta0;
    const Comparison compare = compare_with_reduced(setup);
    const double t_stop = run.t_stop / kT0;
    CHECK_THAT(t_stop, WithinRel(compare.summary["t_stop_over_t0"].get<double>(), kStopTolerance));
    CHECK_THAT(t_stop, WithinRel(compare.summary["t_stop_over_t0_reduced"].get<double>(), kStopTolerance));
    CHECK_THAT(t_stop, WithinRel(c.exact_t_stop, kStopTolerance));

    // η(t) at every sample against the quadrature's η(ξ).
    double worst = 0;
    for (const StepSample& s : run.samples) {
      const double eta = c.problem == Problem::kSliding ? 1.0 - s.fronts[0].s0 : s.fronts[0].s0;
      const double xi = std::min(s.t / kT0, c.exact_t_stop);
      worst = std::max(worst, std::abs(eta - c.exact_eta(xi)));
    }
    CHECK(worst < kEtaTolerance);
  }
}

TEST_CASE("frames of a front run far denser than its steps cost few steps and follow the exact motion",
          "[unit][scene]") {
  for (const Canonical& c : kCanonical) {
    CAPTURE(c.scene);
    // The scene's run with one frame (the stop) and with a frame every 2e-4 s, several per step
    // (erk5 at rtol 1e-9 steps about 1e-3 s between crossings).
    auto run = [&](const std::string& interval) {
      FrontScene<2> scene = build_front_scene<2>(parse_scene(scene_file(c.scene), {"output.interval=" + interval}));
      auto solver = std::make_unique<StringSolver<2>>(*scene.model, scene.solver);
      REQUIRE(solver->run().status == "stopped");
      return std::make_pair(std::move(scene), std::move(solver));
    };
    const auto [sparse_scene, sparse] = run("1");
    const auto [dense_scene, dense] = run("2e-4");
    CHECK(sparse->frames().size() == 2);
    // The output times inside a step are interpolated, not stopped at: a frame every 2e-4 s, 6 to 12
    // frames per step, costs at most a few per cent of steps (the frames still stop the first steps
    // and any step shorter than the interval, which starts a slightly different step sequence:
    // measured 293, 248 and 232 steps against 304, 242 and 213, falling, folded and sliding chain).
    // Stopping at every frame took at least one step per frame.
    const long steps_sparse = sparse->summary().stats.steps, steps_dense = dense->summary().stats.steps;
    CHECK(steps_dense <= 1.2 * steps_sparse);
    CHECK(4 * steps_dense < static_cast<long>(dense->frames().size()));
    // Every multiple of the interval below the stop, then the stop; η and |η'| at each frame against
    // the quadrature (η'² from the first integral).
    const auto& frames = dense->frames();
    const double t_stop = dense->summary().t_stop;
    REQUIRE(frames.size() == static_cast<std::size_t>(std::floor(t_stop / 2e-4)) + 2);
    double worst_eta = 0, worst_rate = 0;
    for (std::size_t k = 0; k < frames.size(); ++k) {
      const auto& f = frames[k];
      CHECK(f.t == (k + 1 < frames.size() ? static_cast<double>(k) * 2e-4 : t_stop));
      REQUIRE(!f.fronts.empty());
      const double xi = f.t / kT0;
      const double eta = c.problem == Problem::kSliding ? 1.0 - f.fronts[0].s0 : f.fronts[0].s0;
      const double rate = (c.problem == Problem::kSliding ? -1.0 : 1.0) * f.fronts[0].s0_dot * kT0;
      const double exact_eta = c.exact_eta(std::min(xi, c.exact_t_stop));
      double exact_rate_squared = 0;
      switch (c.problem) {
        case Problem::kFalling: exact_rate_squared = exact::falling_eta_prime_squared(0.5, exact_eta, c.eta0); break;
        case Problem::kFolded: exact_rate_squared = exact::folded_eta_prime_squared(0.5, exact_eta, c.eta0); break;
        case Problem::kSliding: exact_rate_squared = exact::sliding_eta_prime_squared(0.5, exact_eta, c.eta0); break;
      }
      worst_eta = std::max(worst_eta, std::abs(eta - exact_eta));
      worst_rate = std::max(worst_rate, std::abs(std::abs(rate) - std::sqrt(exact_rate_squared)));
    }
    CHECK(worst_eta < kFrameEtaTolerance);
    CHECK(worst_rate < kFrameRateTolerance);
  }
}

TEST_CASE("model = reduced scenes stop when the exact quadratures say, in any direction of gravity", "[unit][scene]") {
  const auto dir = temp_dir("scene_reduced");
  for (const Canonical& c : kCanonical) {
    CAPTURE(c.scene);
    const nlohmann::json j = run_json(dir, c.scene, with_model(read(scene_file(c.scene)), "reduced"));
    CHECK(j["model"] == "reduced");
    CHECK(j["problem"] == to_string(c.problem));
    CHECK_THAT(j["t_stop_over_t0"].get<double>(), WithinRel(c.exact_t_stop, kReducedTolerance));
    CHECK(first_line(dir / "out" / "series.csv").rfind("t,y,ydot", 0) == 0);
    CHECK(nlohmann::json::parse(read(dir / "out" / "stats.json"))["problem"] == to_string(c.problem));
    CHECK_FALSE(std::filesystem::exists(dir / "out" / "nodes.csv"));
  }
  // The falling chain laid along x, gravity along -x, the table x = 0, in 3D: the same problem.
  const std::string sideways = R"(model = "reduced"
[string]
length = 2.0
density = 0.3
nodes = 11
dimension = 3
[shape]
kind = "polyline"
points = [[1.5, 0.0, 1.0], [0.0, 0.0, 1.0], [0.0, 0.5, 1.0]]
[effects.gravity]
g = [-5.0, 0.0, 0.0]
[[effects.heap]]
side = "end"
s0 = 1.5
f = 0.3
point = [0.0, 0.0, 1.0]
on_plane = true
[effects.plane]
point = [0.0, 2.0, 0.0]
normal = [3.0, 0.0, 0.0]
[stop]
t_end = 5.0
[[stop.front]]
front = "heap_end"
s0 = 0.1
)";
  const ReducedSetup rs = match_canonical_problem(parse_scene_text(sideways, "x.toml"));
  CHECK(rs.problem == Problem::kFalling);
  CHECK_THAT(rs.chain.length, WithinRel(2.0, 1e-14));
  CHECK(rs.chain.density == 0.3);
  CHECK(rs.chain.gravity == 5.0);
  CHECK(rs.chain.dissipation == 0.3);
  CHECK_THAT(rs.initial_eta(), WithinRel(0.75, 1e-15));
  CHECK_THAT(rs.eps, WithinRel(0.05, 1e-15));
  CHECK_THAT(rs.t_max_over_t0, WithinRel(5.0 / std::sqrt(2 * 2.0 / 5.0), 1e-15));
  const nlohmann::json j = run_json(dir, "sideways", sideways);
  CHECK_THAT(j["t_stop_over_t0"].get<double>(), WithinRel(exact::falling_xi(0.3, 0.05, 0.75), kReducedTolerance));
  // A folded chain held back by a constant upward end load F = 2 N: F is read from the load.
  std::string held = with_model(test::kFoldedBase, "reduced");
  held.replace(held.find("start = \"fixed\""), 15, "start = \"fixed\"\nend = { kind = \"loaded\", force = [0.0, 2.0] }");
  const ReducedSetup loaded = match_canonical_problem(parse_scene_text(held, "l.toml"));
  CHECK(loaded.problem == Problem::kFolded);
  CHECK(loaded.force == 2.0);
  CHECK_THAT(loaded.initial_eta(), WithinRel(0.2, 1e-15));
}

TEST_CASE("the detection of the canonical problem refuses every other scene with its reason", "[unit][scene]") {
  // The located messages of every refusal are in test_scene_errors.cpp; here, the function itself.
  CHECK(match_canonical_problem(parse_scene_text(test::kFallingBase, "s.toml")).problem == Problem::kFalling);
  CHECK(match_canonical_problem(parse_scene_text(test::kFoldedBase, "s.toml")).problem == Problem::kFolded);
  CHECK(match_canonical_problem(parse_scene_text(test::kSlidingBase, "s.toml")).problem == Problem::kSliding);
  CHECK_THROWS_WITH(match_canonical_problem(parse_scene(scene_file("swinging_sliding_chain"))),
                    Contains("needs a straight string along gravity: the hanging part is tilted 30.0° from it"));
  CHECK_THROWS_WITH(match_canonical_problem(parse_scene(scene_file("tilted_falling_chain"))),
                    Contains("needs a straight string along gravity: the falling part is tilted 25.0° from it"));
  CHECK_THROWS_WITH(match_canonical_problem(parse_scene(scene_file("hanging_chain"))),
                    Contains("needs a fold or a heap"));
  // Gravity pointing up turns the falling chain upside down: its arm is 180° off.
  std::string upside = test::kFallingBase;
  upside.replace(upside.find("g = [0.0, -9.81]"), 16, "g = [0.0, 9.81]");
  CHECK_THROWS_WITH(match_canonical_problem(parse_scene_text(upside, "u.toml")),
                    Contains("needs the table perpendicular to gravity: effects.plane.normal is tilted 180.0° from -g"));
}

TEST_CASE("a tilted falling chain with f = 1 falls freely while its contact slides along the table", "[unit][scene]") {
  // With f = 1 the tension at the table vanishes: every point falls freely, the straight chain keeps
  // its tilt θ, and the length above the table is L(t) = 1 − g t² / (2 cos θ); the contact is where the
  // lowered line meets the table, x = sin θ (1 − L). Neither uses the front-tracking code.
  SceneSpec spec = parse_scene(scene_file("tilted_falling_chain"));
  spec.effects.heaps[0].dissipation = 1.0;
  const RunSummary run = test::run_front_spec(spec);
  REQUIRE(run.status == "stopped");
  const double theta = 25.0 * 3.14159265358979323846 / 180.0;
  double worst_s0 = 0, worst_x = 0;
  for (const StepSample& s : run.samples) {
    const double L = 1.0 - kG * s.t * s.t / (2 * std::cos(theta));
    worst_s0 = std::max(worst_s0, std::abs(s.fronts[0].s0 - L));
    worst_x = std::max(worst_x, std::abs(s.fronts[0].position[0] - std::sin(theta) * (1 - L)));
  }
  // The straight chain is exact on the mesh (docs/shocks.md) and free fall is exact for the
  // integrator: measured 2.4e-15 m in L and 1.7e-15 m in x, round-off. Bound: 1e-12 m.
  CHECK(worst_s0 < 1e-12);
  CHECK(worst_x < 1e-12);
  CHECK(run.samples.back().fronts[0].position[0] > 0.4);  // it slid about 0.42 m along the table
}

TEST_CASE("a fold without a cutoff stops just before the free end, when the exact quadrature says", "[unit][scene]") {
  // The folded chain without [[stop.front]]: the end node's mass is the partial link's, λ l⁺, which vanishes as the
  // fold reaches it, so the steps past it were refused ("node 100 has lost its mass") until the integration stalled
  // (exit 3 at t = 0.63855 s for f = 1, 101 nodes). The run now stops where l⁺ = (kLastPartial − kCrossingHysteresis) h
  // (a fold's crossings lie kCrossingHysteresis h past the node), "the fold has reached the end of the string", at the
  // time the exact quadrature gives there (the straight problem is exact on the mesh, docs/shocks.md). f = 1: the tip
  // falls freely, ξ = √(2(η − η0)); f = 0.5 and 0: the tip's speed diverges at the end (ξ from the quadrature).
  // Measured at rtol 1e-10: 3.9e-16, 1.2e-11, 6.3e-12 relative.
  const std::string text = test::edit(test::kFoldedBase, "[[stop.front]]\nfront = \"fold\"\ns0 = 0.99\n", "");
  const double ell = 1.0, h = ell / 20, eta0 = 0.2, t0 = std::sqrt(2 * ell / kG);
  const double eta = 1 - (kLastPartial - kCrossingHysteresis) * h / ell;
  for (const double f : {1.0, 0.5, 0.0}) {
    CAPTURE(f);
    SceneSpec spec = parse_scene_text(test::edit(text, "f = 0.5", fmt::format("f = {}", f)), "fold_to_the_end.toml");
    spec.solver.rtol = 1e-10;
    spec.solver.atol = 1e-12;
    const RunSummary run = test::run_front_spec(spec);
    REQUIRE(run.status == "stopped");
    CHECK_THAT(run.stop_reason, Contains("the fold has reached the end of the string"));
    const double exact = t0 * exact::folded_xi(f, eta, eta0);
    if (f == 1.0) CHECK_THAT(exact, WithinRel(t0 * std::sqrt(2 * (eta - eta0)), 1e-13));
    std::printf("fold to the free end, f = %.1f: t_stop %.12f s, exact %.12f s, relative error %.2e\n", f, run.t_stop, exact,
                std::abs(run.t_stop - exact) / exact);
    CHECK_THAT(run.t_stop, WithinRel(exact, 1e-9));
  }
}

TEST_CASE("a fold placed within a thousandth of a link of the free end is refused at the start", "[unit][scene]") {
  // Its crossing at the end lies kLastPartial h before the end node (the test above): a fold closer than that starts
  // with that root function ≤ 0, where ARKODE finds no root, and ran on until the end node lost its mass. It is now
  // refused; a fold twice as far from the end starts and stops there at once.
  const double h = 1.0 / 20;
  auto fold_at = [&](double gap) {  // the fold gap·h before the free end: the free arm is gap·h long
    const double s0 = 1.0 - gap * h;
    const std::string text =
        test::edit(test::edit(test::edit(test::kFoldedBase, "[[stop.front]]\nfront = \"fold\"\ns0 = 0.99\n", ""),
                              "points = [[0.0, 0.0], [0.0, -0.2], [0.0, 0.6]]",
                              fmt::format("points = [[0.0, 0.0], [0.0, {:.17g}], [0.0, {:.17g}]]", -s0, -s0 + gap * h)),
                   "s0 = 0.2", fmt::format("s0 = {:.17g}", s0));
    return parse_scene_text(text, "fold_at_the_end.toml");
  };
  CHECK_THROWS_WITH(test::run_front_spec(fold_at(0.5 * kLastPartial)),
                    Contains("the fold front starts at s0 = ") && Contains("past one of its crossings") &&
                        Contains("move s0 by 5e-05 m (a thousandth of a link) or more"));
  const RunSummary run = test::run_front_spec(fold_at(2 * kLastPartial));
  REQUIRE(run.status == "stopped");
  CHECK_THAT(run.stop_reason, Contains("the fold has reached the end of the string"));
  CHECK(run.t_stop < 1e-2);  // 5e-5 m of material at about ¼ g t²: 4.5 ms
}

TEST_CASE("chainsim run on a front scene writes its outputs, stats.json last, and says why it stopped",
          "[unit][scene]") {
  const auto dir = temp_dir("scene_fronts_run");
  const nlohmann::json j = run_json(dir, "falling", test::kFallingBase + "[output]\ninterval = 0.05\n");
  CHECK(j["status"] == "stopped");
  CHECK(j["model"] == "string");
  CHECK(j["stop_reason"] == "the heap_end front reached s0 = 0.01 m");
  CHECK_THAT(j["fronts_final_s0"]["heap_end"].get<double>(), WithinAbs(0.01, 1e-9));
  CHECK(j["t_end"] == 1.0);
  for (const char* key : {"t_stop", "steps", "transfers", "energy_residual", "momentum_residual", "root_functions",
                          "fronts", "effects", "prescribed", "nodes", "dimension", "stabilization_time"})
    CHECK(j.contains(key));
  const auto out = dir / "out";
  // One output writer for every string run: the moving nodes with their velocities, and the
  // tensions of the arcs' links (the fields a plain string writes), plus series.csv.
  CHECK(first_line(out / "nodes.csv") == "t,node,s,x,y,vx,vy");
  CHECK(first_line(out / "series.csv").rfind("t,s0_0,s0dot_0,", 0) == 0);
  CHECK(std::filesystem::exists(out / "string.pvd"));
  CHECK(std::filesystem::exists(out / "frames" / "frame_0000.vtp"));
  CHECK(first_line(out / "tension.csv") == "t,link,s_mid,T");
  CHECK(nlohmann::json::parse(read(out / "stats.json"))["stop_reason"] == j["stop_reason"]);
  for (const auto& entry : std::filesystem::recursive_directory_iterator(out))
    CHECK(entry.path().extension() != ".tmp");
  // The sliding chain stops when its heap is empty.
  CHECK(run_json(dir, "sliding", test::kSlidingBase)["stop_reason"] == "the heap has run empty");
  // A string run in the same directory leaves none of the front run's files behind.
  run_json(dir, "plain", test::kSceneBase);
  CHECK_FALSE(std::filesystem::exists(out / "series.csv"));
  CHECK(std::filesystem::exists(out / "tension.csv"));
}

TEST_CASE("a front run that fails writes its outputs up to the failure, then reports it (exit code 3)",
          "[unit][scene]") {
  // Three steps allowed per output interval: ARKODE gives up early in the fall.
  const auto dir = temp_dir("scene_fronts_fail");
  const auto scene = dir / "fail.toml";
  std::ofstream(scene) << test::kFallingBase << "[solver]\nmax_steps = 3\n";
  RunCommandOptions options;
  options.scene = scene.string();
  options.out = (dir / "out").string();
  options.json = true;
  std::ostringstream out;
  CHECK_THROWS_AS(run_scene_command(options, out), NumericalError);
  const nlohmann::json j = nlohmann::json::parse(out.str());
  CHECK(j["status"] == "failed");
  CHECK(j["exit_code"] == 3);
  CHECK_THAT(j["error"].get<std::string>(), Contains("ARK_TOO_MUCH_WORK"));
  CHECK(j["t_stop"].get<double>() < 0.38);  // before the cutoff
  const nlohmann::json stats = nlohmann::json::parse(read(dir / "out" / "stats.json"));
  CHECK(stats["status"] == "failed");
  CHECK(std::filesystem::exists(dir / "out" / "series.csv"));
}

TEST_CASE("a scene with fronts takes every tension backend, the slack check, the tension field and implicit methods",
          "[unit][scene]") {
  // One discrete string: the options of a plain string work with fronts too. The folded chain
  // released from rest: at t = 0 the fold carries no tension (ṡ0 = 0) and the resting arm hangs
  // statically from the fixed start, so link 0 (midpoint s = h/2) holds the weight of the arm
  // below it, λ g (y0 − h/2) (λ = 1 kg/m, y0 = 0.2 m, h = 0.05 m). The chain stays taut: no slack.
  const auto dir = temp_dir("scene_fronts_options");
  std::vector<double> t_stop;
  for (const char* backend : {"tridiagonal", "klu", "eigen"}) {
    if (std::string(backend) == "klu" && tension_backend_names().size() < 3) continue;  // built without KLU
    INFO("backend " << backend);
    const std::string text = test::kFoldedBase + fmt::format("[solver]\nbackend = \"{}\"\ncheck_slack = true\n"
                                                             "[output]\nfields = [\"nodes\", \"tension\", \"stats\"]\n",
                                                             backend);
    const nlohmann::json j = run_json(dir, "folded", text);
    CHECK(j["status"] == "stopped");
    CHECK(j["tension_backend"] == backend);
    t_stop.push_back(j["t_stop"].get<double>());
    std::ifstream tension(dir / "out" / "tension.csv");
    std::string line;
    std::getline(tension, line);
    REQUIRE(line == "t,link,s_mid,T");
    std::getline(tension, line);  // t = 0, link 0
    double t = 0, link = 0, s_mid = 0, T = 0;
    char comma = 0;
    std::istringstream(line) >> t >> comma >> link >> comma >> s_mid >> comma >> T;
    CHECK(t == 0);
    CHECK(link == 0);
    CHECK_THAT(T, WithinRel(9.81 * (0.2 - 0.025), 1e-9));
  }
  // The backends solve the same system: the runs agree to the integrator's tolerance.
  for (double t : t_stop) CHECK_THAT(t, WithinRel(t_stop.front(), 1e-8));
  // An implicit method (a dense Jacobian, rebuilt at every crossing, where the state changes size)
  // reaches the same stop to its lower order's accuracy, with the ledgers closed.
  const nlohmann::json implicit = run_json(dir, "folded", test::kFoldedBase + "[solver]\nmethod = \"dirk3\"\n");
  CHECK(implicit["status"] == "stopped");
  CHECK_THAT(implicit["t_stop"].get<double>(), WithinRel(t_stop.front(), 1e-6));
  CHECK(implicit["energy_residual"].get<double>() < 1e-6);
  CHECK(implicit["momentum_residual"].get<double>() < 1e-6);
}

TEST_CASE("model = reduced scenes at g = 1e-100 and l = 1e90 run to their t_end (issue #21)", "[unit][scene]") {
  // The scene's t_end = 1 s is 7e-51 t0 at g = 1e-100 and 4e-45 t0 at l = 1e90: the run stalled (exit 3).
  const std::string reduced = with_model(test::kFallingBase, "reduced");
  const std::string weak = test::edit(reduced, "g = [0.0, -9.81]", "g = [0.0, -1e-100]");
  std::string long_chain = test::edit(reduced, "length = 1.0", "length = 1e90");
  long_chain = test::edit(long_chain, "points = [[0.0, 1.0], [0.0, 0.0]]", "points = [[0.0, 1e90], [0.0, 0.0]]");
  long_chain = test::edit(long_chain, "s0 = 1.0", "s0 = 1e90");
  long_chain = test::edit(long_chain, "s0 = 0.01", "s0 = 1e88");
  for (const std::string* text : {&weak, static_cast<const std::string*>(&long_chain)}) {
    const SceneSpec spec = parse_scene_text(*text, "r.toml");
    const ReducedSetup setup = match_canonical_problem(spec);
    // s0 = l as written may exceed the discretized length by round-off: eta0 <= 1 all the same.
    CHECK(setup.initial_eta() <= 1.0);
    CHECK_THAT(setup.initial_eta(), WithinAbs(1.0, 1e-15));
    const ReducedRun run = solve_reduced(setup);
    CHECK(run.summary["stop_reason"] == "t_max");
    CHECK_THAT(run.summary["t_stop"].get<double>(), WithinRel(1.0, 1e-15));
  }
}
