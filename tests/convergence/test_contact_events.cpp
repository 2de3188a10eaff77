// The contact module's lift-offs in the run's summary (`events`, `contact_lift_offs`, `events_truncated`;
// solver/contact_module.hpp, docs/scenes.md and docs/model.md §10), against independent references:
//  - the heavy Atwood chain over a pulley with links along the arc (cases/scenes/atwood_pulley.toml,
//    contact = "arc"): before the shorter side lifts off, the longer side leaves the pulley at its tangent
//    point (R, 0), link by link: node i (material coordinate s_i) is let go when the exact motion
//    u(t) = u0 cosh(√(2g/ℓ) t) has carried it there, ℓ − (ℓ_free/2 + u) = s_i. The first release by a
//    contact force (the shorter side's lift-off) comes after the exact lift-off t* (exact::pulley_lift_off_u,
//    the reference of `compare pulley`) and no later than the next node's landing on the shorter side,
//    h/v* after it (v* = u̇(t*)), at the node at (−R, 0), within 2h of x2(t*) = ℓ_free/2 − u* in material;
//  - a closed loop running round a pulley in node contact (tests/hard/test_hard_contact.cpp): more lift-offs
//    than the list holds; the first 100 listed, each on the circle (|x| = R, a held node's gap) with the
//    force that let it go not pushing (N ≤ 0 to round-off), and the total equal to series.csv's lift_offs.
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include <catch2/catch.hpp>
#include <fmt/format.h>

#include "cases/reduced/exact_solutions.hpp"
#include "cases/scene/scene.hpp"
#include "solver/string_solver.hpp"

using namespace chainsim;

namespace {

constexpr double kG = 9.81;
constexpr double kPulleyPi = 3.141592653589793;

std::optional<double> value_of(const RunEvent& e, const std::string& name) {
  for (const auto& [key, value] : e.values)
    if (key == name) return value;
  return std::nullopt;
}
std::optional<long> index_of(const RunEvent& e, const std::string& name) {
  for (const auto& [key, index] : e.indices)
    if (key == name) return index;
  return std::nullopt;
}

}  // namespace

