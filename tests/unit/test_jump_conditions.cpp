// shocks/jump_conditions.hpp against states derived by hand from the paper's three problems,
// a moving front, and the reversal of the orientation of s.
#include <cmath>

#include <Eigen/Geometry>
#include <catch2/catch.hpp>

#include "shocks/jump_conditions.hpp"

using namespace chainsim::jump;
using Catch::Matchers::WithinAbs;
using V2 = Vector<2>;
using V3 = Vector<3>;

namespace {
constexpr double kExact = 1e-13;  // every check below is algebra on O(1) numbers: rounding only
const V2 ex(1.0, 0.0), ey(0.0, 1.0);
}  // namespace

TEST_CASE("falling chain at the table: standing front, reaction f lambda ydot^2", "[unit][shocks]") {
  // s runs from the free end down to the table: t⁻ = −e_y (falling part), t⁺ = e_x (towards the heap).
  // The chain moves along itself with speed v = −ẏ > 0, so ṡ0 = ẏ and the front stands still.
  const double lam = 0.7, f = 0.83, ydot = -2.3, v = -ydot;
  Side<2> minus{-ey, v * (-ey), (1.0 - f) * lam * ydot * ydot};
  Side<2> plus{ex, v * ex, lam * ydot * ydot};
  const double s0dot = ydot;
  CHECK_THAT(compatibility_residual(minus, plus, s0dot), WithinAbs(0.0, kExact));
  CHECK_THAT(front_velocity(plus, s0dot).norm(), WithinAbs(0.0, kExact));
  const V2 jv = velocity_jump<2>(minus.tangent, plus.tangent, s0dot);
  CHECK_THAT((jv - (plus.velocity - minus.velocity)).norm(), WithinAbs(0.0, kExact));
  CHECK_THAT(jv.squaredNorm(), WithinAbs(2 * ydot * ydot, kExact));
  // [τ] = τ⁺ − τ⁻ = f λ ẏ²  (paper: τ⁻ = (1 − f) λ ẏ², τ⁺ = λ ẏ²)
  CHECK_THAT(tension_jump(f, lam, s0dot, jv.squaredNorm()), WithinAbs(plus.tension - minus.tension, kExact));
  // The table's reaction Φ0 e_y = f λ ẏ² e_y balances the momentum at x0.
  const V2 F0 = required_force(minus, plus, lam, s0dot);
  CHECK_THAT((F0 - f * lam * ydot * ydot * ey).norm(), WithinAbs(0.0, kExact));
  CHECK_THAT(momentum_residual(minus, plus, F0, lam, s0dot).norm(), WithinAbs(0.0, kExact));
  // W_s = −D = f λ ẏ³ (ẏ < 0), and the heap (+ side, τ* = τ⁺ = λ v²) feels no force, supplies −½ λ ẏ³.
  CHECK_THAT(-dissipation_rate(f, lam, s0dot, jv.squaredNorm()), WithinAbs(f * lam * ydot * ydot * ydot, kExact));
  CHECK_THAT(heap_force<2>(true, plus.tension, lam, v, ex).norm(), WithinAbs(0.0, kExact));
  CHECK_THAT(heap_power(true, plus.tension, lam, v), WithinAbs(-0.5 * lam * ydot * ydot * ydot, kExact));
}

TEST_CASE("folded chain at the bight: moving front, tau+ + tau- = 2 lambda ydot^2", "[unit][shocks]") {
  // s from the fixed end: resting arm t⁻ = −e_y (v⁻ = 0), moving arm t⁺ = +e_y with v⁺ = −2ẏ e_y; ṡ0 = ẏ.
  const double lam = 1.3, f = 0.4;
  for (double ydot : {1.7, -0.9}) {
    CAPTURE(ydot);
    const double s = ydot > 0 ? 1.0 : -1.0;
    Side<2> minus{-ey, V2::Zero(), lam * (1 + f * s) * ydot * ydot};
    Side<2> plus{ey, -2 * ydot * ey, lam * (1 - f * s) * ydot * ydot};
    const double s0dot = ydot;
    CHECK_THAT(compatibility_residual(minus, plus, s0dot), WithinAbs(0.0, kExact));
    // The bight moves at −ẏ e_y (half the free end's speed).
    CHECK_THAT((front_velocity(plus, s0dot) + ydot * ey).norm(), WithinAbs(0.0, kExact));
    const double jv2 = (plus.velocity - minus.velocity).squaredNorm();
    CHECK_THAT(jv2, WithinAbs(4 * ydot * ydot, kExact));
    CHECK_THAT(tension_jump(f, lam, s0dot, jv2), WithinAbs(-2 * lam * f * s * ydot * ydot, kExact));
    CHECK_THAT(tension_jump(f, lam, s0dot, jv2), WithinAbs(plus.tension - minus.tension, kExact));
    // No concentrated force at the bight: the paper's tensions balance the momentum.
    CHECK_THAT(momentum_residual(minus, plus, V2(V2::Zero()), lam, s0dot).norm(), WithinAbs(0.0, kExact));
    CHECK_THAT(-dissipation_rate(f, lam, s0dot, jv2), WithinAbs(-2 * lam * f * s * ydot * ydot * ydot, kExact));
  }
}

