// cases/scene/scene_parts.cpp: the default Baumgarte time follows the physics (gravity, speeds, drivers),
// not the length of the run. A very short run (t_end = 1e-9 s) of the example scenes starts with the
// tensions the discrete equations give in closed form, and reports no false slack.
#include <cmath>
#include <filesystem>
#include <string>

#include <catch2/catch.hpp>

#include "cases/scene/scene.hpp"
#include "test_scene_support.hpp"

using namespace chainsim;
using Catch::Matchers::WithinAbs;
using Catch::Matchers::WithinRel;

namespace {

SceneSpec example(const std::string& name, const std::vector<std::string>& overrides) {
  return parse_scene(std::filesystem::path(CHAINSIM_SOURCE_DIR) / "cases/scenes" / name, overrides);
}

/// The unit vector from node a to node b.
Vec<2> direction(const Points<2>& x, int a, int b) { return (x.col(b) - x.col(a)).normalized(); }

}  // namespace

TEST_CASE("a short run of the damped catenary starts with the exact tensions of the V at rest", "[unit][scene]") {
  // The V: two straight legs of n = 20 links (h = 0.025 m) from fixed ends down to the corner node.
  // At rest the tension equation is e_j·(a_{j+1} − a_j) = 0 with a_i = g + (T_i e_i − T_{i−1} e_{i−1})/m.
  // Along a leg the tangential accelerations are equal and vanish at the fixed end, so
  // T_{j−1} − T_j = m g·t_L (m = λh); at the corner t_L·a_c = 0 with T_{n−1} = T_n = T_c (symmetry):
  //   T_c = m g·t_L / (1 − t_L·t_R),   T_j = T_c + (n − 1 − j) m g·t_L  (j < n; mirrored for j >= n).
  const SceneSpec spec = example("damped_catenary.toml", {"stop.t_end=1e-9"});
  StringScene<2> scene = build_string_scene<2>(spec);
  // The time scale is gravity's, whatever t_end: 0.1 sqrt(ℓ/g).
  CHECK_THAT(scene.model->options().stabilization_time, WithinRel(0.1 * std::sqrt(1.0 / 9.81), 1e-12));
  auto& model = *scene.model;
  const Points<2>& x = model.chain().positions();
  const int links = model.chain().num_links();
  REQUIRE(links == 40);
  const int n = links / 2;
  const Vec<2> t_left = direction(x, 0, n), t_right = direction(x, n, links);
  const Vec<2> g(0.0, -9.81);
  const double m = 0.1 * 0.025;
  REQUIRE(model.chain().masses()(1) == Approx(m).epsilon(1e-14));
  const double gt = g.dot(t_left);
  const double corner = m * gt / (1 - t_left.dot(t_right));
  const Eigen::VectorXd tension = model.snapshot(0.0, model.state_from_chain()).tension;
  for (int j = 0; j < links; ++j) {
    const int from_end = j < n ? n - 1 - j : j - n;  // links between j and the corner
    INFO("link " << j);
    CHECK_THAT(tension(j), WithinAbs(corner + from_end * m * gt, 1e-12));
  }
  // 0.0204 N at the corner, 0.3000 N at the ends (the short run used to give -155 to -12 N).
  CHECK_THAT(tension(n), WithinRel(0.0204375, 1e-9));
  CHECK_THAT(tension(0), WithinRel(0.3000225, 1e-9));
  // And the short run completes.
  StringSolver<2> solver(model, scene.solver);
  CHECK(solver.run().status == "completed");
}

TEST_CASE("a short run of the hanging chain starts with the static tension and reports no slack", "[unit][scene]") {
  // A straight chain at rest from a fixed top, its end free: the tangential accelerations vanish, so
  // T_j = T_{j+1} + m g·t and, at the free end (mass m/2), T_{N−1} = (m/2) g·t: at the link midpoints
  // T_j = λ g·t (ℓ − s_mid,j), the tension of the continuous chain λ g cos θ (ℓ − s).
  const SceneSpec spec = example("hanging_chain.toml", {"stop.t_end=1e-9"});
  REQUIRE(spec.solver.slack == "stop");
  StringScene<2> scene = build_string_scene<2>(spec);
  CHECK_THAT(scene.model->options().stabilization_time, WithinRel(0.1 * std::sqrt(1.0 / 9.81), 1e-9));
  auto& model = *scene.model;
  const Chain<2>& chain = model.chain();
  const int links = chain.num_links();
  const double gt = Vec<2>(0.0, -9.81).dot(direction(chain.positions(), 0, links));
  CHECK_THAT(gt, WithinRel(9.81 * std::cos(0.05), 1e-4));  // the scene's 0.05 rad tilt
  const double length = chain.link_midpoint(links - 1) + 0.5 * chain.link_length(links - 1);
  const Eigen::VectorXd tension = model.snapshot(0.0, model.state_from_chain()).tension;
  for (int j = 0; j < links; ++j) {
    INFO("link " << j);
    CHECK_THAT(tension(j), WithinAbs(0.1 * gt * (length - chain.link_midpoint(j)), 1e-12));
  }
  // The run checks for slack (check_slack = true) and used to stop at t = 0 with T = -311 N.
  StringSolver<2> solver(model, scene.solver);
  CHECK(solver.run().status == "completed");
}

TEST_CASE("the default Baumgarte time is set by gravity, speeds and drivers, and by t_end only without them", "[unit][scene]") {
  auto tau = [](const std::string& text, const std::vector<std::string>& overrides = {}) {
    return build_string_scene<2>(parse_scene_text(text, "s.toml", overrides)).model->options().stabilization_time;
  };
  const std::string& base = test::kSceneBase;  // gravity 9.81, ℓ = 1 m, t_end = 0.2 s
  const double pendulum = 0.1 * std::sqrt(1.0 / 9.81);
  CHECK_THAT(tau(base), WithinRel(pendulum, 1e-12));
  CHECK_THAT(tau(base, {"stop.t_end=1e-9"}), WithinRel(pendulum, 1e-12));
  CHECK_THAT(tau(base, {"stop.t_end=100.0"}), WithinRel(pendulum, 1e-12));
  // Without gravity and at rest, no physical scale: t_end.
  const std::string weightless = test::edit(base, "[effects.gravity]\ng = [0.0, -9.81]\n", "");
  CHECK_THAT(tau(weightless), WithinRel(0.02, 1e-12));
  // A moving start: ℓ/max|v0|.
  CHECK_THAT(tau(weightless, {"velocity.kind=uniform", "velocity.value=[4.0, 0.0]"}), WithinRel(0.1 * 1.0 / 4.0, 1e-12));
  // An end driven along a line at 0.5 m/s (the other end free): ℓ/0.5.
  CHECK_THAT(tau(weightless, {"ends.start=free", "ends.end={ kind = \"driven\", path = \"linear\", velocity = [0.0, 0.5] }"}),
             WithinRel(0.1 * 1.0 / 0.5, 1e-12));
  // A shaken end: 2π/ω.
  CHECK_THAT(tau(weightless, {"ends.start={ kind = \"driven\", amplitude = [0.01, 0.0], omega = 100.0 }"}),
             WithinRel(0.1 * 2 * M_PI / 100.0, 1e-12));
  // The key, when written, wins.
  CHECK(tau(base, {"solver.stabilization_time=0.5"}) == 0.5);
}
