// The chain fountain (docs/model.md §4.5; cases/scenes/chain_fountain.toml): a chain drawn out of a pot that pushes
// (f_p < 0) and falling onto a heap on the floor (f_f) H below. Checked against the closed form of the steady state,
// written here without the solver's or the scene script's code:
//   v² = g H / (f_p + f_f),  T − λ v² = λ g (y − y_c),  y_c = −f_p v² / g,
//   the inverted catenary y = y_c − a cosh((x − x_c)/a) leaving the pot (the origin) at the angle θ of its mouth:
//   a = y_c cos θ, x_c = a asinh(tan θ); the top of the fountain at y_c − a above the pot.
#include <algorithm>
#include <cmath>
#include <filesystem>
#include <string>
#include <vector>

#include <catch2/catch.hpp>
#include <fmt/format.h>

#include "cases/scene/front_scene.hpp"
#include "cases/scene/scene.hpp"
#include "solver/string_solver.hpp"
#include "tests/convergence/observed_order.hpp"

using namespace chainsim;
using chainsim::test::fitted_order;

namespace {

// The scene's physics (checked against the scene file below).
constexpr double kG = 9.81, kH = 0.5, kThetaDeg = 70.0, kFPot = -0.2, kFFloor = 0.6;

struct Steady {
  double v, yc, a, xc, rise, x_floor;
};

Steady steady(double f_pot) {
  Steady s{};
  const double theta = kThetaDeg * M_PI / 180;
  s.v = std::sqrt(kG * kH / (f_pot + kFFloor));
  s.yc = -f_pot * s.v * s.v / kG;
  s.a = s.yc * std::cos(theta);
  s.xc = s.a * std::asinh(std::tan(theta));
  s.rise = s.yc - s.a;
  s.x_floor = s.xc + s.a * std::acosh((s.yc + kH) / s.a);
  return s;
}

/// The distance of (x, y) from the catenary of `s`, to second order in the distance: |F| / |∇F| with
/// F = y_c − y − a cosh((x − x_c)/a).
double distance(const Steady& s, double x, double y) {
  const double c = std::cosh((x - s.xc) / s.a);
  return std::abs(s.yc - y - s.a * c) / c;
}

std::filesystem::path fountain_scene() {
  return std::filesystem::path(CHAINSIM_SOURCE_DIR) / "cases" / "scenes" / "chain_fountain.toml";
}

struct FountainRun {
  RunSummary run;
  double speed_error = 0;  ///< max over the run of | |ṡ0| − v | at the pot and at the floor (m/s)
  double rise = 0;         ///< the highest moving node at the end (m)
  double shape_error = 0;  ///< max distance of a moving node from the steady catenary at the end (m)
  double speed = 0;        ///< the pot's |ṡ0| at the end (m/s)
  std::vector<double> t, pot_speed, floor_x;  ///< per step: time, the pot's |ṡ0|, the floor contact's x
};

FountainRun run_fountain(const std::vector<std::string>& overrides, const Steady& reference) {
  const SceneSpec spec = parse_scene(fountain_scene(), overrides);
  FrontScene<2> scene = build_front_scene<2>(spec);
  StringSolver<2> solver(*scene.model, scene.solver);
  solver.run();
  FountainRun r;
  r.run = solver.summary();
  for (const StepSample& s : r.run.samples) {
    r.t.push_back(s.t);
    r.pot_speed.push_back(std::abs(s.fronts[0].s0_dot));
    r.floor_x.push_back(s.fronts[1].position[0]);
    for (const FrontValues& front : s.fronts)
      r.speed_error = std::max(r.speed_error, std::abs(std::abs(front.s0_dot) - reference.v));
  }
  r.speed = r.pot_speed.back();
  const StringModel<2>& model = *scene.model;
  int top = -1;
  for (const ArcRange& arc : model.arcs())
    for (int i = arc.first; i <= arc.last; ++i) {
      const double x = model.x()(0, i), y = model.x()(1, i);
      if (top < 0 || y > model.x()(1, top)) top = i;
      r.shape_error = std::max(r.shape_error, distance(reference, x, y));
    }
  // The top of the fountain: the vertex of the parabola y(x) through the highest node and its neighbours (the
  // highest node alone is up to h²/(8a) below it).
  const double x0 = model.x()(0, top - 1), x1 = model.x()(0, top), x2 = model.x()(0, top + 1);
  const double y0 = model.x()(1, top - 1), y1 = model.x()(1, top), y2 = model.x()(1, top + 1);
  const double d01 = (y1 - y0) / (x1 - x0), d12 = (y2 - y1) / (x2 - x1), c2 = (d12 - d01) / (x2 - x0);
  const double c1 = d01 - c2 * (x0 + x1);  // y = y0 + c1 (x − …): the parabola's slope is c1 + 2 c2 x
  const double xv = -c1 / (2 * c2);
  r.rise = y0 + d01 * (xv - x0) + c2 * (xv - x0) * (xv - x1);
  return r;
}

}  // namespace