TEST_CASE("contact events: the Atwood chain's lift-offs off the pulley at the exact times, named by node and obstacle",
          "[contact][pulley][events]") {
  const std::filesystem::path file = std::filesystem::path(CHAINSIM_SOURCE_DIR) / "cases" / "scenes" / "atwood_pulley.toml";
  const double ell = 1.0, R = 0.1, u0 = 0.05, lambda = 1.0;
  const double free = ell - kPulleyPi * R;
  const double u_star = exact::pulley_lift_off_u(u0, R, ell);
  const double t_star = exact::pulley_time(u_star, u0, ell, kG);
  const double v_star = exact::pulley_u_dot(t_star, u0, ell, kG);
  // Measured time errors 2.7e-6, 1.3e-7, 3.2e-8 s (the cosh reproduced at second order down to the floor of
  // the scene's rtol 1e-9, as `compare pulley` finds), and distances from (R, 0) up to 1.05e-9 m.
  const std::vector<int> meshes = {51, 101, 201};
  const std::vector<double> bound_t = {8e-6, 4e-7, 1e-7};
  for (std::size_t mesh = 0; mesh < meshes.size(); ++mesh) {
    const int nodes = meshes[mesh];
    CAPTURE(nodes);
    const double h = ell / (nodes - 1);
    const SceneSpec spec = parse_scene(file, {"effects.cylinder[0].contact=arc", fmt::format("string.nodes={}", nodes),
                                              fmt::format("stop.t_end={:.17g}", t_star + 2 * h / v_star)});
    StringScene<2> scene = build_string_scene<2>(spec);
    StringSolver<2> solver(*scene.model, scene.solver);
    const RunSummary& s = solver.run();
    REQUIRE(s.status == "completed");
    // The longer side's nodes that pass its tangent point before t*: s_i from ℓ − ℓ_free/2 − u0 down to
    // ℓ − ℓ_free/2 − u*, in that order.
    std::vector<int> expected;
    for (int i = nodes - 1; i >= 0; --i) {
      const double si = i * h;
      if (si < ell - 0.5 * free - u0 && si > ell - 0.5 * free - u_star) expected.push_back(i);
    }
    std::vector<int> leaving;
    double max_err_t = 0, max_off_tangent = 0;
    const RunEvent* lift = nullptr;
    for (const RunEvent& e : s.events) {
      CHECK(e.kind == "lift_off");
      CHECK(e.obstacle == "effects.cylinder[0]");
      CHECK(e.front == -1);
      REQUIRE(index_of(e, "node"));
      REQUIRE(value_of(e, "s"));
      const int node = static_cast<int>(*index_of(e, "node"));
      CHECK(*value_of(e, "s") == Approx(node * h).margin(1e-14));
      if (value_of(e, "N")) {  // let go by its contact force
        if (!lift) lift = &e;
        continue;
      }
      REQUIRE(index_of(e, "link"));
      CHECK((*index_of(e, "link") == node || *index_of(e, "link") == node - 1));  // one of its two links
      if (e.t >= t_star) continue;  // past t* the motion is no longer the cosh
      leaving.push_back(node);
      // Node i reaches the tangent point when ℓ − (ℓ_free/2 + u(t)) = s_i.
      const double t_exact = exact::pulley_time(ell - 0.5 * free - node * h, u0, ell, kG);
      max_err_t = std::max(max_err_t, std::abs(e.t - t_exact));
      max_off_tangent = std::max(max_off_tangent, std::hypot(e.position[0] - R, e.position[1]));
    }
    CHECK(leaving == expected);
    REQUIRE(lift != nullptr);
    const double s_lift = *value_of(*lift, "s");
    std::printf("\natwood_pulley.toml, contact = \"arc\", %d nodes: %zu nodes leave the longer side before t* "
                "(exact %zu), time errors <= %.3g s, <= %.3g m from (R, 0); first lift-off by its force at t = %.9g s "
                "(t* = %.9g s, after it by %.3g of h/v*), node %ld (s = %.4g m, x2(t*) = %.4g m) at (%.6g, %.6g), "
                "|x| - R = %.3g m, N = %.3g N; %ld lift-offs in all\n",
                nodes, leaving.size(), expected.size(), max_err_t, max_off_tangent, lift->t, t_star,
                (lift->t - t_star) / (h / v_star), *index_of(*lift, "node"), s_lift, 0.5 * free - u_star,
                lift->position[0], lift->position[1], std::hypot(lift->position[0], lift->position[1]) - R,
                *value_of(*lift, "N"),
                s.lift_off_totals.empty() ? 0L : s.lift_off_totals[0].total);
    CHECK(max_err_t < bound_t[mesh]);
    CHECK(max_off_tangent < 3e-9);  // the arc runs out at the tangent point
    // The shorter side's lift-off: after t* (before it the force at φ = 0 pushes), by the next landing
    // (measured 0.29, 0.41, 0.87 of h/v* on 51, 101, 201 nodes), at φ = 0 on the shorter side.
    CHECK(lift->t > t_star - 1e-6);
    CHECK(lift->t < t_star + h / v_star);
    CHECK(std::abs(s_lift - (0.5 * free - u_star)) < 2 * h);
    CHECK(lift->position[0] < 0);  // on the circle (a held node), within h of φ = 0
    CHECK(std::abs(std::hypot(lift->position[0], lift->position[1]) - R) < 3e-13);  // measured 7.4e-14 m
    CHECK(std::abs(lift->position[1]) < h);
    CHECK(*value_of(*lift, "N") < 1e-9 * lambda * kG * ell);  // it no longer pushes
    // The totals: one obstacle, every lift-off listed (fewer than 100), the sum series.csv's lift_offs.
    REQUIRE(s.lift_off_totals.size() == 1);
    CHECK(s.lift_off_totals[0].obstacle == "effects.cylinder[0]");
    CHECK(s.lift_off_totals[0].total == static_cast<long>(s.events.size()));
    CHECK(static_cast<double>(s.lift_off_totals[0].total) == solver.frames().back().terms["lift_offs"]);
    const nlohmann::json j = to_json(s);
    CHECK(j["contact_lift_offs"]["effects.cylinder[0]"] == s.lift_off_totals[0].total);
    CHECK(j["events_truncated"] == false);
    REQUIRE(!j["events"].empty());
    CHECK(j["events"][0]["obstacle"] == "effects.cylinder[0]");
    CHECK(j["events"][0]["front"].is_null());
    CHECK(j["events"][0]["node"].is_number_integer());
    CHECK(j["events"][0]["node"] == *index_of(s.events[0], "node"));
    CHECK(j["events"][0]["link"].is_number_integer());
  }
}