TEST_CASE("sliding chain at the hole: [tau] = f lambda sgn(ydot) ydot^2, heap feels no force", "[unit][shocks]") {
  // s from the heap to the hanging end: t⁻ = e_x (on the table), t⁺ = −e_y (hanging); ṡ0 = −ẏ.
  const double lam = 2.0, f = 0.83, ydot = 1.4;
  Side<2> minus{ex, ydot * ex, lam * ydot * ydot};
  Side<2> plus{-ey, -ydot * ey, lam * ydot * ydot * (1 + f)};
  const double s0dot = -ydot;
  CHECK_THAT(compatibility_residual(minus, plus, s0dot), WithinAbs(0.0, kExact));
  const double jv2 = (plus.velocity - minus.velocity).squaredNorm();
  CHECK_THAT(tension_jump(f, lam, s0dot, jv2), WithinAbs(f * lam * ydot * ydot, kExact));
  // The plane's reaction Φ0 = τ⁺ − λ ẏ² = f λ ẏ² upward.
  const V2 F0 = required_force(minus, plus, lam, s0dot);
  CHECK_THAT((F0 - f * lam * ydot * ydot * ey).norm(), WithinAbs(0.0, kExact));
  // Heap on the − side, τ*⁻ = τ⁻ = λ ẏ²: no force, W*⁻ = −½ λ ẏ³; W_s = −f λ ẏ³.
  CHECK_THAT(heap_force<2>(false, minus.tension, lam, ydot, ex).norm(), WithinAbs(0.0, kExact));
  CHECK_THAT(heap_power(false, minus.tension, lam, ydot), WithinAbs(-0.5 * lam * ydot * ydot * ydot, kExact));
  CHECK_THAT(-dissipation_rate(f, lam, s0dot, jv2), WithinAbs(-f * lam * ydot * ydot * ydot, kExact));
}

TEST_CASE("the jump conditions do not depend on the orientation of s", "[unit][shocks]") {
  // A general moving kink in 3D: given the − side and ṡ0, build the compatible + side, its tension
  // from the energy condition and F0 from the momentum balance; then describe the same shock with s
  // reversed (t → −t, ṡ0 → −ṡ0, sides swapped) and check every condition still holds.
  const double lam = 0.9, f = 0.6;
  const V3 tm = V3(1.0, 2.0, -0.5).normalized(), tp = V3(-0.3, 1.0, 2.0).normalized();
  for (double s0dot : {0.8, -1.1}) {
    CAPTURE(s0dot);
    Side<3> minus{tm, V3(0.2, -1.0, 0.4), 3.0};
    Side<3> plus{tp, minus.velocity + velocity_jump<3>(tm, tp, s0dot), 0.0};
    const double jv2 = (plus.velocity - minus.velocity).squaredNorm();
    plus.tension = minus.tension + tension_jump(f, lam, s0dot, jv2);
    const V3 F0 = required_force(minus, plus, lam, s0dot);
    CHECK_THAT(momentum_residual(minus, plus, F0, lam, s0dot).norm(), WithinAbs(0.0, kExact));

    const Side<3> minus_r{-plus.tangent, plus.velocity, plus.tension};
    const Side<3> plus_r{-minus.tangent, minus.velocity, minus.tension};
    CHECK_THAT(compatibility_residual(minus_r, plus_r, -s0dot), WithinAbs(0.0, kExact));
    const double jv2_r = (plus_r.velocity - minus_r.velocity).squaredNorm();
    CHECK_THAT(plus_r.tension - minus_r.tension, WithinAbs(tension_jump(f, lam, -s0dot, jv2_r), kExact));
    CHECK_THAT(momentum_residual(minus_r, plus_r, F0, lam, -s0dot).norm(), WithinAbs(0.0, kExact));
    CHECK_THAT(dissipation_rate(f, lam, -s0dot, jv2_r), WithinAbs(dissipation_rate(f, lam, s0dot, jv2), kExact));
    // The front itself moves the same way in both descriptions.
    CHECK_THAT((front_velocity(plus_r, -s0dot) - front_velocity(plus, s0dot)).norm(), WithinAbs(0.0, kExact));
  }
}