TEST_CASE("the chain fountain's scene is the steady state of docs/model.md §4.5", "[fountain]") {
  const SceneSpec spec = parse_scene(fountain_scene());
  REQUIRE(spec.effects.heaps.size() == 2);
  CHECK(spec.effects.heaps[0].pot);
  CHECK(spec.effects.heaps[0].dissipation == kFPot);
  CHECK(spec.effects.heaps[1].dissipation == kFFloor);
  CHECK(spec.effects.heaps[1].on_plane);
  CHECK(spec.effects.plane->point[1] == -kH);
  // The closed form at these numbers (B&W's alpha = 0.2, beta = 0.6): v = sqrt(9.81 * 0.5 / 0.4).
  const Steady s = steady(kFPot);
  CHECK_THAT(s.v, Catch::Matchers::WithinRel(3.50178525897863, 1e-14));
  CHECK_THAT(s.yc, Catch::Matchers::WithinRel(0.25, 1e-14));
  // The scene's initial speed and the heaps' points.
  CHECK_THAT(spec.velocity.speed, Catch::Matchers::WithinRel(s.v, 1e-14));
  CHECK_THAT(spec.effects.heaps[1].point[0], Catch::Matchers::WithinAbs(s.x_floor, 1e-12));
}

/// Overrides that lay the chain_fountain scene out on the catenary of `shape` (401 points from the pot to the floor,
/// at equal arc length σ from its top, and `content` m in the pot straight below it), moving at `speed`.
std::vector<std::string> laid_on(const Steady& shape, double content, double speed) {
  const double theta = kThetaDeg * M_PI / 180;
  const double s1 = -shape.a * std::tan(theta), s2 = std::sqrt((shape.yc + kH) * (shape.yc + kH) - shape.a * shape.a);
  std::string points = fmt::format("[[0.0, {:.17g}]", -content);
  double chords = 0, px = 0, py = 0;
  for (int k = 0; k <= 400; ++k) {
    const double sigma = s1 + (s2 - s1) * k / 400;
    const double x = k == 0 ? 0.0 : shape.xc + shape.a * std::asinh(sigma / shape.a);
    const double y = k == 0 ? 0.0 : k == 400 ? -kH : shape.yc - std::sqrt(shape.a * shape.a + sigma * sigma);
    if (k > 0) chords += std::hypot(x - px, y - py);
    points += fmt::format(", [{:.17g}, {:.17g}]", x, y);
    px = x;
    py = y;
  }
  points += "]";
  return {"shape.points=" + points, fmt::format("effects.heap[0].s0={:.17g}", content),
          fmt::format("effects.heap[1].s0={:.17g}", content + chords),
          fmt::format("effects.heap[1].point=[{:.17g}, -0.5]", px), fmt::format("velocity.speed={:.17g}", speed)};
}


