// The kinds of front (shocks/front_kind.hpp: HeapFront, FoldFront) while they run: the state a running
// falling chain (heap on a table), sliding chain (heap feeding a hole) and folded chain (fold) report
// is the jump conditions (shocks/jump_conditions.hpp) evaluated at that state, and the paper's closed
// forms in the velocity of the string's nodes (docs/shocks.md).
#include <catch2/catch.hpp>

#include <cmath>
#include <string>

#include "cases/scene/front_scene.hpp"
#include "mesh/errors.hpp"
#include "cases/scene/scene.hpp"
#include "shocks/front_tracker.hpp"
#include "shocks/jump_conditions.hpp"
#include "solver/string_solver.hpp"
#include "test_scene_support.hpp"

using namespace chainsim;
using Catch::Matchers::WithinAbs;

namespace {

/// Builds the scene, runs it to t_end and evaluates the fronts at the string's last state.
struct Running {
  FrontScene<2> scene;
  const FrontTracker<2>* tracker = nullptr;
  double lambda = 0;
  explicit Running(const std::string& text, double t_end) {
    scene = build_front_scene<2>(
        parse_scene_text(test::edit(text, "t_end = 1.0", "t_end = " + std::to_string(t_end)), "running.toml"));
    StringSolver<2> solver(*scene.model, scene.solver);
    const RunSummary& run = solver.run();
    REQUIRE(run.status == "completed");
    REQUIRE(run.transfers > 0);  // the fronts have crossed nodes: the state is one of a running front
    scene.model->refresh();
    tracker = front_tracker(*scene.model);
    REQUIRE(tracker);
    lambda = scene.model->chain().density();
  }
  const StringModel<2>& model() const { return *scene.model; }
};

}  // namespace

TEST_CASE("a running heap front's state is the jump conditions at that state: falling and sliding chain",
          "[unit][shocks]") {
  const Vec<2> ey(0.0, 1.0);
  for (const bool falling : {true, false}) {
    CAPTURE(falling);
    const Running run(falling ? test::kFallingBase : test::kSlidingBase, 0.2);
    const FrontKind<2>& front = run.tracker->fronts()[0];
    const FrontState<2>& s = run.tracker->front_state(0);
    const bool after = front.arc_plus < 0;
    REQUIRE(after == falling);
    const ArcRange& arc = run.model().arcs()[static_cast<std::size_t>(after ? front.arc_minus : front.arc_plus)];
    const Vec<2> v_end = run.model().v().col(after ? arc.last : arc.first);
    const double lam = run.lambda, f = front.dissipation;
    const double tau = after ? s.tension_minus : s.tension_plus;
    // The jump conditions at the state the front reports (its speed, tangent and the end's velocity).
    CHECK(tau == jump::end_tension(f, lam, s.s0_dot, after ? -1 : +1));
    CHECK(s.power_shock == jump::shock_power(f, lam, s.s0_dot, 1));
    CHECK(s.reaction == jump::heap_reaction<2>(tau, s.direction, v_end, lam, s.inflow));
    CHECK(s.power_heap == jump::heap_power<2>(tau, s.direction, v_end, lam, s.inflow, s.power_shock));
    // The paper's forms in the velocity of the arc's end node ẏ = v_k·e_y (the string moves along a
    // vertical line at the front): falling τ = (1 − f) λ ẏ², sliding τ = (1 + f) λ ẏ²; the support's
    // force f λ ẏ² e_y; W_s = −f λ |ẏ|³, W* = −½ λ ẏ³ (falling) or ½ λ ẏ³ (sliding, ẏ < 0).
    const double ydot = v_end.dot(ey), y2 = ydot * ydot, scale = lam * y2;
    CAPTURE(ydot, tau, s.power_shock, s.power_heap);
    REQUIRE(std::abs(ydot) > 0.5);
    CHECK(std::abs(v_end.x()) <= 1e-12 * std::abs(ydot));
    CHECK_THAT(s.inflow, WithinAbs(falling ? ydot : -ydot, 1e-12 * std::abs(ydot)));
    CHECK_THAT(tau, WithinAbs((falling ? 1 - f : 1 + f) * lam * y2, 1e-12 * scale));
    CHECK_THAT((s.reaction - f * lam * y2 * ey).norm(), WithinAbs(0.0, 1e-12 * scale));
    CHECK_THAT(s.power_shock, WithinAbs(-f * lam * std::abs(ydot) * y2, 1e-12 * scale * std::abs(ydot)));
    CHECK_THAT(s.power_heap, WithinAbs((falling ? -0.5 : 0.5) * lam * ydot * y2, 1e-12 * scale * std::abs(ydot)));
  }
}

