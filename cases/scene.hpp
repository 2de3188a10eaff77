#pragma once
/// @file scene.hpp
/// A minimal string scene (TOML), read in two separate steps:
///   parse_scene()        TOML -> SceneSpec (plain data; every key checked, unknown keys rejected with
///                        file:line:column, the key and the list of valid keys),
///   build_string_scene() SceneSpec -> StringModel + solver options (the physics; the solver itself
///                        never reads files).
/// The full scene format (its own issue) will grow SceneSpec and the parser; the builder stays.
///
/// Example (2D, lengths in m, times in s, SI units throughout):
///
///     [string]
///     length = 1.0        # optional: default = the shape's length
///     density = 0.1       # kg/m
///     nodes = 41
///     closed = false      # default: true for kind = "circle", else false
///     dimension = 2
///
///     [shape]
///     kind = "polyline"   # polyline | points | arc | circle | catenary
///     points = [[0.0, 0.0], [0.0, -1.0]]
///     # arc/circle: center, radius, start_angle_deg, sweep_deg (arc), axis1, axis2 (plane)
///     # catenary:   start, end  (sags along the gravity vector, default -y)
///     length_tolerance = 1e-6   # relative mismatch allowed between the shape and string.length
///
///     [velocity]
///     kind = "rest"       # rest | uniform (value = [..]) | tangential (speed) | nodes (values = [[..], ..])
///
///     [ends]
///     start = "fixed"     # free | fixed | loaded | driven, or a table:
///     end = { kind = "driven", path = "shake", amplitude = [0.05, 0.0], omega = 12.0 }
///     #  loaded: force = [..] (N), amplitude = [..] (N), omega: F(t) = force + amplitude sin(omega t)
///     #  driven: path = "shake": x0 + amplitude (1 - cos omega t)   "sine": x0 + amplitude sin(omega t)
///     #          path = "linear": x0 + velocity t
///
///     [gravity]
///     g = [0.0, -9.81]
///
///     [drag]
///     coefficient = 0.5   # 1/s: force -coefficient m v on every node
///
///     [solver]
///     method = "erk8"     rtol = 1e-8   atol = 1e-10   t_end = 5.0   output_interval = 0.05
///     stabilization_time = 0.03   # Baumgarte time scale (s); 0 = off; default 0.1 t_char
///     backend = "auto"    check_slack = false   slack_tolerance = 1e-8   max_step = 0   vtk = true
#include <filesystem>
#include <memory>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "solver/string_model.hpp"
#include "solver/string_solver.hpp"

namespace chainsim {

/// One end of an open string.
struct EndSpec {
  std::string kind = "free";      ///< free | fixed | loaded | driven
  std::vector<double> force;      ///< loaded: constant force F0 (N)
  std::vector<double> amplitude;  ///< loaded: force amplitude (N); driven: displacement amplitude (m)
  double omega = 0;               ///< angular frequency (rad/s)
  std::string path = "shake";     ///< driven: shake | sine | linear
  std::vector<double> velocity;   ///< driven, linear path: velocity (m/s)
};

struct SceneSpec {
  std::string source;  ///< file name, for messages
  // [string]
  int dimension = 2;
  std::optional<double> length;  ///< m; default: the shape's length
  double density = 1.0;          ///< kg/m
  int nodes = 41;
  std::optional<bool> closed;
  // [shape]
  struct Shape {
    std::string kind;
    std::vector<std::vector<double>> points;
    std::vector<double> center, start, end, axis1, axis2;
    double radius = 0, start_angle_deg = 0, sweep_deg = 0;
    double length_tolerance = 1e-6;
  } shape;
  // [velocity]
  struct Velocity {
    std::string kind = "rest";
    std::vector<double> value;
    double speed = 0;
    std::vector<std::vector<double>> values;
  } velocity;
  // [ends]
  EndSpec start, end;
  // [gravity], [drag]
  std::vector<double> gravity;  ///< empty: no gravity
  double drag = 0;              ///< 1/s; 0: no drag effect
  // [solver]
  struct Solver {
    std::string method = "erk8";
    double rtol = 1e-8, atol = 1e-10;
    double t_end = 1.0, output_interval = 0.05;
    std::optional<double> stabilization_time;  ///< s; default 0.1 t_char (see build_string_scene)
    std::string backend = "auto";
    bool check_slack = false;
    double slack_tolerance = 1e-8;
    double max_step = 0;
    bool vtk = true;
  } solver;
};

/// Reads a scene file. Throws InputError (with file:line:column) on a syntax error, an unknown
/// section or key, or a value of the wrong type.
SceneSpec parse_scene(const std::filesystem::path& file);
/// The same from text; `source` names it in messages.
SceneSpec parse_scene_text(std::string_view text, const std::string& source);

/// A scene ready to run.
template <int dim>
struct StringScene {
  std::unique_ptr<StringModel<dim>> model;
  StringSolverOptions solver;
  bool vtk = true;
  double characteristic_time = 0;  ///< t_char used for the default stabilization time (s)
};

/// Builds the model of a parsed scene (dim must equal spec.dimension). Default Baumgarte time:
/// τ_b = 0.1 t_char with t_char the shortest of sqrt(ℓ/|g|) (gravity), ℓ/max|v0| (moving start),
/// 2π/ω (shaken or periodically loaded ends) and t_end.
template <int dim>
StringScene<dim> build_string_scene(const SceneSpec& spec);

}  // namespace chainsim
