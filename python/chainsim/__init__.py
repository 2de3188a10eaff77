"""chainsim in Python: the solver of inextensible strings and chains with shocks (docs/python.md).

    import chainsim
    r = chainsim.reduced("falling", f=0.5)                 # the reduced ODE: r.series, r.summary
    scene = chainsim.Scene.from_file("cases/scenes/falling_chain.toml")
    result = scene.run(t_end=0.2)                          # the string solver, as `chainsim run`
    result.energy["drift"], result.nodes["x"], result.summary["t_stop"]
    result.write("results/falling")                        # the CLI's run directory (chainsim plot works)
    df = chainsim.sweep(scene, {"f": [0, 0.5, 1], "string.nodes": [51, 101]})   # pandas DataFrame

Every number comes from the C++ library (the extension chainsim._core), through the code the command-line
tool runs; nothing of the solver is written again in Python.
"""
import inspect
import itertools
import json
import os
import threading
import time

import numpy as np

from . import _core
from ._core import ChainsimInputError, NumericalError

__all__ = ["ChainsimInputError", "NumericalError", "Scene", "Result", "ReducedResult", "Comparison", "reduced",
           "compare", "sweep", "read_run", "plot"]


def _main_thread():
    return threading.current_thread() is threading.main_thread()


def _toml_value(value, key):
    """A Python value as TOML text (for --set overrides and grid values); ChainsimInputError naming `key` for a
    value no scene key can hold."""
    if isinstance(value, (bool, np.bool_)):
        return "true" if value else "false"
    if isinstance(value, (int, np.integer)):
        if not -2**63 <= int(value) < 2**63:
            raise ChainsimInputError(f"{key} = {value} is out of range: allowed integers from {-2**63} to {2**63 - 1}")
        return str(int(value))
    if isinstance(value, (float, np.floating)):
        return repr(float(value))
    if isinstance(value, str):
        return json.dumps(value)  # ASCII, escaped: TOML reads it back (and refuses a lone surrogate, at the key)
    if isinstance(value, (list, tuple, np.ndarray)):
        return "[" + ", ".join(_toml_value(v, key) for v in value) + "]"
    if isinstance(value, dict):
        return "{ " + ", ".join(f"{json.dumps(str(k))} = {_toml_value(v, key)}" for k, v in value.items()) + " }"
    raise ChainsimInputError(f"{key} = {value!r} cannot be a scene value: allowed a number, a string, a bool, a list "
                             "or a dict")


def _text_key(key):
    """A scene key given in Python: a str that UTF-8 can hold."""
    if not isinstance(key, str):
        raise ChainsimInputError(f"{key!r} is not a scene key: write a dotted key such as string.nodes")
    try:
        key.encode("utf-8")
    except UnicodeEncodeError:
        raise ChainsimInputError(f"{key!r} is not a scene key: it holds a lone surrogate") from None
    if any(ord(c) < 0x20 for c in key):
        raise ChainsimInputError(f"{key!r} is not a scene key: it holds a control character")
    if not key.strip():
        raise ChainsimInputError(f"{key!r} is not a scene key: the key is empty; write a dotted key such as "
                                 "string.nodes")
    return key


def _override(key, value):
    return f"{_text_key(key)}={_toml_value(value, key)}"


def _t_end(t_end):
    """The t_end keyword: None or a number (its range is checked with the scene, located at t_end)."""
    if t_end is None:
        return None
    if isinstance(t_end, (bool, np.bool_)) or not isinstance(t_end, (int, float, np.integer, np.floating)):
        raise ChainsimInputError(f"t_end = {t_end!r} must be a number (s)")
    try:
        return float(t_end)
    except OverflowError:
        raise ChainsimInputError(f"t_end = {t_end!r} is out of range: allowed t_end > 0 (s), below 1.8e308") from None


class ReducedResult:
    """A run of the reduced ODE: `series` (columns of series.csv as numpy arrays) and `summary` (its JSON)."""

    def __init__(self, series, summary):
        self.series = series
        self.summary = summary

    def __repr__(self):
        s = self.summary
        return f"<ReducedResult {s.get('problem')} f={s.get('parameters', {}).get('f')} t_stop={s.get('t_stop')}>"


