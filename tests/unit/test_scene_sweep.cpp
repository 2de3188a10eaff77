// Sweeps (cases/scene/scene_sweep.hpp) and scenes given as JSON (scene_json.hpp: scene_toml_text).
// The sweep's threads run here under the sanitizers too (the Python tests do not).
#include <atomic>
#include <cmath>
#include <filesystem>

#include <catch2/catch.hpp>
#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "cases/reduced/exact_solutions.hpp"
#include "cases/reduced/reduced_models.hpp"
#include "cases/scene/scene.hpp"
#include "cases/scene/scene_json.hpp"
#include "cases/scene/scene_sweep.hpp"
#include "mesh/errors.hpp"
#include "test_scene_support.hpp"

using namespace chainsim;
using chainsim::test::kFallingBase;
using chainsim::test::kSceneBase;

namespace {
/// 1 m of chain over a sharp peg, 0.6 m and 0.4 m, released at rest (cases/scenes/chain_over_peg.toml on 21 nodes).
const std::string kPeg = "[string]\nlength = 1.0\nnodes = 21\n[shape]\nkind = \"polyline\"\npoints = [[0.0, -0.4], "
                         "[0.0, 0.0], [0.0, -0.6]]\n[effects.gravity]\ng = [0.0, -9.81]\n[[effects.edge]]\n"
                         "point = [0.0, 0.0]\n[solver]\nmethod = \"erk5\"\nrtol = 1e-10\natol = 1e-12\n[stop]\n"
                         "t_end = 2.0\n";
}  // namespace

TEST_CASE("sweep grids: axes, points in order, refused grids", "[unit][sweep]") {
  const SweepAxis a = parse_grid_axis("shape.points=[[0,0],[0,-1]],[[0,0],[1,0]]");
  CHECK(a.key == "shape.points");
  CHECK(a.values == std::vector<std::string>{"[[0,0],[0,-1]]", "[[0,0],[1,0]]"});
  const auto points = sweep_points({parse_grid_axis("f=0,1"), parse_grid_axis("string.nodes=11,21,31")});
  REQUIRE(points.size() == 6);
  CHECK(points[1] == std::vector<std::string>{"f=0", "string.nodes=21"});   // the last axis fastest
  CHECK(points[3] == std::vector<std::string>{"f=1", "string.nodes=11"});
  CHECK_THROWS_AS(parse_grid_axis("f"), InputError);
  CHECK_THROWS_WITH(parse_grid_axis("f=0,,1"), Catch::Contains("empty value"));
  CHECK_THROWS_WITH(sweep_points({parse_grid_axis("f=0"), parse_grid_axis("f=1")}), Catch::Contains("twice"));
  CHECK_THROWS_AS(sweep_points({}), InputError);
}

TEST_CASE("a sweep on two threads gives the rows of one, a bad point is an error row, f names the front",
          "[unit][sweep]") {
  const SweepScene falling{kFallingBase, "falling.toml", {}, std::nullopt};
  const auto points = sweep_points({parse_grid_axis("f=0,1,1.5"), parse_grid_axis("string.nodes=6,11")});
  const std::vector<nlohmann::json> one = run_sweep(falling, points, 1), two = run_sweep(falling, points, 2);
  REQUIRE(one.size() == 6);
  for (std::size_t k = 0; k < one.size(); ++k) {
    nlohmann::json a = one[k], b = two[k];
    for (auto* row : {&a, &b}) {
      row->erase("wall_time_s");
      row->erase("wall_s");
    }
    CHECK(a == b);
  }
  // f = 1.5: refused, located at the override the key f stands for; the sweep went on.
  for (std::size_t k : {4, 5}) {
    CHECK(one[k]["status"] == "error");
    CHECK_THAT(one[k]["error"].get<std::string>(),
               Catch::Contains("--set effects.heap[0].f=1.5") && Catch::Contains("allowed 0 <= f <= 1"));
  }
  // The straight falling chain is exact on any mesh: the stop time is the quadrature's, t0 ξ(ε; f).
  const double t0 = std::sqrt(2 * 1.0 / 9.81);
  for (std::size_t k = 0; k < 4; ++k) {
    const double f = k < 2 ? 0.0 : 1.0;
    CHECK(one[k]["status"] == "stopped");
    CHECK(one[k]["nodes"] == (k % 2 == 0 ? 6 : 11));
    CHECK(one[k]["t_stop"].get<double>() == Approx(t0 * exact::xi(Problem::kFalling, f, 0.01, 1.0)).epsilon(1e-6));
  }
}