TEST_CASE("the steady chain fountain: speed, rise and shape converge to the closed form", "[fountain][convergence]") {
  // Four meshes (h = 4, 2, 1, 0.5 cm; 24 to 196 nodes in the air), 0.4 s each: the chain in the air is replaced
  // 1.4 times. The pot's direction is imposed on the nodes it gives out (docs/shocks.md, "A pot"), a condition of
  // first order in h. Measured (erk5, rtol 1e-9), errors at the end (the speed: the largest over the run, at
  // both heaps):
  //   nodes   speed (m/s)   rise (m)    shape (m)
  //   101     6.11e-2       2.47e-3     7.44e-3
  //   201     1.21e-2       4.24e-4     3.35e-3
  //   401     4.23e-3       4.54e-4     1.77e-3
  //   801     1.22e-3       2.63e-4     8.77e-4
  // fitted orders 1.86 (speed), 0.96 (rise), 1.03 (shape). The bounds sit about 0.2 below.
  const Steady s = steady(kFPot);
  const std::vector<int> nodes = {101, 201, 401, 801};
  std::vector<double> speed, rise, shape;
  for (int n : nodes) {
    const FountainRun r = run_fountain({fmt::format("string.nodes={}", n), "stop.t_end=0.4"}, s);
    INFO(n << " nodes: " << r.run.stop_reason << r.run.error);
    REQUIRE(r.run.status == "completed");
    speed.push_back(r.speed_error);
    rise.push_back(std::abs(r.rise - s.rise));
    shape.push_back(r.shape_error);
    WARN(fmt::format("{} nodes: speed error {:.3e} m/s, rise error {:.3e} m, shape error {:.3e} m", n, speed.back(),
                     rise.back(), shape.back()));
    // Against the scale of each: v = 3.5 m/s, the rise 0.164 m (2 % on the coarsest mesh, 0.2 % on the finest).
    CHECK(r.rise - s.rise < 0.02 * s.rise);
  }
  CHECK(fitted_order(speed) > 1.6);
  CHECK(fitted_order(rise) > 0.75);
  CHECK(fitted_order(shape) > 0.85);
  CHECK(shape.back() < 1e-3);
  CHECK(rise.back() < 4e-4);
  CHECK(speed.back() < 2e-3);
}

TEST_CASE("a chain fountain started off its steady state converges to it", "[fountain]") {
  // The same pot and floor; the chain starts 10 % slow (0.9 v) on the steady shape of a weaker pot (f = -0.1, which
  // leaves the pot in the same direction but rises 0.066 m instead of 0.164 m and meets the floor 0.21 m nearer).
  // Nothing but the pot's direction, the heaps' f and H set the steady state, so the run must forget its start.
  // How fast: a chain moving along a fixed curve would regain its speed at the rate 2 g H / (v L) = 2.9 /s
  // (λ L dv/dt = λ g H − (f_p + f_f) λ v²), but the curve itself changes only by being carried off: both
  // transverse waves run downstream (T < λ v² all along, c = sqrt(T/λ) < v), the slow one at v − c, which near
  // the top is g a/(2 v) ≈ 0.12 m/s; it crosses the fountain in ∫ ds/(v − c) = 3.1 s. Measured here (401 nodes,
  // 2 s): the speed's deficit 0.35 m/s → 0.26 (0.5 s), 0.156 (1 s), 0.066 m/s (2 s), e-folding in 1.1 s; the rise
  // 0.066 → 0.160 m (steady 0.1645); the floor contact, last, 0.181 → 0.298 m (steady 0.393), e-folding in 2.5 s,
  // the slow wave's time.
  const Steady s = steady(kFPot), off = steady(-0.1);
  std::vector<std::string> overrides = laid_on(off, 7.0, 0.9 * s.v);
  overrides.insert(overrides.end(), {"string.nodes=401", "stop.t_end=2.0"});
  const FountainRun r = run_fountain(overrides, s);
  INFO(r.run.stop_reason << r.run.error);
  REQUIRE(r.run.status == "completed");
  // The pot's speed deficit |v − |ṡ0|| at 0.5 s steps: after the first 0.25 s (the shape's first rearrangement
  // slows the chain), it falls monotonically.
  std::vector<double> deficit;
  for (double t : {0.25, 0.5, 1.0, 1.5, 2.0}) {
    const auto it = std::lower_bound(r.t.begin(), r.t.end(), t - 1e-9);
    const double d = std::abs(s.v - r.pot_speed[static_cast<std::size_t>(std::min<std::ptrdiff_t>(
                                   it - r.t.begin(), static_cast<std::ptrdiff_t>(r.t.size()) - 1))]);
    deficit.push_back(d);
  }
  WARN(fmt::format("speed deficit at 0.25, 0.5, 1, 1.5, 2 s: {:.4f} {:.4f} {:.4f} {:.4f} {:.4f} m/s; rise {:.4f} m "
                   "(steady {:.4f}), floor contact at x = {:.4f} m (steady {:.4f}, start {:.4f})",
                   deficit[0], deficit[1], deficit[2], deficit[3], deficit[4], r.rise, s.rise, r.floor_x.back(),
                   s.x_floor, off.x_floor));
  for (std::size_t k = 1; k < deficit.size(); ++k) CHECK(deficit[k] < deficit[k - 1]);
  CHECK(deficit.back() < 0.3 * 0.1 * s.v);              // a third of the initial deficit 0.1 v, at most
  CHECK(s.rise - r.rise < 0.1 * (s.rise - off.rise));  // the rise: within a tenth of its initial deficit
  CHECK(std::abs(s.x_floor - r.floor_x.back()) < 0.6 * (s.x_floor - off.x_floor));  // the floor contact: 0.45
}

