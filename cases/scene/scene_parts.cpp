// String scenes, step 2: SceneSpec -> the string every model is built on (scene_build.hpp): the
// shape discretized, the initial velocity, the effects and ends the scene declares, the solver
// options. Every InputError names the location of the key at fault.
#include <algorithm>
#include <cmath>

#include <Eigen/Geometry>
#include <fmt/format.h>

#include "cases/scene/scene_build.hpp"
#include "cases/scene/scene_text.hpp"
#include "mesh/discretize.hpp"
#include "mesh/errors.hpp"

namespace chainsim::scene_build {

using scene_text::join;

namespace {

/// Prescribed ends closer than this fraction of the string's length to being pulled taut are refused.
constexpr double kTautFraction = 1e-9;
/// Instants at which two prescribed end paths are sampled for their distance (over [0, t_end]).
constexpr int kEndPathSamples = 2001;

template <int dim>
Points<dim> as_points(const SceneSpec& spec, const std::vector<std::vector<double>>& rows, const std::string& key) {
  Points<dim> out(dim, static_cast<Eigen::Index>(rows.size()));
  for (std::size_t k = 0; k < rows.size(); ++k)
    out.col(static_cast<Eigen::Index>(k)) = as_vec<dim>(spec, rows[k], fmt::format("{}[{}]", key, k));
  return out;
}

template <int dim>
Vec<dim> unit(int axis) {
  Vec<dim> e = Vec<dim>::Zero();
  e[axis] = 1;
  return e;
}

/// The initial shape as a curve.
template <int dim>
std::unique_ptr<Curve<dim>> build_curve(const SceneSpec& spec, bool closed, const Vec<dim>& down) {
  const auto& sh = spec.shape;
  if (sh.kind == "polyline" || sh.kind == "points") {
    const Points<dim> points = as_points<dim>(spec, sh.points, "shape.points");
    auto polyline = at_key(spec, "shape.points", [&] { return polyline_curve<dim>(points, closed); });
    if (!sh.corner_radius) return polyline;
    if (closed)
      fail_at(spec, "shape.corner_radius",
              "shape.corner_radius does not apply to a closed string (string.closed = true): only the interior "
              "points of an open polyline are rounded");
    return at_key(spec, "shape.corner_radius", [&] { return rounded_polyline_curve<dim>(points, *sh.corner_radius); });
  }
  if (sh.kind == "arc" || sh.kind == "circle") {
    const Vec<dim> center = as_vec<dim>(spec, sh.center, "shape.center");
    const Vec<dim> axis1 = sh.axis1.empty() ? unit<dim>(0) : as_vec<dim>(spec, sh.axis1, "shape.axis1");
    const Vec<dim> axis2 = sh.axis2.empty() ? unit<dim>(1) : as_vec<dim>(spec, sh.axis2, "shape.axis2");
    const std::string axes = sh.axis2.empty() ? "shape.axis1" : "shape.axis2";
    if (sh.kind == "circle")
      return at_key(spec, axes, [&] { return circle_curve<dim>(center, sh.radius, axis1, axis2); });
    return at_key(spec, axes, [&] {
      return circle_arc_curve<dim>(center, sh.radius, sh.start_angle_deg * kPi / 180, sh.sweep_deg * kPi / 180, axis1,
                                   axis2);
    });
  }
  CHAINSIM_VERIFY(sh.kind == "catenary", "parse_shape admits only the kinds built here");
  if (!spec.length) fail_at(spec, "shape.kind", "a catenary shape needs string.length (the sag follows from it)");
  const Vec<dim> start = as_vec<dim>(spec, sh.start, "shape.start");
  const Vec<dim> end = as_vec<dim>(spec, sh.end, "shape.end");
  return at_key(spec, "shape.end", [&] { return catenary_curve<dim>(start, end, *spec.length, down); });
}

/// The number of links: string.nodes, or the length over string.link_length rounded (default 41 nodes).
int link_count(const SceneSpec& spec, double length, bool closed) {
  const int minimum = closed ? 3 : 1;
  if (spec.link_length) {
    const double links = std::round(length / *spec.link_length);
    if (links > kMaxNodes)
      fail_at(spec, "string.link_length",
              fmt::format("string.link_length = {} m asks for {:.3g} links on {} m: allowed at most {} nodes",
                          *spec.link_length, links, length, kMaxNodes));
    return std::max(minimum, static_cast<int>(links));
  }
  const int nodes = spec.nodes.value_or(41);
  const int links = closed ? nodes : nodes - 1;
  if (links < minimum)
    fail_at(spec, "string.nodes", fmt::format("string.nodes = {} is too small: a closed string needs at least 3 nodes",
                                              nodes));
  return links;
}

/// The scales of a run must leave its scaled problem well inside the double range: the solver forms
/// squares and products of them (energies λ v² ℓ, tensions λ (|g| ℓ + v²) + |F|, the reach
/// ℓ + v t_end + |g| t_end²), so each nonzero input scale lies in [kMinScale, kMaxScale] and each
/// derived one in [kMinScale², kMaxScale²] (mesh/errors.hpp). A scene outside is refused at its key
/// before the run, rather than ending in a non-finite value at its first step.

struct Scale {
  std::string key;   ///< the scene key that sets it
  std::string what;  ///< what it is, with its unit
  double value;
};

void check_scales(const SceneSpec& spec, const std::vector<Scale>& inputs, const std::vector<Scale>& derived) {
  auto check = [&](const Scale& s, double lo, double hi) {
    if (s.value == 0 || (s.value >= lo && s.value <= hi)) return;
    fail_at(spec, s.key,
            fmt::format("{} = {}: {} is {}, out of the range the solver can represent: allowed {} to {} "
                        "(or 0); the scaled problem would overflow or underflow",
                        s.key, text_of(spec, s.key), s.what, s.value, lo, hi));
  };
  for (const Scale& s : inputs) check(s, kMinScale, kMaxScale);
  for (const Scale& s : derived) check(s, kMinScale * kMinScale, kMaxScale * kMaxScale);
}

/// Whether `[velocity] kind = "tangential"` is the string sliding exactly along itself, set by the model
/// once its fronts have bent their links (StringModelOptions::sliding_speed), rather than the nodes'
/// averaged tangents (docs/scenes.md, "The tangential kind"): with slack = "allow" (a unilateral start),
/// over an edge or a peg, where a node beside the point would otherwise move along the chord that
/// crosses the corner and turn the bent link's short piece at speed / (its length), and with a touchdown front
/// (a surface with f), whose lying side and arc the averaged tangent at the front's corner would mix (the front
/// started at 0.64, 0.69, 0.73 m/s instead of 1 on 10, 40, 80 nodes).
bool slides_exactly(const SceneSpec& spec) {
  const bool touchdown = std::any_of(spec.effects.surfaces.begin(), spec.effects.surfaces.end(),
                                     [](const SurfaceEntry& e) { return e.f.has_value(); });
  return spec.solver.slack == "allow" || !spec.effects.edges.empty() || touchdown;
}

/// Two prescribed ends may never be pulled as far apart as the string is long (it would have to
/// stretch); sampled over [0, t_end].
template <int dim>
void check_prescribed_ends(const SceneSpec& spec, const std::vector<PrescribedNode<dim>>& prescribed, double length) {
  if (prescribed.size() < 2) return;
  const EndPath<dim>& a = *prescribed[0].path;
  const EndPath<dim>& b = *prescribed[1].path;
  for (int k = 0; k < kEndPathSamples; ++k) {
    const double t = spec.stop.t_end * k / (kEndPathSamples - 1);
    const double distance = (b.position(t) - a.position(t)).norm();
    if (distance > (1 - kTautFraction) * length)
      fail_at(spec, "ends.end",
              fmt::format("ends.start ({}) and ends.end ({}) are {:.6g} m apart at t = {:.6g} s, but the string is "
                          "{:.6g} m long: prescribed ends may not pull an inextensible string taut",
                          a.description(), b.description(), distance, t, length));
  }
}

}  // namespace

template <int dim>
SceneParts<dim> build_scene_parts(const SceneSpec& spec) {
  CHAINSIM_VERIFY(spec.dimension == dim, "build_scene_parts<dim> called for another dimension");
  const auto& sh = spec.shape;

  // 1. Gravity (its direction also orients a catenary).
  Vec<dim> g = Vec<dim>::Zero();
  if (spec.effects.gravity) g = as_vec<dim>(spec, *spec.effects.gravity, "effects.gravity.g");
  const Vec<dim> down = g.norm() > 0 ? Vec<dim>(g) : Vec<dim>(-unit<dim>(1));

  // 2. The shape, and the string on it.
  const bool closed = spec.closed.value_or(sh.kind == "circle");
  std::unique_ptr<Curve<dim>> curve = build_curve<dim>(spec, closed, down);
  if (curve->closed() != closed)
    fail_at(spec, spec.closed ? "string.closed" : "shape.kind",
            fmt::format("string.closed = {} but the shape ({}) is {}", closed, curve->description(),
                        curve->closed() ? "a closed curve" : "an open curve"));
  const double length = spec.length.value_or(curve->length());
  if (std::abs(curve->length() - length) > sh.length_tolerance * length)
    fail_at(spec, "string.length",
            fmt::format("string.length = {:.9g} m but the shape ({}) is {:.9g} m long: they differ by {:.3g} m, more "
                        "than shape.length_tolerance = {:g} (relative)",
                        length, curve->description(), curve->length(), curve->length() - length,
                        sh.length_tolerance));
  const int links = link_count(spec, length, closed);
  Chain<dim> chain =
      at_key(spec, "shape", [&] { return discretize(*curve, length, spec.density, links, closed, sh.length_tolerance); });
  if (spec.elements == "quadratic") {  // what quadratic elements hold (solver/quadratic_string.hpp)
    std::string why;
    if (spec.has_fronts_declared())
      why = "the scene has a front (a heap, a fold or an edge), which quadratic elements do not meet";
    else if (spec.has_fronts())
      why = "solver.kinks = \"insert\" gives the string a kink front where a kink forms, which quadratic elements "
            "do not meet";
    else if (closed)
      why = "the string is closed; quadratic elements hold open strings only";
    else if (chain.num_nodes() % 2 == 0)
      why = fmt::format("the string has {} nodes; quadratic elements need an odd number (two per element, plus one)",
                        chain.num_nodes());
    if (!why.empty())
      fail_at(spec, "string.elements", fmt::format("string.elements = \"quadratic\" is not allowed here: {}; allowed: "
                                                   "\"links\" (any string), \"quadratic\" (an open string without "
                                                   "fronts, an odd number of nodes)",
                                                   why));
  }
  const auto& vel = spec.velocity;
  if (vel.kind == "uniform") set_uniform_velocity(chain, as_vec<dim>(spec, vel.value, "velocity.value"));
  // (with slack = allow, or an edge or a peg, the model sets a tangential speed itself, along the string's
  // sides: StringModelOptions::sliding_speed)
  if (vel.kind == "tangential")
    at_key(spec, "velocity.speed", [&] {
      if (!slides_exactly(spec)) return set_tangential_velocity(chain, vel.speed);
      if (!std::isfinite(vel.speed))
        throw InputError(fmt::format("velocity.speed = {:g} is not a finite number", vel.speed));
    });
  if (vel.kind == "nodes") {
    const Points<dim> values = as_points<dim>(spec, vel.values, "velocity.values");
    at_key(spec, "velocity.values", [&] { set_node_velocities(chain, values); });
  }
  // A rigid rotation, v_i = ω × (x_i − c): the model sets it once the start has projected the positions onto the
  // links' lengths (StringModelOptions::rotation), so that it is rigid for the projected shape; the chain carries it
  // at the shape's nodes until then (the scales below, a module's set-up).
  std::optional<StringModelOptions::RigidRotation> rotation;
  if (vel.kind == "rotation") {
    const Vec<dim> center = as_vec<dim>(spec, vel.center, "velocity.center");
    const std::size_t components = dim == 2 ? 1 : 3;
    if (vel.omega.size() != components)
      fail_at(spec, "velocity.omega",
              fmt::format("velocity.omega = {} has {} component{} but string.dimension = {}: allowed {}",
                          text_of(spec, "velocity.omega"), vel.omega.size(), vel.omega.size() == 1 ? "" : "s",
                          spec.dimension, dim == 2 ? "a number (rad/s about the out-of-plane axis)" : "[wx, wy, wz]"));
    // Built apart and copied in: clang (14) judges the nested struct, whose members have default initializers, not
    // default-constructible for std::optional::emplace() (its trait was fixed inside the enclosing class).
    StringModelOptions::RigidRotation rigid;
    rigid.center.head<dim>() = center;
    if constexpr (dim == 2)
      rigid.omega.z() = vel.omega[0];
    else
      rigid.omega = Eigen::Vector3d(vel.omega[0], vel.omega[1], vel.omega[2]);
    rotation = rigid;
    Points<dim> values(dim, chain.num_nodes());
    for (int i = 0; i < chain.num_nodes(); ++i) values.col(i) = rotation->velocity<dim>(chain.positions().col(i));
    at_key(spec, "velocity.omega", [&] { set_node_velocities(chain, values); });
  }

  // 3. Effects and ends: exactly those the scene declares.
  std::vector<std::unique_ptr<Force<dim>>> forces;
  std::vector<PrescribedNode<dim>> prescribed;
  if (spec.effects.gravity) forces.push_back(std::make_unique<Gravity<dim>>(g));
  if (spec.effects.drag) forces.push_back(std::make_unique<Drag<dim>>(*spec.effects.drag));
  double forcing_period = INFINITY;
  double driven_speed = 0;  // of ends driven along a line (m/s)
  double force = 0;         // the largest end load, |F0| + |F1| (N)
  std::string force_key = "ends";
  auto add_end = [&](const EndSpec& end, int node, const std::string& key) {
    if (end.kind == "free") return;
    if (closed)
      fail_at(spec, key, fmt::format("{} = \"{}\": a closed string has no ends (string.closed = true)", key, end.kind));
    const Vec<dim> x0 = chain.positions().col(node);
    if (end.kind == "fixed") {
      prescribed.push_back({node, std::make_shared<FixedPoint<dim>>(x0)});
    } else if (end.kind == "driven" && end.path == "linear") {
      const Vec<dim> velocity = as_vec<dim>(spec, end.velocity, key + ".velocity");
      prescribed.push_back({node, std::make_shared<LinearPath<dim>>(x0, velocity)});
      driven_speed = std::max(driven_speed, velocity.norm());
    } else if (end.kind == "driven") {
      const Vec<dim> amplitude = as_vec<dim>(spec, end.amplitude, key + ".amplitude");
      prescribed.push_back({node, std::make_shared<HarmonicPath<dim>>(x0, amplitude, end.omega, end.path == "shake")});
      forcing_period = std::min(forcing_period, 2 * kPi / end.omega);
    } else {
      CHAINSIM_VERIFY(end.kind == "loaded", "parse_end admits only the kinds built here");
      const Vec<dim> f0 = end.force.empty() ? Vec<dim>::Zero() : as_vec<dim>(spec, end.force, key + ".force");
      const Vec<dim> amp = end.amplitude.empty() ? Vec<dim>::Zero() : as_vec<dim>(spec, end.amplitude, key + ".amplitude");
      if (!end.amplitude.empty()) forcing_period = std::min(forcing_period, 2 * kPi / end.omega);
      if (f0.norm() + amp.norm() > force) {
        force = f0.norm() + amp.norm();
        force_key = key + (end.force.empty() ? ".amplitude" : ".force");
      }
      forces.push_back(std::make_unique<EndLoad<dim>>(node, f0, amp, end.omega));
    }
  };
  add_end(spec.start, 0, "ends.start");
  add_end(spec.end, chain.num_nodes() - 1, "ends.end");
  if (prescribed.size() == 2 && chain.num_nodes() < 3)
    fail_at(spec, "string.nodes",
            fmt::format("string.nodes = {} but both ends are prescribed: the link between them could not move and "
                        "its tension would be undetermined; allowed nodes >= 3",
                        chain.num_nodes()));
  check_prescribed_ends<dim>(spec, prescribed, length);

  // 4. Options. Default Baumgarte time: a tenth of the shortest physical time scale: the pendulum
  // time sqrt(ℓ/|g|), the transit time ℓ/v of the fastest initial or driven motion, the period 2π/ω
  // of shaken or periodically loaded ends. The length of the run is no physical scale and counts
  // only when the scene has none of these: a short run must not shorten τ_b, since C''/τ_b² turns
  // the round-off left in the constraints into tensions (t_end = 1e-9 s gave -155 N for 0.3 N).
  const auto& so = spec.solver;
  double t_char = forcing_period;
  if (g.norm() > 0) t_char = std::min(t_char, std::sqrt(length / g.norm()));
  const double v_max = std::max(chain.velocities().colwise().norm().maxCoeff(), driven_speed);
  if (v_max > 0) t_char = std::min(t_char, length / v_max);
  if (!std::isfinite(t_char)) t_char = spec.stop.t_end;
  // 5. The scales, judged before the run (see check_scales).
  {
    const std::string velocity_key = vel.kind == "uniform"      ? "velocity.value"
                                     : vel.kind == "tangential" ? "velocity.speed"
                                     : vel.kind == "nodes"      ? "velocity.values"
                                     : vel.kind == "rotation"   ? "velocity.omega"
                                                                : "ends";
    const double t_end = spec.stop.t_end, gn = g.stableNorm();
    const double tension = spec.density * (gn * length + v_max * v_max) + force;
    check_scales(spec,
                 {{spec.length ? "string.length" : "shape", "the string's length (m)", length},
                  {"string.density", "the line density (kg/m)", spec.density},
                  {"effects.gravity.g", "|g| (m/s^2)", gn},
                  {velocity_key, "the fastest initial or driven speed (m/s)", v_max},
                  {"stop.t_end", "the run's length (s)", t_end},
                  {force_key, "the largest end load (N)", force},
                  {"solver.stabilization_time", "the Baumgarte time (s)", so.stabilization_time.value_or(0.0)}},
                 {{"effects.gravity.g", "the tension scale density (|g| length + v^2) + |F| (N)", tension},
                  {"stop.t_end", "the reach length + v t_end + |g| t_end^2 (m)",
                   length + v_max * t_end + gn * t_end * t_end},
                  {"effects.gravity.g", "the energy scale (tension scale x length, J)", tension * length}});
  }
  IntegratorOptions io;
  io.method = so.method;
  io.rtol = so.rtol;
  io.atol = so.atol;
  io.max_step = so.max_step;
  io.initial_step = so.initial_step;
  io.max_steps = so.max_steps;
  io.max_wall_s = so.max_wall_s.value_or(0.0);
  StringModelOptions mo;
  mo.stabilization_time = so.stabilization_time.value_or(defaults::kSceneStabilizationFraction * t_char);
  mo.backend = so.backend;
  mo.linear_solver = so.linear_solver;
  mo.elements = spec.elements;
  mo.slack = so.slack == "warn"     ? SlackPolicy::kWarn
             : so.slack == "ignore" ? SlackPolicy::kIgnore
             : so.slack == "allow"  ? SlackPolicy::kAllow
                                    : SlackPolicy::kStop;
  mo.snap_restitution = so.snap_restitution;
  if (spec.velocity.kind == "tangential" && slides_exactly(spec)) mo.sliding_speed = spec.velocity.speed;
  mo.rotation = rotation;
  if (mo.slack == SlackPolicy::kAllow) {
    if (spec.elements == "quadratic")
      at_key(spec, "solver.slack", [&] {
        throw InputError("solver.slack = \"allow\" needs link elements: string.elements = \"quadratic\" has no "
                         "tension per link to release");
      });
  }
  mo.slack_tolerance = so.slack_tolerance;
  StringSolverOptions run;
  run.integrator = io;
  run.t_end = spec.stop.t_end;
  run.output_interval = spec.output.interval;
  at_key(spec, "solver", [&] { run.validate(); });
  at_key(spec, "output.interval",
         [&] { run.check_output_budget(chain.num_nodes(), dim, spec.has_fronts(), spec.output.select); });
  return SceneParts<dim>{std::move(curve), std::move(chain), length, g, std::move(forces), std::move(prescribed),
                         t_char, mo, run};
}

template SceneParts<2> build_scene_parts<2>(const SceneSpec&);
template SceneParts<3> build_scene_parts<3>(const SceneSpec&);

std::vector<std::string> front_names(const SceneSpec& spec) {
  auto has_heap = [&](const char* side) {
    return std::any_of(spec.effects.heaps.begin(), spec.effects.heaps.end(),
                       [&](const HeapEntry& heap) { return heap.side == side; });
  };
  std::vector<std::string> names;
  if (has_heap("start")) names.push_back("heap_start");
  if (spec.effects.fold) names.push_back("fold");
  if (has_heap("end")) names.push_back("heap_end");
  for (std::size_t k = 0; k < spec.effects.edges.size(); ++k) names.push_back(fmt::format("edge{}", k));
  for (std::size_t k = 0; k < spec.effects.kinks.size(); ++k) names.push_back(fmt::format("kink{}", k));
  if (spec.solver.kinks == "insert") names.push_back("kink_formed");  // not in the string until it forms
  for (std::size_t k = 0; k < spec.effects.surfaces.size(); ++k)
    if (spec.effects.surfaces[k].f) names.push_back(fmt::format("touchdown{}", k));  // k: the surface's index
  return names;
}

std::vector<int> front_stop_indices(const SceneSpec& spec) {
  const std::vector<std::string> names = front_names(spec);
  std::vector<int> out;
  for (std::size_t k = 0; k < spec.stop.fronts.size(); ++k) {
    const std::string& front = spec.stop.fronts[k].front;
    const auto it = std::find(names.begin(), names.end(), front);
    if (it == names.end()) {
      const std::string what = front == "fold"                      ? "fold ([effects.fold])"
                               : front.rfind("touchdown", 0) == 0 ? fmt::format("touchdown front ([[effects.surface]] {} with f)", front.substr(9))
                                               : fmt::format("heap on side \"{}\"", front.substr(5));
      fail_at(spec, fmt::format("stop.front[{}].front", k),
              fmt::format("stop.front[{}].front = \"{}\" but the scene has no {}; {}", k, front, what,
                          names.empty() ? "it has no fronts" : "its fronts: " + join(names)));
    }
    out.push_back(static_cast<int>(it - names.begin()));
  }
  return out;
}

}  // namespace chainsim::scene_build
