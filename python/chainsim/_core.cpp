// chainsim._core: the compiled half of the Python module (python/chainsim/__init__.py is the other).
// Only bindings: every number comes from the C++ library, through the code the command-line tool runs
// (SceneRun = `chainsim run`, solve_reduced = `chainsim reduced`, compare_problem and run_compare_problem =
// `chainsim compare`, run_sweep / run_sweep_point = `chainsim sweep`). JSON documents cross as text (json.loads
// on the Python side: doubles round-trip exactly); arrays as numpy arrays (copies).
#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <cstring>
#include <future>
#include <limits>
#include <memory>
#include <optional>
#include <string>
#include <variant>
#include <vector>

#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>
#include <pybind11/stl/filesystem.h>

#include <nlohmann/json.hpp>

#include "cases/canonical/canonical_string.hpp"
#include "cases/cli/compare_problem.hpp"
#include "cases/reduced/reduced_models.hpp"
#include "cases/scene/reduced_scene.hpp"
#include "cases/scene/scene.hpp"
#include "cases/scene/scene_json.hpp"
#include "cases/scene/scene_run.hpp"
#include "cases/scene/scene_sweep.hpp"
#include "mesh/errors.hpp"
#include "solver/interrupt.hpp"
#include "solver/output.hpp"

namespace py = pybind11;
using namespace chainsim;

namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

py::array_t<double> array1(const std::vector<double>& v) {
  py::array_t<double> a(static_cast<py::ssize_t>(v.size()));
  std::copy(v.begin(), v.end(), a.mutable_data());
  return a;
}

/// Every column of a table, by its CSV name.
py::dict table_dict(const CsvTable& table) {
  py::dict d;
  for (const std::string& c : table.columns()) d[py::str(c)] = array1(table.column(c));
  return d;
}

/// Builds an array of shape `shape` filled with NaN.
py::array_t<double> nan_array(const std::vector<py::ssize_t>& shape) {
  py::array_t<double> a(shape);
  std::fill(a.mutable_data(), a.mutable_data() + a.size(), kNaN);
  return a;
}