TEST_CASE("energy: the dissipation equals the power lost across the front", "[unit][shocks]") {
  // The identity behind the tension jump (model.md §2.3): ṡ0 [τ] = −D, so the shock dissipates
  // exactly D = ½ f λ |ṡ0| |[v]|² whatever the sign of ṡ0, and a standing front (ṡ0 = 0) nothing.
  const double lam = 1.1, f = 0.75, jv2 = 3.7;
  for (double s0dot : {2.0, -2.0, 0.0}) {
    CAPTURE(s0dot);
    CHECK_THAT(s0dot * tension_jump(f, lam, s0dot, jv2), WithinAbs(-dissipation_rate(f, lam, s0dot, jv2), kExact));
  }
  CHECK(dissipation_rate(0.0, lam, 2.0, jv2) == 0.0);  // f = 0: an elastic shock dissipates nothing
}

// The forms the fronts compute with (front_kind.hpp): end tensions, shock power, heap reaction and heap
// power, at the states of the paper's three problems, derived by hand and against the functions above.

TEST_CASE("end tensions: the paper's tau at the table, the hole and the bight, and [tau] of the energy balance",
          "[unit][shocks]") {
  const double lam = 1.3, f = 0.83;
  for (double ydot : {-2.3, 1.4}) {
    CAPTURE(ydot);
    const double s = ydot > 0 ? 1.0 : -1.0;
    // Falling chain (ẏ < 0) and its reverse: the moving arc on the − side of the front, ṡ0 = ẏ:
    // τ⁻ = (1 + f sgn ẏ) λ ẏ² ((1 − f) λ ẏ² while it falls).
    CHECK_THAT(end_tension(f, lam, ydot, -1), WithinAbs((1 + f * s) * lam * ydot * ydot, kExact));
    // Sliding chain: the moving arc on the + side, ṡ0 = −ẏ: τ⁺ = (1 + f sgn ẏ) λ ẏ² ((1 + f) λ ẏ² while it slides out).
    CHECK_THAT(end_tension(f, lam, -ydot, +1), WithinAbs((1 + f * s) * lam * ydot * ydot, kExact));
    // Folded chain, ṡ0 = ẏ: τ⁺ − τ⁻ is the tension jump of the energy balance with |[v]|² = 4 ẏ², and
    // τ⁻ + τ⁺ = 2 λ ẏ² balances the momentum of arms on one line (t⁻ = −e_y, t⁺ = e_y, v⁺ − v⁻ = −2ẏ e_y).
    const double tm = end_tension(f, lam, ydot, -1), tp = end_tension(f, lam, ydot, +1);
    CHECK_THAT(tp - tm, WithinAbs(tension_jump(f, lam, ydot, 4 * ydot * ydot), kExact));
    Side<2> minus{-ey, V2::Zero(), tm};
    Side<2> plus{ey, -2 * ydot * ey, tp};
    CHECK_THAT(momentum_residual(minus, plus, V2(V2::Zero()), lam, ydot).norm(), WithinAbs(0.0, kExact));
    // Orientation: reversing s swaps the sides and flips ṡ0.
    CHECK(end_tension(f, lam, ydot, -1) == end_tension(f, lam, -ydot, +1));
  }
}

TEST_CASE("shock power: k internal shocks of |[v]|^2 = 2 s0dot^2 each dissipate k f lambda |s0dot|^3",
          "[unit][shocks]") {
  const double lam = 0.7, f = 0.6;
  for (double sd : {-2.3, 0.9}) {
    CAPTURE(sd);
    // A heap's contact (the falling chain's |[v]|² = 2 ẏ², above) and a fold (|[v]|² = 4 ṡ0²).
    CHECK_THAT(shock_power(f, lam, sd, 1), WithinAbs(-dissipation_rate(f, lam, sd, 2 * sd * sd), kExact));
    CHECK_THAT(shock_power(f, lam, sd, 2), WithinAbs(-dissipation_rate(f, lam, sd, 4 * sd * sd), kExact));
    CHECK_THAT(shock_power(f, lam, sd, 2), WithinAbs(-2 * f * lam * std::abs(sd * sd * sd), kExact));
    CHECK(shock_power(f, lam, sd, 1) == shock_power(f, lam, -sd, 1));  // orientation
    CHECK(shock_power(f, lam, sd, 1) <= 0);
    CHECK(shock_power(0.0, lam, sd, 2) == 0);
  }
}

