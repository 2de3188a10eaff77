// A heap front of the front tracker evaluated at single hand-built states (no time integration): its inflow
// against a finite difference of the partial link's geometry, its reaction and powers against the
// momentum and energy the string actually gains (from the model's accelerations), the paper's
// external shock for a string moving along itself, and the reversal of the orientation of s.
#include <catch2/catch.hpp>

#include <cmath>
#include <memory>
#include <vector>

#include "shocks/front_tracker.hpp"

using namespace chainsim;

namespace {

constexpr double kLambda = 2.0, kEll = 1.0, kF = 0.6;
constexpr int kLinks = 4;                 // h = 0.25
const double kTheta = 30 * 3.14159265358979323846 / 180;
const Vec<2> kUp(std::sin(kTheta), std::cos(kTheta));  // along the string, away from the table

/// A straight string tilted by 30° with its contact at the origin of the table y = 0, moving rigidly
/// with velocity V and angular velocity ω about the contact. `end_side`: the heap holds s > 0.6 (the
/// string runs into it at its end); otherwise it holds s < 0.4 (mirror image). The partial link is
/// 0.35 long either way.
struct Setup {
  bool end_side = true, on_plane = true;
  Vec<2> V = Vec<2>(0.3, -1.2);
  double omega = 0.7;
  Vec<2> position(int node) const {
    const double s = node * kEll / kLinks;
    const double sigma = end_side ? 0.6 - s : s - 0.4;  // distance from the contact along the string
    return std::max(sigma, 0.0) * kUp;
  }
  Vec<2> velocity(const Vec<2>& x) const { return V + omega * Vec<2>(-x.y(), x.x()); }
  StringModel<2> model() const {
    Chain<2> chain = Chain<2>::uniform(kLambda, kEll, kLinks, false);
    for (int i = 0; i <= kLinks; ++i) {
      chain.positions().col(i) = position(i);
      chain.velocities().col(i) = velocity(position(i));
    }
    HeapSpec<2> heap;
    heap.side = end_side ? HeapSpec<2>::Side::kAfter : HeapSpec<2>::Side::kBefore;
    heap.point = Vec<2>::Zero();
    heap.dissipation = kF;
    heap.s0 = end_side ? 0.6 : 0.4;
    if (on_plane) heap.plane_normal = Vec<2>(0.0, 1.0);
    return make_front_model<2>(std::move(chain), {}, {}, {heap}, std::nullopt, FrontOptions{});
  }
  /// The arc's nodes: end node first, then its neighbour.
  int end_node() const { return end_side ? 1 : 3; }
  int inner_node() const { return end_side ? 0 : 4; }
  /// Length of the partial link after the rigid motion has run for time dt (exact geometry):
  /// on the plane, the end link continued to y = 0; pinned, the distance to the origin.
  double partial_length(double dt) const {
    auto moved = [&](int node) -> Vec<2> {
      const Vec<2> x = position(node);
      // a rigid rotation by ω dt about the origin, then the translation V dt
      const double c = std::cos(omega * dt), s = std::sin(omega * dt);
      return Vec<2>(c * x.x() - s * x.y(), s * x.x() + c * x.y()) + V * dt;
    };
    const Vec<2> xe = moved(end_node()), xi = moved(inner_node());
    if (!on_plane) return xe.norm();
    const Vec<2> e = (xe - xi).normalized();
    return -xe.y() / e.y();
  }
};

}  // namespace

