#pragma once
/// @file scene.hpp
/// A string scene (TOML, SI units), read in two separate steps:
///   parse_scene()        TOML -> SceneSpec (plain data). Every key is checked: an unknown section or
///                        key, a missing required key, a wrong type or a value out of range throws
///                        InputError with file:line:column, the key, the value as written and what is
///                        allowed (the valid keys for a typo, with a "did you mean" when one is close).
///                        The position of every key read is kept in SceneSpec::locations.
///   build_string_scene() SceneSpec -> StringModel + solver options (the physics; the solver itself
///                        never reads files). It builds only the effects the scene declares, and
///                        refuses a physically inconsistent scene (shape and string of different
///                        lengths, vectors of the wrong dimension, ends on a closed string, prescribed
///                        ends pulled further apart than the string is long, a shape that cannot be
///                        fitted to the links, …) before any run, naming the file:line:column of the
///                        offending key.
/// The keys, their units, defaults and ranges are documented in docs/scenes.md. In short:
///
///     [string]   length (m), density (kg/m), nodes | link_length (m), closed, dimension (2 | 3),
///                elements (links | quadratic)
///     [shape]    kind = polyline | points | arc | circle | catenary, and that kind's keys
///     [velocity] kind = rest | uniform | tangential | nodes | rotation
///     [ends]     start, end = "free" | "fixed" | { kind = "loaded", … } | { kind = "driven", … }
///     [effects.gravity] g (m/s²)          [effects.drag] coefficient (1/s)
///     [[effects.heap]] side = start | end, s0 (m), f, point (m), on_plane, pot
///     [effects.fold]   s0 (m), f          [effects.plane] point (m), normal (the table of a heap)
///     [[effects.kink]] s0 (m)             (a conservative corner, docs/model.md §2.5)
///     [solver]   method, rtol, atol, max_step, initial_step, max_steps, stabilization_time, backend,
///                linear_solver = auto | banded | klu,
///                slack = stop | warn | ignore | allow (check_slack = true | false: its older form),
///                snap_restitution (slack = allow),
///                slack_tolerance, max_wall_s (s)
///     [output]   interval (s), fields = [nodes, tension, energy, stats], formats = [csv, vtk]
///     [stop]     t_end (s), [[stop.front]] front = fold | heap_start | heap_end, s0 (m)
///     model      = "string" (default) | "reduced" (top-level key)
///
/// A scene with a heap or a fold runs on FrontModel (cases/scene/front_scene.hpp); one without runs on
/// StringModel; model = "reduced" runs the reduced ODE of the canonical problem the scene is
/// (cases/scene/reduced_scene.hpp).
#include <algorithm>
#include <filesystem>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include <nlohmann/json.hpp>

#include "solver/string_model.hpp"
#include "solver/string_solver.hpp"

