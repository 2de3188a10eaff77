"""Property tests of the Python front door (issue #21, docs/python.md "Errors"): whatever a caller passes to
Scene.from_dict, Scene.set, sweep, reduced or compare ends in a result, a ChainsimInputError that names the key
at fault, or a NumericalError for numerical trouble; never another exception type (TypeError, RuntimeError,
UnicodeEncodeError, a crash).

The inputs are drawn by Hypothesis (Debian's python3-hypothesis): numbers of every kind (NaN, inf, subnormal,
huge, integers beyond int64, numpy scalars and arrays, bools), text with lone surrogates, None, lists and dicts,
on the real scene keys and on junk keys. Runs are kept cheap: 11 nodes, t_end = 0.02 s, a step budget and a
wall-clock budget on every scene, so that the file runs in well under a minute.

Run by CTest as "python: fuzz" (tests/CMakeLists.txt), or:
    PYTHONPATH=build/python:python /usr/bin/python3 -m pytest -q tests/python/test_fuzz_inputs.py
CHAINSIM_FUZZ_EXAMPLES=N multiplies the examples of each test by N, and CHAINSIM_FUZZ_RANDOM=1 draws new inputs
on each run (by default the draws are fixed, so that a CI run is reproducible).
"""
import math
import os
import tempfile
import warnings

import numpy as np
import pytest

# Hypothesis keeps caches (its Unicode tables) in ./.hypothesis unless told otherwise: not in the source tree.
os.environ.setdefault("HYPOTHESIS_STORAGE_DIRECTORY", os.path.join(tempfile.gettempdir(), "chainsim_hypothesis"))
hypothesis = pytest.importorskip("hypothesis")
from hypothesis import HealthCheck, example, given, settings, strategies as st  # noqa: E402

import chainsim  # noqa: E402

HERE = os.path.dirname(os.path.abspath(__file__))
SCENES = os.path.abspath(os.path.join(HERE, "..", "..", "cases", "scenes"))

SCALE = int(os.environ.get("CHAINSIM_FUZZ_EXAMPLES", "1"))
RANDOM = os.environ.get("CHAINSIM_FUZZ_RANDOM") == "1"


DEADLINE = int(os.environ["CHAINSIM_FUZZ_DEADLINE_MS"]) if "CHAINSIM_FUZZ_DEADLINE_MS" in os.environ else None


def fuzz_settings(examples):
    return settings(max_examples=examples * SCALE, deadline=DEADLINE, derandomize=not RANDOM, database=None,
                    suppress_health_check=[HealthCheck.too_slow, HealthCheck.data_too_large])


# ------------------------------------------------------------------------------------------------------------------
# Values

# Integers: the small ones a scene uses, and ones beyond every range (10**7 + 1 nodes, int64's ends, 10**400);
# never a valid but expensive node count.
integers = st.one_of(st.integers(min_value=-3, max_value=40),
                     st.sampled_from([10**7 + 1, 2**31, 2**63 - 1, 2**63, -2**63 - 1, 10**20, 10**400]))
floats = st.one_of(st.floats(allow_nan=True, allow_infinity=True),
                   st.floats(min_value=-2.0, max_value=2.0),
                   st.sampled_from([0.0, -0.0, 5e-324, 1e-300, 1e-100, 1e100, 1e300, 0.5, 0.9]))
numpy_scalars = st.one_of(st.builds(np.int64, st.integers(min_value=-3, max_value=40)),
                          st.builds(np.int32, st.integers(min_value=-3, max_value=40)),
                          st.builds(np.float32, st.floats(width=32, allow_nan=True)),
                          st.builds(np.float64, floats),
                          st.builds(np.bool_, st.booleans()))
numbers = st.one_of(integers, floats, numpy_scalars, st.booleans())
# Text of every code point, lone surrogates included.
text = st.one_of(st.text(alphabet=st.characters(blacklist_categories=()), max_size=6),
                 st.sampled_from(["erk8", "erk5", "dirk3", "polyline", "fixed", "free", "reduced", "string", "klu",
                                  "stop", "heap_end", "\ud800", "a\udfffb", "", " ", "x" * 50]))
vectors = st.one_of(st.lists(numbers, max_size=4),
                    st.builds(np.array, st.lists(floats, min_size=1, max_size=3)),
                    st.sampled_from([[0.0, -9.81], [0.0, 1e300], [0.0, 0.0], [[0.0, 1.0], [0.0, 0.0]]]))
values = st.one_of(numbers, text, vectors, st.none(),
                   st.lists(st.lists(floats, max_size=3), max_size=3),
                   st.dictionaries(text, numbers, max_size=2),
                   st.sampled_from([1j, object(), b"bytes", {1, 2}]))

