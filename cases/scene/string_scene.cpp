// String scenes, step 3: SceneSpec -> StringModel (build_string_scene, scene.hpp), the one builder of
// scenes with and without fronts (the fronts' part: build_front_model, front_scene.cpp).
#include <algorithm>
#include <cmath>

#include "cases/scene/front_scene.hpp"
#include "cases/scene/scene.hpp"
#include "cases/scene/scene_build.hpp"
#include "solver/contact_module.hpp"

namespace chainsim {

using scene_build::at_key;

namespace {

/// What friction does not meet: unilateral links (the links' complementarity problem, block principal
/// pivoting, needs the symmetric contact-reduced matrix, and a sliding node makes it non-symmetric), and
/// fronts (not yet tested against a reference).
void refuse_friction_with_slack(const SceneSpec& spec) {
  const bool slack = spec.solver.slack == "allow";
  if (!slack && !spec.has_fronts()) return;
  const auto& fx = spec.effects;
  auto refuse = [&](const std::string& key, double mu) {
    if (slack)
      scene_build::fail_at(spec, key, fmt::format("{} = {:g} with solver.slack = \"allow\": friction does not meet "
                                                  "unilateral links (their complementarity problem needs the "
                                                  "symmetric tension matrix of smooth obstacles): allowed mu = 0, or "
                                                  "solver.slack = \"stop\"", key, mu));
    scene_build::fail_at(spec, key, fmt::format("{} = {:g} in a scene with fronts (heaps, folds, edges): with fronts "
                                                "friction is built (and tested) only on a table bounded by its edge "
                                                "([[effects.surface]] with edge = k) in a scene whose only fronts "
                                                "are edges: allowed mu = 0 here",
                                                key, mu));
  };
  // Tested with fronts (docs/model.md §10, tests/convergence/test_table_edge.cpp): a rough table bounded by
  // its edge in a 2D scene whose only fronts are edges, with the bilateral links (slack = "stop"/"warn").
  const bool edges_only = fx.heaps.empty() && !fx.fold.has_value();
  for (std::size_t k = 0; k < fx.surfaces.size(); ++k) {
    if (!(fx.surfaces[k].mu > 0)) continue;
    const std::string key = fmt::format("effects.surface[{}].mu", k);
    if (slack || !edges_only || !fx.surfaces[k].edge) refuse(key, fx.surfaces[k].mu);
    if (spec.dimension == 3)
      scene_build::fail_at(spec, key, fmt::format("{} = {:g} on a table bounded by its edge in 3D: the stuck table "
                                                  "part's locked tensions are not chosen inside the friction cones in "
                                                  "3D (a chain at rest over the edge below mu l/(1+mu) stops with "
                                                  "\"stuck on\" at t = 0): allowed mu = 0, or string.dimension = 2",
                                                  key, fx.surfaces[k].mu));
  }
  for (std::size_t k = 0; k < fx.cylinders.size(); ++k)
    if (fx.cylinders[k].mu > 0) refuse(fmt::format("effects.cylinder[{}].mu", k), fx.cylinders[k].mu);
}

/// effects.cylinder[k].contact = "arc" (links along the arc, docs/model.md §10) where it is built and
/// tested: refused, located at that key, where it is not.
void check_arc_contact(const SceneSpec& spec, std::size_t k) {
  const std::string key = fmt::format("effects.cylinder[{}].contact", k);
  auto refuse = [&](const std::string& why, const std::string& allowed) {
    scene_build::fail_at(spec, key, fmt::format("{} = \"arc\" {}: allowed \"nodes\" (node contact), or \"arc\" {}",
                                                key, why, allowed));
  };
  if (spec.dimension == 3)
    refuse("in 3D: the links along the arc are built for a circle in 2D (a helix on a cylinder is not)",
           "with string.dimension = 2");
  if (spec.closed.value_or(spec.shape.kind == "circle"))
    refuse("on a closed string: a closed loop running round a pulley closes its energy ledger only to 1e-2 with "
           "links along the arc (node contact: 7e-9)",
           "on an open string");
  if (spec.has_fronts())
    refuse("with fronts (heaps, folds, edges, kinks, or solver.kinks = \"insert\"): links along the arc are not built beside the front tracker",
           "on a scene without fronts");
  if (spec.effects.cylinders[k].mu > 0)
    refuse(fmt::format("with mu = {:g}: Coulomb friction along the links' arcs (the capstan) is not built",
                       spec.effects.cylinders[k].mu),
           "with mu = 0 (a smooth cylinder)");
}

}  // namespace

/// The scene's obstacles (solver/contact_module.hpp), each checked at its key; and what they do not
/// meet refused at the key at fault.
template <int dim>
std::vector<Obstacle<dim>> contact_obstacles(const SceneSpec& spec) {
  const auto& fx = spec.effects;
  if (spec.elements == "quadratic")
    scene_build::fail_at(spec, "string.elements", "string.elements = \"quadratic\" does not meet obstacles: allowed "
                                                  "\"links\" (the contact holds nodes)");
  IntegratorOptions method;
  method.method = spec.solver.method;
  if (method.implicit_method())
    scene_build::fail_at(spec, "solver.method",
                         fmt::format("solver.method = \"{}\" is implicit, and implicit methods do not meet obstacles "
                                     "(their Newton systems know no contact): allowed an explicit method (\"auto\", "
                                     "\"erk5\", \"erk8\", ...)",
                                     spec.solver.method));
  auto unit = [&](const std::vector<double>& v, const std::string& key, const std::string& what) {
    return scene_build::as_unit_vec<dim>(spec, v, key, what);
  };
  refuse_friction_with_slack(spec);
  std::vector<Obstacle<dim>> obstacles;
  for (std::size_t k = 0; k < fx.surfaces.size(); ++k) {
    const std::string key = fmt::format("effects.surface[{}]", k);
    Obstacle<dim> o;
    o.kind = Obstacle<dim>::Kind::kPlane;
    o.name = key;
    o.point = scene_build::as_vec<dim>(spec, fx.surfaces[k].point, key + ".point");
    o.normal = unit(fx.surfaces[k].normal, key + ".normal", "a normal");
    o.mu = fx.surfaces[k].mu;
    obstacles.push_back(o);
  }
  for (std::size_t k = 0; k < fx.cylinders.size(); ++k) {
    const std::string key = fmt::format("effects.cylinder[{}]", k);
    const CylinderEntry& c = fx.cylinders[k];
    Obstacle<dim> o;
    o.kind = Obstacle<dim>::Kind::kCylinder;
    o.name = key;
    o.point = scene_build::as_vec<dim>(spec, c.center, key + ".center");
    o.radius = c.radius;
    o.mu = c.mu;
    if constexpr (dim == 3) {
      if (!c.axis) scene_build::fail_at(spec, key, fmt::format("{}.axis is missing: in 3D a cylinder needs its axis, a "
                                                               "finite nonzero vector [ax, ay, az]", key));
      o.axis = unit(*c.axis, key + ".axis", "an axis");
    } else if (c.axis) {
      scene_build::fail_at(spec, key + ".axis", fmt::format("{}.axis = {}: in 2D a cylinder is a circle about the "
                                                            "out-of-plane axis; allowed: no axis key",
                                                            key, scene_build::text_of(spec, key + ".axis")));
    }
    if (c.contact == "arc") {
      check_arc_contact(spec, k);
      o.arc_links = true;
    }
    obstacles.push_back(o);
  }
  if (fx.plane && fx.plane->surface) {
    // The heaps' plane as a surface too (a chain falling onto a table: its heap and its landings).
    Obstacle<dim> o;
    o.kind = Obstacle<dim>::Kind::kPlane;
    o.name = "effects.plane";
    o.point = scene_build::as_vec<dim>(spec, fx.plane->point, "effects.plane.point");
    o.normal = unit(fx.plane->normal, "effects.plane.normal", "a normal");
    obstacles.push_back(o);
  }
  return obstacles;
}

namespace {

/// The key a refusal of the contact module's initial layout is located at.
std::string obstacle_key(const SceneSpec& spec) {
  if (!spec.effects.surfaces.empty()) return "effects.surface";
  return spec.effects.cylinders.empty() ? "effects.plane" : "effects.cylinder";
}

/// The warning for a cylinder whose radius is shorter than the longest link (empty when every one is resolved,
/// nodes_resolving_radius): in node contact a polygon of one or two nodes, whose contact forces and lift-offs are
/// not the cylinder's (docs/scenes.md, "[[effects.cylinder]]": the heavy Atwood chain over R = h/2 lifts off 5 %
/// early); with links along the arc, a lift-off read on links longer than R / kArcLinksPerRadius (compare pulley:
/// 4-7 % early at R = h/2, up to 2.5e-3 off or not found at R = 2h).
std::string cylinder_resolution_warning(const SceneSpec& spec, const std::vector<double>& link_lengths) {
  if (link_lengths.empty()) return {};
  const double h = *std::max_element(link_lengths.begin(), link_lengths.end());
  double length = 0;
  for (double hj : link_lengths) length += hj;
  const bool closed = spec.closed.value_or(spec.shape.kind == "circle");
  std::string warning;
  for (std::size_t k = 0; k < spec.effects.cylinders.size(); ++k) {
    const CylinderEntry& c = spec.effects.cylinders[k];
    const bool nodes = c.contact == "nodes";
    const double per_radius = nodes ? 1 : kArcLinksPerRadius;
    if (!(h * per_radius > c.radius)) continue;
    const std::string why =
        nodes ? "in node contact its nodes are held on the circle and its links are chords, so it is touched by one "
                "or two nodes and its contact forces and lift-offs are not resolved"
              : fmt::format("with links along the arc the wrapped part is exact, but its lift-off, read on links "
                            "longer than 1/{:g} of the radius, is not resolved", per_radius);
    warning += fmt::format("{}effects.cylinder[{}].radius = {:g} m is shorter than {} ({:.3g} m): {} "
                           "(docs/scenes.md); set string.nodes >= {} (links no longer than {})",
                           warning.empty() ? "" : "; ", k, c.radius,
                           nodes ? "the links" : fmt::format("{:g} links", per_radius), h * per_radius, why,
                           nodes_resolving_radius(c.radius, length, closed, per_radius),
                           nodes ? "the radius" : fmt::format("1/{:g} of the radius", per_radius));
  }
  return warning;
}

}  // namespace

template <int dim>
StringScene<dim> build_string_scene(const SceneSpec& spec) {
  if (!spec.has_fronts()) scene_build::front_stop_indices(spec);  // refuses a stop event on a front the scene lacks
  scene_build::SceneParts<dim> parts = scene_build::build_scene_parts<dim>(spec);
  StringScene<dim> scene;
  scene.characteristic_time = parts.characteristic_time;
  scene.solver = parts.solver;
  scene.output = spec.output.select;
  scene.description = {{"model", "string"}, {"fronts", nlohmann::json::array()}, {"num_fronts", 0}};

  if (spec.has_obstacles()) {
    // The obstacles as the run's summary (and stats.json, which the plot tool reads) lists them (a table
    // that ends at an edge: build_front_model adds where it ends, edge_point and inward).
    nlohmann::json obstacles = nlohmann::json::array();
    for (const SurfaceEntry& e : spec.effects.surfaces) {
      obstacles.push_back({{"kind", "surface"}, {"point", e.point}, {"normal", e.normal}});
      if (e.edge) obstacles.back()["edge"] = fmt::format("edge{}", *e.edge);
      if (e.mu > 0) obstacles.back()["mu"] = e.mu;
    }
    for (const CylinderEntry& e : spec.effects.cylinders) {
      obstacles.push_back({{"kind", "cylinder"}, {"center", e.center}, {"radius", e.radius}});
      if (e.axis) obstacles.back()["axis"] = *e.axis;
      if (e.mu > 0) obstacles.back()["mu"] = e.mu;
      if (e.contact != "nodes") obstacles.back()["contact"] = e.contact;
    }
    if (spec.effects.plane && spec.effects.plane->surface)
      obstacles.push_back({{"kind", "surface"}, {"point", spec.effects.plane->point},
                           {"normal", spec.effects.plane->normal}, {"plane", true}});
    scene.description["obstacles"] = obstacles;
  }
  if (spec.has_fronts()) {
    scene.model = build_front_model<dim>(spec, parts, scene);
  } else {
    // The model, its initial state projected onto the constraints now, so that a shape that cannot be
    // fitted (e.g. fixed ends further apart than the string is long) is refused before the run.
    std::string fit_key = "shape";
    if (spec.start.prescribed()) fit_key = "ends.start";
    if (spec.end.prescribed()) fit_key = "ends.end";
    const StringModelOptions& mo = parts.model;
    std::unique_ptr<StringModule<dim>> contact;
    if (spec.has_obstacles()) {
      contact = make_contact_module<dim>(contact_obstacles<dim>(spec));
      fit_key = obstacle_key(spec);
    }
    scene.model = at_key(spec, fit_key, [&] {
      auto model = std::make_unique<StringModel<dim>>(std::move(parts.chain), std::move(parts.forces),
                                                      std::move(parts.prescribed), mo, std::move(contact));
      model->make_consistent(0.0);
      return model;
    });
  }
  // The model's part of the description, read back from it as the run's summary reads it.
  RunSummary built;
  describe_model(*scene.model, built);
  scene.description.update(model_json(built));
  const std::string unresolved = cylinder_resolution_warning(spec, scene.model->chain().link_lengths());
  if (!unresolved.empty()) scene.description["resolution_warning"] = unresolved;
  return scene;
}

template std::vector<Obstacle<2>> contact_obstacles<2>(const SceneSpec&);
template std::vector<Obstacle<3>> contact_obstacles<3>(const SceneSpec&);
template StringScene<2> build_string_scene<2>(const SceneSpec&);
template StringScene<3> build_string_scene<3>(const SceneSpec&);

}  // namespace chainsim