namespace chainsim {

/// One end of an open string: [ends] start / end.
struct EndSpec {
  std::string kind = "free";      ///< free | fixed | loaded | driven
  std::vector<double> force;      ///< loaded: constant force F0 (N)
  std::vector<double> amplitude;  ///< loaded: force amplitude (N); driven: displacement amplitude (m)
  double omega = 0;               ///< angular frequency (rad/s)
  std::string path = "shake";     ///< driven: shake | sine | linear
  std::vector<double> velocity;   ///< driven, linear path: velocity (m/s)
  bool prescribed() const { return kind == "fixed" || kind == "driven"; }
};

/// A heap: [[effects.heap]].
struct HeapEntry {
  std::string side;            ///< "start": the heap holds s < s0 (feeds the string); "end": s > s0
  double s0 = 0;               ///< material coordinate of the front at t = 0 (m)
  double dissipation = 0;      ///< f, in [0, 1]; a pot: [−½, 1]
  bool pot = false;            ///< a start heap that may push the string out (f < 0): the chain fountain's pot
  std::vector<double> point;   ///< hole / edge / contact point at t = 0 (m)
  bool on_plane = false;       ///< the heap lies on [effects.plane] and its contact slides along it
  /// "heap_start" or "heap_end": the name of its front in [[stop.front]] and in the outputs.
  std::string front_name() const { return "heap_" + side; }
};

/// A fold (internal shock): [effects.fold].
struct FoldEntry {
  double s0 = 0;           ///< material coordinate of the fold at t = 0 (m)
  double dissipation = 0;  ///< f, in [0, 1]
};

/// A conservative kink (a corner of the string, f = 0): [[effects.kink]].
struct KinkEntry {
  double s0 = 0;  ///< material coordinate of the kink at t = 0 (m), where the initial shape has a corner
};

/// An edge or a peg the string runs over: [[effects.edge]].
struct EdgeEntry {
  std::vector<double> point;             ///< the edge's point (m); the initial shape passes through it
  std::optional<std::vector<double>> direction;  ///< 3D: the edge's line (any length > 0); 2D: the out-of-plane axis
  double dissipation = 0;                ///< f, in [0, 1]
  std::string table = "none";            ///< "none" | "before" | "after": the side of the string that lies on a table
};

/// A smooth rigid plane (the table under a heap): [effects.plane].
struct PlaneEntry {
  std::vector<double> point;   ///< a point of the plane (m)
  std::vector<double> normal;  ///< its normal, towards the string's side (any length > 0)
  bool surface = false;        ///< the plane is also a contact surface of the string (as [[effects.surface]])
};

/// A rigid smooth plane the string lies on, slides over, lands on and lifts off: [[effects.surface]]
/// (solver/contact_module.hpp).
struct SurfaceEntry {
  std::vector<double> point;   ///< a point of the plane (m)
  std::vector<double> normal;  ///< its normal, towards the string's side (any length > 0)
  double mu = 0;               ///< Coulomb's coefficient of friction (≥ 0; 0: smooth)
  /// The [[effects.edge]] (its index) the surface ends at: a table bounded by its edge.
  std::optional<long long> edge;
  /// f of a touchdown front where the string leaves the surface (docs/model.md §10); absent: node contact.
  std::optional<double> f;
};

/// A rigid smooth cylinder (a circle in 2D): a pulley, a peg with a radius: [[effects.cylinder]].
struct CylinderEntry {
  std::vector<double> center;  ///< the centre (2D) or a point of the axis (3D) (m)
  double radius = 0;           ///< m, > 0
  std::optional<std::vector<double>> axis;  ///< 3D: the axis (any length > 0); 2D: not given
  double mu = 0;                            ///< Coulomb's coefficient of friction (≥ 0; 0: smooth)
  /// How the string touches it: "nodes" (its nodes are held, its links are chords) or "arc" (its links lie
  /// along the arc, Obstacle::arc_links: a smooth circle in 2D only).
  std::string contact = "nodes";
};

/// A stop event: [[stop.front]].
struct FrontStop {
  std::string front;  ///< "fold" | "heap_start" | "heap_end" | "edge<k>" (the [[effects.edge]] of index k)
  double s0 = 0;      ///< stop when that front reaches this material coordinate (m)
};

/// Where a key was written and how.
struct KeyLocation {
  std::string where;  ///< "file:line:column" of its value (of the header, for a section), or the
                      ///< "--set KEY=VALUE" that gave it
  std::string text;   ///< the value as written in the file (shortened if long)
};

struct SceneSpec {
  std::string source;  ///< file name, for messages
  /// Every key and section read, by its dotted name ("string.length", "shape.points[1]",
  /// "effects.gravity.g", "ends.start", "stop"): where it was written.
  std::map<std::string, KeyLocation> locations;
  /// "file:line:column" of `key`, or of the nearest enclosing section written in the file, else
  /// "file:1:1" (a key that is missing altogether concerns the whole file).
  std::string where(const std::string& key) const;
  /// True if `message` already starts with a location of this scene ("file:line:column: ", or an
  /// option such as "--set KEY=VALUE: " or "--t-end: ").
  bool located(const std::string& message) const;

  /// model = "string" (the string solver, with front tracking if the scene has fronts) or "reduced".
  std::string model = "string";