TEST_CASE("a sweep point that fails numerically is a row with its error", "[unit][sweep]") {
  const SweepScene hanging{kSceneBase, "hanging.toml", {"solver.max_steps=3"}, 1.0};
  const nlohmann::json row = run_sweep_point(hanging, {"string.nodes=6"});
  CHECK(row["status"] == "failed");
  CHECK_THAT(row["error"].get<std::string>(), Catch::Contains("steps"));
  CHECK(row["t_end"] == 1.0);
  const nlohmann::json bad = run_sweep_point(hanging, {"f=0.5"});  // no front: f names nothing
  CHECK(bad["status"] == "error");
  CHECK_THAT(bad["error"].get<std::string>(), Catch::Contains("the scene has none: write effects.heap[K].f"));
}

TEST_CASE("the sweep key f names an edge's dissipation when the edge is the scene's only front", "[unit][sweep][edge]") {
  // chainsim sweep chain_over_peg.toml --grid f=0,0.5 said "the scene has 0 fronts": an edge was not counted.
  // The peg lifts off where the exact solution says (compare peg), at each f.
  const SweepScene scene{kPeg, "peg.toml", {}, 2.0};
  for (const double f : {0.0, 0.5}) {
    CAPTURE(f);
    const nlohmann::json row = run_sweep_point(scene, {fmt::format("f={}", f)});
    REQUIRE(row["status"] == "stopped");
    CHECK(row["t_stop"].get<double>() ==
          Approx(exact::peg_time(f, exact::peg_lift_off_x(f, 0.6, 1.0, 9.81), 0.6, 1.0, 9.81)).epsilon(1e-6));
  }
}

TEST_CASE("a sweep row holds the run's events and fronts: a peg's lift-off time at each f", "[unit][sweep][edge]") {
  // The summary's events (lists of objects) were left out of the rows, so chainsim sweep chain_over_peg.toml
  // --grid f=... gave the lift-off time only inside the text of stop_reason.
  const SweepScene scene{kPeg, "peg.toml", {}, 2.0};
  const nlohmann::json row = run_sweep_point(scene, {"f=0.5"});
  REQUIRE(row["status"] == "stopped");
  CHECK(row["events[0].kind"] == "lift_off");
  CHECK(row["events[0].front"] == "edge0");
  CHECK(row["events[0].t"].get<double>() ==
        Approx(exact::peg_time(0.5, exact::peg_lift_off_x(0.5, 0.6, 1.0, 9.81), 0.6, 1.0, 9.81)).epsilon(1e-6));
  CHECK(row["events[0].position[1]"] == 0.0);
  CHECK(row["fronts[0].kind"] == "edge");
  CHECK(row["fronts[0].f"] == 0.5);
  CHECK_FALSE(row.contains("effects[0]"));  // lists of names stay out
}

TEST_CASE("a scene given as JSON is the scene of the same TOML", "[unit][sweep]") {
  const nlohmann::json scene = {
      {"string", {{"length", 1.0}, {"density", 0.1}, {"nodes", 11}}},
      {"shape", {{"kind", "polyline"}, {"points", {{0.0, 0.0}, {0.0, -1.0}}}}},
      {"ends", {{"start", "fixed"}}},
      {"effects", {{"gravity", {{"g", {0.0, -9.81}}}}}},
      {"stop", {{"t_end", 0.2}}}};
  const SceneSpec from_json = parse_scene_text(scene_toml_text(scene), "<dict>");
  CHECK(scene_to_json(from_json) == scene_to_json(parse_scene_text(kSceneBase, "<dict>")));
  // arrays of tables, and a value TOML cannot hold
  nlohmann::json falling = scene;
  falling["effects"]["heap"] = {{{"side", "end"}, {"s0", 1.0}, {"f", 0.1}, {"point", {0.0, -1.0}}}};
  CHECK_THAT(scene_toml_text(falling), Catch::Contains("[[effects.heap]]"));
  CHECK_THROWS_WITH(scene_toml_text({{"string", {{"length", nullptr}}}}), Catch::Contains("string.length = null"));
  CHECK_THROWS_AS(scene_toml_text(nlohmann::json::array()), InputError);
}