class Result:
    """A run of a scene on the string solver (see docs/python.md for every field).

    nodes    t (frames,), node, s (nodes,), x, y[, z], vx, vy[, vz] (frames, nodes), moving (frames, nodes):
             the columns of nodes.csv, with NaN where a node is in a heap (not moving)
    tension  t, link, s_mid (links,), T (frames, links): tension.csv (NaN for a link in no arc)
    energy   t, K, V, W_applied, drift[, W_shocks, W_heaps, W_remesh]: energy.csv (every ledger term)
    forces   t and the measured forces: forces.csv
    series   one entry per accepted step (runs with fronts): series.csv
    fronts   t, s0, s0_dot (frames, fronts), position, reaction (frames, fronts, dim): the fronts at the frames
    summary  stats.json as a dict (also `stats`)
    """

    def __init__(self, run):
        self._run = run
        self.summary = json.loads(run.summary())
        arrays = run.arrays()
        self.nodes = arrays.get("nodes", {})
        self.tension = arrays.get("tension", {})
        self.energy = arrays.get("energy", {})
        self.forces = arrays.get("forces", {})
        self.fronts = arrays.get("fronts", {})
        self.series = arrays.get("series", {})

    @property
    def stats(self):
        return self.summary

    @property
    def status(self):
        return self.summary.get("status", "completed")

    @property
    def t(self):
        """The frame times (s)."""
        return self.nodes["t"] if "t" in self.nodes else self.series["t"]

    def _stack(self, prefix):
        axes = [a for a in ("x", "y", "z") if a in self.nodes]
        return np.stack([self.nodes[prefix + a] for a in axes], axis=-1)

    @property
    def positions(self):
        """Node positions, shape (frames, nodes, dim); NaN for a node in a heap."""
        return self._stack("")

    @property
    def velocities(self):
        """Node velocities, shape (frames, nodes, dim)."""
        return self._stack("v")

    def write(self, directory):
        """Writes the run directory exactly as `chainsim run --out DIR` does (same C++ writer); returns DIR."""
        self._run.write(os.fspath(directory))
        return directory

    def plot(self, directory, **options):
        """Writes the run directory, then draws it as `chainsim plot DIR` does; returns the paths written."""
        self.write(directory)
        return plot(directory, **options)

    def __repr__(self):
        s = self.summary
        return f"<Result {s.get('status')} t_stop={s.get('t_stop')} frames={s.get('frames')} nodes={s.get('nodes')}>"


class Scene:
    """A scene (docs/scenes.md), checked when made: a bad key or value raises ChainsimInputError with the
    file:line:column, the key, the value and the allowed range."""

    def __init__(self, text, source="<scene>", overrides=()):
        self.text = text
        self.source = source
        self.overrides = list(overrides)
        self.effective = json.loads(_core.check_scene(self.text, self.source, self.overrides))

    @classmethod
    def from_file(cls, path):
        path = os.fspath(path)
        return cls(_core.read_scene_file(path), path)

    @classmethod
    def from_dict(cls, scene, name="<dict>"):
        """A scene from a dict of sections, e.g. {"string": {"length": 1.0, "nodes": 41}, "shape": {...},
        "stop": {"t_end": 1.0}}; lists of dicts are arrays of tables ("effects": {"heap": [{...}]}). numpy scalars
        and arrays are taken as their values; a value no scene can hold raises ChainsimInputError naming its key."""
        return cls(_core.scene_toml_text(scene), name)

    def set(self, key=None, value=None, **keys):
        """A new scene with keys set as `chainsim run --set KEY=VALUE` sets them: scene.set("string.nodes", 101),
        or scene.set(**{"effects.heap[0].f": 0.5})."""
        overrides = list(self.overrides)
        if key is not None:
            overrides.append(_override(key, value))
        overrides += [_override(k, v) for k, v in keys.items()]
        return Scene(self.text, self.source, overrides)

    @property
    def toml(self):
        return self.text

    def run(self, t_end=None):
        """Runs the scene as `chainsim run` does; returns a Result (or a ReducedResult for model = "reduced").

        A numerical failure raises NumericalError, whose `result` holds the run up to the failure. Ctrl-C stops
        the run at its next accepted step and raises KeyboardInterrupt."""
        run = _core.run_scene(self.text, self.source, self.overrides, _t_end(t_end), _main_thread())
        if self.effective.get("model") == "reduced":
            return ReducedResult(run.arrays()["series"], json.loads(run.summary()))
        result = Result(run)
        if result.status == "interrupted":
            _core.clear_interrupt()
            raise KeyboardInterrupt(result.summary.get("stop_reason", "interrupted"))
        if run.error:
            error = NumericalError(run.error)
            error.result = result
            raise error
        return result

    def __reduce__(self):
        return (Scene, (self.text, self.source, self.overrides))

    def __repr__(self):
        extra = f" with {', '.join(self.overrides)}" if self.overrides else ""
        return f"<Scene {self.source}{extra}>"