# The scene keys (docs/scenes.md), and keys that are not any.
SCENE_KEYS = ["model", "string.length", "string.density", "string.nodes", "string.link_length", "string.closed", "string.elements",
              "string.dimension", "shape.kind", "shape.points", "shape.length_tolerance", "velocity.kind",
              "velocity.value", "ends.start", "ends.end", "effects.gravity.g", "effects.drag.coefficient",
              "effects.heap[0].f", "effects.heap[0].s0", "effects.heap[0].point", "effects.heap[0].side",
              "effects.heap[0].on_plane", "effects.plane.normal", "effects.plane.point", "solver.method",
              "solver.rtol", "solver.atol", "solver.max_step", "solver.initial_step", "solver.max_steps",
              "solver.stabilization_time", "solver.backend", "solver.slack", "solver.slack_tolerance",
              "output.interval", "output.fields", "stop.t_end", "stop.front[0].s0", "stop.front[0].front"]
keys = st.one_of(st.sampled_from(SCENE_KEYS), text, st.sampled_from(["string.nodes[0]", "effects.heap[7].f",
                                                                      "effects.heap[00].f", "a..b", "=", "[0]"]))


def ends_well(call, names):
    """Runs call(): a result, a ChainsimInputError whose message names one of `names`, or a NumericalError."""
    try:
        return call()
    except chainsim.ChainsimInputError as e:
        message = str(e)
        assert names_one_of(message, names), f"the message names none of {names}: {message}"
    except chainsim.NumericalError:
        pass


def names_one_of(message, names):
    """Whether the message names one of `names` as a whole name: not inside a longer word or key ("f" is not
    named by "of", "t_max" not by "t_max2"), but a key's last part may follow its section (".f")."""
    import re

    def pattern(n):  # word boundaries where the name begins or ends with a word character
        return ((r"(?<![\w-])" if re.match(r"\w", n) else "") + re.escape(n) +
                (r"(?![\w-])" if re.search(r"\w$", n) else ""))
    return any(re.search(pattern(n), message) for n in names if n)


def shown(key):
    """How messages may name a key: as written, or escaped (a lone surrogate) as repr() writes it; and, for a
    value refused for its relation to another key (a heap's point off its plane), its section or its own name."""
    import re
    if key == "":
        return ["--set =", "key is empty", "empty key"]
    names = [key, repr(key)[1:-1]]
    parts = key.split(".")
    if len(parts) > 2:
        names.append(".".join(parts[:-1]))
    if len(parts) > 1:
        names.append(re.sub(r"\[\d+\]$", "", parts[-1]))
    if key.startswith("effects.plane."):  # the plane's keys may be refused at the heap that lies on it
        names.append("effects.heap[0]")
    return names


# ------------------------------------------------------------------------------------------------------------------
# The scene every test starts from: the falling chain (a heap, a plane, a stop event), small and short, with a step
# and wall-clock budget so that no drawn value makes a long run.

BASE = {"model": "string",
        "string": {"length": 1.0, "density": 1.0, "nodes": 11},
        "shape": {"kind": "polyline", "points": [[0.0, 1.0], [0.0, 0.0]]},
        "effects": {"gravity": {"g": [0.0, -9.81]},
                    "heap": [{"side": "end", "s0": 1.0, "f": 0.5, "point": [0.0, 0.0], "on_plane": True}],
                    "plane": {"point": [0.0, 0.0], "normal": [0.0, 1.0]}},
        "solver": {"max_steps": 3000, "max_wall_s": 2.0},
        "output": {"interval": 0.01},
        "stop": {"t_end": 0.02, "front": [{"front": "heap_end", "s0": 0.01}]}}


def with_value(scene, key, value):
    """A copy of the nested dict `scene` with the dotted key (indices allowed) set to value."""
    import copy
    import re
    out = copy.deepcopy(scene)
    node = out
    parts = re.findall(r"[^.\[\]]+|\[\d+\]", key)
    for i, part in enumerate(parts):
        last = i + 1 == len(parts)
        nxt = None if last else parts[i + 1]
        if part.startswith("["):
            k = int(part[1:-1])
            while len(node) <= k:
                node.append({})
            if last:
                node[k] = value
            else:
                node = node[k]
            continue
        if last:
            node[part] = value
        else:
            if not isinstance(node.get(part), (dict, list)):
                node[part] = [] if nxt.startswith("[") else {}
            node = node[part]
    return out