/// A run's frames as arrays (frame index first), named as in the CSV files.
template <int dim>
py::dict frames_dict(const SceneRun<dim>& run) {
  const auto& frames = run.solver().frames();
  const auto& chain = run.model().chain();
  const auto F = static_cast<py::ssize_t>(frames.size());
  const py::ssize_t N = chain.num_nodes(), L = chain.num_links();
  const char* axes[] = {"x", "y", "z"};
  py::dict nodes, tension, energy, forces, fronts;
  std::vector<double> t, s(static_cast<std::size_t>(N)), s_mid(static_cast<std::size_t>(L));
  for (const auto& f : frames) t.push_back(f.t);
  for (int i = 0; i < N; ++i) s[static_cast<std::size_t>(i)] = chain.node_coordinate(i);
  for (int j = 0; j < L; ++j) s_mid[static_cast<std::size_t>(j)] = chain.link_midpoint(j);
  // nodes: x, y[, z], vx, vy[, vz] of shape (frames, nodes); NaN for a node in no arc (in a heap).
  std::vector<py::array_t<double>> x, v;
  for (int d = 0; d < dim; ++d) {
    x.push_back(nan_array({F, N}));
    v.push_back(nan_array({F, N}));
  }
  auto moving = py::array_t<bool>({F, N});
  std::fill(moving.mutable_data(), moving.mutable_data() + moving.size(), false);
  auto T = nan_array({F, L});
  for (py::ssize_t k = 0; k < F; ++k) {
    const auto& f = frames[static_cast<std::size_t>(k)];
    for (int i : f.moving) {
      moving.mutable_at(k, i) = true;
      for (int d = 0; d < dim; ++d) {
        x[d].mutable_at(k, i) = f.x(d, i);
        v[d].mutable_at(k, i) = f.v(d, i);
      }
    }
    for (py::ssize_t j = 0; j < L; ++j) T.mutable_at(k, j) = f.tension[j];
  }
  nodes["t"] = array1(t);
  {
    auto idx = py::array_t<long>(N);
    for (py::ssize_t i = 0; i < N; ++i) idx.mutable_at(i) = i;
    nodes["node"] = idx;
  }
  nodes["s"] = array1(s);
  for (int d = 0; d < dim; ++d) {
    nodes[py::str(axes[d])] = x[d];
    nodes[py::str(std::string("v") + axes[d])] = v[d];
  }
  nodes["moving"] = moving;
  tension["t"] = array1(t);
  {
    auto idx = py::array_t<long>(L);
    for (py::ssize_t j = 0; j < L; ++j) idx.mutable_at(j) = j;
    tension["link"] = idx;
  }
  tension["s_mid"] = array1(s_mid);
  tension["T"] = T;
  // energy: the ledger terms of energy.csv.
  std::vector<double> K, V, W, drift;
  for (const auto& f : frames) {
    K.push_back(f.kinetic);
    V.push_back(f.potential);
    W.push_back(f.work);
    drift.push_back(f.drift);
  }
  energy["t"] = array1(t);
  energy["K"] = array1(K);
  energy["V"] = array1(V);
  energy["W_applied"] = array1(W);
  energy["drift"] = array1(drift);
  // The module's energy terms (front tracking's W_shocks, W_heaps, W_remesh), as energy.csv has them.
  const auto& terms = run.solver().summary().ledger_terms;
  for (std::size_t k = 0; k < terms.size(); ++k) {
    if (!terms[k].energy()) continue;
    std::vector<double> column;
    for (const auto& f : frames) column.push_back(f.terms.values[k]);
    energy[py::str(terms[k].name)] = array1(column);
  }
  // forces: the columns of forces.csv.
  const auto& names = run.solver().summary().force_columns;
  forces["t"] = array1(t);
  for (std::size_t c = 0; c < names.size(); ++c) {
    std::vector<double> col;
    for (const auto& f : frames) col.push_back(c < f.forces.size() ? f.forces[c] : kNaN);
    forces[py::str(names[c])] = array1(col);
  }
  // fronts at the frames: s0, s0_dot (frames, fronts), position and reaction (frames, fronts, dim).
  const py::ssize_t nf = frames.empty() ? 0 : static_cast<py::ssize_t>(frames.front().fronts.size());
  auto s0 = nan_array({F, nf}), s0_dot = nan_array({F, nf});
  auto position = nan_array({F, nf, dim}), reaction = nan_array({F, nf, dim});
  for (py::ssize_t k = 0; k < F; ++k) {
    const auto& fs = frames[static_cast<std::size_t>(k)].fronts;
    for (py::ssize_t q = 0; q < nf && q < static_cast<py::ssize_t>(fs.size()); ++q) {
      const auto& fr = fs[static_cast<std::size_t>(q)];
      s0.mutable_at(k, q) = fr.s0;
      s0_dot.mutable_at(k, q) = fr.s0_dot;
      for (int d = 0; d < dim; ++d) {
        position.mutable_at(k, q, d) = fr.position(d);
        reaction.mutable_at(k, q, d) = fr.reaction(d);
      }
    }
  }
  fronts["t"] = array1(t);
  fronts["s0"] = s0;
  fronts["s0_dot"] = s0_dot;
  fronts["position"] = position;
  fronts["reaction"] = reaction;
  py::dict out;
  out["nodes"] = nodes;
  out["tension"] = tension;
  out["energy"] = energy;
  out["forces"] = forces;
  out["fronts"] = fronts;
  out["series"] = run.solver().summary().samples.empty() ? py::dict() : table_dict(samples_table(run.solver().summary()));
  return out;
}

