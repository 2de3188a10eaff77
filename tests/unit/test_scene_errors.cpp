// cases/scene/ (the scene parser and builders): a table of bad scenes, each refused with its exact message: the file:line:column
// of the key at fault (the value, or the key itself when it is unknown, or the section header when
// a key is missing), the key, the value as written, and what is allowed. Errors found while
// building the model (dimensions, lengths, ends, frames) are located the same way.
#include <filesystem>
#include <string>

#include <catch2/catch.hpp>

#include "cases/cli/run_command.hpp"
#include "cases/scene/scene.hpp"
#include "mesh/errors.hpp"
#include "solver/tension_system.hpp"
#include "test_scene_support.hpp"

using namespace chainsim;
using test::edit;

namespace {

// The messages below point into this text: lines 1-17 are test_scene_support.hpp's scene.
const std::string& kBase = test::kSceneBase;
const char* kPolyline = "kind = \"polyline\"\npoints = [[0.0, 0.0], [0.0, -1.0]]";

/// The message of the InputError that parsing `text` and building the model it asks for (string,
/// string with fronts, or reduced) raises, or "" if none.
std::string error_of(const std::string& text) {
  try {
    check_scene(parse_scene_text(text, "s.toml"));
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}

struct BadScene {
  const char* what;
  std::string text;
  std::string message;
};

}  // namespace

TEST_CASE("the bases of the bad scenes are good", "[unit][scene]") {
  CHECK(error_of(kBase).empty());
  // The three canonical problems, on the string solver and as reduced models.
  for (const std::string* base : {&test::kFallingBase, &test::kFoldedBase, &test::kSlidingBase}) {
    CHECK(error_of(*base).empty());
    CHECK(error_of(edit(*base, "model = \"string\"", "model = \"reduced\"")).empty());
  }
}

TEST_CASE("bad scenes are refused with the location, the key, the value and what is allowed", "[unit][scene]") {
  // The tension backends of this build (KLU is optional), as the message lists them.
  std::string backends;
  for (const auto& name : tension_backend_names()) backends += (backends.empty() ? "" : ", ") + name;
  const BadScene cases[] = {
      {"typo in a key",
       edit(kBase, "length = 1.0", "lenght = 1.0"),
       "s.toml:2:1: unknown key 'lenght' in [string]; valid keys: length, density, nodes, link_length, closed, dimension, elements (did you mean 'length'?)"},
      {"a section of the old format",
       edit(kBase, "[effects.gravity]", "[gravity]"),
       "s.toml:13:2: unknown section [gravity]; valid sections: string, shape, velocity, ends, effects, solver, output, stop; valid top-level keys: model; gravity is now written [effects.gravity]"},
      {"typo in a section",
       edit(kBase, "[stop]", "[stp]"),
       "s.toml:16:2: unknown section [stp]; valid sections: string, shape, velocity, ends, effects, solver, output, stop; valid top-level keys: model (did you mean [stop]?)"},
      {"typo in an effect",
       edit(kBase, "[effects.gravity]", "[effects.gravty]"),
       "s.toml:13:10: unknown effect [effects.gravty]; valid effects: gravity, drag, heap, fold, plane, edge, surface, cylinder, kink (did you mean [effects.gravity]?)"},
      {"a solver key of the old format",
       kBase + std::string("[solver]\nt_end = 1.0\n"),
       "s.toml:19:1: unknown key 't_end' in [solver]; valid keys: method, rtol, atol, max_step, initial_step, max_steps, stabilization_time, backend, linear_solver, check_slack, slack_tolerance, slack, snap_restitution, kinks, kink_turn, kink_window, max_wall_s; t_end is now written in [stop]"},
      {"a top-level key",
       std::string("title = \"x\"\n") + kBase,
       "s.toml:1:1: unknown top-level key 'title'; valid sections: string, shape, velocity, ends, effects, solver, output, stop; valid top-level keys: model"},
      {"a section written as a value",
       "ends = \"fixed\"\n" + edit(kBase, "[ends]\nstart = \"fixed\"\n", ""),
       "s.toml:1:8: ends = \"fixed\" must be a table: write [ends] and its keys below it"},
      {"a fractional node count",
       edit(kBase, "nodes = 11", "nodes = 11.5"),
       "s.toml:4:9: string.nodes = 11.5 must be an integer"},
      {"a density in words",
       edit(kBase, "density = 0.1", "density = \"heavy\""),
       "s.toml:3:11: string.density = \"heavy\" must be a number"},
      {"a negative density",
       edit(kBase, "density = 0.1", "density = -0.1"),
       "s.toml:3:11: string.density = -0.1 is out of range: allowed density > 0"},
      {"one node",
       edit(kBase, "nodes = 11", "nodes = 1"),
       "s.toml:4:9: string.nodes = 1 is out of range: allowed 2 <= nodes <= 10000000"},
      {"one node too many (issue #21: it printed 'nodes = 1e+07 ... nodes <= 1e+07')",
       edit(kBase, "nodes = 11", "nodes = 10000001"),
       "s.toml:4:9: string.nodes = 10000001 is out of range: allowed 2 <= nodes <= 10000000"},
      {"a node count beyond every integer type but int64's",
       edit(kBase, "nodes = 11", "nodes = 9223372036854775807"),
       "s.toml:4:9: string.nodes = 9223372036854775807 is out of range: allowed 2 <= nodes <= 10000000"},
      {"a Baumgarte time below the solver's range (issue #21: exit 3 'non-finite' at t = 0)",
       kBase + std::string("[solver]\nstabilization_time = 1e-300\n"),
       "s.toml:19:22: solver.stabilization_time = 1e-300: the Baumgarte time (s) is 1e-300, out of the range the "
       "solver can represent: allowed 1e-100 to 1e+100 (or 0); the scaled problem would overflow or underflow"},
      {"a fourth dimension",
       edit(kBase, "nodes = 11", "nodes = 11\ndimension = 4"),
       "s.toml:5:13: string.dimension = 4 is not allowed; valid values: 2, 3"},
      {"nodes and link length together",
       edit(kBase, "nodes = 11", "nodes = 11\nlink_length = 0.1"),
       "s.toml:5:15: string.link_length = 0.1 and string.nodes = 11 both set the resolution: give one of them"},
      {"closed as a word",
       edit(kBase, "nodes = 11", "nodes = 11\nclosed = \"yes\""),
       "s.toml:5:10: string.closed = \"yes\" must be true or false"},
      {"no shape section",
       edit(kBase, "[shape]\nkind = \"polyline\"\npoints = [[0.0, 0.0], [0.0, -1.0]]\n", ""),
       "s.toml:1:1: the scene needs a [shape] section with kind = one of polyline, points, arc, circle, catenary"},
      {"a shape without kind",
       edit(kBase, "kind = \"polyline\"\n", ""),
       "s.toml:6:1: [shape] needs kind (one of polyline, points, arc, circle, catenary)"},
      {"a misspelt shape kind",
       edit(kBase, "kind = \"polyline\"", "kind = \"polyine\""),
       "s.toml:7:8: shape.kind = \"polyine\" is not allowed; valid values: polyline, points, arc, circle, catenary (did you mean \"polyline\"?)"},
      {"a circle without radius",
       edit(kBase, "kind = \"polyline\"\npoints = [[0.0, 0.0], [0.0, -1.0]]", "kind = \"circle\"\ncenter = [0.0, 0.0]"),
       "s.toml:6:1: [shape] needs radius (m, > 0, for kind = \"circle\")"},
      {"a key of another shape kind",
       edit(kBase, "points = [[0.0, 0.0], [0.0, -1.0]]", "points = [[0.0, 0.0], [0.0, -1.0]]\nradius = 1.0"),
       "s.toml:9:10: shape.radius does not apply to kind = \"polyline\""},
      {"an arc swept more than a turn",
       edit(kBase, "kind = \"polyline\"\npoints = [[0.0, 0.0], [0.0, -1.0]]", "kind = \"arc\"\ncenter = [0.0, 0.0]\nradius = 1.0\nsweep_deg = 400.0"),
       "s.toml:10:13: shape.sweep_deg = 400.0 is out of range: allowed 0 < |sweep_deg| <= 360"},
      {"a polyline of one point",
       edit(kBase, "points = [[0.0, 0.0], [0.0, -1.0]]", "points = [[0.0, 0.0]]"),
       "s.toml:8:10: shape.points = [[0.0, 0.0]] has 1 point: a shape needs at least 2"},
      {"a length tolerance above one",
       edit(kBase, "points = [[0.0, 0.0], [0.0, -1.0]]", "points = [[0.0, 0.0], [0.0, -1.0]]\nlength_tolerance = 2.0"),
       "s.toml:9:20: shape.length_tolerance = 2 is out of range: allowed 0 < length_tolerance <= 1"},
      {"a corner radius on an arc",
       edit(kBase, kPolyline, "kind = \"arc\"\ncenter = [0.0, 0.0]\nradius = 1.0\nsweep_deg = 90.0\ncorner_radius = 0.1"),
       "s.toml:11:17: shape.corner_radius does not apply to kind = \"arc\""},
      {"a zero corner radius",
       edit(kBase, "points = [[0.0, 0.0], [0.0, -1.0]]", "points = [[0.0, 0.0], [0.0, -1.0]]\ncorner_radius = 0.0"),
       "s.toml:9:17: shape.corner_radius = 0 is out of range: allowed corner_radius > 0"},
      {"a corner radius too large for a segment",
       edit(kBase, "points = [[0.0, 0.0], [0.0, -1.0]]", "points = [[0.0, 0.0], [0.0, -0.3], [0.04, -0.3], [0.04, 0.377]]\ncorner_radius = 0.03"),
       "s.toml:9:17: shape.corner_radius = 0.03 m is too large for the segment from point 1 = [0, -0.3] to point 2 = "
       "[0.04, -0.3]: it is 0.04 m long but the fillets at its ends need 0.06 m of it (tangent lengths 0.03 m + "
       "0.03 m); the largest corner_radius that fits every segment is 0.02 m"},
      {"a corner radius where the polyline turns back",
       edit(kBase, "points = [[0.0, 0.0], [0.0, -1.0]]", "points = [[0.0, 0.0], [0.0, -0.5], [0.0, 0.0]]\ncorner_radius = 0.05"),
       "s.toml:9:17: shape.corner_radius = 0.05 m cannot round point 1 = [0, -0.5]: the polyline turns back on itself "
       "there (it turns by 180 deg, to within 1e-09 rad of 180 deg), and no arc is tangent to both of its segments"},
      {"a corner radius on a closed string",
       edit(edit(kBase, "nodes = 11", "nodes = 11\nclosed = true"), "points = [[0.0, 0.0], [0.0, -1.0]]", "points = [[0.0, 0.0], [0.3, 0.0], [0.0, 0.4]]\ncorner_radius = 0.05"),
       "s.toml:10:17: shape.corner_radius does not apply to a closed string (string.closed = true): only the interior "
       "points of an open polyline are rounded"},
      {"an unknown velocity kind",
       kBase + std::string("[velocity]\nkind = \"spin\"\n"),
       "s.toml:19:8: velocity.kind = \"spin\" is not allowed; valid values: rest, uniform, tangential, nodes, rotation"},
      {"a tangential velocity without speed",
       kBase + std::string("[velocity]\nkind = \"tangential\"\n"),
       "s.toml:18:1: [velocity] needs speed (m/s, along the string, for kind = \"tangential\")"},
      {"a misspelt end kind",
       edit(kBase, "start = \"fixed\"", "start = \"fxed\""),
       "s.toml:11:9: ends.start = \"fxed\" is not allowed; valid values: free, fixed, loaded, driven (did you mean \"fixed\"?)"},
      {"a driven end without parameters",
       edit(kBase, "start = \"fixed\"", "start = \"driven\""),
       "s.toml:11:9: ends.start = \"driven\" needs parameters: write it as a table, e.g. { kind = \"driven\", path = \"shake\", amplitude = [0.05, 0.0], omega = 10.0 }"},
      {"a shaken end without omega",
       edit(kBase, "start = \"fixed\"", "start = { kind = \"driven\", amplitude = [0.05, 0.0] }"),
       "s.toml:11:9: [ends.start] needs omega (rad/s, > 0, for kind = \"driven\", path = \"shake\")"},
      {"a shaken end at zero frequency",
       edit(kBase, "start = \"fixed\"", "start = { kind = \"driven\", amplitude = [0.05, 0.0], omega = 0.0 }"),
       "s.toml:11:61: ends.start.omega = 0 is out of range: allowed omega > 0"},
      {"a loaded end with a path",
       edit(kBase, "start = \"fixed\"", "start = \"fixed\"\nend = { kind = \"loaded\", force = [0.0, -1.0], path = \"sine\" }"),
       "s.toml:12:54: ends.end.path does not apply to kind = \"loaded\""},
      {"a misspelt key of an end",
       edit(kBase, "start = \"fixed\"", "start = \"fixed\"\nend = { kind = \"loaded\", forse = [0.0, -1.0] }"),
       "s.toml:12:26: unknown key 'forse' in [ends.end]; valid keys: kind, force, amplitude, omega, path, velocity (did you mean 'force'?)"},
      {"gravity without g",
       edit(kBase, "g = [0.0, -9.81]\n", ""),
       "s.toml:13:1: [effects.gravity] needs g (m/s^2, a vector [gx, gy] or [gx, gy, gz])"},
      {"a negative drag",
       kBase + std::string("[effects.drag]\ncoefficient = -1.0\n"),
       "s.toml:19:15: effects.drag.coefficient = -1 is out of range: allowed coefficient >= 0"},
      {"drag without coefficient",
       kBase + std::string("[effects.drag]\n"),
       "s.toml:18:1: [effects.drag] needs coefficient (1/s, >= 0: the force -coefficient m v on every node)"},
      {"an unknown integration method",
       kBase + std::string("[solver]\nmethod = \"rk99\"\n"),
       "s.toml:19:10: solver.method = \"rk99\" is not a known integration method: allowed auto, dirk2, dirk3, dirk4, "
       "dirk5, erk3, erk4, erk5, erk6, erk8, or an ARKODE_* Butcher table name"},
      {"a relative tolerance of one",
       kBase + std::string("[solver]\nrtol = 1.0\n"),
       "s.toml:19:8: solver.rtol = 1 is out of range: allowed 1e-14 <= rtol <= 0.01"},
      {"an absolute tolerance of a million",
       kBase + std::string("[solver]\natol = 1e6\n"),
       "s.toml:19:8: solver.atol = 1000000 is out of range: allowed 0 < atol <= 0.01"},
      {"an unknown Newton solver",
       kBase + std::string("[solver]\nlinear_solver = \"lu\"\n"),
       "s.toml:19:17: solver.linear_solver = \"lu\" is not allowed; valid values: auto, banded, klu (did you mean \"klu\"?)"},
      {"an unknown tension backend",
       kBase + std::string("[solver]\nbackend = \"lu\"\n"),
       "s.toml:19:11: solver.backend = \"lu\" is not a tension solver: allowed auto, " + backends},
      {"an unknown output field",
       kBase + std::string("[output]\nfields = [\"nodes\", \"strain\"]\n"),
       "s.toml:19:20: output.fields[1] = \"strain\" is not allowed; valid values: nodes, tension, energy, forces, stats"},
      {"ParaView frames without nodes",
       kBase + std::string("[output]\nfields = [\"energy\"]\n"),
       "s.toml:19:10: output.formats includes \"vtk\" (the default), which draws the string from its nodes: output.fields must include \"nodes\" (or set formats = [\"csv\"])"},
      {"a format listed twice",
       kBase + std::string("[output]\nformats = [\"csv\", \"csv\"]\n"),
       "s.toml:19:19: output.formats lists \"csv\" twice"},
      {"no stop section",
       edit(kBase, "[stop]\nt_end = 0.2\n", ""),
       "s.toml:1:1: the scene needs a [stop] section with t_end (the end time, s, > 0)"},
      {"a stop section without t_end",
       edit(kBase, "t_end = 0.2\n", ""),
       "s.toml:16:1: [stop] needs t_end (the end time, s, > 0)"},
      {"a zero end time",
       edit(kBase, "t_end = 0.2", "t_end = 0.0"),
       "s.toml:17:9: stop.t_end = 0 is out of range: allowed t_end > 0"},
      {"an end time in words",
       edit(kBase, "t_end = 0.2", "t_end = \"long\""),
       "s.toml:17:9: stop.t_end = \"long\" must be a number"},
      {"a TOML syntax error",
       edit(kBase, "length = 1.0", "length = = 1.0"),
       "s.toml:2:10: Error while parsing value: could not determine value type"},
      {"an end given twice",
       edit(kBase, "start = \"fixed\"", "start = \"fixed\"\nstart = \"free\""),
       "s.toml:12:9: Error while parsing key-value pair: cannot redefine existing string 'start'"},
      {"too many frames",
       kBase + std::string("[output]\ninterval = 1e-9\n"),
       "s.toml:19:12: output.interval = 1e-09 s with stop.t_end = 0.2 s asks for 2e+08 frames of 11 nodes (2.2e+09 node-frames): they would take 199 GB of memory until written, allowed at most 2.15 GB; raise output.interval"},
      {"outputs over the disk budget",
       kBase + std::string("[output]\ninterval = 1e-3\nmax_megabytes = 0.01\n"),
       "s.toml:19:12: output.interval = 0.001 s with stop.t_end = 0.2 s asks for 202 frames of 11 nodes (2.22e+03 "
       "node-frames): the selected outputs would take about 1.46 MB on disk, more than output.max_megabytes = 0.01; "
       "raise output.interval, select fewer fields or formats, or raise output.max_megabytes"},
      {"gravity out of the double range",
       edit(kBase, "g = [0.0, -9.81]", "g = [5.0, -1e300]"),
       "s.toml:14:5: effects.gravity.g = [5.0, -1e300]: |g| (m/s^2) is 1e+300, out of the range the solver can "
       "represent: allowed 1e-100 to 1e+100 (or 0); the scaled problem would overflow or underflow"},
      {"a run long enough for its reach to overflow",
       edit(edit(kBase, "t_end = 0.2", "t_end = 1e99"), "g = [0.0, -9.81]", "g = [0.0, -1e5]"),
       "s.toml:17:9: stop.t_end = 1e99: the reach length + v t_end + |g| t_end^2 (m) is 1e+203, out of the range the "
       "solver can represent: allowed 1e-200 to 1e+200 (or 0); the scaled problem would overflow or underflow"},
      {"a shape shorter than the string",
       edit(kBase, "length = 1.0", "length = 1.5"),
       "s.toml:2:10: string.length = 1.5 m but the shape (polyline through 2 points) is 1 m long: they differ by "
       "-0.5 m, more than shape.length_tolerance = 1e-06 (relative)"},
      {"gravity in three dimensions on a plane string",
       edit(kBase, "g = [0.0, -9.81]", "g = [0.0, -9.81, 0.0]"),
       "s.toml:14:5: effects.gravity.g = [0.0, -9.81, 0.0] has 3 components but string.dimension = 2"},
      {"a point in three dimensions",
       edit(kBase, "points = [[0.0, 0.0], [0.0, -1.0]]", "points = [[0.0, 0.0], [0.0, -1.0, 0.0]]"),
       "s.toml:8:23: shape.points[1] = [0.0, -1.0, 0.0] has 3 components but string.dimension = 2"},
      {"a fixed end on a closed string",
       edit(edit(kBase, "length = 1.0\n", ""), kPolyline, "kind = \"circle\"\ncenter = [0.0, 0.0]\nradius = 0.2"),
       "s.toml:11:9: ends.start = \"fixed\": a closed string has no ends (string.closed = true)"},
      {"both ends fixed, pulled taut",
       edit(kBase, "start = \"fixed\"", "start = \"fixed\"\nend = \"fixed\""),
       "s.toml:12:7: ends.start (fixed) and ends.end (fixed) are 1 m apart at t = 0 s, but the string is 1 m long: prescribed ends may not pull an inextensible string taut"},
      {"an end driven away from a fixed one",
       edit(edit(edit(kBase, "[0.0, -1.0]]", "[0.3, -0.4], [0.6, 0.0]]"), "start = \"fixed\"", "start = \"fixed\"\nend = { kind = \"driven\", path = \"linear\", velocity = [1.0, 0.0] }"), "t_end = 0.2", "t_end = 1.0"),
       "s.toml:12:7: ends.start (fixed) and ends.end (linear) are 1 m apart at t = 0.4 s, but the string is 1 m long: prescribed ends may not pull an inextensible string taut"},
      {"two prescribed nodes and one link",
       edit(edit(edit(kBase, "[0.0, -1.0]]", "[0.3, -0.4], [0.6, 0.0]]"), "start = \"fixed\"", "start = \"fixed\"\nend = \"fixed\""), "nodes = 11", "nodes = 2"),
       "s.toml:4:9: string.nodes = 2 but both ends are prescribed: the link between them could not move and its tension would be undetermined; allowed nodes >= 3"},
      {"an open circle",
       edit(edit(kBase, "length = 1.0\n", "closed = false\n"), kPolyline, "kind = \"circle\"\ncenter = [0.0, 0.0]\nradius = 0.2"),
       "s.toml:2:10: string.closed = false but the shape (circle of radius 0.2 m) is a closed curve"},
      {"a catenary without length",
       edit(edit(kBase, "length = 1.0\n", ""), kPolyline, "kind = \"catenary\"\nstart = [0.0, 0.0]\nend = [0.5, 0.0]"),
       "s.toml:6:8: a catenary shape needs string.length (the sag follows from it)"},
      {"node velocities for too few nodes",
       kBase + std::string("[velocity]\nkind = \"nodes\"\nvalues = [[0.0, 0.0], [0.0, 0.0]]\n"),
       "s.toml:20:10: velocity.values has 2 entries but the string has 11 nodes"},
  };
  CHECK(sizeof(cases) / sizeof(cases[0]) >= 30);
  for (const BadScene& c : cases) {
    CAPTURE(c.what, c.text);
    CHECK(error_of(c.text) == c.message);
  }
}

TEST_CASE("bad scenes with fronts, and scenes the reduced model does not fit, are refused with their reasons",
          "[unit][scene]") {
  // The messages point into test_scene_support.hpp's falling (F), folded (D) and sliding (S) chains.
  const std::string& F = test::kFallingBase;
  const std::string& D = test::kFoldedBase;
  const std::string& S = test::kSlidingBase;
  auto reduced = [](const std::string& text) { return edit(text, "model = \"string\"", "model = \"reduced\""); };
  const BadScene cases[] = {
      {"typo in a heap's key", edit(F, "side = \"end\"", "sid = \"end\""),
       "s.toml:15:1: unknown key 'sid' in effects.heap[0]; valid keys: side, s0, f, point, on_plane, pot (did you mean 'side'?)"},
      {"a heap that pushes but is no pot", edit(S, "f = 0.5", "f = -0.2"), 
       "s.toml:17:5: effects.heap[0].f = -0.2 is out of range: allowed 0 <= f <= 1; a heap that pushes the string out (f < 0, down to -0.5) must be a pot: side = \"start\" with pot = true"},
      {"a pot below f = -1/2", edit(S, "f = 0.5", "f = -0.6\npot = true"), 
       "s.toml:17:5: effects.heap[0].f = -0.6 is out of range: allowed -0.5 <= f <= 1 for a pot (it loses (1/2 + f) lambda v^3, which must not be negative)"},
      {"a pot the string runs into", edit(F, "f = 0.5", "f = 0.5\npot = true"), 
       "s.toml:18:7: effects.heap[0].pot = true on side = \"end\": a pot feeds the string; allowed only for side = \"start\""},
      {"a pot in a reduced scene", reduced(edit(S, "f = 0.5", "f = -0.2\npot = true")), 
       "s.toml:1:9: model = \"reduced\" has no pot: the reduced sliding chain draws from a heap with 0 <= f <= 1 (effects.heap[0].pot = true)"},
      {"a heap's f above one", edit(F, "f = 0.5", "f = 1.5"),
       "s.toml:17:5: effects.heap[0].f = 1.5 is out of range: allowed 0 <= f <= 1"},
      {"a heap on neither side", edit(F, "side = \"end\"", "side = \"top\""),
       "s.toml:15:8: effects.heap[0].side = \"top\" is not allowed; valid values: start, end"},
      {"a heap written as one table", edit(F, "[[effects.heap]]", "[effects.heap]"),
       "s.toml:14:1: effects.heap must be an array of tables: write [[effects.heap]] once per heap"},
      {"two heaps on one side", edit(F, "[effects.plane]", "[[effects.heap]]\nside = \"end\"\ns0 = 0.5\npoint = [0.0, 0.5]\n\n[effects.plane]"),
       "s.toml:22:8: effects.heap[1].side = \"end\": effects.heap[0] already holds that side of the string; allowed at most one heap per side"},
      {"a heap without s0", edit(F, "s0 = 1.0\n", ""),
       "s.toml:14:1: effects.heap[0] needs s0 (m, the material coordinate of the front at t = 0)"},
      {"a heap on a plane without a plane", edit(F, "[effects.plane]\npoint = [0.0, 0.0]\nnormal = [0.0, 1.0]\n", ""),
       "s.toml:19:12: effects.heap[0].on_plane = true needs [effects.plane] (point, normal): the table the heap lies on"},
      {"a plane under no heap", edit(F, "on_plane = true", "on_plane = false"),
       "s.toml:21:1: [effects.plane] is the table under a heap, but no [[effects.heap]] has on_plane = true (for a table the string lies on and lands on, without a heap, write [[effects.surface]])"},
      {"a heap not on its plane", edit(F, "[effects.plane]\npoint = [0.0, 0.0]", "[effects.plane]\npoint = [0.0, 0.1]"),
       "s.toml:18:9: effects.heap[0].point = [0.0, 0.0] is not on its plane: it is 0.1 m from effects.plane (through [0, 0.1] with normal [0, 1])"},
      {"a plane facing away from the string", edit(F, "normal = [0.0, 1.0]", "normal = [0.0, -1.0]"),
       "s.toml:23:10: effects.plane.normal = [0.0, -1.0]: node 0 (s = 0 m) of the moving string lies 1 m on the other side of the plane; the normal points to the string's side, and the string may not start below its table"},
      {"a heap's s0 outside the string", edit(F, "s0 = 1.0", "s0 = 1.5"),
       "s.toml:16:6: effects.heap[0].s0 = 1.5 is outside the string: allowed 0 < s0 <= 1 for side = \"end\" (the string is 1 m long)"},
      {"a shape that misses the heap point", edit(F, "point = [0.0, 0.0]\non_plane", "point = [0.1, 0.0]\non_plane"),
       "s.toml:18:9: effects.heap[0].point = [0.1, 0.0] is 0.1 m from the string's material point s0 = 1 m, which the shape puts at [0, 0]: the shape must pass through the heap point at s0"},
      {"a closed string with a heap", edit(edit(F, "kind = \"polyline\"\npoints = [[0.0, 1.0], [0.0, 0.0]]", "kind = \"circle\"\ncenter = [0.0, 0.5]\nradius = 0.15915494309189535"), "length = 1.0\n", ""),
       "s.toml:14:1: [[effects.heap]] on a closed string: fronts are tracked on open strings only (string.closed = true)"},
      {"a fixed end inside a heap", edit(F, "[effects.gravity]", "[ends]\nend = \"fixed\"\n\n[effects.gravity]"),
       "s.toml:12:7: ends.end = \"fixed\" is inside the heap of effects.heap[0] (side = \"end\", s0 = 1 m): an end held by a heap cannot be fixed, loaded or driven"},
      {"a fold outside the heaps", edit(S, "[stop]", "[effects.fold]\ns0 = 0.5\n\n[stop]"),
       "s.toml:21:6: effects.fold.s0 = 0.5 is not between the heaps: allowed 0.8 < s0 < 1"},
      {"a fold where the shape does not fold", edit(D, "points = [[0.0, 0.0], [0.0, -0.2], [0.0, 0.6]]", "points = [[0.0, 0.0], [0.0, -1.0]]"),
       "s.toml:18:6: effects.fold.s0 = 0.2: the shape does not fold back there (it turns by 0 deg at s = 0.2 m; a fold turns by 180 deg, its two arms side by side)"},
      {"a kink where the shape has no corner", kBase + "[[effects.kink]]\ns0 = 0.45\n",
       "s.toml:19:6: effects.kink[0].s0 = 0.45: the shape has no corner there (it turns by 0 deg at s = 0.45 m; a kink's arms turn by at least 1 deg)"},
      {"a kink without a full link on one side", edit(kBase + "[[effects.kink]]\ns0 = 0.05\n", "[[0.0, 0.0], [0.0, -1.0]]", "[[0.0, 0.0], [0.05, 0.0], [0.05, -0.95]]"),
       "s.toml:19:6: effects.kink[0].s0 = 0.05: allowed inside the moving part of the string with a full link on either side, 0.1 < s0 < 0.9 m"},
      {"a kink without s0", kBase + "[[effects.kink]]\n", "s.toml:18:1: effects.kink[0] needs s0 (m, the material coordinate of the kink at t = 0, at a corner of the shape)"},
      {"two kinks less than two links apart", edit(kBase + "[[effects.kink]]\ns0 = 0.45\n[[effects.kink]]\ns0 = 0.5\n", "[[0.0, 0.0], [0.0, -1.0]]", "[[0.0, 0.0], [0.0, -0.45], [0.05, -0.45], [0.05, -0.95]]"),
       "s.toml:21:6: effects.kink[1].s0 = 0.5 is less than two links from effects.kink[0]"},
      {"an inserted kink with an obstacle",
       edit(kBase, "[stop]", "[[effects.surface]]\npoint = [0.0, -2.0]\nnormal = [0.0, 1.0]\n\n[solver]\nslack = \"allow\"\nkinks = \"insert\"\n\n[stop]"),
       "s.toml:22:9: solver.kinks = \"insert\" with an obstacle ([[effects.surface]]): a kink front and node contact are not built together (their impulses are not shared, and the ledgers would not close); allowed: no kink front (solver.kinks = \"off\", no [[effects.kink]]), or no [[effects.surface]], [[effects.cylinder]] or [effects.plane] surface"},
      {"reduced: a kink", reduced(D) + "[[effects.kink]]\ns0 = 0.5\n", "s.toml:1:9: model = \"reduced\" has no kink: remove [[effects.kink]] (the string solver runs it: model = \"string\")"},
      {"a stop on a front the scene lacks", edit(F, "front = \"heap_end\"", "front = \"fold\""),
       "s.toml:28:9: stop.front[0].front = \"fold\" but the scene has no fold ([effects.fold]); its fronts: heap_end"},
      {"a misspelt front in a stop", edit(F, "front = \"heap_end\"", "front = \"heap_ned\""),
       "s.toml:28:9: stop.front[0].front = \"heap_ned\" is not allowed; valid values: fold, heap_start, heap_end (did you mean \"heap_end\"?)"},
      {"a stop where the front starts", edit(F, "s0 = 0.01", "s0 = 1.0"),
       "s.toml:29:6: stop.front[0].s0 = 1.0 is where the heap_end front starts: a stop event needs a front that gets there"},
      {"two heaps closer than two links (the front model's own check, located at the first heap)",
       edit(S, "[stop]", "[[effects.heap]]\nside = \"end\"\ns0 = 0.85\npoint = [0.0, -0.05]\n\n[stop]"),
       "s.toml:14:1: effects.heap[0]: the heaps are less than two links apart: use more nodes"},
      {"a chain lying along its table (a degenerate contact, located at the heap)",
       edit(F, "points = [[0.0, 1.0], [0.0, 0.0]]", "points = [[1.0, 0.0], [0.0, 0.0]]"),
       "s.toml:14:1: effects.heap[0]: the initial shape does not fit the fronts: the string meets the heap's plane at a grazing angle (n·t = 0 at node 19)"},
      {"a string with fronts of one link (issue #21: the message did not name string.nodes)",
       edit(F, "nodes = 21", "nodes = 2"),
       "s.toml:5:9: string.nodes = 2 gives 1 link: a string with fronts needs at least 2 links (allowed nodes >= 3)"},
      {"a misspelt model", edit(F, "model = \"string\"", "model = \"reduce\""),
       "s.toml:1:9: model = \"reduce\" is not allowed; valid values: string, reduced (did you mean \"reduced\"?)"},
      {"reduced: no front", "model = \"reduced\"\n" + kBase,
       "s.toml:1:9: model = \"reduced\" needs a fold or a heap: the reduced models are the falling chain (a heap at the end, on a table), the folded chain (a fold) and the sliding chain (a heap at the start, at a hole)"},
      {"reduced: no gravity", reduced(edit(D, "[effects.gravity]\ng = [0.0, -9.81]\n", "")),
       "s.toml:1:9: model = \"reduced\" needs gravity ([effects.gravity]): each reduced model is driven by it"},
      {"reduced: a tilted falling chain", reduced(edit(F, "points = [[0.0, 1.0], [0.0, 0.0]]", "points = [[0.34202014332567, 0.93969262078591], [0.0, 0.0]]")),
       "s.toml:1:9: model = \"reduced\" needs a straight string along gravity: the falling part is tilted 20.0° from it"},
      {"reduced: a bent resting arm", reduced(edit(edit(D, "[[0.0, 0.0], [0.0, -0.2], [0.0, 0.6]]", "[[0.0, 0.0], [0.06, -0.08], [0.0, -0.16], [0.0, -0.3], [0.0, 0.36]]"), "s0 = 0.2", "s0 = 0.34")),
       "s.toml:1:9: model = \"reduced\" needs a straight string along gravity: the resting arm is not straight (node 2 is 0.0632 m off the line along gravity)"},
      {"reduced: a moving start", reduced(S + "[velocity]\nkind = \"uniform\"\nvalue = [0.5, 0.0]\n"),
       "s.toml:1:9: model = \"reduced\" needs the string at rest: node 16 (s = 0.8 m) moves at 0.5 m/s"},
      {"reduced: drag", reduced(S + "[effects.drag]\ncoefficient = 0.1\n"),
       "s.toml:1:9: model = \"reduced\" has no drag: remove [effects.drag]"},
      {"reduced: a falling chain into a hole", reduced(edit(edit(F, "on_plane = true\n", ""), "[effects.plane]\npoint = [0.0, 0.0]\nnormal = [0.0, 1.0]\n", "")),
       "s.toml:1:9: model = \"reduced\" needs the falling chain's heap on a table: on_plane = true, with [effects.plane] perpendicular to gravity"},
      {"reduced: a sloping table", reduced(edit(F, "normal = [0.0, 1.0]", "normal = [0.1, 1.0]")),
       "s.toml:1:9: model = \"reduced\" needs the table perpendicular to gravity: effects.plane.normal is tilted 5.7° from -g"},
      {"reduced: a falling chain without cutoff", reduced(edit(F, "[[stop.front]]\nfront = \"heap_end\"\ns0 = 0.01\n", "")),
       "s.toml:1:9: model = \"reduced\" needs a cutoff for the falling chain: one [[stop.front]] with front = \"heap_end\" and 0 < s0 < 1 (s0 = eps l; the reduced model is singular at the end of the motion)"},
      {"reduced: a folded chain with a free start", reduced(edit(D, "start = \"fixed\"", "start = \"free\"")),
       "s.toml:1:9: model = \"reduced\" needs the folded chain's start fixed: ends.start = \"free\" (the resting arm hangs from it)"},
      {"reduced: a sideways end load", reduced(edit(D, "start = \"fixed\"", "start = \"fixed\"\nend = { kind = \"loaded\", force = [1.0, 1.0] }")),
       "s.toml:1:9: model = \"reduced\" needs the load on the free end along -g (upward, F >= 0): ends.end.force is tilted 45.0° from it"},
      {"reduced: a sliding chain with a stop", reduced(S + "[[stop.front]]\nfront = \"heap_start\"\ns0 = 0.9\n"),
       "s.toml:1:9: model = \"reduced\" stops the sliding chain when the heap runs empty (eta = 1): remove [[stop.front]]"},
      {"reduced: two fronts", reduced(edit(S, "[stop]", "[[effects.heap]]\nside = \"end\"\ns0 = 1.0\npoint = [0.0, -0.2]\n\n[stop]")),
       "s.toml:1:9: model = \"reduced\" needs exactly one front (a heap or a fold): the scene has 2 (heap_start, heap_end)"},
  };
  CHECK(sizeof(cases) / sizeof(cases[0]) >= 12);
  for (const BadScene& c : cases) {
    CAPTURE(c.what, c.text);
    CHECK(error_of(c.text) == c.message);
  }
}

TEST_CASE("solver.slack and solver.max_wall_s are parsed and checked, and check_slack is the older form of slack",
          "[unit][scene]") {
  auto solver = [](const std::string& keys) {
    return parse_scene_text(kBase + "\n[solver]\n" + keys, "s.toml").solver;  // [solver] keys from line 20
  };
  // Defaults: slack = "stop", no wall-clock limit.
  CHECK(solver("").slack == "stop");
  CHECK_FALSE(solver("").max_wall_s);
  for (const char* value : {"stop", "warn", "ignore", "allow"})
    CHECK(solver(std::string("slack = \"") + value + "\"\n").slack == value);
  CHECK(solver("slack = \"allow\"\nsnap_restitution = 0.5\n").snap_restitution == 0.5);
  // kinks: off by default; "insert" with its turn and window.
  CHECK(solver("").kinks == "off");
  CHECK(solver("kinks = \"insert\"\nkink_turn = 60\nkink_window = 0.03\n").kink_turn == 60.0);
  CHECK(solver("kinks = \"insert\"\nkink_window = 0.03\n").kink_window == 0.03);
  // check_slack, the older key: true is "stop", false is "ignore".
  CHECK(solver("check_slack = true\n").slack == "stop");
  CHECK(solver("check_slack = false\n").slack == "ignore");
  CHECK(solver("max_wall_s = 30\n").max_wall_s == 30.0);
  CHECK(solver("max_wall_s = 0.5\n").max_wall_s == 0.5);
  const BadScene cases[] = {
      {"slack misspelt", kBase + "\n[solver]\nslack = \"wran\"\n",
       "s.toml:20:9: solver.slack = \"wran\" is not allowed; valid values: stop, warn, ignore, allow (did you mean \"warn\"?)"},
      {"slack as a boolean", kBase + "\n[solver]\nslack = true\n", "s.toml:20:9: solver.slack = true must be a string"},
      {"slack and check_slack together", kBase + "\n[solver]\ncheck_slack = true\nslack = \"warn\"\n",
       "s.toml:20:15: solver.check_slack = true and solver.slack = \"warn\" both say what a slack link does: give one of them (check_slack = true is slack = \"stop\", false is slack = \"ignore\")"},
      {"a key misspelt", kBase + "\n[solver]\nslak = \"warn\"\n",
       "s.toml:20:1: unknown key 'slak' in [solver]; valid keys: method, rtol, atol, max_step, initial_step, max_steps, stabilization_time, backend, linear_solver, check_slack, slack_tolerance, slack, snap_restitution, kinks, kink_turn, kink_window, max_wall_s (did you mean 'slack'?)"},
      {"snap_restitution above 1", kBase + "\n[solver]\nslack = \"allow\"\nsnap_restitution = 1.5\n", "s.toml:21:20: solver.snap_restitution = 1.5 is out of range: allowed 0 <= snap_restitution <= 1"},
      {"snap_restitution below 0", kBase + "\n[solver]\nslack = \"allow\"\nsnap_restitution = -0.1\n", "s.toml:21:20: solver.snap_restitution = -0.1 is out of range: allowed 0 <= snap_restitution <= 1"},
      {"snap_restitution without slack = allow", kBase + "\n[solver]\nsnap_restitution = 0.5\n", "s.toml:20:20: solver.snap_restitution = 0.5 applies only with solver.slack = \"allow\""},
      {"kinks misspelt", kBase + "\n[solver]\nkinks = \"inset\"\n",
       "s.toml:20:9: solver.kinks = \"inset\" is not allowed; valid values: off, insert (did you mean \"insert\"?)"},
      {"kink_turn above 179", kBase + "\n[solver]\nkinks = \"insert\"\nkink_turn = 180\n",
       "s.toml:21:13: solver.kink_turn = 180 is out of range: allowed 1 <= kink_turn <= 179"},
      {"kink_window of 0", kBase + "\n[solver]\nkinks = \"insert\"\nkink_window = 0.0\n",
       "s.toml:21:15: solver.kink_window = 0 is out of range: allowed kink_window > 0"},
      {"kink_turn without kinks = insert", kBase + "\n[solver]\nkink_turn = 60\n",
       "s.toml:20:13: solver.kink_turn = 60 applies only with solver.kinks = \"insert\""},
      {"slack = allow with an implicit method", kBase + "\n[solver]\nmethod = \"dirk3\"\nslack = \"allow\"\n", "s.toml:20:10: solver.method = \"dirk3\" is implicit, and implicit methods do not meet solver.slack = \"allow\" (their Newton systems know no slack link): use an explicit method (\"auto\", \"erk8\", ...)"},
      {"a surface with a zero normal", kBase + "[[effects.surface]]\npoint = [0.0, -2.0]\nnormal = [0.0, 0.0]\n",
       "s.toml:20:10: effects.surface[0].normal = [0.0, 0.0] is not a normal: allowed a finite nonzero vector"},
      {"a touchdown surface with a zero normal", kBase + "[[effects.surface]]\npoint = [0.0, -2.0]\nnormal = [0.0, 0.0]\nf = 0.5\n",
       "s.toml:20:10: effects.surface[0].normal = [0.0, 0.0] is not a normal: allowed a finite nonzero vector"},
      {"a surface point of the wrong dimension", kBase + "[[effects.surface]]\npoint = [0.0, -2.0, 1.0]\nnormal = [0.0, 1.0]\n",
       "s.toml:19:9: effects.surface[0].point = [0.0, -2.0, 1.0] has 3 components but string.dimension = 2"},
      {"a cylinder of radius 0", kBase + "[[effects.cylinder]]\ncenter = [0.5, -0.5]\nradius = 0.0\n",
       "s.toml:20:10: effects.cylinder[0].radius = 0 is out of range: allowed radius > 0"},
      {"a cylinder without radius", kBase + "[[effects.cylinder]]\ncenter = [0.5, -0.5]\n",
       "s.toml:18:1: effects.cylinder[0] needs radius (m, > 0)"},
      {"a 2D cylinder with an axis", kBase + "[[effects.cylinder]]\ncenter = [0.5, -0.5]\nradius = 0.1\naxis = [0.0, 0.0, 1.0]\n",
       "s.toml:21:8: effects.cylinder[0].axis = [0.0, 0.0, 1.0]: in 2D a cylinder is a circle about the out-of-plane axis; "
       "allowed: no axis key"},
      {"a string starting inside a surface", kBase + "[[effects.surface]]\npoint = [0.0, -0.5]\nnormal = [0.0, 1.0]\n",
       "s.toml:18:1: node 6 of the string starts 0.1 m inside the obstacle effects.surface[0] (allowed: on or outside its "
       "surface, within 0.001 of a link length)"},
      {"obstacles with an implicit method", kBase + "[[effects.cylinder]]\ncenter = [0.5, -0.5]\nradius = 0.1\n[solver]\nmethod = \"dirk3\"\n",
       "s.toml:22:10: solver.method = \"dirk3\" is implicit, and implicit methods do not meet obstacles (their Newton "
       "systems know no contact): allowed an explicit method (\"auto\", \"erk5\", \"erk8\", ...)"},
      {"a negative mu", kBase + "[[effects.cylinder]]\ncenter = [0.5, -0.5]\nradius = 0.1\nmu = -0.2\n",
       "s.toml:21:6: effects.cylinder[0].mu = -0.2 is out of range: allowed mu >= 0"},
      {"an infinite mu", kBase + "[[effects.surface]]\npoint = [0.0, -2.0]\nnormal = [0.0, 1.0]\nmu = inf\n",
       "s.toml:21:6: effects.surface[0].mu = inf must be a finite number"},
      {"a mu that is not a number", kBase + "[[effects.surface]]\npoint = [0.0, -2.0]\nnormal = [0.0, 1.0]\nmu = nan\n",
       "s.toml:21:6: effects.surface[0].mu = nan must be a finite number"},
      {"friction with slack = allow", kBase + "[[effects.cylinder]]\ncenter = [0.5, -0.5]\nradius = 0.1\nmu = 0.3\n[solver]\nslack = \"allow\"\n",
       "s.toml:21:6: effects.cylinder[0].mu = 0.3 with solver.slack = \"allow\": friction does not meet unilateral links "
       "(their complementarity problem needs the symmetric tension matrix of smooth obstacles): allowed mu = 0, or "
       "solver.slack = \"stop\""},
      {"a cylinder's contact of another kind", kBase + "[[effects.cylinder]]\ncenter = [0.5, -0.5]\nradius = 0.1\ncontact = \"links\"\n",
       R"(s.toml:21:11: effects.cylinder[0].contact = "links" is not allowed; valid values: nodes, arc)"},
      {"links along the arc with friction", kBase + "[[effects.cylinder]]\ncenter = [0.5, -0.5]\nradius = 0.1\nmu = 0.3\ncontact = \"arc\"\n",
       R"(s.toml:22:11: effects.cylinder[0].contact = "arc" with mu = 0.3: Coulomb friction along the links' arcs (the capstan) is not built: allowed "nodes" (node contact), or "arc" with mu = 0 (a smooth cylinder))"},
      {"links along the arc on a closed string", edit(edit(edit(kBase, kPolyline, "kind = \"circle\"\ncenter = [0.0, 0.0]\nradius = 0.5"), "[ends]\nstart = \"fixed\"\n", ""), "length = 1.0\n", "") + "[[effects.cylinder]]\ncenter = [0.5, -0.5]\nradius = 0.1\ncontact = \"arc\"\n",
       R"(s.toml:19:11: effects.cylinder[0].contact = "arc" on a closed string: a closed loop running round a pulley closes its energy ledger only to 1e-2 with links along the arc (node contact: 7e-9): allowed "nodes" (node contact), or "arc" on an open string)"},
      {"links along the arc with a front", kBase + "[[effects.cylinder]]\ncenter = [0.5, -0.5]\nradius = 0.1\ncontact = \"arc\"\n[solver]\nkinks = \"insert\"\n",
       R"(s.toml:21:11: effects.cylinder[0].contact = "arc" with fronts (heaps, folds, edges, kinks, or solver.kinks = "insert"): links along the arc are not built beside the front tracker: allowed "nodes" (node contact), or "arc" on a scene without fronts)"},
      {"links along the arc on a string off the circle", kBase + "[[effects.cylinder]]\ncenter = [0.5, -0.5]\nradius = 0.1\ncontact = \"arc\"\n",
       R"(s.toml:18:1: effects.cylinder[0].contact = "arc": no node of the string starts on the circle (within 0.001 of a link length): links along the arc are built for a string that starts wrapped on it; allowed "nodes" for a string that reaches the cylinder from off it)"},
      {"no wall time", kBase + "\n[solver]\nmax_wall_s = 0\n",
       "s.toml:20:14: solver.max_wall_s = 0 is out of range: allowed max_wall_s > 0"},
      {"a negative wall time", kBase + "\n[solver]\nmax_wall_s = -5.0\n",
       "s.toml:20:14: solver.max_wall_s = -5 is out of range: allowed max_wall_s > 0"},
      {"an infinite wall time", kBase + "\n[solver]\nmax_wall_s = inf\n",
       "s.toml:20:14: solver.max_wall_s = inf must be a finite number"},
      {"a wall time in words", kBase + "\n[solver]\nmax_wall_s = \"1 h\"\n",
       "s.toml:20:14: solver.max_wall_s = \"1 h\" must be a number"},
  };
  for (const auto& c : cases) {
    INFO(c.what);
    CHECK(error_of(c.text) == c.message);
  }
}

TEST_CASE("an end time given on the command line (--t-end) is located at the option in every message about "
          "stop.t_end (issue #21)",
          "[unit][scene]") {
  // `chainsim run --t-end 1e-300` blamed "file:30:9: stop.t_end = 10.0".
  SceneSpec spec = parse_scene_text(kBase, "s.toml");
  replace_t_end(spec, 1e-300, "--t-end");
  CHECK(spec.stop.t_end == 1e-300);
  try {
    check_scene(spec);
    FAIL("a run of 1e-300 s was not refused");
  } catch (const InputError& e) {
    CHECK(std::string(e.what()) ==
          "--t-end: stop.t_end = 1e-300: the run's length (s) is 1e-300, out of the range the solver can represent: "
          "allowed 1e-100 to 1e+100 (or 0); the scaled problem would overflow or underflow");
  }
  CHECK_THROWS_WITH(replace_t_end(spec, -1, "--t-end"), "--t-end = -1 is out of range: allowed t_end > 0 (s)");
  CHECK_THROWS_WITH(replace_t_end(spec, NAN, "t_end"), "t_end = nan is out of range: allowed t_end > 0 (s)");
}

TEST_CASE("a plane's normal of any representable size is a direction (issue #21)", "[unit][scene]") {
  // normal = [0, 1e300] said "must be a nonzero vector": its norm overflows, its direction does not.
  const std::string huge = edit(test::kFallingBase, "normal = [0.0, 1.0]", "normal = [0.0, 1e300]");
  CHECK(error_of(huge).empty());
  CHECK(error_of(edit(huge, "model = \"string\"", "model = \"reduced\"")).empty());
  CHECK_THAT(error_of(edit(test::kFallingBase, "normal = [0.0, 1.0]", "normal = [0.0, 0.0]")),
             Catch::Contains("effects.plane.normal = [0.0, 0.0] is zero"));
}

TEST_CASE("a heap on a plane too close to a corner on a coarse mesh is refused with that cause", "[unit][scene]") {
  // chain_into_heap_on_table.toml on 5 nodes: its corner (s = 0.5 m) is node 2, two links from the heap. The
  // front on the plane is found on the curve through nodes 1, 2, 3, which folds back at the corner, so it
  // lands at s0 = 0.859 m; the message was "place the heap point at the string's material point s0", which
  // it is.
  const std::filesystem::path file =
      std::filesystem::path(CHAINSIM_SOURCE_DIR) / "cases" / "scenes" / "chain_into_heap_on_table.toml";
  const std::string text = edit(read_scene_file(file), "nodes = 81", "nodes = 5");
  CHECK(error_of(text) ==
        "s.toml:26:1: effects.heap[0]: the heap front on the plane is found where the curve through the last three "
        "nodes before it (nodes 1, 2, 3) meets the plane, and the initial shape turns by 143 degrees at node 2 (links "
        "of h = 0.25 m): that curve puts the front at s0 = 0.859047822 m, not at s0 = 1 m; allowed a string that runs "
        "straight over its last two links before the heap: more nodes (string.nodes), or the corner further from the "
        "heap");
}

TEST_CASE("kinks = \"insert\" on a shape that already has a corner at t = 0 is refused at the key (issue 27)",
          "[unit][scene][kink]") {
  // A corner at t = 0 (a sharp polyline vertex, the turn over an edge or a peg) starts the formation's root
  // function negative, where ARKODE finds no root. Before this refusal a sharp L stopped at an internal check
  // ("a check failed at the start must stop the run", exit 1), as did the chain over two pegs, and the chain
  // over one peg or off a table's edge stopped at t = 0 ("a kink formed at t = 0 s where no link fits it").
  const std::string sharp = edit(kBase, "points = [[0.0, 0.0], [0.0, -1.0]]", "points = [[0.0, 0.0], [0.0, -0.5], [0.3, -0.1]]");
  const std::string insert = "\n[solver]\nkinks = \"insert\"\n";
  // The L turns by 143.13 deg at its vertex (cos = -0.8), over the default window (ℓ/50 = 0.02 m, one link each side:
  // the message says how wide the window measured on this mesh is).
  CHECK(error_of(sharp + insert) ==
        "s.toml:20:9: solver.kinks = \"insert\": the initial shape already turns by 143.1 deg over kink_window = 0.02 m "
        "(2 links of 0.1 m on this mesh), past kink_turn = 90 deg: a corner present at t = 0 (a sharp polyline vertex, the turn over an edge or a peg, "
        "or a bend that turns this much within a window this wide), which insertion cannot take (it inserts the kinks "
        "that form during the run); allowed: a shape that turns by less than kink_turn over kink_window at t = 0 (round "
        "a corner with shape.corner_radius or declare it with [[effects.kink]], narrow kink_window, or raise "
        "solver.kink_turn above 143.1 deg)");
  // Accepted: the same L with kink_turn above its turn, with the corner rounded, or without insertion.
  CHECK(error_of(sharp + insert + "kink_turn = 150\n").empty());
  CHECK(error_of(edit(edit(sharp, "length = 1.0\n", ""), "[ends]", "corner_radius = 0.15\n\n[ends]") + insert).empty());
  CHECK(error_of(sharp).empty());
  // A peg: the string turns by 180 deg over it, which no kink_turn (at most 179) exceeds.
  const std::string peg = edit(edit(kBase, "points = [[0.0, 0.0], [0.0, -1.0]]", "points = [[0.0, -0.4], [0.0, 0.0], [0.0, -0.6]]"),
                               "[ends]\nstart = \"fixed\"", "[[effects.edge]]\npoint = [0.0, 0.0]\nf = 0.5");
  CHECK(error_of(peg).empty());
  CHECK(error_of(peg + insert).find(
            "solver.kinks = \"insert\": the initial shape already turns by 180 deg") != std::string::npos);
}

TEST_CASE("kinks = \"insert\" with a window that fits nowhere in the string is refused at the key, and quadratic "
          "elements name the kink front (issue 27)",
          "[unit][scene][kink]") {
  // A window longer than the string (or a mesh too coarse for any window) left the formation's root function
  // at its "no window" value: the run went on and never inserted a kink (the swinging U with kink_window = 100 m
  // ran to its end with 0 crossings), and on 3 nodes the U did the same. The refusal reads the kink front's own
  // measure.
  const std::string insert = "\n[solver]\nkinks = \"insert\"\n";
  CHECK(error_of(kBase + insert + "kink_window = 1.5\n") ==
        "s.toml:21:15: solver.kink_window = 1.5: no window of kink_window = 1.5 m of material fits inside the string "
        "(10 links of h = 0.1 m; a window is 2m links, m = kink_window / 2h rounded and at least 1, and needs a link "
        "beyond it: 2m + 1 links in all), so no kink could ever be inserted; allowed: kink_window below the string's "
        "length between its fronts, on at least 3 links");
  // 2 links: no window of even 2 links and one more.
  CHECK(error_of(edit(kBase, "nodes = 11", "nodes = 3") + insert).find(
            "s.toml:20:9: solver.kinks = \"insert\": no window of kink_window = 0.02 m of material fits inside the string "
            "(2 links of h = 0.5 m;") == 0);
  // The largest window that fits: 2m + 1 <= 10 links, m = 4 (kink_window = 0.8 m); and the default window.
  CHECK(error_of(kBase + insert + "kink_window = 0.8\n").empty());
  CHECK(error_of(kBase + insert).empty());
  // Quadratic elements are refused with the reason: the kink front that insertion gives the string (the message
  // spoke of "a heap, a fold or an edge", which the scene does not have).
  CHECK(error_of(edit(kBase, "nodes = 11", "nodes = 11\nelements = \"quadratic\"") + insert) ==
        "s.toml:5:12: string.elements = \"quadratic\" is not allowed here: solver.kinks = \"insert\" gives the string a "
        "kink front where a kink forms, which quadratic elements do not meet; allowed: \"links\" (any string), "
        "\"quadratic\" (an open string without fronts, an odd number of nodes)");
}