@fuzz_settings(400)
@given(key=st.sampled_from(SCENE_KEYS), value=values)
# The reproducers of issue #21, and what the random draws found (each failed before its fix).
@example(key="string.nodes", value=np.int64(11))
@example(key="string.length", value=np.float32(1.0))
@example(key="shape.points", value=np.array([[0.0, 1.0], [0.0, 0.0]]))
@example(key="string.closed", value=np.bool_(False))
@example(key="string.length", value=math.nan)
@example(key="string.length", value=math.inf)
@example(key="string.nodes", value=10**400)
@example(key="solver.method", value="\ud800")
@example(key="string.nodes", value=10000001)
@example(key="effects.plane.normal", value=[0.0, 1e300])
@example(key="effects.plane.normal", value=np.array([1.0, 0.0]))
@example(key="solver.stabilization_time", value=1e-300)
def test_scene_from_dict_with_any_value(key, value):
    scene = ends_well(lambda: chainsim.Scene.from_dict(with_value(BASE, key, value)), shown(key))
    if scene is not None:
        ends_well(lambda: scene.run(), shown(key))


@fuzz_settings(150)
@given(scene=st.recursive(st.one_of(numbers, text, st.none()),
                          lambda inner: st.one_of(st.lists(inner, max_size=3),
                                                  st.dictionaries(st.one_of(text, integers), inner, max_size=3)),
                          max_leaves=8))
def test_scene_from_dict_of_anything(scene):
    # Anything at all: refused (naming a key, or the scene as a whole) or a valid scene.
    try:
        chainsim.Scene.from_dict(scene)
    except chainsim.ChainsimInputError:
        pass


@fuzz_settings(300)
@given(key=keys, value=values)
@example(key="\x00", value=10000001)
@example(key="\ud800", value=1)
@example(key="string.nodes", value=2)
@example(key="string.nodes", value=np.int64(21))
def test_scene_set_with_any_key_and_value(key, value):
    scene = chainsim.Scene.from_dict(BASE)
    changed = ends_well(lambda: scene.set(key, value), shown(key) if isinstance(key, str) else [repr(key)])
    if changed is not None:
        ends_well(lambda: changed.run(), shown(key))


REDUCED_KEYWORDS = ["f", "eta0", "eps", "force", "length", "density", "gravity", "t_max", "method", "rtol", "atol",
                    "max_step", "max_steps"]
COMPARE_KEYWORDS = REDUCED_KEYWORDS + ["nodes", "tilt_deg", "bend_deg"]
# The command line's spelling of a keyword, which the shared checks print (--t-max, --eta0).
CLI_NAMES = {"t_max": "--t-max", "tilt_deg": "--tilt", "bend_deg": "--bend", "max_steps": "max_steps"}


# A value can be refused for what it does to another keyword, whose default it is checked against: f and eta0
# against the cutoff eps (and eps against them), the chain's scales against the end force (the weight) and the
# safety stop (t_max t0), tilt against bend. Only these pairs may name a keyword that was not drawn.
RELATED = {"f": ["eps"], "eta0": ["eps"], "eps": ["eta0", "f"], "length": ["force", "t_max"],
           "density": ["force"], "gravity": ["force", "t_max"], "tilt_deg": ["bend_deg"], "bend_deg": ["tilt_deg"]}


def keyword_names(kwargs):
    names = []
    for k in kwargs:
        for name in [k] + RELATED.get(k, []):
            names += [name, CLI_NAMES.get(name, "--" + name)]
    return names


@fuzz_settings(300)
@given(problem=st.one_of(st.sampled_from(["falling", "folded", "sliding"]), text, numbers),
       kwargs=st.dictionaries(st.sampled_from(REDUCED_KEYWORDS), st.one_of(numbers, text, st.none()), max_size=3))
@example(problem="falling", kwargs={"f": "0.5"})
@example(problem="sliding", kwargs={"t_max": 1e-6})
@example(problem="falling", kwargs={"t_max": 1e-7})
@example(problem="falling", kwargs={"gravity": 1e-100, "t_max": 1e-49})
@example(problem="falling", kwargs={"length": 5e-324})
@example(problem="sliding", kwargs={"t_max": 2.2227587494850775e-162})
def test_reduced_with_any_keywords(problem, kwargs):
    kwargs.setdefault("max_steps", 20000)
    ends_well(lambda: chainsim.reduced(problem, **kwargs), keyword_names(kwargs) + ["problem"])


def cheap(kwargs):
    """compare()'s keywords with a small mesh, a short run and a step budget unless they set them."""
    if "nodes" in kwargs and isinstance(kwargs["nodes"], (int, np.integer)) and 13 <= kwargs["nodes"] <= 200001:
        kwargs["nodes"] = 13  # a valid but large mesh: keep the run cheap
    kwargs.setdefault("nodes", 9)
    kwargs.setdefault("t_max", 0.05)
    kwargs.setdefault("max_steps", 20000)
    return kwargs