TEST_CASE("a sweep refuses, before any run, two grid keys that set one scene key (issue #21)", "[unit][sweep]") {
  // `chainsim sweep falling.toml --grid f=0.1 --grid effects.heap[0].f=0.9` ran one point with f = 0.9 and
  // labelled its row f = 0.1 (its t_stop was the f = 0.9 answer).
  const SweepScene falling{kFallingBase, "falling.toml", {}, std::nullopt};
  auto grid = [](std::initializer_list<const char*> axes) {
    std::vector<SweepAxis> out;
    for (const char* a : axes) out.push_back(parse_grid_axis(a));
    return sweep_points(out);
  };
  const auto alias = grid({"f=0.1", "effects.heap[0].f=0.9"});
  CHECK_THROWS_WITH(run_sweep(falling, alias, 1),
                    Catch::Contains("the grid key f and the grid key effects.heap[0].f both set effects.heap[0].f"));
  CHECK_THROWS_AS(check_sweep_points(falling, alias), InputError);
  // Another spelling of an index is the same key.
  CHECK_THROWS_WITH(check_sweep_points(falling, grid({"effects.heap[00].f=0.1", "effects.heap[0].f=0.9"})),
                    Catch::Contains("effects.heap[00].f and the grid key effects.heap[0].f"));
  // stop.t_end on the grid and the sweep's own t_end.
  const SweepScene timed{kFallingBase, "falling.toml", {}, 0.2};
  CHECK_THROWS_WITH(check_sweep_points(timed, grid({"stop.t_end=0.1,0.3"})),
                    Catch::Contains("the grid key stop.t_end and the sweep's --t-end both set stop.t_end"));
  // A point run on its own (the Dask path) is an error row, not a mislabelled run.
  const nlohmann::json row = run_sweep_point(falling, alias[0]);
  CHECK(row["status"] == "error");
  CHECK(!row.contains("t_stop"));
  // Keys that set different scene keys still run, and each row's values are the ones that ran: the
  // alias f and the full key give the same stop time (the quadrature's, t0 ξ(ε; f)).
  const double t0 = std::sqrt(2 * 1.0 / 9.81);
  for (const char* key : {"f", "effects.heap[0].f"}) {
    const auto rows = run_sweep(falling, grid({(std::string(key) + "=0.9").c_str()}), 1);
    REQUIRE(rows[0]["status"] == "stopped");
    CHECK(rows[0]["t_stop"].get<double>() == Approx(t0 * exact::xi(Problem::kFalling, 0.9, 0.01, 1.0)).epsilon(1e-6));
  }
}

TEST_CASE("a sweep point run by another runner (the Python module's that keeps the run) and the points ended counted",
          "[unit][sweep]") {
  const SweepScene falling{kFallingBase, "falling.toml", {}, std::nullopt};
  // The runner gets the point's scene with its overrides applied (f is the front's key), and its summary makes
  // the row as run_point's does.
  std::vector<std::pair<int, double>> seen;
  const nlohmann::json row = run_sweep_point(falling, {"f=0.25", "string.nodes=7"}, [&](const SceneSpec& spec) {
    seen.emplace_back(*spec.nodes, spec.effects.heaps.at(0).dissipation);
    return nlohmann::json{{"status", "stopped"}, {"t_stop", 0.5}, {"integrator", {{"steps", 3}}}};
  });
  REQUIRE(seen.size() == 1);
  CHECK(seen[0] == std::make_pair(7, 0.25));
  CHECK(row["status"] == "stopped");
  CHECK(row["error"] == "");
  CHECK(row["t_stop"] == 0.5);
  CHECK(row["integrator.steps"] == 3);
  // What the runner throws is the row's error, as for run_point.
  const nlohmann::json bad = run_sweep_point(falling, {"f=0.25"}, [](const SceneSpec&) -> nlohmann::json {
    throw InputError("falling.toml: refused here");
  });
  CHECK(bad["status"] == "error");
  CHECK(bad["error"] == "falling.toml: refused here");
  // The counter a progress bar reads: one per point, on any number of threads.
  const auto points = sweep_points({parse_grid_axis("f=0,0.5,1"), parse_grid_axis("string.nodes=6,11")});
  for (int workers : {1, 2}) {
    std::atomic<std::size_t> done{0};
    run_sweep(falling, points, workers, &done);
    CHECK(done.load() == points.size());
  }
}

TEST_CASE("the sweep key f names a touchdown front's dissipation when it is the scene's only front",
          "[unit][sweep][touchdown]") {
  // chainsim sweep chain_drawn_onto_table.toml --grid f=0,0.5,1 said "the scene has 0 fronts": the touchdown front
  // of a surface with f (docs/model.md §10) was not counted (a tester, issue 23). The key is the surface's f.
  SweepScene scene;
  scene.text = read_scene_file(std::filesystem::path(CHAINSIM_SOURCE_DIR) / "cases" / "scenes" /
                             "chain_drawn_onto_table.toml");
  scene.source = "chain_drawn_onto_table.toml";
  CHECK(canonical_sweep_key(scene, "f") == "effects.surface[0].f");
  const nlohmann::json row = run_sweep_point(scene, {"f=0.5", "stop.t_end=0.01"});
  CHECK(row["status"] == "completed");
  CHECK(row["fronts[0].f"] == 0.5);
}