TEST_CASE("heap reaction and power at the table and the hole: the concentrated force and the paper's W*",
          "[unit][shocks]") {
  SECTION("falling chain: the string runs into the heap on the table") {
    // e from the arc into the heap = −e_y, end velocity v e = −ẏ e, the arc gains material at w = ẏ < 0.
    const double lam = 0.7, f = 0.83, ydot = -2.3;
    const V2 e = -ey, v_end = -ydot * e;
    const double tau = end_tension(f, lam, ydot, -1), w_s = shock_power(f, lam, ydot, 1);
    // R is the table's force Φ0 = f λ ẏ² e_y that balances the momentum at x0 (first test case)...
    Side<2> minus{-ey, -ydot * (-ey), tau};
    Side<2> plus{ex, -ydot * ex, lam * ydot * ydot};
    const V2 R = heap_reaction<2>(tau, e, v_end, lam, ydot);
    CHECK_THAT((R - required_force(minus, plus, lam, ydot)).norm(), WithinAbs(0.0, kExact));
    CHECK_THAT((R - f * lam * ydot * ydot * ey).norm(), WithinAbs(0.0, kExact));
    // ... and W* the paper's external shock −½ λ ẏ³ (the heap's own τ* = λ v², feeling no force), which
    // is W*+ at the arc's end tension less the shock's power.
    const double W = heap_power<2>(tau, e, v_end, lam, ydot, w_s);
    CHECK_THAT(W, WithinAbs(-0.5 * lam * ydot * ydot * ydot, kExact));
    CHECK_THAT(W, WithinAbs(heap_power(true, lam * ydot * ydot, lam, -ydot), kExact));
    CHECK_THAT(W, WithinAbs(heap_power(true, tau, lam, -ydot) - w_s, kExact));
    CHECK_THAT((R - heap_force<2>(true, tau, lam, -ydot, e)).norm(), WithinAbs(0.0, kExact));
  }
  SECTION("sliding chain: the heap feeds a hole, the string hangs below it") {
    // e from the hanging arc up into the hole = e_y, end velocity −ẏ e_y, w = ẏ > 0, ṡ0 = −ẏ.
    const double lam = 2.0, f = 0.83, ydot = 1.4;
    const V2 e = ey, v_end = -ydot * ey;
    const double tau = end_tension(f, lam, -ydot, +1), w_s = shock_power(f, lam, -ydot, 1);
    Side<2> minus{ex, ydot * ex, lam * ydot * ydot};
    Side<2> plus{-ey, -ydot * ey, tau};
    const V2 R = heap_reaction<2>(tau, e, v_end, lam, ydot);
    CHECK_THAT((R - required_force(minus, plus, lam, -ydot)).norm(), WithinAbs(0.0, kExact));
    const double W = heap_power<2>(tau, e, v_end, lam, ydot, w_s);
    CHECK_THAT(W, WithinAbs(-0.5 * lam * ydot * ydot * ydot, kExact));
    CHECK_THAT(W, WithinAbs(heap_power(false, lam * ydot * ydot, lam, ydot), kExact));
    CHECK_THAT(W, WithinAbs(heap_power(false, tau, lam, ydot) - w_s, kExact));
    CHECK_THAT((R - heap_force<2>(false, tau, lam, ydot, plus.tangent)).norm(), WithinAbs(0.0, kExact));
    CHECK_THAT(w_s, WithinAbs(-f * lam * ydot * ydot * ydot, kExact));
  }
  SECTION("a string moving along itself into the heap at any angle: R = Phi*+ and W* = W*+ - W_s") {
    const double lam = 1.1, f = 0.3, v = 1.7;
    const V3 t = V3(0.3, -0.4, 0.5).normalized();
    const double tau = end_tension(f, lam, -v, -1), w_s = shock_power(f, lam, -v, 1);
    CHECK_THAT((heap_reaction<3>(tau, t, v * t, lam, -v) - heap_force<3>(true, tau, lam, v, t)).norm(),
               WithinAbs(0.0, kExact));
    CHECK_THAT(heap_power<3>(tau, t, v * t, lam, -v, w_s), WithinAbs(heap_power(true, tau, lam, v) - w_s, kExact));
  }
}

