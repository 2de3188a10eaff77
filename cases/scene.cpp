// The minimal string scene: parser (TOML -> SceneSpec) and builder (SceneSpec -> StringModel).
// See scene.hpp for the format.
#include "cases/scene.hpp"

#include <algorithm>
#include <cmath>
#include <fstream>
#include <limits>
#include <sstream>

#include <fmt/format.h>
#include <toml++/toml.h>

#include "mesh/discretize.hpp"
#include "solver/errors.hpp"

namespace chainsim {

namespace {


// ================================================================================================
// 1. Parsing: a checked view of one TOML table.
// ================================================================================================
std::string where(const std::string& source, const toml::source_region& region) {
  if (region.begin.line == 0) return source;
  return fmt::format("{}:{}:{}", source, region.begin.line, region.begin.column);
}

std::string join(const std::vector<std::string>& words) {
  std::string out;
  for (const auto& w : words) out += (out.empty() ? "" : ", ") + w;
  return out;
}

class Section {
 public:
  /// Checks that every key of `table` is in `allowed`.
  Section(const toml::table& table, std::string name, const std::string& source, std::vector<std::string> allowed)
      : table_(table), name_(std::move(name)), source_(source) {
    for (const auto& [key, node] : table) {
      const std::string k(key.str());
      if (std::find(allowed.begin(), allowed.end(), k) != allowed.end()) continue;
      if (name_.empty())
        throw InputError(fmt::format("{}: unknown section [{}]; valid sections: {}", where(source_, key.source()), k,
                                     join(allowed)));
      throw InputError(fmt::format("{}: unknown key '{}' in [{}]; valid keys: {}", where(source_, key.source()), k,
                                   name_, join(allowed)));
    }
  }

  bool has(const char* key) const { return table_.contains(key); }
  const toml::node* node(const char* key) const { return table_.get(key); }
  std::string at(const char* key) const {
    const toml::node* n = node(key);
    return n ? where(source_, n->source()) : where(source_, table_.source());
  }
  std::string full(const char* key) const { return name_ + "." + key; }

  [[noreturn]] void wrong_type(const char* key, const char* expected) const {
    throw InputError(fmt::format("{}: {} must be {}", at(key), full(key), expected));
  }

  std::optional<double> number(const char* key) const {
    const toml::node* n = node(key);
    if (!n) return std::nullopt;
    if (auto v = n->value<double>(); v && (n->is_floating_point() || n->is_integer())) {
      if (!std::isfinite(*v)) wrong_type(key, "a finite number");
      return *v;
    }
    wrong_type(key, "a number");
  }
  double number(const char* key, double fallback) const { return number(key).value_or(fallback); }

  std::optional<long long> integer(const char* key) const {
    const toml::node* n = node(key);
    if (!n) return std::nullopt;
    if (!n->is_integer()) wrong_type(key, "an integer");
    return n->value<long long>();
  }

  std::optional<bool> boolean(const char* key) const {
    const toml::node* n = node(key);
    if (!n) return std::nullopt;
    if (!n->is_boolean()) wrong_type(key, "true or false");
    return n->value<bool>();
  }

  std::optional<std::string> string(const char* key) const {
    const toml::node* n = node(key);
    if (!n) return std::nullopt;
    if (!n->is_string()) wrong_type(key, "a string");
    return n->value<std::string>();
  }
  /// A string that must be one of `choices`.
  std::string choice(const char* key, const std::vector<std::string>& choices, const std::string& fallback) const {
    const auto value = string(key);
    if (!value) return fallback;
    if (std::find(choices.begin(), choices.end(), *value) == choices.end())
      throw InputError(fmt::format("{}: {} = \"{}\" is not allowed; valid values: {}", at(key), full(key), *value,
                                   join(choices)));
    return *value;
  }