TEST_CASE("heap front: the inflow is the rate of the partial link, the reaction and powers are what the string "
          "gains",
          "[unit][shocks]") {
  for (bool end_side : {true, false})
    for (bool on_plane : {true, false}) {
      Setup setup;
      setup.end_side = end_side;
      setup.on_plane = on_plane;
      // A rigid rotation about the contact keeps a pinned partial link's length: translate only then,
      // with a velocity that is not along the string.
      if (!on_plane) setup.omega = 0.0;
      INFO("end_side " << end_side << ", on_plane " << on_plane);
      StringModel<2> model = setup.model();
      const Eigen::VectorXd y = model.state_from_chain();
      const auto snap = model.snapshot(0.0, y);
      REQUIRE(snap.fronts.size() == 1);
      const FrontState<2> front = front_tracker(model)->front_state(0);  // the kind's state at the snapshot
      const double l = end_side ? front.l_minus : front.l_plus;
      CHECK(l == Approx(0.35).epsilon(1e-12));
      // w = dl/dt by central differences of the exact geometry.
      const double dt = 1e-5;
      const double w_fd = (setup.partial_length(dt) - setup.partial_length(-dt)) / (2 * dt);
      CHECK(front.inflow == Approx(w_fd).epsilon(1e-8));
      CHECK(front.s0_dot == Approx(end_side ? w_fd : -w_fd).epsilon(1e-8));
      const double w = front.inflow;
      REQUIRE(w < 0);  // the string runs into the heap
      CHECK((end_side ? front.tension_minus : front.tension_plus) == Approx((1 - kF) * kLambda * w * w));
      // Momentum and energy the arc gains (no forces act but the front's): from the model's own
      // accelerations, with the end node's mass λ (h/2 + l) changing at λ w.
      Eigen::VectorXd ydot(y.size());
      model.rhs(0.0, y, ydot);
      const int moving = model.num_moving_nodes();
      REQUIRE(moving == 2);
      const double h = kEll / kLinks;
      Vec<2> dp = Vec<2>::Zero();
      double dK = 0;
      for (int node : {setup.end_node(), setup.inner_node()}) {
        const int slot = node == setup.end_node() ? (end_side ? 1 : 0) : (end_side ? 0 : 1);
        const Vec<2> v = y.segment<2>(2 * moving + 2 * slot);
        const Vec<2> a = ydot.segment<2>(2 * moving + 2 * slot);
        const double m = node == setup.end_node() ? kLambda * (h / 2 + l) : kLambda * h / 2;
        dp += m * a;
        dK += m * v.dot(a);
        if (node == setup.end_node()) {
          dp += kLambda * w * v;
          dK += 0.5 * kLambda * w * v.squaredNorm();
        }
      }
      CHECK((dp - front.reaction).norm() < 1e-12 * front.reaction.norm());
      CHECK(dK == Approx(front.power_shock + front.power_heap).epsilon(1e-12));
      CHECK(front.power_shock == Approx(-kF * kLambda * std::abs(w) * w * w));
    }
}

TEST_CASE("heap front: a string moving along itself meets the paper's external shock", "[unit][shocks]") {
  for (bool end_side : {true, false})
    for (bool on_plane : {true, false}) {
      Setup setup;
      setup.end_side = end_side;
      setup.on_plane = on_plane;
      setup.omega = 0;
      setup.V = -1.7 * kUp;  // along itself, into the heap at 1.7 m/s
      INFO("end_side " << end_side << ", on_plane " << on_plane);
      StringModel<2> model = setup.model();
      model.snapshot(0.0, model.state_from_chain());
      const FrontState<2> front = front_tracker(model)->front_state(0);
      const double u = 1.7;
      CHECK(front.inflow == Approx(-u).epsilon(1e-12));
      // Falling chain (docs/model.md §4.1): the table holds the string with f λ ẏ² back along it, the shock
      // dissipates f λ |ẏ|³ and the heap's power is W*⁺ = −½ λ ẏ³ with ẏ = −u.
      CHECK((front.reaction - kF * kLambda * u * u * kUp).norm() < 1e-12);
      CHECK(front.power_shock == Approx(-kF * kLambda * u * u * u));
      CHECK(front.power_heap == Approx(0.5 * kLambda * u * u * u));
      CHECK((front.position - Vec<2>::Zero()).norm() < 1e-14);
    }
}

TEST_CASE("a heap's f: 0 <= f <= 1, and -1/2 <= f <= 1 for a pot, which only a start heap may be", "[unit][shocks][fountain]") {
  HeapSpec<2> heap;
  heap.side = HeapSpec<2>::Side::kBefore;
  for (double f : {0.0, 0.5, 1.0}) {
    heap.dissipation = f;
    CHECK_NOTHROW(check_heap_dissipation(heap));
  }
  heap.dissipation = -0.2;
  CHECK_THROWS_WITH(check_heap_dissipation(heap), "heap.dissipation = -0.2 is out of range: allowed 0 <= dissipation <= 1");
  heap.pot = true;
  for (double f : {-0.5, -0.2, 0.0, 1.0}) {
    heap.dissipation = f;
    CHECK_NOTHROW(check_heap_dissipation(heap));
  }
  heap.dissipation = -0.6;
  CHECK_THROWS_WITH(check_heap_dissipation(heap),
                    "heap.dissipation = -0.6 is out of range: allowed -0.5 <= dissipation <= 1 for a pot (it loses (1/2 + f) "
                    "lambda v^3, which must not be negative)");
  heap.dissipation = 0.5;
  heap.side = HeapSpec<2>::Side::kAfter;
  CHECK_THROWS_WITH(check_heap_dissipation(heap),
                    "heap.pot = true on a heap the string runs into: a pot feeds the string; allowed only for a start "
                    "heap (side before s0)");
}