TEST_CASE("a pot (f < 0) pushes the string out: T = (1 + f) lambda v^2, loss (1/2 + f) lambda v^3, no internal shock",
          "[unit][shocks][fountain]") {
  // A string drawn out of a pot at speed v along t (the fountain's first leg, any direction): ṡ0 = −v, the arc
  // gains material at w = v, e (from the arc into the heap) = −t, the end moves at v t. By hand: the tension
  // (1 + f) λ v² (less than λ v²: the pot pushes with −f λ v², Biggins & Warner's α λ v²); the pot's support takes
  // the momentum flux λ v² t less that tension; the string gains K at ½ λ v³ per unit time from new material and
  // loses τ v at its end, so the pot's whole exchange is −(½ + f) λ v³ (the sliding chain's K̇ + V̇ at the hole).
  const double lam = 0.7, v = 2.3;
  const V3 t = V3(0.2, 0.9, -0.1).normalized();
  for (double f : {-0.5, -0.2, 0.0, 0.4}) {
    INFO("f = " << f);
    const double tau = end_tension(f, lam, -v, +1);
    CHECK_THAT(tau, WithinAbs((1 + f) * lam * v * v, kExact));
    const double w_s = heap_shock_power(f, lam, -v);
    // f < 0 is no internal shock (it would dissipate −f λ v³ < 0): none is booked; f >= 0 books −f λ v³.
    CHECK_THAT(w_s, WithinAbs(f < 0 ? 0.0 : -f * lam * v * v * v, kExact));
    const double w_heap = heap_power<3>(tau, V3(-t), V3(v * t), lam, v, w_s);
    CHECK_THAT(w_s + w_heap, WithinAbs(-(0.5 + f) * lam * v * v * v, kExact));
    CHECK_THAT(pot_dissipation_rate(f, lam, v), WithinAbs((0.5 + f) * lam * v * v * v, kExact));
    CHECK(w_s <= 0);
    CHECK(w_heap <= 0);  // both ledgers are losses, down to f = −½ (none there)
    // The pot's reaction: the momentum flux λ v² t the string takes away, less the tension that pulls it out.
    const V3 R = heap_reaction<3>(tau, V3(-t), V3(v * t), lam, v);
    CHECK_THAT((R - (-f) * lam * v * v * t).norm(), WithinAbs(0.0, kExact));
  }
  CHECK(kPotMinDissipation == -0.5);
}

TEST_CASE("pinned front (an edge): the chain sliding off a table, F0 in the normal cone while tau >= lambda v^2",
          "[unit][shocks][edge]") {
  // s from the far end on the table (t⁻ = e_x, towards the edge at the origin) to the hanging end
  // (t⁺ = −e_y). The chain moves at speed v > 0: v⁻ = v e_x, v⁺ = −v e_y, ṡ0 = −v (the edge moves
  // back through the material). The table part (length ℓ − x) is pulled by τ⁻ = λ (ℓ − x) ẍ; the
  // hanging part (length x) obeys λ x ẍ = λ g x − τ⁺ (docs/model.md §8).
  const double lam = 0.9, g = 9.81, ell = 2.0, x = 0.7;
  for (double f : {0.0, 0.35, 1.0}) {
    for (double v : {0.4, 2.6}) {
      CAPTURE(f, v);
      const double s0dot = -v;
      const double xdd = (g * x - f * v * v) / ell;  // the reduced equation ℓ ẍ = g x − f ẋ²
      const double tm = lam * (ell - x) * xdd;
      const double tp = pinned_tension_plus<2>(tm, ex, -ey, f, lam, s0dot);
      // The hanging part's momentum balance with this τ⁺ gives the same ẍ: [τ] = f λ v².
      CHECK_THAT(tp - tm, WithinAbs(f * lam * v * v, kExact));
      CHECK_THAT(lam * x * xdd, WithinAbs(lam * g * x - tp, kExact));
      Side<2> minus{ex, v * ex, tm};
      Side<2> plus{-ey, -v * ey, tp};
      CHECK_THAT(compatibility_residual(minus, plus, s0dot), WithinAbs(0.0, kExact));
      CHECK_THAT(front_velocity(plus, s0dot).norm(), WithinAbs(0.0, kExact));  // pinned: v0 = 0
      const V2 F0 = pinned_reaction<2>(ex, -ey, tm, tp, lam, s0dot);
      CHECK_THAT((F0 - required_force(minus, plus, lam, s0dot)).norm(), WithinAbs(0.0, kExact));
      CHECK_THAT((F0 - V2(tm - lam * v * v, tp - lam * v * v)).norm(), WithinAbs(0.0, kExact));
      // The faces: the table's top (normal e_y) under the − side, its side (normal e_x) under the + side.
      const V2 jt = -ey - ex;
      const V2 nm = face_normal<2>(ex, jt), np = face_normal<2>(-ey, jt);
      CHECK_THAT((nm - ey).norm(), WithinAbs(0.0, kExact));
      CHECK_THAT((np - ex).norm(), WithinAbs(0.0, kExact));
      const Eigen::Vector2d ab = pinned_cone<2>(F0, nm, np);
      CHECK_THAT(ab[0], WithinAbs(tp - lam * v * v, kExact));
      CHECK_THAT(ab[1], WithinAbs(tm - lam * v * v, kExact));
      // The kink dissipates D = f λ v³ = −ṡ0 [τ] (the power the tensions feed into the front).
      const double D = pinned_dissipation_rate<2>(ex, -ey, f, lam, s0dot);
      CHECK_THAT(D, WithinAbs(f * lam * v * v * v, kExact));
      CHECK_THAT(D, WithinAbs(-s0dot * (tp - tm), kExact));
    }
  }
  // f = 0, released at rest from x0: ẋ² = (g/ℓ)(x² − x0²), and the margin τ⁻ − λ ẋ² vanishes at
  // x* = (ℓ + √(ℓ² + 8 x0²))/4 (the closed form).
  const double x0 = 0.3, xs = (ell + std::sqrt(ell * ell + 8 * x0 * x0)) / 4;
  const double v2 = g / ell * (xs * xs - x0 * x0);
  const double tm = lam * (ell - xs) * g * xs / ell;
  const V2 F0 = pinned_reaction<2>(ex, -ey, tm, tm, lam, -std::sqrt(v2));
  // With f = 0 the tension is continuous (τ⁺ = τ⁻): both faces let go at once.
  CHECK_THAT(pinned_cone<2>(F0, ey, ex)[1], WithinAbs(0.0, 1e-12));
  CHECK_THAT(pinned_cone<2>(F0, ey, ex)[0], WithinAbs(0.0, 1e-12));
}

