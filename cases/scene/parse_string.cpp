// [string], [shape], [velocity], [ends]: the string and its initial state (parse_sections.hpp).
#include <cmath>

#include "cases/scene/parse_sections.hpp"
#include "cases/scene/scene_build.hpp"

namespace chainsim::scene_parse {

using scene_build::kMaxNodes;
using scene_text::join;

namespace {

EndSpec parse_end(const Section& ends, const std::string& key, Context& ctx) {
  EndSpec spec;
  const toml::node* n = ends.node(key);
  if (!n) return spec;
  const std::vector<std::string> kinds = {"free", "fixed", "loaded", "driven"};
  const std::string name = ends.full(key);
  if (n->is_string()) {
    spec.kind = ends.choice(key, kinds, "free");
    if (spec.kind == "loaded" || spec.kind == "driven")
      ends.fail(key, fmt::format("{} = \"{}\" needs parameters: write it as a table, e.g. {}", name, spec.kind,
                                 spec.kind == "loaded"
                                     ? "{ kind = \"loaded\", force = [0.0, -1.0] }"
                                     : "{ kind = \"driven\", path = \"shake\", amplitude = [0.05, 0.0], omega = 10.0 }"));
    return spec;
  }
  if (!n->is_table()) ends.wrong_type(key, "a string (free, fixed) or a table with kind = ...");
  Section s(*n->as_table(), name, ctx, {"kind", "force", "amplitude", "omega", "path", "velocity"});
  if (!s.has("kind")) s.missing("kind", "one of " + join(kinds));
  spec.kind = s.choice("kind", kinds, "free");
  spec.path = s.choice("path", {"shake", "sine", "linear"}, "shake");
  spec.force = s.vector("force");
  spec.amplitude = s.vector("amplitude");
  spec.velocity = s.vector("velocity");
  const bool loaded = spec.kind == "loaded", driven = spec.kind == "driven";
  const bool harmonic = driven && spec.path != "linear";
  const std::string context =
      driven ? fmt::format("kind = \"driven\", path = \"{}\"", spec.path) : fmt::format("kind = \"{}\"", spec.kind);
  s.forbid("force", loaded, context);
  s.forbid("amplitude", loaded || harmonic, context);
  s.forbid("omega", (loaded && s.has("amplitude")) || harmonic, context + (loaded ? " without amplitude" : ""));
  s.forbid("path", driven, context);
  s.forbid("velocity", driven && spec.path == "linear", context);
  if (loaded && !s.has("force") && !s.has("amplitude"))
    s.missing("force", "N: F(t) = force + amplitude sin(omega t); give force and/or amplitude");
  if (harmonic && !s.has("amplitude")) s.missing("amplitude", fmt::format("m, for {}", context));
  if (driven && spec.path == "linear" && !s.has("velocity")) s.missing("velocity", fmt::format("m/s, for {}", context));
  if ((harmonic || (loaded && s.has("amplitude"))) && !s.has("omega"))
    s.missing("omega", fmt::format("rad/s, > 0, for {}{}", context, loaded ? " with amplitude" : ""));
  if (s.has("omega")) {
    spec.omega = *s.number("omega");
    s.located("omega", s.full("omega"), [&] { require_positive(s.full("omega"), spec.omega); });
  }
  return spec;
}

}  // namespace

void parse_string(const Section& top, Context& ctx) {
  SceneSpec& spec = ctx.spec;
  Section s(subtable(top, "string"), "string", ctx, {"length", "density", "nodes", "link_length", "closed", "dimension", "elements"});
  spec.length = s.positive("length");
  spec.density = s.positive("density").value_or(spec.density);
  if (auto n = s.integer_in("nodes", 2, kMaxNodes)) spec.nodes = static_cast<int>(*n);
  spec.link_length = s.positive("link_length");
  if (spec.nodes && spec.link_length)
    s.fail("link_length", fmt::format("string.link_length = {} and string.nodes = {} both set the resolution: give "
                                      "one of them",
                                      s.text("link_length"), s.text("nodes")));
  spec.closed = s.boolean("closed");
  spec.elements = s.choice("elements", {"links", "quadratic"}, defaults::kElements);
  if (auto d = s.integer("dimension")) {
    if (*d != 2 && *d != 3) s.fail("dimension", fmt::format("string.dimension = {} is not allowed; valid values: 2, 3", *d));
    spec.dimension = static_cast<int>(*d);
  }
}

void parse_shape(const Section& top, Context& ctx) {
  auto& sh = ctx.spec.shape;
  const std::vector<std::string> kinds = {"polyline", "points", "arc", "circle", "catenary"};
  if (!top.has("shape"))
    throw InputError(fmt::format("{}:1:1: the scene needs a [shape] section with kind = one of {}", ctx.text.name(),
                                 join(kinds)));
  Section s(subtable(top, "shape"), "shape", ctx,
            {"kind", "points", "corner_radius", "center", "radius", "start_angle_deg", "sweep_deg", "axis1", "axis2",
             "start", "end", "length_tolerance"});
  if (!s.has("kind")) s.missing("kind", "one of " + join(kinds));
  sh.kind = s.choice("kind", kinds, "");
  sh.points = s.matrix("points");
  sh.corner_radius = s.positive("corner_radius");
  sh.center = s.vector("center");
  sh.radius = s.positive("radius").value_or(0.0);
  sh.start_angle_deg = s.number("start_angle_deg").value_or(0.0);
  sh.sweep_deg = s.number("sweep_deg").value_or(0.0);
  if (s.has("sweep_deg") && !(sh.sweep_deg != 0 && std::abs(sh.sweep_deg) <= 360))
    s.fail("sweep_deg", fmt::format("shape.sweep_deg = {} is out of range: allowed 0 < |sweep_deg| <= 360",
                                    s.text("sweep_deg")));
  sh.axis1 = s.vector("axis1");
  sh.axis2 = s.vector("axis2");
  sh.start = s.vector("start");
  sh.end = s.vector("end");
  sh.length_tolerance = s.number_in("length_tolerance", sh.length_tolerance, 0, 1, Bound::kOpen);
  // Keys the chosen kind needs, and keys that do not apply to it.
  const std::string context = fmt::format("kind = \"{}\"", sh.kind);
  auto need = [&](const char* key, const char* what) {
    if (!s.has(key)) s.missing(key, fmt::format("{}, for kind = \"{}\"", what, sh.kind));
  };
  const bool line = sh.kind == "polyline" || sh.kind == "points", round = sh.kind == "arc" || sh.kind == "circle";
  const bool arc = sh.kind == "arc", catenary = sh.kind == "catenary";
  if (line) need("points", "the vertices, e.g. [[0.0, 0.0], [1.0, 0.0]] (m)");
  if (round) need("center", "a point (m)");
  if (round) need("radius", "m, > 0");
  if (arc) need("sweep_deg", "degrees, 0 < |sweep_deg| <= 360");
  if (catenary) need("start", "the first suspension point (m)");
  if (catenary) need("end", "the second suspension point (m)");
  if (line && sh.points.size() < 2)
    s.fail("points", fmt::format("shape.points = {} has {} point: a shape needs at least 2", s.text("points"),
                                 sh.points.size()));
  s.forbid("points", line, context);
  s.forbid("corner_radius", line, context);
  for (const char* key : {"center", "radius", "start_angle_deg", "axis1", "axis2"}) s.forbid(key, round, context);
  s.forbid("sweep_deg", arc, context);
  s.forbid("start", catenary, context);
  s.forbid("end", catenary, context);
}

void parse_velocity(const Section& top, Context& ctx) {
  auto& v = ctx.spec.velocity;
  Section s(subtable(top, "velocity"), "velocity", ctx, {"kind", "value", "speed", "values", "omega", "center"});
  v.kind = s.choice("kind", {"rest", "uniform", "tangential", "nodes", "rotation"}, "rest");
  v.value = s.vector("value");
  v.speed = s.number("speed").value_or(0.0);
  v.values = s.matrix("values");
  if (const toml::node* omega = s.node("omega"))  // a number in 2D, a vector in 3D
    v.omega = omega->is_array() ? s.vector("omega") : std::vector<double>{*s.number("omega")};
  v.center = s.vector("center");
  const std::string context = fmt::format("kind = \"{}\"", v.kind);
  if (v.kind == "uniform" && !s.has("value")) s.missing("value", "m/s, the velocity of every node, for kind = \"uniform\"");
  if (v.kind == "tangential" && !s.has("speed")) s.missing("speed", "m/s, along the string, for kind = \"tangential\"");
  if (v.kind == "nodes" && !s.has("values")) s.missing("values", "m/s, one vector per node, for kind = \"nodes\"");
  if (v.kind == "rotation" && !s.has("omega"))
    s.missing("omega", "rad/s, the angular velocity: a number in 2D, [wx, wy, wz] in 3D, for kind = \"rotation\"");
  if (v.kind == "rotation" && !s.has("center"))
    s.missing("center", "m, the point the string turns about, for kind = \"rotation\"");
  s.forbid("value", v.kind == "uniform", context);
  s.forbid("speed", v.kind == "tangential", context);
  s.forbid("values", v.kind == "nodes", context);
  s.forbid("omega", v.kind == "rotation", context);
  s.forbid("center", v.kind == "rotation", context);
}

void parse_ends(const Section& top, Context& ctx) {
  Section s(subtable(top, "ends"), "ends", ctx, {"start", "end"});
  ctx.spec.start = parse_end(s, "start", ctx);
  ctx.spec.end = parse_end(s, "end", ctx);
}


}  // namespace chainsim::scene_parse