def _settings(**kwargs):
    return {k: v for k, v in kwargs.items() if v is not None}


def reduced(problem, *, f=None, eta0=None, eps=None, force=None, length=None, density=None, gravity=None, t_max=None,
            method=None, rtol=None, atol=None, max_step=None, max_steps=None):
    """The reduced ODE of a canonical problem ("falling", "folded", "sliding"), as `chainsim reduced`.
    Parameters left at None take the command's defaults (docs/reduced.md)."""
    series, summary = _core.reduced(problem, _settings(
        f=f, eta0=eta0, eps=eps, force=force, length=length, density=density, gravity=gravity, t_max=t_max,
        method=method, rtol=rtol, atol=atol, max_step=max_step, max_steps=max_steps))
    return ReducedResult(series, json.loads(summary))


class Comparison:
    """`chainsim compare`: the string solver's series (string_series.csv), the reduced model's (reduced_series.csv)
    and the summary (summary.json)."""

    def __init__(self, string_series, reduced_series, summary):
        self.string_series = string_series
        self.reduced_series = reduced_series
        self.summary = summary


def compare(problem, *, nodes=None, f=None, eta0=None, eps=None, force=None, length=None, density=None, gravity=None,
            t_max=None, tilt_deg=None, bend_deg=None, method=None, rtol=None, atol=None, max_step=None,
            max_steps=None):
    """A canonical problem on the string solver with front tracking and as its reduced ODE, as `chainsim compare`.
    A failed string run raises NumericalError (its `comparison` holds what was done)."""
    string_series, reduced_series, summary, error = _core.compare(problem, _settings(
        nodes=nodes, f=f, eta0=eta0, eps=eps, force=force, length=length, density=density, gravity=gravity,
        t_max=t_max, tilt_deg=tilt_deg, bend_deg=bend_deg, method=method, rtol=rtol, atol=atol, max_step=max_step,
        max_steps=max_steps))
    comparison = Comparison(string_series, reduced_series, json.loads(summary))
    if error:
        e = NumericalError(f"the string solver failed: {error}")
        e.comparison = comparison
        raise e
    return comparison


# ------------------------------------------------------------------------------------------------------------------
# Sweeps

def _scene_point(task):
    """One point of a scene sweep (runs on a Dask worker too): the row as a dict."""
    text, source, overrides, t_end, point = task
    return json.loads(_core.run_sweep_point(text, source, overrides, t_end, point))


def _reduced_point(task):
    """One point of a reduced-model sweep: the summary flattened as a scene sweep's row."""
    problem, params = task
    start = time.perf_counter()
    try:
        result = reduced(problem, **params)
        row = json.loads(_core.flatten_summary(json.dumps(result.summary)))
        row.update(status="completed", error="")
    except (ChainsimInputError, NumericalError) as e:
        row = {"status": "failed" if isinstance(e, NumericalError) else "error", "error": str(e)}
    row["wall_time_s"] = time.perf_counter() - start
    return row