/// Raises `type` with the message `what`. Messages quote what the user wrote, which need not be valid
/// UTF-8 (the bytes of a scene file): decoded with backslash escapes, so that the error raised is always
/// the one thrown, never a UnicodeDecodeError.
void set_error(PyObject* type, const char* what) {
  const py::object message = py::reinterpret_steal<py::object>(
      PyUnicode_DecodeUTF8(what, static_cast<Py_ssize_t>(std::strlen(what)), "backslashreplace"));
  if (message) PyErr_SetObject(type, message.ptr());
}

/// A finished run of a scene: the string solver's (2D or 3D) or the reduced model's.
class Run {
 public:
  using Variant = std::variant<std::unique_ptr<SceneRun<2>>, std::unique_ptr<SceneRun<3>>, ReducedRun>;
  explicit Run(Variant run) : run_(std::move(run)) {}

  std::string summary() const {
    return std::visit(
        [](const auto& r) -> std::string {
          if constexpr (std::is_same_v<std::decay_t<decltype(r)>, ReducedRun>)
            return r.summary.dump();
          else
            return r->summary().dump();
        },
        run_);
  }

  py::dict arrays() const {
    return std::visit(
        [](const auto& r) -> py::dict {
          if constexpr (std::is_same_v<std::decay_t<decltype(r)>, ReducedRun>) {
            py::dict d;
            d["series"] = table_dict(r.series);
            return d;
          } else {
            return frames_dict(*r);
          }
        },
        run_);
  }

  /// The run directory, as `chainsim run --out DIR` writes it (string runs; a reduced run's arrays and
  /// summary are all it has).
  void write(const std::filesystem::path& dir) const {
    std::visit(
        [&](const auto& r) {
          if constexpr (std::is_same_v<std::decay_t<decltype(r)>, ReducedRun>)
            throw InputError("write(): a reduced run has no run directory here (chainsim run writes one)");
          else
            r->write(dir, r->summary());
        },
        run_);
  }

  std::string error;  ///< a numerical failure's message ("" if none)

 private:
  Variant run_;
};

/// Builds and runs a scene without the GIL (the caller releases it): the string solver's run, or the
/// reduced model's for model = "reduced". Throws InputError for an inconsistent scene.
template <int dim>
std::unique_ptr<Run> run_string(const SceneSpec& spec) {
  auto run = std::make_unique<SceneRun<dim>>(spec);
  const std::optional<NumericalError> failure = run->run();
  auto out = std::make_unique<Run>(Run::Variant(std::move(run)));
  if (failure) out->error = failure->what();
  return out;
}

std::unique_ptr<Run> run_spec(const SceneSpec& spec) {
  if (spec.model == "reduced") {
    ReducedRun r = solve_reduced(match_canonical_problem(spec));
    r.summary["t_end"] = spec.stop.t_end;
    return std::make_unique<Run>(Run::Variant(std::move(r)));
  }
  return spec.dimension == 3 ? run_string<3>(spec) : run_string<2>(spec);
}

SceneSpec parse(const std::string& text, const std::string& source, const std::vector<std::string>& overrides,
                std::optional<double> t_end) {
  SceneSpec spec = parse_scene_text(text, source, overrides);
  if (t_end) replace_t_end(spec, *t_end, "t_end");
  return spec;
}

std::unique_ptr<Run> run_scene(const std::string& text, const std::string& source,
                               const std::vector<std::string>& overrides, std::optional<double> t_end,
                               bool handle_sigint) {
  const SceneSpec spec = parse(text, source, overrides, t_end);
  clear_interrupt();
  ScopedSigintHandler sigint(handle_sigint);
  py::gil_scoped_release release;
  return run_spec(spec);
}

// --- Python values to C++ values, every refusal an InputError naming the key ----------------------