@fuzz_settings(60)
@given(problem=st.sampled_from(["falling", "folded", "sliding"]),
       kwargs=st.dictionaries(st.sampled_from(COMPARE_KEYWORDS), st.one_of(numbers, text, st.none()), max_size=3))
@example(problem="falling", kwargs={"nodes": 10**20})
@example(problem="falling", kwargs={"tilt_deg": 1, "bend_deg": 2.1316282072803006e-14})
def test_compare_with_any_keywords(problem, kwargs):
    cheap(kwargs)
    ends_well(lambda: chainsim.compare(problem, **kwargs), keyword_names(kwargs) + ["problem"])


# compare() of the contact problems: their own keywords (x0, u0, R) with the shared ones, and those they refuse
# (eta0, eps, force, tilt_deg; f for pulley). The pulley's R and u0 are checked against the length and each other.
CONTACT_KEYWORDS = COMPARE_KEYWORDS + ["x0", "u0", "R"]
CONTACT_RELATED = {**RELATED, "length": RELATED["length"] + ["R", "u0", "x0"], "R": ["u0"]}


@fuzz_settings(60)
@given(problem=st.sampled_from(["edge", "peg", "pulley"]),
       kwargs=st.dictionaries(st.sampled_from(CONTACT_KEYWORDS), st.one_of(numbers, text, st.none()), max_size=3))
@example(problem="pulley", kwargs={"R": 0.5})
@example(problem="edge", kwargs={"t_max": 0})   # was "t_max_over_t0 = 0 is out of range", naming no keyword
@example(problem="edge", kwargs={"t_max": 5e-324})   # was "stop.t_end = 0 is out of range"
@example(problem="edge", kwargs={"x0": 5e-324})   # was "the polyline's points 1 and 2 coincide"
@example(problem="edge", kwargs={"x0": 1e-100})   # was "the edge point is on an end node of the string"
@example(problem="pulley", kwargs={"R": 5.695819295555511e-160})   # was "shape.corner_radius = ... is too large"
@example(problem="pulley", kwargs={"length": 10000001, "R": 5e-324})
@example(problem="pulley", kwargs={"length": 0.2})
@example(problem="edge", kwargs={"u0": 0.1, "x0": "0.2"})
@example(problem="peg", kwargs={"x0": np.float32(0.7), "tilt_deg": 0})
def test_contact_compare_with_any_keywords(problem, kwargs):
    cheap(kwargs)
    names = []
    for k in kwargs:
        for name in [k] + CONTACT_RELATED.get(k, []):
            names += [name, CLI_NAMES.get(name, "--" + name)]
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", chainsim.ResolutionWarning)  # a pulley thinner than 9 nodes' links
        ends_well(lambda: chainsim.compare(problem, **kwargs), names + ["problem"])


@fuzz_settings(60)
@given(grid=st.dictionaries(st.one_of(st.sampled_from(SCENE_KEYS + ["f"]), keys),
                            st.one_of(st.lists(values, max_size=2), values), min_size=0, max_size=2),
       t_end=st.one_of(st.none(), floats, text))
@example(grid={"f": [0.1], "effects.heap[0].f": [0.9]}, t_end=None)
@example(grid={"stop.t_end": [0.01]}, t_end=0.02)
@example(grid={"model": [10**400]}, t_end=None)
def test_scene_sweep_with_any_grid(grid, t_end):
    scene = chainsim.Scene.from_dict(BASE)
    names = [n for k in grid for n in (shown(k) if isinstance(k, str) else [repr(k)])]
    # the alias f names the front's dissipation key, which its messages name
    aliases = ["effects.heap[0].f"] if "f" in grid else []
    table = ends_well(lambda: chainsim.sweep(scene, grid, t_end=t_end, workers=1),
                      names + aliases + ["t_end", "grid"])
    if table is not None:
        # one row per point, each a result or an error row: its status says which
        assert len(table) == math.prod(len(v) for v in grid.values())
        assert set(table.status) <= {"completed", "stopped", "failed", "error"}


@fuzz_settings(60)
@given(problem=st.one_of(st.sampled_from(["falling", "folded", "sliding"]), text),
       grid=st.dictionaries(st.one_of(st.sampled_from(REDUCED_KEYWORDS), text),
                            st.one_of(st.lists(st.one_of(numbers, text), max_size=2), numbers), min_size=0,
                            max_size=2))
@example(problem="falling", grid={"f": ["x", 0.5]})
@example(problem="falling", grid={"length": [5e-324]})
def test_reduced_sweep_with_any_grid(problem, grid):
    table = ends_well(lambda: chainsim.sweep(problem, {**grid, "max_steps": [20000]}, workers=1),
                      [n for k in grid for n in shown(k)] + ["problem", "grid"])
    if table is not None:
        assert set(table.status) <= {"completed", "failed", "error"}
