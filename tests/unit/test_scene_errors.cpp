// cases/scene.cpp: a table of bad scenes, each refused with its exact message: the file:line:column
// of the key at fault (the value, or the key itself when it is unknown, or the section header when
// a key is missing), the key, the value as written, and what is allowed. Errors found while
// building the model (dimensions, lengths, ends, frames) are located the same way.
#include <string>

#include <catch2/catch.hpp>

#include "cases/scene.hpp"
#include "solver/errors.hpp"
#include "solver/tension_system.hpp"
#include "test_scene_support.hpp"

using namespace chainsim;

namespace {

// The messages below point into this text: lines 1-17 are test_scene_support.hpp's scene.
const std::string& kBase = test::kSceneBase;
const char* kPolyline = "kind = \"polyline\"\npoints = [[0.0, 0.0], [0.0, -1.0]]";

/// `text` with its first `from` replaced by `to` (which must be there).
std::string edit(const std::string& text, const std::string& from, const std::string& to) {
  const auto at = text.find(from);
  REQUIRE(at != std::string::npos);
  std::string out = text;
  out.replace(at, from.size(), to);
  return out;
}

/// The message of the InputError that parsing and building `text` raises, or "" if none.
std::string error_of(const std::string& text) {
  try {
    const SceneSpec spec = parse_scene_text(text, "s.toml");
    if (spec.dimension == 3)
      build_string_scene<3>(spec);
    else
      build_string_scene<2>(spec);
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

TEST_CASE("the base of the bad scenes is good", "[unit][scene]") { CHECK(error_of(kBase).empty()); }

TEST_CASE("bad scenes are refused with the location, the key, the value and what is allowed", "[unit][scene]") {
  // The tension backends of this build (KLU is optional), as the message lists them.
  std::string backends;
  for (const auto& name : tension_backend_names()) backends += (backends.empty() ? "" : ", ") + name;
  const BadScene cases[] = {
      {"typo in a key",
       edit(kBase, "length = 1.0", "lenght = 1.0"),
       "s.toml:2:1: unknown key 'lenght' in [string]; valid keys: length, density, nodes, link_length, closed, dimension (did you mean 'length'?)"},
      {"a section of the old format",
       edit(kBase, "[effects.gravity]", "[gravity]"),
       "s.toml:13:2: unknown section [gravity]; valid sections: string, shape, velocity, ends, effects, solver, output, stop; valid top-level keys: model; gravity is now written [effects.gravity]"},
      {"typo in a section",
       edit(kBase, "[stop]", "[stp]"),
       "s.toml:16:2: unknown section [stp]; valid sections: string, shape, velocity, ends, effects, solver, output, stop; valid top-level keys: model (did you mean [stop]?)"},
      {"typo in an effect",
       edit(kBase, "[effects.gravity]", "[effects.gravty]"),
       "s.toml:13:10: unknown effect [effects.gravty]; valid effects: gravity, drag, heap, fold, plane (did you mean [effects.gravity]?)"},
      {"a solver key of the old format",
       kBase + std::string("[solver]\nt_end = 1.0\n"),
       "s.toml:19:1: unknown key 't_end' in [solver]; valid keys: method, rtol, atol, max_step, initial_step, max_steps, stabilization_time, backend, check_slack, slack_tolerance; t_end is now written in [stop]"},
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
       "s.toml:4:9: string.nodes = 1 is out of range: allowed 2 <= nodes <= 1e+07"},
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
      {"an unknown velocity kind",
       kBase + std::string("[velocity]\nkind = \"spin\"\n"),
       "s.toml:19:8: velocity.kind = \"spin\" is not allowed; valid values: rest, uniform, tangential, nodes"},
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
       "s.toml:19:10: solver.method = \"rk99\" is not a known integration method: allowed dirk2, dirk3, dirk4, "
       "dirk5, erk3, erk4, erk5, erk6, erk8, or an ARKODE_* Butcher table name"},
      {"a relative tolerance of one",
       kBase + std::string("[solver]\nrtol = 1.0\n"),
       "s.toml:19:8: solver.rtol = 1 is out of range: allowed 1e-14 <= rtol <= 0.01"},
      {"an unknown tension backend",
       kBase + std::string("[solver]\nbackend = \"lu\"\n"),
       "s.toml:19:11: solver.backend = \"lu\" is not a tension solver: allowed auto, " + backends},
      {"an unknown output field",
       kBase + std::string("[output]\nfields = [\"nodes\", \"strain\"]\n"),
       "s.toml:19:20: output.fields[1] = \"strain\" is not allowed; valid values: nodes, tension, energy, stats"},
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
       "s.toml:19:12: output.interval = 1e-09 s with stop.t_end = 0.2 s asks for 2e+08 frames of 11 nodes (2.2e+09 node-frames): allowed at most 2e+07; raise output.interval"},
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