/// repr(value), for messages (ascii(value) if the repr is no valid text).
std::string shown(py::handle value) {
  const py::str text = py::repr(value);
  Py_ssize_t size = 0;
  if (const char* data = PyUnicode_AsUTF8AndSize(text.ptr(), &size))
    return std::string(data, static_cast<std::size_t>(size));
  PyErr_Clear();
  return py::reinterpret_steal<py::str>(PyObject_ASCII(value.ptr())).cast<std::string>();
}

/// A numpy scalar or array as the Python value it holds (a number, a bool, a list); other values as they are.
py::object plain(py::handle value) {
  if (py::hasattr(value, "dtype") && py::hasattr(value, "tolist")) return value.attr("tolist")();
  return py::reinterpret_borrow<py::object>(value);
}

bool is_bool(py::handle value) { return PyBool_Check(value.ptr()); }

/// Python text as UTF-8; InputError naming `at` for text UTF-8 cannot hold (a lone surrogate).
std::string utf8(py::handle text, const std::string& at) {
  Py_ssize_t size = 0;
  const char* data = PyUnicode_AsUTF8AndSize(text.ptr(), &size);
  if (!data) {
    PyErr_Clear();
    throw InputError(fmt::format("{} = {} is not valid text: it holds a lone surrogate, which UTF-8 cannot hold", at,
                                 shown(text)));
  }
  return std::string(data, static_cast<std::size_t>(size));
}

/// A Python int as text, long ones shortened ("1000000000…0000 (401 digits)").
std::string integer_text(py::handle value) {
  const std::string text = py::str(value).cast<std::string>();
  const std::size_t digits = text.size() - (text[0] == '-' ? 1 : 0);
  if (digits <= 40) return text;
  return fmt::format("{}…{} ({} digits)", text.substr(0, text.size() - digits + 12), text.substr(text.size() - 4),
                     digits);
}

/// A real number (int, float, numpy scalar; not a bool, a string or None).
double real_arg(const std::string& fn, const std::string& key, py::handle value) {
  const py::object v = plain(value);
  if (is_bool(v) || !(PyFloat_Check(v.ptr()) || PyLong_Check(v.ptr())))
    throw InputError(fmt::format("{}(): {} = {} must be a number", fn, key, shown(value)));
  const double x = PyFloat_AsDouble(v.ptr());
  if (x == -1.0 && PyErr_Occurred()) {  // an int beyond the double range
    PyErr_Clear();
    throw InputError(fmt::format("{}(): {} = {} is out of range: allowed a number below 1.8e308 in magnitude", fn,
                                 key, integer_text(v)));
  }
  return x;
}

/// An integer (int or numpy integer; not a bool or a float) within the range of T.
template <class T>
T integer_arg(const std::string& fn, const std::string& key, py::handle value) {
  const py::object v = plain(value);
  if (is_bool(v) || !PyLong_Check(v.ptr()))
    throw InputError(fmt::format("{}(): {} = {} must be an integer", fn, key, shown(value)));
  int overflow = 0;
  const long long n = PyLong_AsLongLongAndOverflow(v.ptr(), &overflow);
  if (overflow != 0 || n < std::numeric_limits<T>::min() || n > std::numeric_limits<T>::max())
    throw InputError(fmt::format("{}(): {} = {} is out of range: allowed integers from {} to {}", fn, key,
                                 integer_text(v), std::numeric_limits<T>::min(),
                                 std::numeric_limits<T>::max()));
  return static_cast<T>(n);
}

std::string text_arg(const std::string& fn, const std::string& key, py::handle value) {
  if (!PyUnicode_Check(value.ptr()))
    throw InputError(fmt::format("{}(): {} = {} must be a string", fn, key, shown(value)));
  return utf8(value, fmt::format("{}(): {}", fn, key));
}