TEST_CASE("pinned front at any angle, in 3D and with s reversed: the momentum balance holds, the cone is A >= B cos",
          "[unit][shocks][edge]") {
  const double lam = 1.4, f = 0.6;
  for (double theta : {0.3, 1.2, 2.5}) {
    for (double s0dot : {-1.3, 0.8}) {
      CAPTURE(theta, s0dot);
      const V3 tm(1, 0, 0), tp(std::cos(theta), -std::sin(theta), 0);
      const double taum = 2.1;
      const double taup = pinned_tension_plus<3>(taum, tm, tp, f, lam, s0dot);
      Side<3> minus{tm, -s0dot * tm, taum};
      Side<3> plus{tp, -s0dot * tp, taup};
      const V3 F0 = pinned_reaction<3>(tm, tp, taum, taup, lam, s0dot);
      CHECK_THAT(momentum_residual(minus, plus, F0, lam, s0dot).norm(), WithinAbs(0.0, kExact));
      const double jv2 = (plus.velocity - minus.velocity).squaredNorm();
      CHECK_THAT(taup - taum, WithinAbs(tension_jump(f, lam, s0dot, jv2), kExact));
      CHECK_THAT(pinned_dissipation_rate<3>(tm, tp, f, lam, s0dot), WithinAbs(dissipation_rate(f, lam, s0dot, jv2), kExact));
      // F0 = A t⁻ − B t⁺ with A = τ⁻ − λṡ0², B = τ⁺ − λṡ0²; it is in the cone of the faces' normals
      // iff F0·t⁻ ≥ 0 and F0·t⁺ ≤ 0 (the polar of the wedge's tangent cone {−t⁻, t⁺}).
      const V3 jt = tp - tm;
      const V3 nm = face_normal<3>(tm, jt), np = face_normal<3>(tp, jt);
      CHECK_THAT(nm.dot(tm), WithinAbs(0.0, kExact));
      CHECK(nm.dot(jt) < 0);
      const Eigen::Vector2d ab = pinned_cone<3>(F0, nm, np);
      CHECK_THAT((ab[0] * nm + ab[1] * np - F0).norm(), WithinAbs(0.0, 1e-12));
      CHECK(std::signbit(ab[1]) == std::signbit(F0.dot(tm)));
      CHECK(std::signbit(ab[0]) == std::signbit(-F0.dot(tp)));
      // Reversed orientation: t → −t, the sides swap, ṡ0 → −ṡ0 ([t] is unchanged): the same
      // reaction, the cone's coordinates swapped.
      const V3 F0r = pinned_reaction<3>(V3(-tp), V3(-tm), taup, taum, lam, -s0dot);
      CHECK_THAT((F0r - F0).norm(), WithinAbs(0.0, kExact));
      CHECK_THAT(pinned_tension_plus<3>(taup, V3(-tp), V3(-tm), f, lam, -s0dot), WithinAbs(taum, kExact));
      const Eigen::Vector2d abr = pinned_cone<3>(F0r, face_normal<3>(V3(-tp), jt), face_normal<3>(V3(-tm), jt));
      CHECK_THAT(abr[0], WithinAbs(ab[1], 1e-12));
      CHECK_THAT(abr[1], WithinAbs(ab[0], 1e-12));
    }
  }
}

