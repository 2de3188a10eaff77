// [effects.*]: gravity, drag, heaps, fold and plane, each existing only if its section is written
// (parse_sections.hpp).
#include "cases/scene/parse_sections.hpp"
#include "cases/scene/scene_front_keys.hpp"

namespace chainsim::scene_parse {

namespace {

/// [[effects.heap]]: one table per heap, at most one per side.
void parse_heaps(const Section& effects, Context& ctx) {
  auto& heaps = ctx.spec.effects.heaps;
  const auto tables = table_array(effects, "heap", "heap");
  for (std::size_t k = 0; k < tables.size(); ++k) {
    Section h(*tables[k], fmt::format("effects.heap[{}]", k), ctx, {"side", "s0", "f", "point", "on_plane", "pot"});
    if (!h.has("side")) h.missing("side", "\"start\" (the heap holds s < s0 and feeds the string) or \"end\" (it holds s > s0)");
    if (!h.has("s0")) h.missing("s0", "m, the material coordinate of the front at t = 0");
    if (!h.has("point")) h.missing("point", "m, the hole or edge the front sits at, or the contact point on the plane at t = 0");
    HeapEntry heap;
    heap.side = h.choice("side", {"start", "end"}, "");
    const SceneFrontKeys keys(ctx.spec);
    std::optional<std::size_t> other;
    for (std::size_t j = 0; j < heaps.size(); ++j)
      if (heaps[j].side == heap.side) other = j;
    check_one_heap_per_side(k, heap.side == "end", other, keys);
    heap.s0 = *h.number("s0");
    // f: 0 <= f <= 1; a pot (a start heap that pushes the string out) also -1/2 <= f < 0 (docs/model.md §5).
    heap.pot = h.boolean("pot").value_or(false);
    heap.dissipation = h.number("f").value_or(0.0);
    check_heap_dissipation(k, heap.side == "end", heap.pot, heap.dissipation, keys);
    heap.point = h.vector("point");
    heap.on_plane = h.boolean("on_plane").value_or(false);
    heaps.push_back(heap);
  }
}

/// [[effects.edge]]: edges and pegs the string runs over (their place on the string: front_scene.cpp).
void parse_edges(const Section& effects, Context& ctx) {
  const auto tables = table_array(effects, "edge", "edge");
  for (std::size_t k = 0; k < tables.size(); ++k) {
    Section e(*tables[k], fmt::format("effects.edge[{}]", k), ctx, {"point", "direction", "f", "table"});
    if (!e.has("point")) e.missing("point", "m, the edge's point, which the initial shape passes through");
    EdgeEntry edge;
    edge.point = e.vector("point");
    if (e.has("direction")) edge.direction = e.vector("direction");
    edge.dissipation = e.number_in("f", 0.0, 0.0, 1.0);
    edge.table = e.choice("table", {"none", "before", "after"}, "none");
    ctx.spec.effects.edges.push_back(edge);
  }
}

/// [[effects.kink]]: conservative kinks (their place on the string: front_scene.cpp).
void parse_kinks(const Section& effects, Context& ctx) {
  const auto tables = table_array(effects, "kink", "kink");
  for (std::size_t k = 0; k < tables.size(); ++k) {
    Section e(*tables[k], fmt::format("effects.kink[{}]", k), ctx, {"s0"});
    if (!e.has("s0")) e.missing("s0", "m, the material coordinate of the kink at t = 0, at a corner of the shape");
    ctx.spec.effects.kinks.push_back(KinkEntry{*e.number("s0")});
  }
}

/// An obstacle's `mu`: Coulomb's coefficient of friction, finite and ≥ 0 (0, the default: smooth).
double friction_coefficient(const Section& e) { return e.number_in("mu", 0.0, 0.0, INFINITY); }

/// [[effects.surface]] and [[effects.cylinder]]: the rigid obstacles the string touches along arcs
/// (solver/contact_module.hpp; their geometry is checked against the dimension in scene_parts.cpp).
void parse_obstacles(const Section& effects, Context& ctx) {
  const auto surfaces = table_array(effects, "surface", "surface");
  for (std::size_t k = 0; k < surfaces.size(); ++k) {
    Section e(*surfaces[k], fmt::format("effects.surface[{}]", k), ctx, {"point", "normal", "mu", "edge", "f"});
    if (!e.has("point")) e.missing("point", "m, a point of the plane");
    if (!e.has("normal")) e.missing("normal", "a vector normal to the plane (any length > 0), pointing to the side the string is on");
    SurfaceEntry surface{e.vector("point"), e.vector("normal"), friction_coefficient(e), std::nullopt, std::nullopt};
    if (e.has("edge")) {
      const long long edges = static_cast<long long>(ctx.spec.effects.edges.size());
      if (edges == 0)
        e.fail("edge", fmt::format("{} = {} names an [[effects.edge]], and the scene has none: allowed only with "
                                   "[[effects.edge]] (the index of the edge the table ends at, 0 for the first)",
                                   e.full("edge"), e.text("edge")));
      surface.edge = e.integer_in("edge", 0, edges - 1);
      for (std::size_t j = 0; j < ctx.spec.effects.surfaces.size(); ++j)
        if (ctx.spec.effects.surfaces[j].edge == surface.edge)
          e.fail("edge", fmt::format("{} = {}: effects.surface[{}] already ends at effects.edge[{}]; allowed one "
                                     "table per edge",
                                     e.full("edge"), *surface.edge, j, *surface.edge));
    }
    if (e.has("f")) {
      // A touchdown front where the string leaves the surface (docs/model.md §10): smooth, unbounded.
      surface.f = e.number_in("f", 0.0, 0.0, 1.0);
      if (surface.edge)
        e.fail("f", fmt::format("{} = {} with {}.edge: a touchdown front on a table bounded by its edge is not "
                                "supported; allowed f on an unbounded surface (no edge)",
                                e.full("f"), e.text("f"), fmt::format("effects.surface[{}]", k)));
      if (surface.mu > 0)
        e.fail("f", fmt::format("{} = {} with mu = {}: a touchdown front with Coulomb friction is not built; "
                                "allowed f on a smooth surface (mu = 0 or absent)",
                                e.full("f"), e.text("f"), surface.mu));
    }
    ctx.spec.effects.surfaces.push_back(surface);
  }
  const auto cylinders = table_array(effects, "cylinder", "cylinder");
  for (std::size_t k = 0; k < cylinders.size(); ++k) {
    Section e(*cylinders[k], fmt::format("effects.cylinder[{}]", k), ctx, {"center", "radius", "axis", "mu", "contact"});
    if (!e.has("center")) e.missing("center", "m, the centre of the circle (2D) or a point of the axis (3D)");
    if (!e.has("radius")) e.missing("radius", "m, > 0");
    CylinderEntry cylinder;
    cylinder.center = e.vector("center");
    cylinder.radius = *e.positive("radius");
    if (e.has("axis")) cylinder.axis = e.vector("axis");
    cylinder.mu = friction_coefficient(e);
    // How the string touches it (docs/scenes.md): its nodes (the links are chords), or its links lying
    // along the arc (Obstacle::arc_links; where it applies is checked in string_scene.cpp).
    cylinder.contact = e.choice("contact", {"nodes", "arc"}, "nodes");
    ctx.spec.effects.cylinders.push_back(cylinder);
  }
}

}  // namespace

void parse_effects(const Section& top, Context& ctx) {
  auto& fx = ctx.spec.effects;
  std::vector<std::string> names;
  for (const EffectTable& table : effect_tables()) names.emplace_back(table.name);
  Section s(subtable(top, "effects"), "effects", ctx, names, {}, "effect");
  if (s.has("gravity")) {
    Section g(subtable(s, "gravity"), "effects.gravity", ctx, {"g"});
    if (!g.has("g")) g.missing("g", "m/s^2, a vector [gx, gy] or [gx, gy, gz]");
    fx.gravity = g.vector("g");
  }
  if (s.has("drag")) {
    Section d(subtable(s, "drag"), "effects.drag", ctx, {"coefficient"});
    if (!d.has("coefficient")) d.missing("coefficient", "1/s, >= 0: the force -coefficient m v on every node");
    fx.drag = d.number_in("coefficient", 0.0, 0.0, INFINITY);
  }
  parse_heaps(s, ctx);
  parse_edges(s, ctx);
  parse_kinks(s, ctx);
  parse_obstacles(s, ctx);
  if (s.has("fold")) {
    Section f(subtable(s, "fold"), "effects.fold", ctx, {"s0", "f"});
    if (!f.has("s0")) f.missing("s0", "m, the material coordinate of the fold at t = 0");
    fx.fold = FoldEntry{*f.number("s0"), f.number("f").value_or(0.0)};
    check_fold_dissipation(fx.fold->dissipation, SceneFrontKeys(ctx.spec));
  }
  if (s.has("plane")) {
    Section p(subtable(s, "plane"), "effects.plane", ctx, {"point", "normal", "surface"});
    if (!p.has("point")) p.missing("point", "m, a point of the plane");
    if (!p.has("normal")) p.missing("normal", "a vector normal to the plane, pointing to the string's side");
    fx.plane = PlaneEntry{p.vector("point"), p.vector("normal"), p.boolean("surface").value_or(false)};
  }
  // The plane is the table of a heap: it exists for on_plane heaps only (the string itself collides
  // with it only with surface = true), and an on_plane heap needs it.
  bool on_plane = false;
  for (std::size_t k = 0; k < fx.heaps.size(); ++k) {
    on_plane = on_plane || fx.heaps[k].on_plane;
    if (fx.heaps[k].on_plane && !fx.plane)
      throw InputError(fmt::format("{}: effects.heap[{}].on_plane = true needs [effects.plane] (point, normal): the "
                                   "table the heap lies on",
                                   ctx.spec.where(fmt::format("effects.heap[{}].on_plane", k)), k));
  }
  if (fx.plane && !on_plane)
    throw InputError(fmt::format("{}: [effects.plane] is the table under a heap, but no [[effects.heap]] has on_plane = "
                                 "true (for a table the string lies on and lands on, without a heap, write [[effects.surface]])",
                                 ctx.spec.where("effects.plane")));
}

}  // namespace chainsim::scene_parse
