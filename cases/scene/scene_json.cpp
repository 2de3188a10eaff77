// The effective scene as JSON (scene_json.hpp).
#include "cases/scene/scene_json.hpp"

#include <optional>

namespace chainsim {

namespace {

using nlohmann::json;

template <class T>
json or_null(const std::optional<T>& value) {
  return value ? json(*value) : json(nullptr);
}

/// The unit vector along `axis` in the scene's dimension (the default axes of arcs and circles).
std::vector<double> unit(int dimension, int axis) {
  std::vector<double> e(static_cast<std::size_t>(dimension), 0.0);
  e[static_cast<std::size_t>(axis)] = 1.0;
  return e;
}

json shape_json(const SceneSpec& spec) {
  const auto& sh = spec.shape;
  json j = {{"kind", sh.kind}, {"length_tolerance", sh.length_tolerance}};
  if (sh.kind == "polyline" || sh.kind == "points") {
    j["points"] = sh.points;
    j["corner_radius"] = or_null(sh.corner_radius);
  } else if (sh.kind == "arc" || sh.kind == "circle") {
    j["center"] = sh.center;
    j["radius"] = sh.radius;
    j["start_angle_deg"] = sh.start_angle_deg;
    if (sh.kind == "arc") j["sweep_deg"] = sh.sweep_deg;
    j["axis1"] = sh.axis1.empty() ? unit(spec.dimension, 0) : sh.axis1;
    j["axis2"] = sh.axis2.empty() ? unit(spec.dimension, 1) : sh.axis2;
  } else if (sh.kind == "catenary") {
    j["start"] = sh.start;
    j["end"] = sh.end;
  }
  return j;
}

json velocity_json(const SceneSpec::Velocity& v) {
  json j = {{"kind", v.kind}};
  if (v.kind == "uniform") j["value"] = v.value;
  if (v.kind == "tangential") j["speed"] = v.speed;
  if (v.kind == "nodes") j["values"] = v.values;
  if (v.kind == "rotation") {
    j["omega"] = v.omega.size() == 1 ? json(v.omega[0]) : json(v.omega);
    j["center"] = v.center;
  }
  return j;
}

json end_json(const EndSpec& end, int dimension) {
  if (end.kind == "free" || end.kind == "fixed") return end.kind;
  json j = {{"kind", end.kind}};
  if (end.kind == "loaded") {
    j["force"] = end.force.empty() ? std::vector<double>(static_cast<std::size_t>(dimension), 0.0) : end.force;
    if (!end.amplitude.empty()) {
      j["amplitude"] = end.amplitude;
      j["omega"] = end.omega;
    }
    return j;
  }
  j["path"] = end.path;
  if (end.path == "linear") {
    j["velocity"] = end.velocity;
  } else {
    j["amplitude"] = end.amplitude;
    j["omega"] = end.omega;
  }
  return j;
}

json effects_json(const SceneSpec::Effects& fx) {
  json j = json::object();
  if (fx.gravity) j["gravity"] = {{"g", *fx.gravity}};
  if (fx.drag) j["drag"] = {{"coefficient", *fx.drag}};
  if (!fx.heaps.empty()) {
    j["heap"] = json::array();
    for (const HeapEntry& h : fx.heaps) {
      j["heap"].push_back({{"side", h.side}, {"s0", h.s0}, {"f", h.dissipation}, {"point", h.point}, {"on_plane", h.on_plane}});
      if (h.pot) j["heap"].back()["pot"] = true;
    }
  }
  if (fx.fold) j["fold"] = {{"s0", fx.fold->s0}, {"f", fx.fold->dissipation}};
  if (fx.plane) {
    j["plane"] = {{"point", fx.plane->point}, {"normal", fx.plane->normal}};
    if (fx.plane->surface) j["plane"]["surface"] = true;
  }
  if (!fx.edges.empty()) {
    j["edge"] = json::array();
    for (const EdgeEntry& e : fx.edges) {
      j["edge"].push_back({{"point", e.point}, {"f", e.dissipation}, {"table", e.table}});
      if (e.direction) j["edge"].back()["direction"] = *e.direction;
    }
  }
  if (!fx.kinks.empty()) {
    j["kink"] = json::array();
    for (const KinkEntry& e : fx.kinks) j["kink"].push_back({{"s0", e.s0}});
  }
  if (!fx.surfaces.empty()) {
    j["surface"] = json::array();
    for (const SurfaceEntry& e : fx.surfaces) {
      j["surface"].push_back({{"point", e.point}, {"normal", e.normal}});
      // mu only where it is not the default (smooth), so that a scene without the key writes what it always wrote.
      if (e.mu != 0) j["surface"].back()["mu"] = e.mu;
      if (e.edge) j["surface"].back()["edge"] = *e.edge;
      if (e.f) j["surface"].back()["f"] = *e.f;
    }
  }
  if (!fx.cylinders.empty()) {
    j["cylinder"] = json::array();
    for (const CylinderEntry& e : fx.cylinders) {
      j["cylinder"].push_back({{"center", e.center}, {"radius", e.radius}});
      if (e.axis) j["cylinder"].back()["axis"] = *e.axis;
      // mu and contact only where they are not the default, so that a scene without them writes what it always wrote.
      if (e.mu != 0) j["cylinder"].back()["mu"] = e.mu;
      if (e.contact != "nodes") j["cylinder"].back()["contact"] = e.contact;
    }
  }
  return j;
}

json output_json(const SceneSpec& spec) {
  const SceneSpec::Output& out = spec.output;
  const OutputSelection& o = out.select;
  json fields = json::array(), formats = json::array();
  for (const auto& [on, name] : {std::pair{o.nodes, "nodes"}, {o.tension, "tension"}, {o.energy, "energy"}, {o.forces, "forces"},
                                  {o.stats, "stats"}})
    if (on) fields.push_back(name);
  for (const auto& [on, name] : {std::pair{o.csv, "csv"}, {o.vtk, "vtk"}})
    if (on) formats.push_back(name);
  return {{"interval", out.interval},
          {"fields", fields},
          {"formats", formats},
          {"vtk_encoding", o.vtk_ascii ? "ascii" : "binary"},
          {"max_megabytes", o.max_megabytes}};
}

}  // namespace

json scene_to_json(const SceneSpec& spec) {
  const auto& so = spec.solver;
  json stops = json::array();
  for (const FrontStop& f : spec.stop.fronts) stops.push_back({{"front", f.front}, {"s0", f.s0}});
  // string.nodes: 41 unless the resolution is set by link_length.
  const json nodes = spec.link_length ? json(nullptr) : json(spec.nodes.value_or(41));
  json out = {
      {"model", spec.model},
      {"string",
       {{"dimension", spec.dimension},
        {"length", or_null(spec.length)},
        {"density", spec.density},
        {"nodes", nodes},
        {"link_length", or_null(spec.link_length)},
        {"closed", spec.closed.value_or(spec.shape.kind == "circle")},
        {"elements", spec.elements}}},
      {"shape", shape_json(spec)},
      {"velocity", velocity_json(spec.velocity)},
      {"ends", {{"start", end_json(spec.start, spec.dimension)}, {"end", end_json(spec.end, spec.dimension)}}},
      {"effects", effects_json(spec.effects)},
      {"solver",
       {{"method", so.method},
        {"rtol", so.rtol},
        {"atol", so.atol},
        {"max_step", so.max_step},
        {"initial_step", so.initial_step},
        {"max_steps", so.max_steps},
        {"stabilization_time", or_null(so.stabilization_time)},
        {"backend", so.backend},
        {"linear_solver", so.linear_solver},
        {"slack", so.slack},  // check_slack, its older form, is not repeated
        {"slack_tolerance", so.slack_tolerance},
        {"max_wall_s", or_null(so.max_wall_s)}}},
      {"output", output_json(spec)},
      {"stop", {{"t_end", spec.stop.t_end}, {"front", stops}}},
  };
  // Only where it applies, so that a scene without slack = "allow" writes what it always wrote.
  if (so.slack == "allow") out["solver"]["snap_restitution"] = so.snap_restitution;
  if (so.kinks == "insert") {
    out["solver"]["kinks"] = so.kinks;
    out["solver"]["kink_turn"] = so.kink_turn;
    if (so.kink_window) out["solver"]["kink_window"] = *so.kink_window;
  }
  return out;
}

}  // namespace chainsim