/// A scene given as Python values (Scene.from_dict) as JSON, in memory: NaN and inf stay numbers (the
/// scene's checks refuse them at their key, as in a file), numpy scalars and arrays become their
/// values, and whatever no scene can hold is refused naming its key.
nlohmann::json scene_value(py::handle value, const std::string& at, int depth = 0) {
  constexpr int kMaxDepth = 32;
  const std::string where = at.empty() ? "the scene" : at;
  if (depth > kMaxDepth)
    throw InputError(fmt::format("{} is nested deeper than {} levels: no scene key is", where, kMaxDepth));
  const py::object v = plain(value);
  if (v.is_none()) return nullptr;  // scene_toml_text refuses it, naming the key
  if (is_bool(v)) return v.cast<bool>();
  if (PyLong_Check(v.ptr())) {
    int overflow = 0;
    const long long n = PyLong_AsLongLongAndOverflow(v.ptr(), &overflow);
    if (overflow != 0)
      throw InputError(fmt::format("{} = {} is out of range: allowed integers from {} to {}", where, integer_text(v),
                                   std::numeric_limits<long long>::min(),
                                   std::numeric_limits<long long>::max()));
    return n;
  }
  if (PyFloat_Check(v.ptr())) return v.cast<double>();
  if (PyUnicode_Check(v.ptr())) return utf8(v, where);
  if (PyDict_Check(v.ptr())) {
    nlohmann::json object = nlohmann::json::object();
    for (const auto& [key, item] : py::reinterpret_borrow<py::dict>(v)) {
      if (!PyUnicode_Check(key.ptr()))
        throw InputError(fmt::format("{} has the key {}: the keys of a scene are strings", where, shown(key)));
      if (!PyUnicode_AsUTF8AndSize(key.ptr(), nullptr)) {
        PyErr_Clear();
        throw InputError(fmt::format("{} has the key {}: it holds a lone surrogate, which UTF-8 cannot hold", where,
                                     shown(key)));
      }
      const std::string name = utf8(key, where);
      if (std::any_of(name.begin(), name.end(), [](char c) { return static_cast<unsigned char>(c) < 0x20; }))
        throw InputError(fmt::format("{} has the key {}: no scene key holds a control character", where, shown(key)));
      object[name] = scene_value(item, at.empty() ? name : at + "." + name, depth + 1);
    }
    return object;
  }
  if (PyList_Check(v.ptr()) || PyTuple_Check(v.ptr())) {
    nlohmann::json array = nlohmann::json::array();
    std::size_t k = 0;
    for (const auto& item : v) array.push_back(scene_value(item, fmt::format("{}[{}]", at, k++), depth + 1));
    return array;
  }
  throw InputError(fmt::format("{} = {} cannot be a scene value: allowed a number, a string, a bool, a list or a dict",
                               where, shown(value)));
}

/// The chain's and the integrator's settings shared by reduced() and compare(): keyword -> field; compare()'s
/// keywords of the problems' own (x0, u0, R) into `options`.
template <class Setup>
void set_common(Setup& s, const py::dict& kw, CompareCommandOptions* options = nullptr) {
  constexpr bool string_case = std::is_same_v<Setup, StringCaseSetup>;
  const std::string fn = string_case ? "compare" : "reduced";
  for (const auto& [key, value] : kw) {
    const std::string k = utf8(key, fn + "() keyword");
    auto real = [&] { return real_arg(fn, k, value); };
    if (k == "f") {
      s.chain.dissipation = real();
      if (options) options->f_given = true;  // (compare pulley refuses f at any value, as the command's --f)
    } else if (k == "eta0") { if (!value.is_none()) s.eta0 = real(); }
    else if (k == "eps") {
      s.eps = real();
      if (options) options->eps_given = true;
    }
    else if (k == "force") s.force = real();
    else if (k == "length") s.chain.length = real();
    else if (k == "density") s.chain.density = real();
    else if (k == "gravity") s.chain.gravity = real();
    else if (k == "t_max") s.t_max_over_t0 = real();
    else if (k == "method") s.integrator.method = text_arg(fn, k, value);
    else if (k == "rtol") s.integrator.rtol = real();
    else if (k == "atol") s.integrator.atol = real();
    else if (k == "max_step") s.integrator.max_step = real();
    else if (k == "max_steps") s.integrator.max_steps = integer_arg<long>(fn, k, value);
    else if constexpr (string_case) {
      const bool exact =  // against an exact solution: edge, peg, pulley
          options && (options->problem == "edge" || options->problem == "peg" || options->problem == "pulley");
      if (k == "nodes") s.nodes = integer_arg<int>(fn, k, value);
      else if (k == "x0" && options) options->x0 = real();
      else if (k == "u0" && options) options->u0 = real();
      else if (k == "R" && options) options->radius = real();
      else if ((k == "tilt_deg" || k == "bend_deg" || k == "frame_interval") && exact)
        throw InputError(fmt::format("compare(): {} = {}: compare {} releases the chain straight and records every "
                                     "step (tilt_deg, bend_deg and frame_interval are falling, folded and sliding's)",
                                     k, shown(value), options->problem));
      else if (k == "tilt_deg") s.tilt_deg = real();
      else if (k == "bend_deg") s.bend_deg = real();
      else if (k == "frame_interval") s.frame_interval = real();
      else throw InputError(fmt::format("compare() got an unknown keyword {}", k));
    } else {
      throw InputError(fmt::format("reduced() got an unknown keyword {}", k));
    }
  }
}