TEST_CASE("pinned front: the lift-off margin has the signs of the normal cone's coordinates, and is defined at a peg",
          "[unit][shocks][jump][edge]") {
  // Against pinned_cone (F0 = α n⁻ + β n⁺): margin = min(F·t⁻, −F·t⁺) = min(β, α) sin θ at every turn angle
  // θ in (0, π), for forces inside and outside the cone.
  const Vector<2> zero = Vector<2>::Zero();
  for (const double theta : {0.3, 1.0, 1.5707963267948966, 2.5, 3.0}) {
    const Vector<2> tm(1.0, 0.0), tp(std::cos(theta), -std::sin(theta));
    const Vector<2> nm = face_normal<2>(tm, tp - tm), np = face_normal<2>(tp, tp - tm);
    for (const double a : {-1.0, 0.5, 2.0})
      for (const double b : {-0.7, 0.3, 1.5}) {
        const Vector<2> F = a * nm + b * np;
        const Eigen::Vector2d ab = pinned_cone<2>(F, nm, np);
        const double margin = pinned_lift_off_margin<2>(F, tm, tp, zero);
        CHECK_THAT(margin, WithinAbs(std::min(ab[0], ab[1]) * std::sin(theta), 1e-12));
      }
  }
  // A peg: the string turns by 180°, n⁻ = −n⁺ (pinned_cone is singular there); the cone is the half-plane
  // F·t⁻ ≥ 0, and F0 = (τ⁻ + τ⁺ − 2 λ ṡ0²) t⁻.
  const Vector<2> up(0.0, 1.0), down(0.0, -1.0);
  const Vector<2> F0 = pinned_reaction<2>(up, down, 3.0, 4.0, 1.0, 2.0);  // τ∓ = 3, 4 N, λ = 1, ṡ0 = 2
  CHECK_THAT(F0[1], WithinAbs(3.0 + 4.0 - 8.0, 1e-12));
  CHECK_THAT(pinned_lift_off_margin<2>(F0, up, down, zero), WithinAbs(-1.0, 1e-12));
  // In 3D the part of F along the edge's line does not count.
  const Vector<3> d(0.0, 0.0, 1.0), tm3(1.0, 0.0, 0.5), tp3(0.0, -1.0, 0.5);
  CHECK_THAT(pinned_lift_off_margin<3>(Vector<3>(1.0, 2.0, 5.0), tm3, tp3, d), WithinAbs(1.0, 1e-12));
}

TEST_CASE("touchdown front: the tensions and the reaction on a compatible state are the closed forms of docs/model.md §10",
          "[unit][shocks]") {
  // A plane y = 0 (e = x, n = y), the arc leaving it at θ; [v] = −ṡ0 (t − e) (the two sides compatible). By hand:
  // −t·[v] = ṡ0 (1 − cos θ), |[v]|² = 2 ṡ0² (1 − cos θ), so τ⁺ = (1 − f sgn ṡ0) λ ṡ0²; [v]·e = ṡ0 (1 − cos θ), so
  // τ⁻ = λ ṡ0² (1 − cos θ) + τ⁺ cos θ = λ ṡ0² (1 − f sgn ṡ0 cos θ); R = τ⁻ e − τ⁺ t + λ ṡ0² (t − e)
  // = f sgn ṡ0 λ ṡ0² (t − cos θ e) = f λ ṡ0 |ṡ0| sin θ n.
  const double lam = 0.7;
  const V2 e(1, 0), n(0, 1);
  for (const double theta_deg : {30.0, 60.0, 120.0})
    for (const double f : {0.0, 0.5, 1.0})
      for (const double s0dot : {1.3, -0.8}) {
        CAPTURE(theta_deg, f, s0dot);
        const double th = theta_deg * std::acos(-1.0) / 180, c = std::cos(th), sn = std::sin(th), sg = s0dot > 0 ? 1 : -1;
        const V2 t(c, sn), jump = -s0dot * (t - e);
        const double taup = touchdown_tension_plus<2>(t, c, jump, f, lam, s0dot);
        const double taum = touchdown_tension_minus<2>(taup, e, c, jump, lam, s0dot);
        CHECK(taup == Approx((1 - f * sg) * lam * s0dot * s0dot).epsilon(kExact).margin(kExact));
        CHECK(taum == Approx(lam * s0dot * s0dot * (1 - f * sg * c)).epsilon(kExact).margin(kExact));
        const V2 R = touchdown_reaction<2>(e, t, taum, taup, jump, lam, s0dot);
        CHECK(R.dot(e) == Approx(0).margin(kExact));
        CHECK(R.dot(n) == Approx(f * lam * s0dot * std::abs(s0dot) * sn).epsilon(kExact).margin(kExact));
        // The loads' power with the lying side at rest (v⁻ = 0, v⁺ = [v]): −τ⁺ t·[v] = ½ λ ṡ0 |[v]|² − D, the kinetic
        // energy the material crossing the front changes by, less the dissipation D = ½ f λ |ṡ0| |[v]|².
        CHECK(-taup * t.dot(jump) ==
              Approx(-dissipation_rate(f, lam, s0dot, jump.squaredNorm()) + 0.5 * lam * s0dot * jump.squaredNorm())
                  .epsilon(kExact)
                  .margin(kExact));
      }
}