  std::vector<double> vector(const char* key) const {
    const toml::node* n = node(key);
    if (!n) return {};
    const toml::array* arr = n->as_array();
    if (!arr || arr->empty()) wrong_type(key, "a non-empty array of numbers, e.g. [0.0, -9.81]");
    std::vector<double> out;
    for (const auto& item : *arr) {
      auto v = item.value<double>();
      if (!v || !(item.is_floating_point() || item.is_integer()) || !std::isfinite(*v))
        wrong_type(key, "an array of finite numbers");
      out.push_back(*v);
    }
    return out;
  }

  std::vector<std::vector<double>> matrix(const char* key) const {
    const toml::node* n = node(key);
    if (!n) return {};
    const toml::array* arr = n->as_array();
    if (!arr || arr->empty()) wrong_type(key, "an array of points, e.g. [[0.0, 0.0], [1.0, 0.0]]");
    std::vector<std::vector<double>> out;
    for (const auto& row : *arr) {
      const toml::array* r = row.as_array();
      if (!r || r->empty()) wrong_type(key, "an array of points, e.g. [[0.0, 0.0], [1.0, 0.0]]");
      std::vector<double> p;
      for (const auto& item : *r) {
        auto v = item.value<double>();
        if (!v || !(item.is_floating_point() || item.is_integer()) || !std::isfinite(*v))
          wrong_type(key, "an array of points with finite coordinates");
        p.push_back(*v);
      }
      out.push_back(std::move(p));
    }
    return out;
  }

  const toml::table& table() const { return table_; }