Problem problem_arg(const std::string& fn, py::handle problem) {
  if (!PyUnicode_Check(problem.ptr()))
    throw InputError(fmt::format("{}(): problem = {} is not a known problem: allowed falling, folded, sliding", fn,
                                 shown(problem)));
  return parse_problem(utf8(problem, fn + "(): problem"));
}

py::tuple reduced(py::handle problem, const py::dict& kw) {
  ReducedSetup setup;
  setup.problem = problem_arg("reduced", problem);
  set_common(setup, kw);
  ReducedRun r{CsvTable(series_columns()), {}};
  {
    py::gil_scoped_release release;
    r = solve_reduced(setup);
  }
  return py::make_tuple(table_dict(r.series), r.summary.dump());
}

/// `chainsim compare PROBLEM` with the keywords as its options (compare_problem checks them as it checks the
/// command's): (string series, reduced series, exact series, summary JSON text, the string run's error); the
/// series the problem has no use for is empty (reduced for edge, peg, pulley; exact for the others).
py::tuple compare(py::handle problem, const py::dict& kw) {
  CompareCommandOptions options;
  if (!PyUnicode_Check(problem.ptr()))
    throw InputError(fmt::format("compare(): problem = {} is not a known problem: allowed falling, folded, sliding, "
                                 "edge, peg, pulley", shown(problem)));
  options.problem = utf8(problem, "compare(): problem");
  set_common(options.setup, kw, &options);
  const CompareProblem setup = compare_problem(options);
  std::optional<CompareOutcome> c;
  {
    py::gil_scoped_release release;
    c = run_compare_problem(setup);
  }
  const RunSummary& run = c->run();
  return py::make_tuple(table_dict(samples_table(run)),
                        c->reduced ? table_dict(c->reduced->reduced.series) : py::dict(),
                        c->exact ? table_dict(c->exact->exact) : py::dict(), c->summary().dump(),
                        run.status == "failed" ? run.error : std::string());
}

SweepScene sweep_scene(const std::string& text, const std::string& source, const std::vector<std::string>& overrides,
                       std::optional<double> t_end) {
  return SweepScene{text, source, overrides, t_end, "t_end"};
}

}  // namespace

