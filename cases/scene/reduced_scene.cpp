// model = "reduced": which canonical problem a scene is (reduced_scene.hpp).
//
// Steps: 1. the scene must be a valid scene with fronts; 2. the effects (gravity, one front, no
// drag); 3. the problem from its front, with that problem's ends, table and cutoff; 4. the shape
// against the problem's straight arms along gravity, and rest; 5. the reduced setup.
#include "cases/scene/reduced_scene.hpp"

#include <algorithm>
#include <cmath>

#include <fmt/format.h>

#include "cases/scene/front_scene.hpp"
#include "cases/scene/scene_build.hpp"
#include "mesh/errors.hpp"

namespace chainsim {

using scene_build::as_vec;
using scene_build::at_key;
using scene_build::fail_at;

namespace {

/// Positions within this fraction of ℓ of the canonical ones, and directions within this angle
/// (rad), are the canonical geometry; speeds below this fraction of sqrt(g ℓ) are rest.
constexpr double kGeometryTolerance = 1e-9;

std::string degrees(double radians) {
  const double deg = radians * 180 / kPi;
  return deg >= 0.05 ? fmt::format("{:.1f}°", deg) : fmt::format("{:.3g}°", deg);
}

template <int dim>
double angle_between(const Vec<dim>& a, const Vec<dim>& b) {
  const double c = a.stableNormalized().dot(b.stableNormalized());  // no overflow for huge vectors
  return std::acos(std::clamp(c, -1.0, 1.0));
}

/// A straight part of the canonical shape: the material s ∈ [s_from, s_to] at x(s) = anchor + (s − s_anchor) dir.
template <int dim>
struct Arm {
  std::string name;  ///< for messages: "falling part", "hanging part", "resting arm", "moving arm"
  double s_from = 0, s_to = 0, s_anchor = 0;
  Vec<dim> anchor, dir;
  Vec<dim> at(double s) const { return anchor + (s - s_anchor) * dir; }
};

template <int dim>
ReducedSetup match(const SceneSpec& spec) {
  const std::string model_key = "model";
  auto refuse = [&](const std::string& why) { fail_at(spec, model_key, "model = \"reduced\" " + why); };
  const auto& fx = spec.effects;

  // 1.-2. The effects: a front, gravity, nothing the reduced models lack. (A scene that is not even
  //       a valid scene is refused for that first, at its own key.)
  if (!spec.has_fronts())
    refuse("needs a fold or a heap: the reduced models are the falling chain (a heap at the end, on a table), the "
           "folded chain (a fold) and the sliding chain (a heap at the start, at a hole)");
  if (spec.has_obstacles())
    refuse("has no obstacle: remove [[effects.surface]] and [[effects.cylinder]] (the string solver runs them: model = "
           "\"string\")");
  if (!fx.edges.empty()) refuse("has no edge: remove [[effects.edge]] (the string solver runs it: model = \"string\")");
  if (!fx.kinks.empty()) refuse("has no kink: remove [[effects.kink]] (the string solver runs it: model = \"string\")");
  const FrontScene<dim> scene = build_front_scene<dim>(spec);
  const std::vector<std::string> names = scene_build::front_names(spec);
  if (names.size() > 1)
    refuse(fmt::format("needs exactly one front (a heap or a fold): the scene has {} ({}, {}{})", names.size(),
                       names[0], names[1], names.size() > 2 ? ", " + names[2] : ""));
  if (!fx.gravity) refuse("needs gravity ([effects.gravity]): each reduced model is driven by it");
  const Vec<dim> g = as_vec<dim>(spec, *fx.gravity, "effects.gravity.g");
  if (!(g.norm() > 0)) refuse("needs gravity: effects.gravity.g is zero");
  if (fx.drag) refuse("has no drag: remove [effects.drag]");
  const Vec<dim> down = g.stableNormalized();
  const Chain<dim>& chain = scene.model->chain();
  const double ell = chain.length();

  // 3. The problem, its ends, its table and its cutoff.
  ReducedSetup setup;
  setup.chain.length = ell;
  setup.chain.density = chain.density();
  setup.chain.gravity = g.norm();
  std::vector<Arm<dim>> arms;
  // The cutoff: the one stop event, on `front`, at lo < s0 < hi.
  auto cutoff = [&](const std::string& front, double lo, double hi, const char* meaning) {
    const bool ok = spec.stop.fronts.size() == 1 && spec.stop.fronts[0].front == front &&
                    spec.stop.fronts[0].s0 > lo && spec.stop.fronts[0].s0 < hi;
    if (!ok)
      refuse(fmt::format("needs a cutoff for the {} chain: one [[stop.front]] with front = \"{}\" and {:g} < s0 < "
                         "{:g} ({}; the reduced model is singular at the end of the motion)",
                         to_string(setup.problem), front, lo, hi, meaning));
    return spec.stop.fronts[0].s0;
  };
  if (fx.fold) {
    setup.problem = Problem::kFolded;
    const double s0 = fx.fold->s0;
    setup.chain.dissipation = fx.fold->dissipation;
    if (spec.start.kind != "fixed")
      refuse(fmt::format("needs the folded chain's start fixed: ends.start = \"{}\" (the resting arm hangs from it)",
                         spec.start.kind));
    if (spec.end.kind == "loaded") {
      if (!spec.end.amplitude.empty())
        refuse("needs a constant load on the free end: ends.end.amplitude makes it vary");
      const Vec<dim> f0 = as_vec<dim>(spec, spec.end.force, "ends.end.force");
      setup.force = -f0.dot(down);
      if (f0.norm() > 0 && angle_between<dim>(f0, -down) > kGeometryTolerance)
        refuse(fmt::format("needs the load on the free end along -g (upward, F >= 0): ends.end.force is tilted {} "
                           "from it",
                           degrees(angle_between<dim>(f0, -down))));
    } else if (spec.end.kind != "free") {
      refuse(fmt::format("needs the folded chain's end free or loaded: ends.end = \"{}\"", spec.end.kind));
    }
    const Vec<dim> x0 = chain.positions().col(0);
    arms.push_back({"resting arm", 0, s0, 0, x0, down});
    arms.push_back({"moving arm", s0, ell, s0, Vec<dim>(x0 + s0 * down), Vec<dim>(-down)});
    setup.eta0 = s0 / ell;
    setup.eps = 1 - cutoff("fold", s0, ell, "s0 = (1 - eps) l") / ell;
  } else {
    const HeapEntry& heap = fx.heaps.front();
    const Vec<dim> point = as_vec<dim>(spec, heap.point, "effects.heap[0].point");
    setup.chain.dissipation = heap.dissipation;
    if (heap.side == "end") {
      setup.problem = Problem::kFalling;
      if (!heap.on_plane)
        refuse("needs the falling chain's heap on a table: on_plane = true, with [effects.plane] perpendicular to "
               "gravity");
      const Vec<dim> normal = as_vec<dim>(spec, fx.plane->normal, "effects.plane.normal");
      if (angle_between<dim>(normal, -down) > kGeometryTolerance)
        refuse(fmt::format("needs the table perpendicular to gravity: effects.plane.normal is tilted {} from -g",
                           degrees(angle_between<dim>(normal, -down))));
      if (spec.start.kind != "free")
        refuse(fmt::format("needs the falling chain's top end free: ends.start = \"{}\"", spec.start.kind));
      arms.push_back({"falling part", 0, heap.s0, heap.s0, point, down});
      setup.eta0 = std::min(heap.s0 / ell, 1.0);  // s0 = ℓ as written may exceed the chain's length by round-off
      setup.eps = cutoff("heap_end", 0.0, heap.s0, "s0 = eps l") / ell;
    } else {
      setup.problem = Problem::kSliding;
      if (heap.on_plane)
        refuse("needs the sliding chain's heap at a hole: on_plane = false (the front pinned at the heap point)");
      if (heap.pot)
        refuse("has no pot: the reduced sliding chain draws from a heap with 0 <= f <= 1 (effects.heap[0].pot = true)");
      if (spec.end.kind != "free")
        refuse(fmt::format("needs the sliding chain's lower end free: ends.end = \"{}\"", spec.end.kind));
      if (!spec.stop.fronts.empty())
        refuse("stops the sliding chain when the heap runs empty (eta = 1): remove [[stop.front]]");
      arms.push_back({"hanging part", heap.s0, ell, heap.s0, point, down});
      setup.eta0 = (ell - heap.s0) / ell;
    }
  }
  if (spec.start.kind == "loaded")
    refuse(fmt::format("has no load on the start of the {} chain: ends.start is loaded", to_string(setup.problem)));

  // 4. The shape: each arm straight along gravity from its anchor, and at rest.
  for (const Arm<dim>& arm : arms) {
    int worst = -1, far = -1;
    double worst_off = 0;
    for (int i = 0; i < chain.num_nodes(); ++i) {
      const double s = chain.node_coordinate(i);
      if (s < arm.s_from - 1e-12 * ell || s > arm.s_to + 1e-12 * ell) continue;
      const double off = (chain.positions().col(i) - arm.at(s)).norm();
      if (off > worst_off) {
        worst_off = off;
        worst = i;
      }
      if (far < 0 || std::abs(s - arm.s_anchor) > std::abs(chain.node_coordinate(far) - arm.s_anchor)) far = i;
      const double speed = chain.velocities().col(i).norm();
      if (speed > kGeometryTolerance * std::sqrt(g.norm() * ell))
        refuse(fmt::format("needs the string at rest: node {} (s = {:g} m) moves at {:.3g} m/s", i, s, speed));
    }
    if (worst_off <= kGeometryTolerance * ell) continue;
    const double s_far = chain.node_coordinate(far);
    const double tilt = angle_between<dim>(Vec<dim>(chain.positions().col(far) - arm.anchor),
                                           Vec<dim>(arm.at(s_far) - arm.anchor));
    if (tilt > kGeometryTolerance)
      refuse(fmt::format("needs a straight string along gravity: the {} is tilted {} from it", arm.name, degrees(tilt)));
    refuse(fmt::format("needs a straight string along gravity: the {} is not straight (node {} is {:.3g} m off the "
                       "line along gravity)",
                       arm.name, worst, worst_off));
  }

  // 5. The setup, with the scene's end time as the safety stop.
  setup.t_max_over_t0 = spec.stop.t_end / setup.chain.t0();
  at_key(spec, model_key, [&] { setup.validate(); });
  return setup;
}

}  // namespace

ReducedSetup match_canonical_problem(const SceneSpec& spec) {
  return spec.dimension == 3 ? match<3>(spec) : match<2>(spec);
}

}  // namespace chainsim