TEST_CASE("a running fold's state is the jump conditions at that state: folded chain", "[unit][shocks]") {
  const Running run(test::kFoldedBase, 0.25);
  const FrontKind<2>& front = run.tracker->fronts()[0];
  const FrontState<2>& s = run.tracker->front_state(0);
  const int a = run.model().arcs()[static_cast<std::size_t>(front.arc_minus)].last;
  const int b = run.model().arcs()[static_cast<std::size_t>(front.arc_plus)].first;
  const double lam = run.lambda, f = front.dissipation;
  CHECK(s.tension_minus == jump::end_tension(f, lam, s.s0_dot, -1));
  CHECK(s.tension_plus == jump::end_tension(f, lam, s.s0_dot, +1));
  CHECK(s.power_shock == jump::shock_power(f, lam, s.s0_dot, 2));
  CHECK(s.reaction == Vec<2>::Zero());
  CHECK(s.power_heap == 0);
  // The resting arm (node a) and the falling arm (node b, speed 2 ṡ0): arms on one line, so the fold
  // moves at ṡ0 = ½ |v_b − v_a| and the tensions are the paper's (1 ± f) λ ṡ0², their jump the energy
  // balance's −½ f λ sgn(ṡ0) |[v]|² with [v] = v_b − v_a, and the shock dissipates 2 f λ ṡ0³.
  const Vec<2> jump_v = run.model().v().col(b) - run.model().v().col(a);
  const double sd = 0.5 * jump_v.norm(), scale = lam * sd * sd;
  CAPTURE(sd, s.s0_dot, s.tension_minus, s.tension_plus);
  REQUIRE(sd > 0.5);
  CHECK_THAT(s.s0_dot, WithinAbs(sd, 1e-12 * sd));
  CHECK_THAT(s.tension_minus, WithinAbs((1 + f) * lam * sd * sd, 1e-12 * scale));
  CHECK_THAT(s.tension_plus, WithinAbs((1 - f) * lam * sd * sd, 1e-12 * scale));
  CHECK_THAT(s.tension_plus - s.tension_minus,
             WithinAbs(jump::tension_jump(f, lam, s.s0_dot, jump_v.squaredNorm()), 1e-12 * scale));
  CHECK_THAT(s.power_shock, WithinAbs(-jump::dissipation_rate(f, lam, sd, jump_v.squaredNorm()), 1e-12 * scale * sd));
}

TEST_CASE("a running pot's state is the jump conditions at that state: a sliding chain drawn out of a pot",
          "[unit][shocks][fountain]") {
  // The sliding chain whose heap is a pot that pushes (f = −0.3): τ = (1 + f) λ ẏ² = 0.7 λ ẏ² at the hole, the
  // pot's support pushes the string out with f λ ẏ² e_y (down, into the hole), no internal shock is booked and the
  // heap's exchange is the whole loss −(½ + f) λ |ẏ|³ (docs/model.md §4.5). The string hangs straight below the
  // pot's mouth, so every node comes out on it.
  const Vec<2> ey(0.0, 1.0);
  const Running run(test::edit(test::kSlidingBase, "f = 0.5", "f = -0.3\npot = true"), 0.2);
  const FrontKind<2>& front = run.tracker->fronts()[0];
  const FrontState<2>& s = run.tracker->front_state(0);
  REQUIRE(front.dissipation == -0.3);
  const ArcRange& arc = run.model().arcs()[static_cast<std::size_t>(front.arc_plus)];
  const Vec<2> v_end = run.model().v().col(arc.first);
  const double lam = run.lambda, f = front.dissipation;
  CHECK(s.tension_plus == jump::end_tension(f, lam, s.s0_dot, +1));
  CHECK(s.power_shock == 0.0);
  CHECK(s.power_heap == jump::heap_power<2>(s.tension_plus, s.direction, v_end, lam, s.inflow, 0.0));
  const double ydot = v_end.dot(ey), y2 = ydot * ydot, scale = lam * y2;
  CAPTURE(ydot, s.tension_plus, s.power_heap);
  REQUIRE(ydot < -0.5);
  CHECK(std::abs(v_end.x()) <= 1e-12 * std::abs(ydot));
  CHECK_THAT(s.tension_plus, WithinAbs((1 + f) * lam * y2, 1e-12 * scale));
  CHECK_THAT((s.reaction - f * lam * y2 * ey).norm(), WithinAbs(0.0, 1e-12 * scale));
  CHECK_THAT(s.power_heap, WithinAbs(-(0.5 + f) * lam * std::abs(ydot) * y2, 1e-12 * scale * std::abs(ydot)));
}

TEST_CASE("a node whose mass a front took is refused by the model: the fold's partial link past its node",
          "[unit][shocks]") {
  // The folded chain running at 0.25 s: arc A (the resting arm) hangs from the fixed end down to node a, arc B (the
  // falling arm) runs from node b up. The fold lumps λ l⁻ on a and λ l⁺ on b, l± = ½ (h ∓ c), c the chord along the
  // fold direction e. Node b moved to x_a + 2.5 h e (its link to b + 1 still points up, e stays): c = 2.5 h, so
  // m_b = λ h/2 (its link of arc B) + λ (h − 2.5 h)/2 = −λ h/4: the front has overshot b, and a trial state like this
  // is refused with a RecoverableError naming b (StringModel::refresh, a pass over the free nodes), never a NaN.
  const Running run(test::kFoldedBase, 0.25);
  StringModel<2>& model = *run.scene.model;
  const FrontKind<2>& front = run.tracker->fronts()[0];
  const int a = model.arcs()[static_cast<std::size_t>(front.arc_minus)].last;
  const int b = model.arcs()[static_cast<std::size_t>(front.arc_plus)].first;
  REQUIRE(model.arcs()[static_cast<std::size_t>(front.arc_plus)].num_links() > 2);
  const double h = model.chain().link_length(0), t = 0.25;
  Points<2> x = model.x(), v = model.v();
  const Vec<2> e = run.tracker->front_state(0).direction;
  REQUIRE(e.dot(Vec<2>(0.0, -1.0)) > 0.99);  // the bight points down
  CHECK_NOTHROW(model.evaluate(t, x, v));      // the running state itself: every node keeps its mass
  x.col(b) = x.col(a) + 2.5 * h * e;
  const std::string expected = "node " + std::to_string(b) + " has lost its mass";
  CHECK_THROWS_AS(model.evaluate(t, x, v), RecoverableError);
  CHECK_THROWS_WITH(model.evaluate(t, x, v), Catch::Matchers::Contains(expected));
}