PYBIND11_MODULE(_core, m) {
  m.doc() = "chainsim's C++ library (see the package chainsim and docs/python.md)";
  m.attr("__version__") = CHAINSIM_VERSION;          // project(chainsim VERSION ...)
  m.attr("version_text") = CHAINSIM_VERSION_TEXT;    // `chainsim --version`
  static py::exception<InputError> input_error(m, "ChainsimInputError", PyExc_ValueError);
  static py::exception<NumericalError> numerical_error(m, "NumericalError", PyExc_RuntimeError);
  py::register_exception_translator([](std::exception_ptr p) {
    try {
      if (p) std::rethrow_exception(p);
    } catch (const InputError& e) {
      set_error(input_error.ptr(), e.what());
    } catch (const NumericalError& e) {
      set_error(numerical_error.ptr(), e.what());
    }
  });

  py::class_<Run>(m, "Run", "a finished run (use chainsim.Result)")
      .def("summary", &Run::summary, "the summary (stats.json) as JSON text")
      .def("arrays", &Run::arrays, "the recorded frames and samples as numpy arrays, by CSV file and column")
      .def("write", &Run::write, py::arg("dir"), "the run directory, as `chainsim run --out DIR` writes it")
      .def_readonly("error", &Run::error);

  m.def("check_scene",
        [](const std::string& text, const std::string& source, const std::vector<std::string>& overrides,
           std::optional<double> t_end) { return scene_to_json(parse(text, source, overrides, t_end)).dump(); },
        py::arg("text"), py::arg("source"), py::arg("overrides"), py::arg("t_end") = py::none(),
        "parses and checks a scene (as `chainsim run` reads it); returns the effective scene as JSON text");
  m.def("read_scene_file", [](const std::filesystem::path& path) { return read_scene_file(path); }, py::arg("path"),
        "the text of a scene file, read as `chainsim run` reads it");
  m.def("scene_toml_text", [](py::handle scene) { return scene_toml_text(scene_value(scene, "")); }, py::arg("scene"),
        "a scene given as a dict of sections (numpy values too), written as TOML; ChainsimInputError naming the key "
        "of a value no scene can hold");
  m.def("check_problem", [](py::handle problem) { problem_arg("sweep", problem); }, py::arg("problem"),
        "refuses (ChainsimInputError) a name that is not a canonical problem");
  m.def("run_scene", &run_scene, py::arg("text"), py::arg("source"), py::arg("overrides"),
        py::arg("t_end") = py::none(), py::arg("handle_sigint") = false,
        "builds and runs a scene as `chainsim run` does (the GIL released; with handle_sigint, Ctrl-C stops the run "
        "at its next accepted step: status \"interrupted\")");
  m.def("reduced", &reduced, py::arg("problem"), py::arg("kwargs"),
        "`chainsim reduced`: returns (series columns, summary JSON text)");
  m.def("compare", &compare, py::arg("problem"), py::arg("kwargs"),
        "`chainsim compare`: returns (string series, reduced series, exact series, summary JSON text, the string run's "
        "error); the series a problem has no use for is empty");
  m.def("sweep_points",
        [](const std::vector<std::pair<std::string, std::vector<std::string>>>& grid) {
          std::vector<SweepAxis> axes;
          for (const auto& [key, values] : grid) axes.push_back({key, values});
          return sweep_points(axes);
        },
        py::arg("grid"), "the grid's points as lists of KEY=VALUE overrides");
  m.def("check_sweep_points",
        [](const std::string& text, const std::string& source, const std::vector<std::string>& overrides,
           std::optional<double> t_end, const std::vector<std::vector<std::string>>& points) {
          check_sweep_points(sweep_scene(text, source, overrides, t_end), points);
        },
        py::arg("text"), py::arg("source"), py::arg("overrides"), py::arg("t_end"), py::arg("points"),
        "refuses (ChainsimInputError) points that set one scene key twice, before any runs");
  m.def("sweep_key",
        [](const std::string& text, const std::string& source, const std::vector<std::string>& overrides,
           const std::string& key) { return canonical_sweep_key(sweep_scene(text, source, overrides, {}), key); },
        py::arg("text"), py::arg("source"), py::arg("overrides"), py::arg("key"),
        "the scene key a grid or fit key stands for (`f`: the dissipation of the scene's only front with an f)");
  m.def("run_sweep_point",
        [](const std::string& text, const std::string& source, const std::vector<std::string>& overrides,
           std::optional<double> t_end, const std::vector<std::string>& point) {
          const SweepScene scene = sweep_scene(text, source, overrides, t_end);
          py::gil_scoped_release release;
          return run_sweep_point(scene, point).dump();
        },
        py::arg("text"), py::arg("source"), py::arg("overrides"), py::arg("t_end"), py::arg("point"),
        "one sweep point as `chainsim sweep` runs it: the row as JSON text");
  m.def("run_sweep_point_full",
        [](const std::string& text, const std::string& source, const std::vector<std::string>& overrides,
           std::optional<double> t_end, const std::vector<std::string>& point) {
          const SweepScene scene = sweep_scene(text, source, overrides, t_end);
          std::unique_ptr<Run> kept;
          std::string row;
          {
            py::gil_scoped_release release;
            row = run_sweep_point(scene, point, [&](const SceneSpec& spec) {
                    kept = run_spec(spec);
                    nlohmann::json summary = nlohmann::json::parse(kept->summary());
                    if (spec.model == "reduced") summary["status"] = "completed";  // as `chainsim sweep`'s rows
                    if (!kept->error.empty()) summary["error"] = kept->error;
                    return summary;
                  }).dump();
          }
          py::object run = kept ? py::cast(std::move(kept)) : py::none();
          return py::make_tuple(row, run);
        },
        py::arg("text"), py::arg("source"), py::arg("overrides"), py::arg("t_end"), py::arg("point"),
        "one sweep point as run_sweep_point runs it, and its run: (row as JSON text, Run or None for a refused "
        "point)");
  m.def("run_sweep",
        [](const std::string& text, const std::string& source, const std::vector<std::string>& overrides,
           std::optional<double> t_end, const std::vector<std::vector<std::string>>& points, int workers,
           bool handle_sigint, py::object progress) {
          const SweepScene scene = sweep_scene(text, source, overrides, t_end);
          std::vector<nlohmann::json> rows;
          {
            clear_interrupt();
            ScopedSigintHandler sigint(handle_sigint);
            py::gil_scoped_release release;
            if (progress.is_none()) {
              rows = run_sweep(scene, points, workers);
            } else {  // the sweep on its own thread; this one reports the points ended, every 0.1 s
              std::atomic<std::size_t> done{0};
              auto sweep = std::async(std::launch::async, [&] { rows = run_sweep(scene, points, workers, &done); });
              std::size_t shown = 0;
              bool report = true;
              for (bool ended = false; !ended;) {
                ended = sweep.wait_for(std::chrono::milliseconds(100)) == std::future_status::ready;
                const std::size_t now = done.load();
                if (!report || now == shown) continue;
                py::gil_scoped_acquire acquire;
                try {
                  progress(now);
                } catch (py::error_already_set&) {  // a broken progress bar does not stop the sweep
                  report = false;
                }
                shown = now;
              }
              sweep.get();  // rethrows check_sweep_points' InputError
            }
          }
          std::vector<std::string> out;
          for (const auto& r : rows) out.push_back(r.dump());
          return out;
        },
        py::arg("text"), py::arg("source"), py::arg("overrides"), py::arg("t_end"), py::arg("points"),
        py::arg("workers"), py::arg("handle_sigint") = false, py::arg("progress") = py::none(),
        "the points on `workers` threads, as `chainsim sweep` runs them: rows as JSON text; `progress(n)` is called "
        "with the number of points ended as they end");
  m.def("flatten_summary", [](const std::string& json) { return flatten_summary(nlohmann::json::parse(json)).dump(); },
        py::arg("json"), "a summary flattened into a sweep row's columns");
  m.def("interrupt_requested", &interrupt_requested);
  m.def("clear_interrupt", &clear_interrupt);
}