TEST_CASE("touchdown front in 3D: the balance across the plane of e and n is (tau+ - lambda s0dot^2)(t.b) = 0",
          "[unit][shocks]") {
  // docs/model.md §10, "A touchdown front in 3D": e, b = n × e, n an orthonormal frame, t = c e + β b + σ n, and the
  // two sides compatible, [v] = −ṡ0 (t − e). By hand: −t·[v] = ṡ0 (1 − c) and |[v]|² = 2 ṡ0² (1 − c) as in 2D, so
  // τ⁺ = (1 − f sgn ṡ0) λ ṡ0² and τ⁻ = λ ṡ0² (1 − f sgn ṡ0 c); across, [v]·b = −ṡ0 β, so the load on the lying end
  // along b that keeps the reaction normal (touchdown_tension_minus with b for e) is τ_b = −λ ṡ0² β + τ⁺ β
  // = (τ⁺ − λ ṡ0²) β = −f λ ṡ0 |ṡ0| β: zero for f = 0 at any azimuth, nonzero for f > 0 unless β = 0. The reaction
  // R = τ⁻ e + τ_b b − τ⁺ t − λ ṡ0 [v] = f λ ṡ0 |ṡ0| σ n.
  const double lam = 0.7;
  const V3 n = V3(0.2, 1.0, -0.3).normalized(), e = V3(1.0, 0.2, 0.0).cross(n).normalized(), b = n.cross(e);
  for (const double elevation_deg : {20.0, 60.0})
    for (const double azimuth_deg : {0.0, 40.0, 90.0, 150.0})
      for (const double f : {0.0, 0.5, 1.0})
        for (const double s0dot : {1.3, -0.8}) {
          CAPTURE(elevation_deg, azimuth_deg, f, s0dot);
          const double el = elevation_deg * std::acos(-1.0) / 180, az = azimuth_deg * std::acos(-1.0) / 180;
          const double c = std::cos(el) * std::cos(az), beta = std::cos(el) * std::sin(az), sigma = std::sin(el);
          const double sg = s0dot > 0 ? 1 : -1;
          const V3 t = c * e + beta * b + sigma * n, jump = -s0dot * (t - e);
          const double taup = touchdown_tension_plus<3>(t, c, jump, f, lam, s0dot);
          const double taum = touchdown_tension_minus<3>(taup, e, c, jump, lam, s0dot);
          const double taub = touchdown_tension_minus<3>(taup, b, t.dot(b), jump, lam, s0dot);
          CHECK(taup == Approx((1 - f * sg) * lam * s0dot * s0dot).epsilon(kExact).margin(kExact));
          CHECK(taum == Approx(lam * s0dot * s0dot * (1 - f * sg * c)).epsilon(kExact).margin(kExact));
          CHECK(taub == Approx(-f * lam * s0dot * std::abs(s0dot) * beta).epsilon(kExact).margin(kExact));
          const V3 R = touchdown_reaction<3>(e, t, taum, taup, jump, lam, s0dot) + taub * b;
          CHECK(R.dot(e) == Approx(0).margin(kExact));
          CHECK(R.dot(b) == Approx(0).margin(kExact));
          CHECK(R.dot(n) == Approx(f * lam * s0dot * std::abs(s0dot) * sigma).epsilon(kExact).margin(kExact));
        }
}