 private:
  const toml::table& table_;
  std::string name_;
  const std::string& source_;
};

const toml::table& subtable(const toml::table& root, const char* name, const std::string& source) {
  static const toml::table empty;
  const toml::node* n = root.get(name);
  if (!n) return empty;
  if (!n->is_table()) throw InputError(fmt::format("{}: [{}] must be a table", where(source, n->source()), name));
  return *n->as_table();
}

EndSpec parse_end(const Section& ends, const char* key, const std::string& source) {
  EndSpec spec;
  const toml::node* n = ends.node(key);
  if (!n) return spec;
  const std::vector<std::string> kinds = {"free", "fixed", "loaded", "driven"};
  if (n->is_string()) {
    spec.kind = ends.choice(key, kinds, "free");
    if (spec.kind == "loaded" || spec.kind == "driven")
      throw InputError(fmt::format("{}: ends.{} = \"{}\" needs parameters: write it as a table, e.g. {}", ends.at(key), key,
                                   spec.kind,
                                   spec.kind == "loaded" ? "{ kind = \"loaded\", force = [0.0, -1.0] }"
                                                         : "{ kind = \"driven\", path = \"shake\", amplitude = [0.05, 0.0], omega = 10.0 }"));
    return spec;
  }
  if (!n->is_table()) ends.wrong_type(key, "a string (free, fixed) or a table with kind = ...");
  const std::string name = std::string("ends.") + key;
  Section s(*n->as_table(), name, source, {"kind", "force", "amplitude", "omega", "path", "velocity"});
  if (!s.has("kind")) throw InputError(fmt::format("{}: {} needs kind = one of {}", ends.at(key), name, join(kinds)));
  spec.kind = s.choice("kind", kinds, "free");
  spec.force = s.vector("force");
  spec.amplitude = s.vector("amplitude");
  spec.omega = s.number("omega", 0.0);
  spec.path = s.choice("path", {"shake", "sine", "linear"}, "shake");
  spec.velocity = s.vector("velocity");
  auto forbid = [&](const char* k, bool allowed) {
    if (s.has(k) && !allowed)
      throw InputError(fmt::format("{}: {}.{} does not apply to kind = \"{}\"", s.at(k), name, k, spec.kind));
  };
  const bool loaded = spec.kind == "loaded", driven = spec.kind == "driven";
  forbid("force", loaded);
  forbid("amplitude", loaded || driven);
  forbid("omega", loaded || driven);
  forbid("path", driven);
  forbid("velocity", driven && spec.path == "linear");
  if (loaded && spec.force.empty() && spec.amplitude.empty())
    throw InputError(fmt::format("{}: {} (loaded) needs force = [...] and/or amplitude = [...]", ends.at(key), name));
  if (driven && spec.path != "linear" && spec.amplitude.empty())
    throw InputError(fmt::format("{}: {} (driven, path = \"{}\") needs amplitude = [...] and omega", ends.at(key), name,
                                 spec.path));
  if (driven && spec.path == "linear" && spec.velocity.empty())
    throw InputError(fmt::format("{}: {} (driven, path = \"linear\") needs velocity = [...]", ends.at(key), name));
  return spec;
}

SceneSpec parse_table(const toml::table& root, const std::string& source) {
  SceneSpec spec;
  spec.source = source;
  Section top(root, "", source, {"string", "shape", "velocity", "ends", "gravity", "drag", "solver"});
  (void)top;

  Section string(subtable(root, "string", source), "string", source,
                 {"length", "density", "nodes", "closed", "dimension"});
  spec.length = string.number("length");
  spec.density = string.number("density", spec.density);
  if (auto n = string.integer("nodes")) {
    if (*n < 2 || *n > 10000000)
      throw InputError(fmt::format("{}: string.nodes = {} is out of range: allowed 2 <= nodes <= 10000000",
                                   string.at("nodes"), *n));
    spec.nodes = static_cast<int>(*n);
  }
  spec.closed = string.boolean("closed");
  if (auto d = string.integer("dimension")) {
    if (*d != 2 && *d != 3)
      throw InputError(fmt::format("{}: string.dimension = {} is not allowed; valid values: 2, 3", string.at("dimension"), *d));
    spec.dimension = static_cast<int>(*d);
  }

  if (!root.contains("shape"))
    throw InputError(fmt::format("{}: the scene needs a [shape] section with kind = polyline, points, arc, circle "
                                 "or catenary",
                                 source));
  Section shape(subtable(root, "shape", source), "shape", source,
                {"kind", "points", "center", "radius", "start_angle_deg", "sweep_deg", "axis1", "axis2", "start", "end",
                 "length_tolerance"});
  if (!shape.has("kind"))
    throw InputError(fmt::format("{}: [shape] needs kind = one of polyline, points, arc, circle, catenary", shape.at("kind")));
  spec.shape.kind = shape.choice("kind", {"polyline", "points", "arc", "circle", "catenary"}, "");
  spec.shape.points = shape.matrix("points");
  spec.shape.center = shape.vector("center");
  spec.shape.radius = shape.number("radius", 0.0);
  spec.shape.start_angle_deg = shape.number("start_angle_deg", 0.0);
  spec.shape.sweep_deg = shape.number("sweep_deg", 0.0);
  spec.shape.axis1 = shape.vector("axis1");
  spec.shape.axis2 = shape.vector("axis2");
  spec.shape.start = shape.vector("start");
  spec.shape.end = shape.vector("end");
  spec.shape.length_tolerance = shape.number("length_tolerance", spec.shape.length_tolerance);
  // Keys that the chosen kind needs / ignores.
  const std::string& kind = spec.shape.kind;
  auto need = [&](const char* key) {
    if (!shape.has(key))
      throw InputError(fmt::format("{}: shape kind = \"{}\" needs shape.{}", shape.at("kind"), kind, key));
  };
  auto only_for = [&](const char* key, std::initializer_list<const char*> kinds) {
    if (!shape.has(key)) return;
    for (const char* k : kinds)
      if (kind == k) return;
    throw InputError(fmt::format("{}: shape.{} does not apply to kind = \"{}\"", shape.at(key), key, kind));
  };
  if (kind == "polyline" || kind == "points") need("points");
  if (kind == "arc" || kind == "circle") {
    need("center");
    need("radius");
  }
  if (kind == "arc") need("sweep_deg");
  if (kind == "catenary") {
    need("start");
    need("end");
  }
  only_for("points", {"polyline", "points"});
  only_for("center", {"arc", "circle"});
  only_for("radius", {"arc", "circle"});
  only_for("start_angle_deg", {"arc", "circle"});
  only_for("sweep_deg", {"arc"});
  only_for("axis1", {"arc", "circle"});
  only_for("axis2", {"arc", "circle"});
  only_for("start", {"catenary"});
  only_for("end", {"catenary"});

  Section velocity(subtable(root, "velocity", source), "velocity", source, {"kind", "value", "speed", "values"});
  spec.velocity.kind = velocity.choice("kind", {"rest", "uniform", "tangential", "nodes"}, "rest");
  spec.velocity.value = velocity.vector("value");
  spec.velocity.speed = velocity.number("speed", 0.0);
  spec.velocity.values = velocity.matrix("values");
  if (spec.velocity.kind == "uniform" && spec.velocity.value.empty())
    throw InputError(fmt::format("{}: velocity kind = \"uniform\" needs value = [...]", velocity.at("kind")));
  if (spec.velocity.kind == "tangential" && !velocity.has("speed"))
    throw InputError(fmt::format("{}: velocity kind = \"tangential\" needs speed", velocity.at("kind")));
  if (spec.velocity.kind == "nodes" && spec.velocity.values.empty())
    throw InputError(fmt::format("{}: velocity kind = \"nodes\" needs values = [[...], ...]", velocity.at("kind")));

  Section ends(subtable(root, "ends", source), "ends", source, {"start", "end"});
  spec.start = parse_end(ends, "start", source);
  spec.end = parse_end(ends, "end", source);

  Section gravity(subtable(root, "gravity", source), "gravity", source, {"g"});
  spec.gravity = gravity.vector("g");
  if (root.contains("gravity") && spec.gravity.empty())
    throw InputError(fmt::format("{}: [gravity] needs g = [gx, gy(, gz)] (m/s^2)", gravity.at("g")));

  Section drag(subtable(root, "drag", source), "drag", source, {"coefficient"});
  spec.drag = drag.number("coefficient", 0.0);
  if (spec.drag < 0)
    throw InputError(fmt::format("{}: drag.coefficient = {:g} is out of range: allowed coefficient >= 0",
                                 drag.at("coefficient"), spec.drag));

  Section solver(subtable(root, "solver", source), "solver", source,
                 {"method", "rtol", "atol", "t_end", "output_interval", "stabilization_time", "backend", "check_slack",
                  "slack_tolerance", "max_step", "vtk"});
  auto& so = spec.solver;
  so.method = solver.string("method").value_or(so.method);
  so.rtol = solver.number("rtol", so.rtol);
  so.atol = solver.number("atol", so.atol);
  so.t_end = solver.number("t_end", so.t_end);
  so.output_interval = solver.number("output_interval", so.output_interval);
  so.stabilization_time = solver.number("stabilization_time");
  so.backend = solver.string("backend").value_or(so.backend);
  so.check_slack = solver.boolean("check_slack").value_or(so.check_slack);
  so.slack_tolerance = solver.number("slack_tolerance", so.slack_tolerance);
  so.max_step = solver.number("max_step", so.max_step);
  so.vtk = solver.boolean("vtk").value_or(so.vtk);
  return spec;
}

// ================================================================================================
// 2. Building: SceneSpec -> model.
// ================================================================================================
template <int dim>
Vec<dim> as_vec(const std::vector<double>& v, const std::string& key, int dimension) {
  if (static_cast<int>(v.size()) != dim)
    throw InputError(fmt::format("{} has {} components but string.dimension = {}", key, v.size(), dimension));
  Vec<dim> out;
  for (int d = 0; d < dim; ++d) out[d] = v[static_cast<std::size_t>(d)];
  return out;
}

template <int dim>
Points<dim> as_points(const std::vector<std::vector<double>>& rows, const std::string& key, int dimension) {
  Points<dim> out(dim, static_cast<Eigen::Index>(rows.size()));
  for (std::size_t k = 0; k < rows.size(); ++k)
    out.col(static_cast<Eigen::Index>(k)) = as_vec<dim>(rows[k], fmt::format("{}[{}]", key, k), dimension);
  return out;
}

template <int dim>
Vec<dim> unit(int axis) {
  Vec<dim> e = Vec<dim>::Zero();
  e[axis] = 1;
  return e;
}

}  // namespace

SceneSpec parse_scene_text(std::string_view text, const std::string& source) {
  try {
    toml::table root = toml::parse(text, source);
    return parse_table(root, source);
  } catch (const toml::parse_error& e) {
    throw InputError(fmt::format("{}: {}", where(source, e.source()), e.description()));
  }
}

SceneSpec parse_scene(const std::filesystem::path& file) {
  std::ifstream in(file);
  if (!in) throw InputError(fmt::format("cannot read the scene file '{}'", file.string()));
  std::stringstream buffer;
  buffer << in.rdbuf();
  return parse_scene_text(buffer.str(), file.string());
}

template <int dim>
StringScene<dim> build_string_scene(const SceneSpec& spec) {
  CHAINSIM_VERIFY(spec.dimension == dim, "build_string_scene<dim> called for another dimension");
  const int D = spec.dimension;
  const auto& sh = spec.shape;
  require_positive("string.density", spec.density);

  // 1. Gravity (its direction also orients a catenary).
  Vec<dim> g = Vec<dim>::Zero();
  if (!spec.gravity.empty()) g = as_vec<dim>(spec.gravity, "gravity.g", D);
  const Vec<dim> down = g.norm() > 0 ? Vec<dim>(g) : Vec<dim>(-unit<dim>(1));

  // 2. The shape as a curve.
  std::unique_ptr<Curve<dim>> curve;
  const bool closed = spec.closed.value_or(sh.kind == "circle");
  const Vec<dim> axis1 = sh.axis1.empty() ? unit<dim>(0) : as_vec<dim>(sh.axis1, "shape.axis1", D);
  const Vec<dim> axis2 = sh.axis2.empty() ? unit<dim>(1) : as_vec<dim>(sh.axis2, "shape.axis2", D);
  if (sh.kind == "polyline" || sh.kind == "points") {
    curve = polyline_curve<dim>(as_points<dim>(sh.points, "shape.points", D), closed);
  } else if (sh.kind == "arc") {
    curve = circle_arc_curve<dim>(as_vec<dim>(sh.center, "shape.center", D), sh.radius, sh.start_angle_deg * kPi / 180,
                                  sh.sweep_deg * kPi / 180, axis1, axis2);
  } else if (sh.kind == "circle") {
    curve = circle_curve<dim>(as_vec<dim>(sh.center, "shape.center", D), sh.radius, axis1, axis2);
  } else if (sh.kind == "catenary") {
    if (!spec.length) throw InputError("a catenary shape needs string.length (the sag follows from it)");
    curve = catenary_curve<dim>(as_vec<dim>(sh.start, "shape.start", D), as_vec<dim>(sh.end, "shape.end", D),
                                *spec.length, down);
  } else {
    throw InputError(fmt::format("shape.kind = \"{}\" is not a shape", sh.kind));
  }

  // 3. The chain on the curve, and its initial velocities.
  const double length = spec.length.value_or(curve->length());
  const int links = closed ? spec.nodes : spec.nodes - 1;
  Chain<dim> chain = discretize(*curve, length, spec.density, links, closed, sh.length_tolerance);
  const auto& vel = spec.velocity;
  if (vel.kind == "uniform") set_uniform_velocity(chain, as_vec<dim>(vel.value, "velocity.value", D));
  if (vel.kind == "tangential") set_tangential_velocity(chain, vel.speed);
  if (vel.kind == "nodes") set_node_velocities(chain, as_points<dim>(vel.values, "velocity.values", D));

  // 4. Ends and forces (only the effects the scene declares).
  std::vector<std::unique_ptr<Force<dim>>> forces;
  std::vector<PrescribedNode<dim>> prescribed;
  if (g.norm() > 0) forces.push_back(std::make_unique<Gravity<dim>>(g));
  if (spec.drag > 0) forces.push_back(std::make_unique<Drag<dim>>(spec.drag));
  double forcing_period = INFINITY;
  auto add_end = [&](const EndSpec& end, int node, const char* name) {
    const std::string key = std::string("ends.") + name;
    if (end.kind == "free") return;
    if (closed)
      throw InputError(fmt::format("{} = \"{}\": a closed string has no ends (string.closed = true)", key, end.kind));
    const Vec<dim> x0 = chain.positions().col(node);
    if (end.kind == "fixed") {
      prescribed.push_back({node, std::make_shared<FixedPoint<dim>>(x0)});
    } else if (end.kind == "driven") {
      if (end.path == "linear") {
        prescribed.push_back({node, std::make_shared<LinearPath<dim>>(x0, as_vec<dim>(end.velocity, key + ".velocity", D))});
      } else {
        require_positive(key + ".omega", end.omega);
        prescribed.push_back({node, std::make_shared<HarmonicPath<dim>>(
                                        x0, as_vec<dim>(end.amplitude, key + ".amplitude", D), end.omega,
                                        end.path == "shake")});
        forcing_period = std::min(forcing_period, 2 * kPi / end.omega);
      }
    } else if (end.kind == "loaded") {
      const Vec<dim> f0 = end.force.empty() ? Vec<dim>::Zero() : as_vec<dim>(end.force, key + ".force", D);
      const Vec<dim> amp = end.amplitude.empty() ? Vec<dim>::Zero() : as_vec<dim>(end.amplitude, key + ".amplitude", D);
      if (amp.norm() > 0) {
        require_positive(key + ".omega", end.omega);
        forcing_period = std::min(forcing_period, 2 * kPi / end.omega);
      }
      forces.push_back(std::make_unique<EndLoad<dim>>(node, f0, amp, end.omega));
    }
  };
  add_end(spec.start, 0, "start");
  add_end(spec.end, chain.num_nodes() - 1, "end");

  // 5. Options. Default Baumgarte time: a tenth of the shortest physical time scale.
  StringScene<dim> scene;
  const auto& so = spec.solver;
  double t_char = so.t_end;
  if (g.norm() > 0) t_char = std::min(t_char, std::sqrt(length / g.norm()));
  const double v_max = chain.velocities().colwise().norm().maxCoeff();
  if (v_max > 0) t_char = std::min(t_char, length / v_max);
  t_char = std::min(t_char, forcing_period);
  scene.characteristic_time = t_char;
  StringModelOptions mo;
  mo.stabilization_time = so.stabilization_time.value_or(0.1 * t_char);
  mo.backend = so.backend;
  mo.check_slack = so.check_slack;
  mo.slack_tolerance = so.slack_tolerance;
  scene.solver.integrator.method = so.method;
  scene.solver.integrator.rtol = so.rtol;
  scene.solver.integrator.atol = so.atol;
  scene.solver.integrator.max_step = so.max_step;
  scene.solver.t_end = so.t_end;
  scene.solver.output_interval = so.output_interval;
  scene.solver.validate();
  scene.vtk = so.vtk;
  scene.model = std::make_unique<StringModel<dim>>(std::move(chain), std::move(forces), std::move(prescribed), mo);
  return scene;
}

template StringScene<2> build_string_scene<2>(const SceneSpec&);
template StringScene<3> build_string_scene<3>(const SceneSpec&);

}  // namespace chainsim