def sweep(target, grid, *, t_end=None, workers=None, client=None):
    """Runs `target` at every point of `grid` and returns a pandas DataFrame, one row per point.

    target   a Scene (grid keys: the dotted keys of `chainsim run --set`, and `f` for the scene's only front), or
             the name of a canonical problem for the reduced model (grid keys: the keywords of reduced()).
    grid     {key: [values]}; the points are all combinations (the last key varies fastest).
    t_end    replaces the scene's [stop] t_end (s) at every point.
    workers  local threads (default: every core this process may use); the C++ runs release the GIL and share
             nothing.
    client   a dask.distributed.Client: the points go to its workers instead (one task per point).

    Columns: the grid keys, status (completed | stopped | failed | error | interrupted), error, wall_time_s,
    then the run's summary (stats.json flattened: nested keys as "a.b"). A failed point is a row with its error.
    Refused before any point runs (ChainsimInputError): a grid that is not a dict of lists, an axis without values,
    and two keys that set one scene key (f and effects.heap[0].f, or stop.t_end with t_end): a row would show
    one value while the other ran.
    """
    import pandas as pd

    if not isinstance(grid, dict) or not grid:
        raise ChainsimInputError(f"a sweep needs a grid: {{key: [values], ...}}, not {grid!r}")
    keys = list(grid)
    for k in keys:
        _text_key(k)
        if isinstance(grid[k], (str, bytes, dict)) or not hasattr(grid[k], "__iter__"):
            raise ChainsimInputError(f"the grid axis {k} = {grid[k]!r} is not a list of values, "
                                     f"e.g. {{{k!r}: [0.1, 0.5]}}")
    values = [list(grid[k]) for k in keys]
    t_end = _t_end(t_end)
    if workers is not None and (isinstance(workers, (bool, np.bool_)) or not isinstance(workers, (int, np.integer))
                                or workers < 1):
        raise ChainsimInputError(f"workers = {workers!r} is out of range: allowed an integer >= 1 (None: every core)")
    # The grid's own checks (an axis without values), the same as `chainsim sweep`'s.
    points = _core.sweep_points([(k, ["0"] * len(vs)) for k, vs in zip(keys, values)])
    params = [dict(zip(keys, combo)) for combo in itertools.product(*values)]
    if isinstance(target, str):
        _core.check_problem(target)
        allowed = [p for p in inspect.signature(reduced).parameters if p != "problem"]
        for k in keys:
            if k not in allowed:
                raise ChainsimInputError(f"the grid key {k} is not a keyword of reduced(): allowed {', '.join(allowed)}")
        if t_end is not None:
            raise ChainsimInputError("t_end applies to Scene sweeps: a reduced sweep takes t_max (units of t0) as a "
                                     "grid key")
        tasks = [(target, p) for p in params]
        point = _reduced_point
    elif isinstance(target, Scene):
        points = _core.sweep_points([(k, [_toml_value(v, k) for v in vs]) for k, vs in zip(keys, values)])
        assert len(points) == len(params)
        # A scene key set twice (an alias and its full key, or stop.t_end with t_end) is refused before any runs.
        _core.check_sweep_points(target.text, target.source, target.overrides, t_end, points)
        tasks = [(target.text, target.source, target.overrides, t_end, p) for p in points]
        point = _scene_point
    else:
        raise ChainsimInputError(f"sweep() runs a Scene or a problem name (falling, folded, sliding), not {target!r}")

    workers = int(workers or len(os.sched_getaffinity(0)) or 1)
    if client is not None:
        rows = client.gather(client.map(point, tasks, pure=False))
    elif point is _scene_point:
        rows = [json.loads(r) for r in _core.run_sweep(target.text, target.source, target.overrides, t_end,
                                                        [t[4] for t in tasks], workers, _main_thread())]
    else:
        from concurrent.futures import ThreadPoolExecutor
        with ThreadPoolExecutor(max_workers=workers) as pool:
            rows = list(pool.map(point, tasks))
    if any(r.get("status") == "interrupted" for r in rows) and client is None:
        _core.clear_interrupt()
        raise KeyboardInterrupt("sweep interrupted by the user")
    table = pd.DataFrame([{**p, **r} for p, r in zip(params, rows)])
    first = keys + ["status", "error", "wall_time_s"]
    return table[first + [c for c in table.columns if c not in first]]


# ------------------------------------------------------------------------------------------------------------------
# Run directories and figures (the plotting tool, python/chainsim_plot)

def read_run(directory):
    """Reads a run directory of any chainsim command (run, reduced, compare, canonical) with the plotting tool's
    reader: tables by column name (docs/plotting.md)."""
    from chainsim_plot.readers import load_run
    return load_run(os.fspath(directory))


def plot(directory, times=None, animate=False, speed=1.0, fps=25, fmt=None):
    """Draws a run directory into DIR/figures/ as `chainsim plot DIR` does; returns the paths written."""
    from chainsim_plot.cli import plot_run
    return plot_run(os.fspath(directory), times=times, animate=animate, speed=speed, fps=fps, fmt=fmt)


# ------------------------------------------------------------------------------------------------------------------
# Fits to measured series (python/chainsim/fitting.py, docs/fit.md)

from .fitting import Data, FitResult, fit  # noqa: E402

__all__ += ["Data", "FitResult", "fit"]
