// Scenes with shocks: SceneSpec -> the string with front tracking, the run's summary and its outputs (front_scene.hpp).
//
// Steps of build_front_scene: 1. the string, as for any scene (scene_build.hpp); 2. what a string
// with fronts cannot have (a closed string, ends inside heaps, keys for scenes without fronts);
// 3. each heap against the string, the shape and its plane; 4. the fold; 5. the stop events;
// 6. the model (its own layout checks re-located at the fronts' keys) and the run options.
#include "cases/scene/front_scene.hpp"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <limits>
#include <optional>

#include <fmt/format.h>

#include "cases/scene/scene_build.hpp"
#include "cases/scene/scene_front_keys.hpp"
#include "mesh/errors.hpp"
#include "solver/output.hpp"
#include "shocks/touchdown_front.hpp"
#include "solver/string_solver.hpp"

namespace chainsim {

using scene_build::as_vec;
using scene_build::as_unit_vec;
using scene_build::at_key;
using scene_build::fail_at;
using scene_build::text_of;

namespace {

/// A heap point, a fold or a stop event closer than this (relative to ℓ) to where it should be is
/// there (the front tracker checks the fronts' initial positions to 1e-6 ℓ as well).
constexpr double kPlaceTolerance = 1e-6;
/// A fold's arms must be antiparallel to this angle (rad).
constexpr double kFoldAngleTolerance = 1e-6;
/// Step (relative to ℓ) on each side of a fold or an edge for the shape's tangents there.
constexpr double kTangentStep = 1e-4;
/// The shape must turn by more than this (rad) at an edge's point: where it runs straight through, the
/// edge's reaction and its lift-off margin vanish identically.
constexpr double kEdgeTurnTolerance = 1e-6;

/// The shape's unit tangents just before and just after s0: its chords over kTangentStep ℓ on each side;
/// nothing where s0 is closer than that to an end of the string.
template <int dim>
std::optional<std::pair<Vec<dim>, Vec<dim>>> shape_tangents(const Curve<dim>& curve, double s0, double ell) {
  const double d = kTangentStep * ell;
  if (!(s0 - d > 0 && s0 + d < ell)) return std::nullopt;
  return std::pair<Vec<dim>, Vec<dim>>((curve.point(s0) - curve.point(s0 - d)).normalized(),
                                       (curve.point(s0 + d) - curve.point(s0)).normalized());
}

/// The angle (rad) by which the shape turns at s0 (between shape_tangents); nothing near an end.
template <int dim>
std::optional<double> shape_turn(const Curve<dim>& curve, double s0, double ell) {
  const auto t = shape_tangents<dim>(curve, s0, ell);
  if (!t) return std::nullopt;
  return std::acos(std::clamp(t->first.dot(t->second), -1.0, 1.0));
}


template <int dim>
nlohmann::json to_array(const Vec<dim>& v) {
  nlohmann::json a = nlohmann::json::array();
  for (int d = 0; d < dim; ++d) a.push_back(v[d]);
  return a;
}

/// "front 2 reached s0 = …" (the front tracker's wording) -> "the heap_end front reached s0 = …".
std::string name_fronts(const std::string& reason, const std::vector<std::string>& names) {
  const std::string prefix = "front ";
  if (reason.rfind(prefix, 0) != 0) return reason;
  std::size_t end = prefix.size();
  while (end < reason.size() && std::isdigit(static_cast<unsigned char>(reason[end]))) ++end;
  if (end == prefix.size()) return reason;
  const std::size_t k = std::stoul(reason.substr(prefix.size(), end - prefix.size()));
  if (k >= names.size()) return reason;
  return fmt::format("the {} front{}", names[k], reason.substr(end));
}

/// The key a layout refusal of the tracker is located at: the first heap, else the fold, else the first
/// edge, else the first kink.
template <int dim>
std::string fit_key_of(const SceneSpec& spec, const std::optional<FoldSpec>& fold, const std::vector<HeapSpec<dim>>& heaps) {
  if (!heaps.empty()) return "effects.heap[0]";
  if (fold) return "effects.fold.s0";
  for (std::size_t k = 0; k < spec.effects.surfaces.size(); ++k)
    if (spec.effects.surfaces[k].f && spec.effects.edges.empty() && spec.effects.kinks.empty())
      return fmt::format("effects.surface[{}].f", k);
  if (spec.effects.edges.empty() && !spec.effects.kinks.empty()) return "effects.kink[0].s0";
  return spec.effects.edges.empty() ? "effects.fold" : "effects.edge[0]";
}

/// A table that ends at an edge ([[effects.surface]] edge = k): the side of the edge it lies on in the
/// material, and the direction from the edge into it.
template <int dim>
struct TableSide {
  std::size_t surface = 0, edge = 0;
  bool before = true;  ///< the table holds the string before the edge (s < s0), else after it
  Vec<dim> inward = Vec<dim>::Zero();
};

/// Checks a table against its edge and the initial shape (refusals located at the table's keys).
template <int dim>
TableSide<dim> table_side(const SceneSpec& spec, std::size_t k, const EdgeSpec<dim>& edge, const Curve<dim>& curve,
                          double ell) {
  const SurfaceEntry& entry = spec.effects.surfaces[k];
  const std::size_t e = static_cast<std::size_t>(*entry.edge);
  const std::string key = fmt::format("effects.surface[{}]", k), edge_key = fmt::format("effects.edge[{}]", e);
  const std::string& table = spec.effects.edges[e].table;
  if (table != "none")
    fail_at(spec, edge_key + ".table",
            fmt::format("{}.table = \"{}\" holds the table's part of the string with a known load, and {}.edge = {} "
                        "makes that table a contact surface: allowed table = \"none\" with a surface that ends at the "
                        "edge (or no surface)",
                        edge_key, table, key, e));
  const Vec<dim> n = scene_build::as_unit_vec<dim>(spec, entry.normal, key + ".normal", "a normal");
  const double off = n.dot(edge.point - as_vec<dim>(spec, entry.point, key + ".point"));
  if (!(std::abs(off) <= kPlaceTolerance * ell))
    fail_at(spec, key + ".point",
            fmt::format("{}.point = {}: the surface passes {:.6g} m from the point of {} it ends at; allowed within "
                        "{:g} m (1e-6 of the string's length): the table's plane goes through its edge",
                        key, text_of(spec, key + ".point"), std::abs(off), edge_key, kPlaceTolerance * ell));
  if constexpr (dim == 3) {
    if (!(std::abs(edge.axis.dot(n)) <= kFoldAngleTolerance))
      fail_at(spec, key + ".normal",
              fmt::format("{}.normal = {} is not normal to the line of {} (direction {}): the table's edge lies in "
                          "its plane",
                          key, text_of(spec, key + ".normal"), edge_key, show_point<dim>(edge.axis)));
  }
  const double d = std::min({kTangentStep * ell, 0.5 * edge.s0, 0.5 * (ell - edge.s0)});
  const Vec<dim> tm = (curve.point(edge.s0) - curve.point(edge.s0 - d)).normalized();
  const Vec<dim> tp = (curve.point(edge.s0 + d) - curve.point(edge.s0)).normalized();
  const bool on_before = std::abs(tm.dot(n)) <= kFoldAngleTolerance, on_after = std::abs(tp.dot(n)) <= kFoldAngleTolerance;
  auto shown = [](Vec<dim> v) {  // the tangents of a polyline, without the round-off of their differences
    for (int c = 0; c < dim; ++c)
      if (std::abs(v[c]) < 1e-9) v[c] = 0;
    return show_point<dim>(v);
  };
  if (on_before == on_after)
    fail_at(spec, key + ".edge",
            fmt::format("{}.edge = {}: the string lies along the surface on {} of {} (tangents {} before it, {} after "
                        "it, normal {}); allowed a table the string lies along on one side of its edge and leaves on "
                        "the other",
                        key, e, on_before ? "both sides" : "neither side", edge_key, shown(tm), shown(tp), shown(n)));
  // The other side turns to the table's far side of its plane (it hangs below the table).
  const double other = on_before ? tp.dot(n) : -tm.dot(n);
  if (!(other < 0))
    fail_at(spec, key + ".normal",
            fmt::format("{}.normal = {}: the string leaves the table at {} towards the side the normal points to; "
                        "the normal points away from the table, to the side the string lies on, and the string past "
                        "the edge turns down, over the edge",
                        key, text_of(spec, key + ".normal"), edge_key));
  TableSide<dim> side;
  side.surface = k;
  side.edge = e;
  side.before = on_before;
  side.inward = on_before ? Vec<dim>(-tm) : tp;
  if constexpr (dim == 3) side.inward -= side.inward.dot(edge.axis) * edge.axis;
  side.inward -= side.inward.dot(n) * n;
  if (!(side.inward.norm() > kFoldAngleTolerance))
    fail_at(spec, key + ".edge",
            fmt::format("{}.edge = {}: the string on the table runs along the line of {} (tangent {}): allowed a table "
                        "the string crosses the edge's line from",
                        key, e, edge_key, shown(on_before ? tm : tp)));
  side.inward.normalize();
  return side;
}

}  // namespace

template <int dim>
FrontScene<dim> build_front_scene(const SceneSpec& spec) {
  CHAINSIM_VERIFY(spec.has_fronts(), "a scene without fronts has no front description");
  return build_string_scene<dim>(spec);
}

template <int dim>
std::unique_ptr<StringModel<dim>> build_front_model(const SceneSpec& spec, scene_build::SceneParts<dim>& parts,
                                                    StringScene<dim>& scene) {
  CHAINSIM_VERIFY(spec.has_fronts(), "a scene without fronts runs on StringModel (build_string_scene)");
  const auto& fx = spec.effects;

  // 1. The string, its forces and ends (build_string_scene built them).
  const double ell = parts.length;
  const Chain<dim>& chain = parts.chain;

  // 2. What a string with fronts cannot have.
  const SceneFrontKeys keys(spec);
  if (chain.closed() && spec.solver.kinks == "insert" && !spec.has_fronts_declared())
    fail_at(spec, "solver.kinks",
            "solver.kinks = \"insert\" on a closed string: kink fronts are tracked on open strings only (string.closed = "
            "true); allowed: \"off\"");
  // A kink front's constraint (its arms meeting) and node contact do not share their impulses: a coil with an
  // inserted kink landing on a floor closed its energy ledger only to 9e-5 and its momentum ledger to 1e-3, a
  // declared kink over a floor to 8.5e-6 and 1.4e-4, at every rtol (reviews of #27). Refused rather than run with
  // ledgers that do not close. (A cylinder with links along the arc is refused with fronts at its own key,
  // check_arc_contact.)
  const bool arc_cylinder =
      std::any_of(fx.cylinders.begin(), fx.cylinders.end(), [](const CylinderEntry& c) { return c.contact == "arc"; });
  const bool inserted = spec.solver.kinks == "insert";
  if ((inserted || !fx.kinks.empty()) && spec.has_obstacles() && !arc_cylinder)
    fail_at(spec, inserted ? "solver.kinks" : "effects.kink[0]",
            fmt::format("{} with an obstacle ({}): a kink front and node contact are not built together (their "
                        "impulses are not shared, and the ledgers would not close); allowed: no kink front "
                        "(solver.kinks = \"off\", no [[effects.kink]]), or no [[effects.surface]], [[effects.cylinder]] "
                        "or [effects.plane] surface",
                        inserted ? "solver.kinks = \"insert\"" : "[[effects.kink]]",
                        !fx.surfaces.empty() ? "[[effects.surface]]" : !fx.cylinders.empty() ? "[[effects.cylinder]]"
                                                                                            : "[effects.plane] surface"));
  for (std::size_t k = 0; k < fx.surfaces.size() && chain.closed(); ++k)
    if (fx.surfaces[k].f)
      fail_at(spec, fmt::format("effects.surface[{}].f", k),
              fmt::format("effects.surface[{}].f = {} on a closed string: a touchdown front is tracked on open strings "
                          "only (string.closed = false); allowed: leave out f (node contact) or open the string",
                          k, text_of(spec, fmt::format("effects.surface[{}].f", k))));
  check_open_string(chain.closed(), !fx.heaps.empty(), keys);
  if (chain.num_links() < 2) {
    const std::string key = spec.link_length ? "string.link_length" : "string.nodes";
    fail_at(spec, key,
            fmt::format("{} = {} gives {} link: a string with fronts needs at least 2 links (allowed nodes >= 3)", key,
                        text_of(spec, key), chain.num_links()));
  }
  for (std::size_t k = 0; k < fx.heaps.size(); ++k) {
    const HeapEntry& heap = fx.heaps[k];
    const EndSpec& end = heap.side == "start" ? spec.start : spec.end;
    check_end_free(k, heap.side == "end", heap.s0, end.kind == "free" ? "" : fmt::format("\"{}\"", end.kind), keys);
  }

  // 3. Heaps: s0 inside the string, the shape through the heap point at s0, the point on its plane.
  double s_lo = 0, s_hi = ell;  // the moving part at t = 0
  std::vector<HeapSpec<dim>> heaps;
  std::optional<Vec<dim>> plane_point, plane_normal;
  if (fx.plane) {
    plane_point = as_vec<dim>(spec, fx.plane->point, "effects.plane.point");
    const Vec<dim> n = as_vec<dim>(spec, fx.plane->normal, "effects.plane.normal");
    check_plane_normal(n, show_point<dim>(n), keys);
    plane_normal = n.stableNormalized();  // [0, 1e300] too: its norm overflows, its direction does not
  }
  for (std::size_t k = 0; k < fx.heaps.size(); ++k) {
    const HeapEntry& heap = fx.heaps[k];
    const std::string key = fmt::format("effects.heap[{}]", k);
    const bool start = heap.side == "start";
    check_heap_s0(k, !start, heap.s0, ell, keys);
    const Vec<dim> point = as_vec<dim>(spec, heap.point, key + ".point");
    const Vec<dim> on_shape = parts.curve->point(heap.s0);
    const double miss = (point - on_shape).norm();
    if (miss > kPlaceTolerance * ell)
      fail_at(spec, key + ".point",
              fmt::format("{}.point = {} is {:.6g} m from the string's material point s0 = {:g} m, which the shape puts "
                          "at {}: the shape must pass through the heap point at s0",
                          key, text_of(spec, key + ".point"), miss, heap.s0, show_point<dim>(on_shape)));
    if (heap.on_plane) {
      const double distance = (point - *plane_point).dot(*plane_normal);
      if (std::abs(distance) > kPlaceTolerance * ell)
        fail_at(spec, key + ".point",
                fmt::format("{}.point = {} is not on its plane: it is {:.6g} m from effects.plane (through {} with "
                            "normal {})",
                            key, text_of(spec, key + ".point"), std::abs(distance), show_point<dim>(*plane_point),
                            show_point<dim>(*plane_normal)));
    }
    (start ? s_lo : s_hi) = heap.s0;
    HeapSpec<dim> hs;
    hs.side = start ? HeapSpec<dim>::Side::kBefore : HeapSpec<dim>::Side::kAfter;
    hs.point = point;
    hs.dissipation = heap.dissipation;
    hs.pot = heap.pot;
    hs.s0 = heap.s0;
    if (heap.on_plane) {
      hs.plane_normal = *plane_normal;
      hs.plane_surface = fx.plane->surface;
    }
    heaps.push_back(hs);
  }
  if (plane_normal) {
    // The moving string starts on the side the normal points to (it may touch the plane).
    for (int i = 0; i < chain.num_nodes(); ++i) {
      const double s = chain.node_coordinate(i);
      if (s < s_lo || s > s_hi) continue;
      const double side = (chain.positions().col(i) - *plane_point).dot(*plane_normal);
      if (side < -kPlaceTolerance * ell)
        fail_at(spec, "effects.plane.normal",
                fmt::format("effects.plane.normal = {}: node {} (s = {:g} m) of the moving string lies {:.6g} m on the "
                            "other side of the plane; the normal points to the string's side, and the string may not "
                            "start below its table",
                            text_of(spec, "effects.plane.normal"), i, s, -side));
    }
  }

  // 4. The fold: inside the moving part, where the shape folds back on itself.
  std::optional<FoldSpec> fold;
  if (fx.fold) {
    const double s0 = fx.fold->s0;
    const std::string key = "effects.fold.s0";
    std::optional<double> start_heap, end_heap;
    for (const HeapEntry& e : fx.heaps) (e.side == "start" ? start_heap : end_heap) = e.s0;
    check_fold_s0(s0, ell, start_heap, end_heap, keys);
    if (const std::optional<double> turn = shape_turn<dim>(*parts.curve, s0, ell); turn && kPi - *turn > kFoldAngleTolerance)
      fail_at(spec, key,
              fmt::format("effects.fold.s0 = {}: the shape does not fold back there (it turns by {:.3g} deg at s = "
                          "{:g} m; a fold turns by 180 deg, its two arms side by side)",
                          text_of(spec, key), *turn * 180 / kPi, s0));
    fold = FoldSpec{fx.fold->dissipation, s0};
  }

  // 4b. Edges: where the initial shape passes through each edge's point (its material coordinate s0).
  std::vector<EdgeSpec<dim>> edges;
  if (!fx.edges.empty()) {
    IntegratorOptions method;
    method.method = spec.solver.method;
    if (method.implicit_method())
      fail_at(spec, "solver.method",
              fmt::format("solver.method = \"{}\" is implicit, and implicit methods do not meet an edge (the "
                          "linearisation of a link bent over its point is not written): allowed an explicit method "
                          "(\"auto\", \"erk5\", \"erk8\", ...)",
                          spec.solver.method));
  }
  for (std::size_t k = 0; k < fx.edges.size(); ++k) {
    const EdgeEntry& entry = fx.edges[k];
    const std::string key = fmt::format("effects.edge[{}]", k);
    const Vec<dim> point = as_vec<dim>(spec, entry.point, key + ".point");
    EdgeSpec<dim> edge;
    edge.point = point;
    edge.dissipation = entry.dissipation;
    edge.table = entry.table == "before"  ? EdgeSpec<dim>::Table::kBefore
                 : entry.table == "after" ? EdgeSpec<dim>::Table::kAfter
                                          : EdgeSpec<dim>::Table::kNone;
    if constexpr (dim == 3) {
      if (!entry.direction)
        fail_at(spec, key,
                fmt::format("{} has no direction: a 3D edge needs its line, direction = [dx, dy, dz] (nonzero)", key));
      edge.axis = scene_build::as_unit_vec<dim>(spec, *entry.direction, key + ".direction", "a direction");
    } else if (entry.direction) {
      const std::vector<double>& dir = *entry.direction;
      if (dir.size() != 3 || dir[0] != 0 || dir[1] != 0 || dir[2] == 0)
        fail_at(spec, key + ".direction",
                fmt::format("{}.direction = {}: in 2D an edge's line is the out-of-plane axis; allowed [0, 0, 1] (or "
                            "leave it out)",
                            key, text_of(spec, key + ".direction")));
    }
    // The nearest point of the initial shape: the closest of fine samples, refined by golden section, in
    // the shape's arc length; the string's nodes sit on the shape at equal arc length (discretize), so the
    // material point there is that arc length scaled by ℓ / L (the shape's length L may differ from ℓ
    // within shape.length_tolerance).
    const double shape_length = parts.curve->length();
    const int samples = std::max(4000, 40 * chain.num_links());
    double best_s = 0, best = INFINITY;
    for (int i = 0; i <= samples; ++i) {
      const double s = shape_length * i / samples, dist = (parts.curve->point(s) - point).norm();
      if (dist < best) best = dist, best_s = s;
    }
    double lo = std::max(0.0, best_s - shape_length / samples), hi = std::min(shape_length, best_s + shape_length / samples);
    for (int it = 0; it < 100 && hi - lo > 1e-15 * shape_length; ++it) {
      const double m1 = lo + 0.382 * (hi - lo), m2 = hi - 0.382 * (hi - lo);
      if ((parts.curve->point(m1) - point).norm() < (parts.curve->point(m2) - point).norm())
        hi = m2;
      else
        lo = m1;
    }
    const double s_shape = 0.5 * (lo + hi);
    edge.s0 = s_shape * ell / shape_length;
    best = (parts.curve->point(s_shape) - point).norm();
    if (!(best <= kPlaceTolerance * ell))
      fail_at(spec, key + ".point",
              fmt::format("{}.point = {} is not on the string: the initial shape passes {:.6g} m from it at the "
                          "nearest (at s = {:.6g} m); allowed within {:g} m (1e-6 of its length): the string runs over "
                          "the edge where its initial shape passes through the point",
                          key, text_of(spec, key + ".point"), best, edge.s0, kPlaceTolerance * ell));
    if (!(edge.s0 > s_lo && edge.s0 < s_hi) || (fx.fold && std::abs(edge.s0 - fx.fold->s0) < 2 * chain.link_length(0)))
      fail_at(spec, key + ".point",
              fmt::format("{}.point = {} is at s = {:.6g} m of the string: allowed inside its moving part, {:g} < s < "
                          "{:g} m, and two links from a fold",
                          key, text_of(spec, key + ".point"), edge.s0, s_lo, s_hi));
    // The string must bend over the edge (the jump conditions' [t] ≠ 0), and a table needs a face beside
    // the string on its side: none where the string turns back on itself (a peg).
    if (const std::optional<double> turn = shape_turn<dim>(*parts.curve, s_shape, shape_length)) {
      if (!(*turn > kEdgeTurnTolerance))
        fail_at(spec, key + ".point",
                fmt::format("{}.point = {}: the shape runs straight through it (it turns by {:.3g} deg at s = {:.6g} "
                            "m), and an edge acts only where the string bends over it; allowed a point where the shape "
                            "turns, e.g. a corner of the polyline",
                            key, text_of(spec, key + ".point"), *turn * 180 / kPi, edge.s0));
      if (edge.table != EdgeSpec<dim>::Table::kNone && kPi - *turn <= kFoldAngleTolerance)
        fail_at(spec, key + ".table",
                fmt::format("{}.table = \"{}\": the shape turns back on itself at the edge (by {:.6g} deg: a peg), "
                            "so no table face lies beside the string there; allowed table = \"none\" where the shape "
                            "turns by 180 deg",
                            key, entry.table, *turn * 180 / kPi));
    }
    // Several edges on one string (a chain over two pegs): each at least two links from the others, so
    // that a link lies between their bent links; no table then (a table's side would hold the string
    // beyond the other edge as well).
    for (std::size_t j = 0; j < edges.size(); ++j)
      if (std::abs(edges[j].s0 - edge.s0) < 2 * chain.link_length(0))
        fail_at(spec, key + ".point",
                fmt::format("{}.point = {} is at s = {:.6g} m of the string, less than two links ({:g} m) from "
                            "effects.edge[{}] at s = {:.6g} m: allowed edges at least two links apart along the string",
                            key, text_of(spec, key + ".point"), edge.s0, 2 * chain.link_length(0), j, edges[j].s0));
    // Nor a whole number of links apart along the string: the material moves through both by the same
    // length, so a node would reach each at the same instant, which one crossing at a time does not
    // handle (the second node is carried over its edge by the first crossing: the links cannot be projected).
    for (std::size_t j = 0; j < edges.size(); ++j) {
      const double links = std::abs(edges[j].s0 - edge.s0) / chain.link_length(0);
      if (std::abs(links - std::round(links)) < 1e-6)
        fail_at(spec, key + ".point",
                fmt::format("{}.point = {} is at s = {:.9g} m of the string, a whole number of links ({:.0f} h) from "
                            "effects.edge[{}] at s = {:.9g} m: nodes would reach both at the same instant, which the edge "
                            "fronts do not handle; move a point along the string by a fraction of a link or change "
                            "string.nodes",
                            key, text_of(spec, key + ".point"), edge.s0, std::round(links), j, edges[j].s0));
    }
    const bool surface_table = std::any_of(fx.surfaces.begin(), fx.surfaces.end(), [](const auto& f) { return f.edge.has_value(); });
    if (fx.edges.size() > 1 && (edge.table != EdgeSpec<dim>::Table::kNone || surface_table))
      fail_at(spec, edge.table != EdgeSpec<dim>::Table::kNone ? key + ".table" : key,
              fmt::format("{}: the scene has {} edges and a table ({}): a table with more than one edge on the "
                          "string is not supported (its side would hold the string beyond the other edge too); allowed "
                          "table = \"none\" and no [[effects.surface]] with edge when there are several edges",
                          key, fx.edges.size(),
                          edge.table != EdgeSpec<dim>::Table::kNone ? key + ".table = \"" + entry.table + "\""
                                                                   : std::string("an [[effects.surface]] with edge")));
    // With several edges, none on a node: the nudge that moves the string off it (EdgeFront::initialize)
    // moves the string beyond the other edges along the wrong lines, and their links then meet their
    // points off the line they approach along (a tension spike at every crossing).
    if (fx.edges.size() > 1) {
      const double h = chain.link_length(0), off = edge.s0 - h * std::floor(edge.s0 / h);
      if (std::min(off, h - off) < 2 * EdgeFront<dim>::kCross * h)
        fail_at(spec, key + ".point",
                fmt::format("{}.point = {} is on node {} of the string (s = {:.9g} m), and with several edges each "
                            "point must lie inside a link; move the point along the string or change string.nodes",
                            key, text_of(spec, key + ".point"), static_cast<int>(std::lround(edge.s0 / h)), edge.s0));
    }
    edges.push_back(edge);
  }

  // 4b'. Kinks: inside the moving part, a full link from its ends, where the initial shape turns.
  std::vector<KinkSpec> kinks;
  for (std::size_t k = 0; k < fx.kinks.size(); ++k) {
    const double s0 = fx.kinks[k].s0, h = chain.link_length(0);
    const std::string key = fmt::format("effects.kink[{}].s0", k);
    if (!(s0 > s_lo + h && s0 < s_hi - h))
      fail_at(spec, key,
              fmt::format("{} = {}: allowed inside the moving part of the string with a full link on either side, "
                          "{:g} < s0 < {:g} m",
                          key, text_of(spec, key), s_lo + h, s_hi - h));
    const double d = std::min(kTangentStep * ell, 0.25 * h);
    const Vec<dim> before = parts.curve->point(s0) - parts.curve->point(s0 - d);
    const Vec<dim> after = parts.curve->point(s0 + d) - parts.curve->point(s0);
    const double turn = std::acos(std::clamp(before.dot(after) / (before.norm() * after.norm()), -1.0, 1.0));
    if (!(turn >= KinkFront<dim>::kMinTurnDeg * kPi / 180))
      fail_at(spec, key,
              fmt::format("{} = {}: the shape has no corner there (it turns by {:.3g} deg at s = {:g} m; a kink's arms "
                          "turn by at least {:g} deg)",
                          key, text_of(spec, key), turn * 180 / kPi, s0, KinkFront<dim>::kMinTurnDeg));
    for (const EdgeSpec<dim>& edge : edges)
      if (std::abs(edge.s0 - s0) < 2 * h)
        fail_at(spec, key, fmt::format("{} = {} is less than two links from an edge at s = {:g} m", key,
                                       text_of(spec, key), edge.s0));
    if (fx.fold && std::abs(fx.fold->s0 - s0) < 2 * h)
      fail_at(spec, key, fmt::format("{} = {} is less than two links from the fold", key, text_of(spec, key)));
    for (std::size_t j = 0; j < k; ++j)
      if (std::abs(fx.kinks[j].s0 - s0) < 2 * h)
        fail_at(spec, key, fmt::format("{} = {} is less than two links from effects.kink[{}]", key, text_of(spec, key), j));
    kinks.push_back(KinkSpec{s0});
  }
  // 4b''. A kink inserted where one forms ([solver] kinks = "insert"): last in s until then.
  if (spec.solver.kinks == "insert") {
    KinkSpec formed;
    formed.s0 = ell;
    formed.inserted = true;
    formed.turn_deg = spec.solver.kink_turn;
    formed.window = spec.solver.kink_window.value_or(ell / 50);
    kinks.push_back(formed);
  }

  // 4c. Tables that end at an edge.
  std::vector<TableSide<dim>> tables;
  for (std::size_t k = 0; k < fx.surfaces.size(); ++k)
    if (fx.surfaces[k].edge)
      tables.push_back(table_side<dim>(spec, k, edges[static_cast<std::size_t>(*fx.surfaces[k].edge)], *parts.curve, ell));
  // After a table's own checks (which name its surface): a 3D edge's lift-off cone lies normal to its
  // line, so a side of the string along that line has no direction in it (the margin stays zero): the
  // string must cross the line on both sides.
  if constexpr (dim == 3)
    for (std::size_t k = 0; k < edges.size(); ++k) {
      const EdgeSpec<dim>& edge = edges[k];
      const std::string key = fmt::format("effects.edge[{}]", k);
      if (const auto t = shape_tangents<dim>(*parts.curve, edge.s0, ell))
        for (const auto& [side, tangent] : {std::pair("before", t->first), std::pair("after", t->second)})
          if (!((tangent - tangent.dot(edge.axis) * edge.axis).norm() > kEdgeTurnTolerance))
            fail_at(spec, key + ".direction",
                    fmt::format("{}.direction = {}: the string {} the edge runs along its line (tangent {}), and the "
                                "edge's lift-off cone lies normal to the line; allowed a direction the string crosses "
                                "on both sides",
                                key, text_of(spec, key + ".direction"), side, show_point<dim>(tangent)));
    }

  // 4d. Touchdown fronts ([[effects.surface]] with f): where the initial shape leaves the surface.
  std::vector<std::pair<std::size_t, TouchdownSpec<dim>>> touchdowns;
  for (std::size_t k = 0; k < fx.surfaces.size(); ++k) {
    if (!fx.surfaces[k].f) continue;
    const std::string key = fmt::format("effects.surface[{}]", k);
    if (!fx.heaps.empty() || fx.fold || !fx.edges.empty() || !fx.kinks.empty() || spec.solver.kinks == "insert" ||
        !touchdowns.empty() || !fx.cylinders.empty())
      fail_at(spec, key + ".f",
              fmt::format("{}.f = {}: a touchdown front is supported as the scene's only front and obstacle besides "
                          "unbounded surfaces without f (no heap, fold, edge, kink, cylinder or second surface with f)",
                          key, text_of(spec, key + ".f")));
    TouchdownSpec<dim> td;
    td.point = as_vec<dim>(spec, fx.surfaces[k].point, key + ".point");
    td.normal = as_unit_vec<dim>(spec, fx.surfaces[k].normal, key + ".normal", "a normal");
    td.dissipation = *fx.surfaces[k].f;
    td.name = key;
    const double h = chain.link_length(0), tol = 1e-11 * ell;
    auto height = [&](double s) { return td.normal.dot(parts.curve->point(s) - td.point); };
    if (!(std::abs(height(0)) <= tol))
      fail_at(spec, key + ".f",
              fmt::format("{}.f = {}: the string's start (s = 0) is {:.6g} m from the surface; a touchdown front needs "
                          "the string lying on the surface from its start (s = 0) to where it leaves it: list the "
                          "shape from its lying end",
                          key, text_of(spec, key + ".f"), height(0)));
    const int samples = std::max(4000, 40 * chain.num_links());
    int first_off = -1;
    for (int i = 1; i <= samples && first_off < 0; ++i)
      if (!(std::abs(height(ell * i / samples)) <= tol)) first_off = i;
    if (first_off < 0)
      fail_at(spec, key + ".f",
              fmt::format("{}.f = {}: the whole string lies on the surface: a touchdown front needs a string that "
                          "leaves it",
                          key, text_of(spec, key + ".f")));
    double lo = ell * (first_off - 1) / samples, hi = ell * first_off / samples;
    for (int it = 0; it < 200 && hi - lo > 1e-15 * ell; ++it) {
      const double mid = 0.5 * (lo + hi);
      (std::abs(height(mid)) <= tol ? lo : hi) = mid;
    }
    td.s0 = lo;
    // lo is the last point within the height tolerance, tol / sin θ before where the shape leaves the plane: the
    // height's secant just past hi puts s0 where the height is zero (exact on a straight arc; the run refuses
    // arcs under 5°, so the step is at most 12 tol).
    const double d = 1e-6 * ell, y1 = height(hi), y2 = height(hi + d);
    if (y1 > 0 && y2 > y1) {
      const double s_zero = hi - y1 * d / (y2 - y1);
      if (s_zero <= hi && s_zero >= hi - 100 * tol) td.s0 = s_zero;
    }
    const double frac = td.s0 / h - std::floor(td.s0 / h);
    if (std::min(frac, 1 - frac) < 1e-6)
      fail_at(spec, key + ".f",
              fmt::format("{}.f = {}: the shape leaves the surface at s = {:.9g} m, on node {} of the string: the "
                          "touchdown front needs that point inside a link; change string.nodes or the shape",
                          key, text_of(spec, key + ".f"), td.s0, static_cast<long>(std::lround(td.s0 / h))));
    for (int i = 0; i < chain.num_nodes(); ++i)
      if (chain.node_coordinate(i) > td.s0 && !(td.normal.dot(chain.positions().col(i) - td.point) > tol))
        fail_at(spec, key + ".f",
                fmt::format("{}.f = {}: node {} (s = {:g} m) is on or below the surface after the string leaves it at "
                            "s = {:.9g} m: a touchdown front needs the string above the surface past its front",
                            key, text_of(spec, key + ".f"), i, chain.node_coordinate(i), td.s0));
    touchdowns.emplace_back(k, td);
  }
  // The touchdown front named touchdown<k> (k: its surface's index), which front_names lists for every surface
  // with f.
  auto touchdown_named = [&](const std::string& name) -> const std::pair<std::size_t, TouchdownSpec<dim>>& {
    const auto it = std::find_if(touchdowns.begin(), touchdowns.end(),
                                 [&](const auto& p) { return name == fmt::format("touchdown{}", p.first); });
    CHAINSIM_VERIFY(it != touchdowns.end(), fmt::format("the front {} has no surface with f", name));
    return *it;
  };

  // 5. Stop events: a front reaching a material coordinate inside the string.
  const std::vector<std::string> names = scene_build::front_names(spec);
  const std::vector<int> stop_fronts = scene_build::front_stop_indices(spec);
  FrontOptions options;
  for (std::size_t k = 0; k < stop_fronts.size(); ++k) {
    const double s = spec.stop.fronts[k].s0;
    const std::string key = fmt::format("stop.front[{}].s0", k);
    if (!(s >= 0 && s <= ell))
      fail_at(spec, key,
              fmt::format("{} = {} is outside the string: allowed 0 <= s0 <= {} m", key, text_of(spec, key), ell));
    const std::string& name = names[static_cast<std::size_t>(stop_fronts[k])];
    const double s_start = name == "fold"               ? fx.fold->s0
                           : name == "heap_start"       ? s_lo
                           : name == "heap_end"         ? s_hi
                           : name == "kink_formed"      ? std::numeric_limits<double>::quiet_NaN()
                           : name.rfind("touchdown", 0) == 0 ? touchdown_named(name).second.s0
                           : name.rfind("kink", 0) == 0 ? kinks[std::stoul(name.substr(4))].s0
                                                        : edges[std::stoul(name.substr(4))].s0;
    if (std::abs(s - s_start) <= kPlaceTolerance * ell)
      fail_at(spec, key,
              fmt::format("{} = {} is where the {} front starts: a stop event needs a front that gets there", key,
                          text_of(spec, key), name));
    options.stop_at.push_back({stop_fronts[k], s});
  }

  // 6. The model (the front tracker's own layout checks, located at the fronts) and the run options.
  nlohmann::json& d = scene.description;
  const StringModelOptions mo = parts.model;
  const std::string fit_key = fit_key_of(spec, fold, heaps);
  std::vector<std::string> ordered_names;
  // Located at the front and naming it: the tracker's messages speak of "the heap's plane", "the fold".
  // The fronts in order of s: heaps and the fold, the edges merged in by their s0 (the names follow,
  // and the stop events' front indices with them).
  std::vector<const FrontKind<dim>*> kind_of;  // the fronts in order of s, held by the model's tracker
  std::unique_ptr<StringModel<dim>> model = at_key(spec, fit_key, [&] {
    try {
      std::vector<std::unique_ptr<FrontKind<dim>>> kinds;
      std::vector<std::pair<std::unique_ptr<FrontKind<dim>>, std::string>> all;
      std::vector<std::unique_ptr<FrontKind<dim>>> hf = heap_and_fold_fronts<dim>(heaps, fold, ell, parts.chain.link_length(0));
      std::size_t n = 0;
      for (auto& kind : hf) all.emplace_back(std::move(kind), names[n++]);
      std::vector<EdgeFront<dim>*> edge_fronts;  // held by the tracker
      for (std::size_t k = 0; k < edges.size(); ++k) {
        auto edge = std::make_unique<EdgeFront<dim>>(edges[k]);
        edge_fronts.push_back(edge.get());
        all.emplace_back(std::move(edge), names[n++]);
      }
      for (const KinkSpec& kink : kinks) all.emplace_back(std::make_unique<KinkFront<dim>>(kink), names[n++]);
      std::vector<const TouchdownFront<dim>*> touchdown_fronts;  // held by the tracker
      for (const auto& [k, td] : touchdowns) {
        auto front = std::make_unique<TouchdownFront<dim>>(td);
        touchdown_fronts.push_back(front.get());
        all.emplace_back(std::move(front), names[n++]);
      }
      std::stable_sort(all.begin(), all.end(),
                       [](const auto& p, const auto& q) { return p.first->expected_s0 < q.first->expected_s0; });
      for (auto& [kind, name] : all) {
        kind_of.push_back(kind.get());
        kinds.push_back(std::move(kind));
        ordered_names.push_back(name);
      }
      for (auto& stop : options.stop_at)
        stop.front = static_cast<int>(std::find(ordered_names.begin(), ordered_names.end(),
                                                names[static_cast<std::size_t>(stop.front)]) -
                                      ordered_names.begin());
      if (!spec.has_obstacles())
        return std::make_unique<StringModel<dim>>(make_front_model<dim>(
            std::move(parts.chain), std::move(parts.forces), std::move(parts.prescribed), std::move(kinds), options, mo));
      // Obstacles too: the contact module wraps the front tracker (solver/contact_module.hpp). A table
      // that ends at an edge holds the nodes on its side of the edge front's bent link.
      std::vector<Obstacle<dim>> obstacles = contact_obstacles<dim>(spec);
      for (const TableSide<dim>& table : tables) {
        Obstacle<dim>& o = obstacles[table.surface];
        const double mu = o.mu;  // the table's friction (edge_table builds the geometry only)
        o = edge_table<dim>(*edge_fronts[table.edge], o.normal, table.inward, table.before, edges[table.edge].axis,
                            o.name);
        o.mu = mu;
      }
      for (std::size_t q = 0; q < touchdowns.size(); ++q)  // a surface with f holds the lying arc only
        touchdown_surface<dim>(*touchdown_fronts[q], obstacles[touchdowns[q].first]);
      return std::make_unique<StringModel<dim>>(
          std::move(parts.chain), std::move(parts.forces), std::move(parts.prescribed), mo,
          make_contact_module<dim>(std::move(obstacles),
                                   std::make_unique<FrontTracker<dim>>(std::move(kinds), options)));
    } catch (const RecoverableError& e) {  // a degenerate front geometry found while placing the fronts
      throw InputError(fmt::format("{}: {}", fit_key, e.what()));
    } catch (const InputError& e) {
      if (spec.located(e.what())) throw;
      throw InputError(fmt::format("{}: {}", fit_key, e.what()));
    }
  });
  scene.front_names = ordered_names;
  // A kink already in the shape at t = 0 (a sharp polyline corner, the turn over an edge or a peg): the
  // formation's root function starts negative, where no root is found, and the insertion is made for
  // events that form in the run (it stopped the run at t = 0, or failed an internal check at the start).
  for (std::size_t k = 0; k < ordered_names.size(); ++k)
    if (ordered_names[k] == "kink_formed") {
      const double margin = kind_of[k]->formation_margin(*model);
      // No window fits in an arc: the margin is the measure's "no window" value, 2 − cos(kink_turn), above every
      // turn's 1 − cos(kink_turn) (a window of 2m links and the links at its ends, m = round(kink_window / 2h)).
      if (margin > 1.5 - std::cos(spec.solver.kink_turn * kPi / 180)) {
        const std::string key = spec.solver.kink_window ? "solver.kink_window" : "solver.kinks";
        fail_at(spec, key,
                fmt::format("{} = {}: no window of kink_window = {:g} m of material fits inside the string{} ({} "
                            "links of h = {:g} m; a window is 2m links, m = kink_window / 2h rounded and at least 1, "
                            "and needs a link beyond it: 2m + 1 links in all), so no kink could ever be inserted; "
                            "allowed: kink_window below the string's length between its fronts, on at least 3 links",
                            key, text_of(spec, key), kinks.back().window,
                            spec.has_fronts_declared() ? " between its fronts" : "", model->chain().num_links(),
                            model->chain().link_length(0)));
      }
      if (!(margin < 0)) continue;
      const double turn =
          std::acos(std::clamp(margin + std::cos(spec.solver.kink_turn * kPi / 180), -1.0, 1.0)) * 180 / kPi;
      // The window as measured on this mesh: 2m links, m = kink_window / 2h rounded and at least 1.
      const double h = model->chain().link_length(0);
      const int window_links = 2 * KinkFront<dim>::window_half_links(kinks.back().window, h);
      fail_at(spec, "solver.kinks",
              fmt::format("solver.kinks = {}: the initial shape already turns by {:.4g} deg over kink_window = {:g} m "
                          "({} links of {:g} m on this mesh), past kink_turn = {:g} deg: a corner present at t = 0 (a sharp polyline vertex, the turn "
                          "over an edge or a peg, or a bend that turns this much within a window this wide), which "
                          "insertion cannot take (it inserts the kinks that form during the run); allowed: a shape "
                          "that turns by less than kink_turn over kink_window at t = 0 (round a corner with "
                          "shape.corner_radius or declare it with [[effects.kink]], narrow kink_window{})",
                          text_of(spec, "solver.kinks"), turn, kinks.back().window, window_links, h,
                          spec.solver.kink_turn,
                          turn < 179 ? fmt::format(", or raise solver.kink_turn above {:.4g} deg", turn) : ""));
    }
  for (const TableSide<dim>& table : tables) {  // where each table ends (the plot tool draws it up to there)
    nlohmann::json& o = d["obstacles"][table.surface];
    o["edge_point"] = to_array<dim>(edges[table.edge].point);
    o["inward"] = to_array<dim>(table.inward);
  }
  d["fronts"] = nlohmann::json::array();
  for (std::size_t k = 0; k < ordered_names.size(); ++k) {
    const FrontKind<dim>& front = *kind_of[k];
    const std::string& name = ordered_names[k];
    nlohmann::json f = {{"name", name}, {"kind", front.name()},
                        {"f", front.dissipation}};
    if (name.rfind("edge", 0) == 0) {
      const std::size_t e = std::stoul(name.substr(4));
      f["s0"] = edges[e].s0;
      f["point"] = to_array<dim>(edges[e].point);
      f["table"] = fx.edges[e].table;
      if constexpr (dim == 3) f["direction"] = to_array<dim>(edges[e].axis);
    } else if (name == "fold") {
      f["s0"] = fold->s0;
    } else if (name.rfind("touchdown", 0) == 0) {
      const auto& td = touchdown_named(name);
      f["s0"] = td.second.s0;
      f["surface"] = td.first;
    } else if (name == "kink_formed") {  // not in the string until a kink forms
      f["inserted"] = true;
      f["s0"] = kinks.back().s0;  // ℓ: the list is in order of s until it forms
      f["turn"] = spec.solver.kink_turn;
      f["window"] = kinks.back().window;
    } else if (name.rfind("kink", 0) == 0) {
      f["s0"] = kinks[std::stoul(name.substr(4))].s0;
    } else {
      const bool start = name == "heap_start";
      const auto& heap = *std::find_if(fx.heaps.begin(), fx.heaps.end(),
                                       [&](const HeapEntry& e) { return e.side == (start ? "start" : "end"); });
      f["side"] = heap.side;
      f["s0"] = heap.s0;
      f["point"] = to_array<dim>(dynamic_cast<const HeapFront<dim>&>(front).point());
      f["on_plane"] = heap.on_plane;
      if (heap.pot) f["pot"] = true;
      if (heap.on_plane) f["plane_normal"] = to_array<dim>(*plane_normal);
    }
    d["fronts"].push_back(f);
  }
  d["num_fronts"] = names.size();
  d["stop_events"] = nlohmann::json::array();
  for (const auto& stop : options.stop_at)
    d["stop_events"].push_back({{"front", ordered_names[static_cast<std::size_t>(stop.front)]}, {"s0", stop.s}});
  scene.solver.record_steps = true;
  return model;
}

template <int dim>
nlohmann::json front_summary(const FrontScene<dim>& scene, const RunSummary& run) {
  nlohmann::json j = to_json(run);
  j.update(scene.description);
  if (!scene.has_fronts()) return j;
  j["t_end"] = scene.solver.t_end;
  j["stop_reason"] = name_fronts(run.stop_reason, scene.front_names);
  nlohmann::json final_s0 = nlohmann::json::object();
  if (!run.samples.empty())
    for (std::size_t k = 0; k < scene.front_names.size(); ++k) final_s0[scene.front_names[k]] = run.samples.back().fronts[k].s0;
  j["fronts_final_s0"] = final_s0;
  // The events name their front.
  for (auto& event : j["events"])
    if (event.contains("front") && event["front"].is_number_integer()) {
      const int k = event["front"].get<int>();
      if (k >= 0 && static_cast<std::size_t>(k) < scene.front_names.size())
        event["front"] = scene.front_names[static_cast<std::size_t>(k)];
    }
  return j;
}

template <int dim>
RunSummary run_front_scene(const SceneSpec& spec) {
  FrontScene<dim> scene = build_front_scene<dim>(spec);
  StringSolver<dim> solver(*scene.model, scene.solver);
  try {
    solver.run();
  } catch (const NumericalError&) {  // the summary says "failed" and why
  }
  return solver.summary();
}

template std::unique_ptr<StringModel<2>> build_front_model<2>(const SceneSpec&, scene_build::SceneParts<2>&,
                                                               StringScene<2>&);
template std::unique_ptr<StringModel<3>> build_front_model<3>(const SceneSpec&, scene_build::SceneParts<3>&,
                                                               StringScene<3>&);
template FrontScene<2> build_front_scene<2>(const SceneSpec&);
template FrontScene<3> build_front_scene<3>(const SceneSpec&);
template nlohmann::json front_summary<2>(const FrontScene<2>&, const RunSummary&);
template nlohmann::json front_summary<3>(const FrontScene<3>&, const RunSummary&);
template RunSummary run_front_scene<2>(const SceneSpec&);
template RunSummary run_front_scene<3>(const SceneSpec&);

}  // namespace chainsim