TEST_CASE("the chain fountain stays on its steady state, which the mesh approaches at first order", "[fountain][convergence]") {
  // 12 m in the pot, 3 s (the chain in the air is replaced 11 times, the slow wave crosses once): h = 2 and 1 cm.
  // Between 2 s and 3 s the floor contact moves by 6.7e-4 m (2 cm) and 3.7e-4 m (1 cm), the speed by 9e-5 m/s: the
  // discrete fountain is steady (the bounds: 1e-3 m, 2e-3 m/s). It differs from the closed form by O(h), the pot's direction being imposed on the nodes
  // it gives out (docs/shocks.md, "A pot"). Measured at 3 s (and 4.6 s, 16 m in the pot; 3401 nodes, h = 5 mm):
  //   h       rise − h_closed   x_floor − closed   speed − v
  //   2 cm    +4.17e-3 m        −1.30e-2 m         −3.6e-4 m/s
  //   1 cm    +2.41e-3 m        −7.12e-3 m         −3.4e-4 m/s
  //   5 mm    +1.33e-3 m        −3.53e-3 m         −2.2e-5 m/s (4.6 s)
  const Steady s = steady(kFPot);
  std::vector<double> rise, floor_x;
  for (int n : {621, 1241}) {  // ℓ = 12.98 m
    std::vector<std::string> overrides = laid_on(s, 12.0, s.v);
    overrides.insert(overrides.end(), {fmt::format("string.nodes={}", n), "stop.t_end=3.0"});
    const FountainRun r = run_fountain(overrides, s);
    INFO(n << " nodes: " << r.run.stop_reason << r.run.error);
    REQUIRE(r.run.status == "completed");
    const auto at = [&](const std::vector<double>& series, double t) {
      const auto it = std::lower_bound(r.t.begin(), r.t.end(), t - 1e-9);
      return series[static_cast<std::size_t>(it - r.t.begin())];
    };
    WARN(fmt::format("{} nodes, 3 s: rise − closed form {:+.3e} m, floor contact {:+.3e} m, speed {:+.3e} m/s; floor "
                     "contact moved {:.2e} m and the speed {:.2e} m/s from 2 s",
                     n, r.rise - s.rise, r.floor_x.back() - s.x_floor, r.speed - s.v,
                     r.floor_x.back() - at(r.floor_x, 2.0), r.speed - at(r.pot_speed, 2.0)));
    CHECK(std::abs(r.floor_x.back() - at(r.floor_x, 2.0)) < 1e-3);
    CHECK(std::abs(r.speed - at(r.pot_speed, 2.0)) < 2e-3);
    CHECK(std::abs(r.speed - s.v) < 1e-3);
    rise.push_back(std::abs(r.rise - s.rise));
    floor_x.push_back(std::abs(r.floor_x.back() - s.x_floor));
  }
  // Halving h: first order (measured 0.79 and 0.88 for the rise, 0.87 and 0.93 for the floor contact).
  CHECK(fitted_order(rise) > 0.6);
  CHECK(fitted_order(floor_x) > 0.7);
  CHECK(rise.back() < 0.02 * s.rise);
}