TEST_CASE("contact events: a loop running round a pulley lists its first 100 lift-offs and counts them all",
          "[contact][events]") {
  // The closed loop of tests/hard/test_hard_contact.cpp (80 nodes, a half circle on a pulley of radius 0.1 m,
  // launched along itself at 3 m/s), node contact, slack = "stop", to 0.5 s.
  std::string points;
  for (int i = 0; i <= 60; ++i) {
    const double a = kPulleyPi * i / 60, r = 0.1 * 1.0003;
    points += fmt::format("[{:.17g}, {:.17g}], ", r * std::cos(a), r * std::sin(a));
  }
  points += "[-0.10003, -0.35], [0.10003, -0.35]";
  auto loop = [&](double t_end) {
    return fmt::format(
        "[string]\nclosed = true\nnodes = 80\n[shape]\nkind = \"points\"\npoints = [{}]\n[velocity]\n"
        "kind = \"tangential\"\nspeed = 3.0\n[effects.gravity]\ng = [0.0, -9.81]\n[solver]\nslack = \"stop\"\n"
        "[stop]\nt_end = {}\n",
        points, t_end);
  };
  const std::string pulley = "[[effects.cylinder]]\ncenter = [0.0, 0.0]\nradius = 0.1\n";
  const double R = 0.1;
  {
    StringScene<2> scene = build_string_scene<2>(parse_scene_text(loop(0.5) + pulley, "loop.toml"));
    StringSolver<2> solver(*scene.model, scene.solver);
    const RunSummary& s = solver.run();
    REQUIRE(s.status == "completed");
    REQUIRE(s.lift_off_totals.size() == 1);
    const long total = s.lift_off_totals[0].total;
    double off_circle = 0, most_n = -INFINITY;
    for (std::size_t k = 0; k < s.events.size(); ++k) {
      const RunEvent& e = s.events[k];
      CHECK(e.obstacle == "effects.cylinder[0]");
      if (k > 0) CHECK(e.t >= s.events[k - 1].t);
      off_circle = std::max(off_circle, std::abs(std::hypot(e.position[0], e.position[1]) - R));
      REQUIRE(value_of(e, "N"));
      most_n = std::max(most_n, *value_of(e, "N"));
    }
    std::printf("\nloop round a pulley, node contact, 0.5 s: %ld lift-offs, %zu listed (the first at %.6g s, the last "
                "at %.6g s), |x| - R <= %.3g m, N <= %.3g N\n",
                total, s.events.size(), s.events.front().t, s.events.back().t, off_circle, most_n);
    CHECK(total > 100);  // measured 269
    CHECK(s.events.size() == 100);
    CHECK(static_cast<double>(total) == solver.frames().back().terms["lift_offs"]);
    CHECK(off_circle < 2e-13);  // a held node's gap (measured 6.2e-14 m)
    CHECK(most_n < 1e-12);      // measured 1.9e-13 N: let go where the force stops pushing, or pulls
    const nlohmann::json j = to_json(s);
    CHECK(j["contact_lift_offs"]["effects.cylinder[0]"] == total);
    CHECK(j["events_truncated"] == true);
    CHECK(j["events"].size() == 100);
  }
  // Without an obstacle the summary has neither key (and `events` stays empty).
  StringScene<2> scene = build_string_scene<2>(parse_scene_text(loop(0.01), "loop.toml"));
  StringSolver<2> solver(*scene.model, scene.solver);
  const RunSummary& s = solver.run();
  const nlohmann::json j = to_json(s);
  CHECK(!j.contains("contact_lift_offs"));
  CHECK(!j.contains("events_truncated"));
  CHECK(j["events"].empty());
}