  // [string]
  int dimension = 2;
  std::optional<double> length;       ///< m; default: the shape's length
  double density = 1.0;               ///< kg/m
  std::optional<int> nodes;           ///< default 41 (unless link_length is given)
  std::optional<double> link_length;  ///< m; target material length of a link (instead of nodes)
  std::optional<bool> closed;         ///< default: true for a circle, else false
  std::string elements = defaults::kElements;     ///< "links" (order 2) | "quadratic" (order 4: StringModelOptions::elements)
  // [shape]
  struct Shape {
    std::string kind;
    std::vector<std::vector<double>> points;
    std::vector<double> center, start, end, axis1, axis2;
    double radius = 0, start_angle_deg = 0, sweep_deg = 0;
    std::optional<double> corner_radius;  ///< m; polyline, points: fillet radius at every interior point
    double length_tolerance = 1e-6;
  } shape;
  // [velocity]
  struct Velocity {
    std::string kind = "rest";
    std::vector<double> value;
    double speed = 0;
    std::vector<std::vector<double>> values;
    std::vector<double> omega;   ///< rotation: rad/s, one component in 2D (about the out-of-plane axis), three in 3D
    std::vector<double> center;  ///< rotation: m, the point the string turns about
  } velocity;
  // [ends]
  EndSpec start, end;
  // [effects.*]: each effect exists only if its section is written (std::nullopt: not declared).
  struct Effects {
    std::optional<std::vector<double>> gravity;  ///< [effects.gravity] g (m/s²)
    std::optional<double> drag;                  ///< [effects.drag] coefficient (1/s)
    std::vector<HeapEntry> heaps;                ///< [[effects.heap]], at most one per side
    std::optional<FoldEntry> fold;               ///< [effects.fold]
    std::optional<PlaneEntry> plane;             ///< [effects.plane]
    std::vector<EdgeEntry> edges;                ///< [[effects.edge]]
    std::vector<KinkEntry> kinks;                ///< [[effects.kink]]
    std::vector<SurfaceEntry> surfaces;          ///< [[effects.surface]]
    std::vector<CylinderEntry> cylinders;        ///< [[effects.cylinder]]
  } effects;
  /// The scene has a surface or a cylinder: the string runs with the contact module.
  bool has_obstacles() const {
    return !effects.surfaces.empty() || !effects.cylinders.empty() || (effects.plane && effects.plane->surface);
  }
  /// The scene has a heap, a fold, an edge or a kink: the string runs with front tracking.
  bool has_fronts() const { return has_fronts_declared() || solver.kinks == "insert"; }
  /// A front declared among the effects (not only a kink that may form).
  bool has_fronts_declared() const {
    return !effects.heaps.empty() || effects.fold.has_value() || !effects.edges.empty() || !effects.kinks.empty() ||
           std::any_of(effects.surfaces.begin(), effects.surfaces.end(), [](const SurfaceEntry& e) { return e.f.has_value(); });
  }
  // [solver]
  struct Solver {
    std::string method = defaults::kScene.method;
    double rtol = defaults::kScene.rtol, atol = defaults::kScene.atol;
    double max_step = 0, initial_step = 0;
    long max_steps = defaults::kMaxSteps;
    /// s; default defaults::kSceneStabilizationFraction × t_char (see build_string_scene)
    std::optional<double> stabilization_time;
    std::string backend = defaults::kBackend;
    /// Newton systems of implicit methods: "auto", "banded" or "klu" (StringModelOptions::linear_solver).
    std::string linear_solver = defaults::kLinearSolver;
    double slack_tolerance = defaults::kSlackTolerance;
    /// What a slack link (a negative tension at an accepted step) does: "stop" (a numerical failure),
    /// "warn" (reported, the run goes on), "ignore", or "allow" (unilateral links: slack links fly
    /// freely and snap taut, docs/model.md "Slack and snap-taut"). The older key check_slack = true / false is
    /// read as "stop" / "ignore".
    std::string slack = defaults::kSceneSlack;
    /// slack = "allow": Newton's restitution of a link that snaps taut, in [0, 1] (0: perfectly inelastic).
    double snap_restitution = 0;
    /// "off" (default) or "insert": a kink front (shocks/kink_front.hpp) is inserted where a kink forms, the
    /// turn of the tangent over kink_window (m of material; default ℓ/50) first passing kink_turn (degrees,
    /// default 90) (docs/model.md §9, "Inserting a kink front where a kink forms").
    std::string kinks = "off";
    double kink_turn = 90;
    std::optional<double> kink_window;
    std::optional<double> max_wall_s;  ///< s of wall-clock time the run may take (> 0); none: no limit
  } solver;
  // [output]
  struct Output {
    double interval = defaults::kSceneOutputInterval;  ///< s between frames
    OutputSelection select;  ///< fields and formats
  } output;
  // [stop]
  struct Stop {
    double t_end = 0;  ///< s (required in a scene file)
    std::vector<FrontStop> fronts;  ///< [[stop.front]]
  } stop;
};

/// Reads a scene file. Throws InputError (with file:line:column) on a syntax error, an unknown
/// section or key, a missing required key, or a value of the wrong type or out of range.
SceneSpec parse_scene(const std::filesystem::path& file);
/// The effect tables of the scene format, [effects.NAME] (or [[effects.NAME]], an array of tables):
/// the one list the parser reads (parse_effects.cpp) and names in messages (parse_scene.cpp). Every
/// effect a scene declares is written back by scene_to_json (scene_json.cpp); a test checks each one
/// (tests/unit/test_scene_json.cpp).
struct EffectTable {
  const char* name;
  bool array;  ///< [[effects.NAME]]: one table per instance
};
const std::vector<EffectTable>& effect_tables();
/// The same with the command line's overrides "KEY=VALUE" (`chainsim run --set`, in order; see
/// docs/scenes.md): each sets a key of the scene, creating its section or array element if the scene
/// has none, before any check, so that a bad value or unknown key is refused as in the file, located
/// at "--set KEY=VALUE".
SceneSpec parse_scene(const std::filesystem::path& file, const std::vector<std::string>& overrides);
/// The text of a scene file (read up to the size limit of a scene; InputError if it cannot be read).
std::string read_scene_file(const std::filesystem::path& file);
/// The same from text; `source` names it in messages.
SceneSpec parse_scene_text(std::string_view text, const std::string& source);
SceneSpec parse_scene_text(std::string_view text, const std::string& source, const std::vector<std::string>& overrides);

/// Replaces [stop] t_end by the value of an option (`--t-end` of `chainsim run` and `chainsim sweep`,
/// the t_end keyword in Python), named `origin` in messages: checked (t_end > 0, finite) and, for every
/// later message about stop.t_end (the scales, the output budget), located at `origin` with the value
/// given, not at the file's line. Throws InputError.
void replace_t_end(SceneSpec& spec, double t_end, const std::string& origin);

/// A scene ready to run, with or without fronts (one builder: build_string_scene).
template <int dim>
struct StringScene {
  std::unique_ptr<StringModel<dim>> model;  ///< already projected onto the constraints at t = 0
  StringSolverOptions solver;  ///< with fronts, record_steps on: series.csv
  OutputSelection output;
  double characteristic_time = 0;  ///< t_char used for the default stabilization time (s)
  std::vector<std::string> front_names;  ///< "heap_start", "fold", "heap_end": those built, in order of s
  /// What was built, read back from the model: "model": "string", the model's part of the summary
  /// (model_json: dimension, nodes, links, effects, prescribed, root_functions (the fronts', the stop
  /// events' and the other modules'), tension_unknowns, stabilization_time), fronts (name, kind, side, f, s0, point, on_plane,
  /// plane_normal, pot; [] without fronts), num_fronts and, with fronts, stop_events.
  nlohmann::json description;
  bool has_fronts() const { return !front_names.empty(); }
};

/// Builds the model of a parsed scene (dim must equal spec.dimension) with exactly the effects the
/// scene declares, and its fronts when it declares a heap or a fold (front_scene.hpp), checks it
/// physically and projects its initial state onto the constraints.
/// Default Baumgarte time: τ_b = 0.1 t_char with t_char the shortest of sqrt(ℓ/|g|) (gravity),
/// ℓ/v (v the largest initial speed or the speed of an end driven along a line) and 2π/ω (shaken or
/// periodically loaded ends); t_end only when the scene has none of these.
/// Throws InputError naming the file:line:column of the key at fault.
template <int dim>
StringScene<dim> build_string_scene(const SceneSpec& spec);

}  // namespace chainsim
