"""chainsim in Python: the solver of inextensible strings and chains with shocks (docs/python.md).

    import chainsim
    r = chainsim.reduced("falling", f=0.5)                 # the reduced ODE: r.series, r.summary
    scene = chainsim.Scene.from_file("cases/scenes/falling_chain.toml")
    result = scene.run(t_end=0.2)                          # the string solver, as `chainsim run`
    result.energy["drift"], result.nodes["x"], result.summary["t_stop"]
    result.to_xarray(), result.to_dataframe("energy")      # xarray and pandas; result.to_netcdf("run.nc")
    result.write("results/falling")                        # the CLI's run directory (chainsim plot works)
    df = chainsim.sweep(scene, {"f": [0, 0.5, 1], "string.nodes": [51, 101]})   # pandas DataFrame
    c = chainsim.compare("edge", x0=0.2, f=0.5)            # as `chainsim compare edge`: c.exact_series, c.summary

Every number comes from the C++ library (the extension chainsim._core), through the code the command-line
tool runs; nothing of the solver is written again in Python. Results, scenes and errors pickle (Dask).
"""
from __future__ import annotations

import inspect
import itertools
import json
import os
import sys
import threading
import time
import warnings
from typing import TYPE_CHECKING, Any, Callable, Dict, Iterable, List, Mapping, Optional, Sequence, Tuple, Union

import numpy as np

from . import _core
from ._core import ChainsimInputError, NumericalError
from ._results import Comparison, ReducedResult, Result, result_of_run

#: The version of the built module: the number in `chainsim --version` ("chainsim 0.1.0 (revision)"), whose whole
#: text is `chainsim._core.version_text`.
__version__: str = _core.__version__

__all__ = ["ChainsimInputError", "NumericalError", "Scene", "Result", "ReducedResult", "Comparison", "reduced",
           "compare", "sweep", "read_run", "plot", "ToleranceWarning", "ResolutionWarning", "__version__"]


class ToleranceWarning(UserWarning):
    """Scene.run(): atol is coarser than rtol times the motion's size (the summary's
    ``tolerance_warning``, which names the value of ``solver.atol`` that resolves the motion)."""


class ResolutionWarning(UserWarning):
    """Scene.run(): a cylinder is thinner than the links in node contact, or than 4 links with contact = "arc", so
    the mesh does not resolve it (the summary's ``resolution_warning``, which names the ``string.nodes`` that
    does)."""

if TYPE_CHECKING:  # pragma: no cover
    from pandas import DataFrame
else:  # pandas is imported by sweep(): the name labels the hints
    DataFrame = Any

PathLike = Union[str, "os.PathLike[str]"]


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


class Scene:
    """A scene (docs/scenes.md), checked when it is made.

    Parameters
    ----------
    text : str
        The scene as TOML text.
    source : str, optional
        How messages name it (a file's path; default ``"<scene>"``).
    overrides : sequence of str, optional
        ``KEY=VALUE`` overrides, applied as ``chainsim run --set KEY=VALUE`` applies them.

    Attributes
    ----------
    text, source, overrides
        What it was made of (a Scene pickles as these, so it can be sent to Dask workers).
    effective : dict
        The effective scene (``scene_effective`` of ``chainsim run --json``).

    Raises
    ------
    ChainsimInputError
        A bad key or value, with the file:line:column, the key, the value and the allowed range.
    """

    def __init__(self, text: str, source: str = "<scene>", overrides: Iterable[str] = ()) -> None:
        self.text = text
        self.source = source
        self.overrides: List[str] = list(overrides)
        self.effective: Dict[str, Any] = json.loads(_core.check_scene(self.text, self.source, self.overrides))

    @classmethod
    def from_file(cls, path: PathLike) -> "Scene":
        """Reads a scene file as ``chainsim run`` reads it (with its size limit).

        Parameters
        ----------
        path : str or os.PathLike
            The scene file (.toml).

        Returns
        -------
        Scene
        """
        path = os.fspath(path)
        return cls(_core.read_scene_file(path), path)

    @classmethod
    def from_dict(cls, scene: Mapping[str, Any], name: str = "<dict>") -> "Scene":
        """A scene from a dict of sections.

        Parameters
        ----------
        scene : dict
            Sections, e.g. ``{"string": {"length": 1.0, "nodes": 41}, "shape": {...}, "stop": {"t_end": 1.0}}``;
            lists of dicts are arrays of tables (``"effects": {"heap": [{...}]}``); numpy scalars and arrays are
            taken as their values.
        name : str, optional
            How messages name it.

        Returns
        -------
        Scene

        Raises
        ------
        ChainsimInputError
            A value no scene can hold, naming its key.
        """
        return cls(_core.scene_toml_text(scene), name)

    def set(self, key: Optional[str] = None, value: Any = None, **keys: Any) -> "Scene":
        """A new scene with keys set as ``chainsim run --set KEY=VALUE`` sets them.

        Parameters
        ----------
        key : str, optional
            A dotted key, e.g. ``"string.nodes"``.
        value : number, str, bool, list or dict
            Its value.
        **keys
            More keys, e.g. ``scene.set(**{"effects.heap[0].f": 0.5})``.

        Returns
        -------
        Scene
        """
        overrides = list(self.overrides)
        if key is not None:
            overrides.append(_override(key, value))
        overrides += [_override(k, v) for k, v in keys.items()]
        return Scene(self.text, self.source, overrides)

    @property
    def toml(self) -> str:
        """The scene's TOML text (without the overrides)."""
        return self.text

    def run(self, t_end: Optional[float] = None) -> Union[Result, ReducedResult]:
        """Runs the scene as ``chainsim run`` does, with the GIL released.

        Parameters
        ----------
        t_end : float, optional
            Replaces ``[stop] t_end`` (s); a message about it is located at ``t_end``.

        Returns
        -------
        Result or ReducedResult
            A ReducedResult for ``model = "reduced"``.

        Raises
        ------
        NumericalError
            A numerical failure; its ``result`` holds the run up to the failure.
        KeyboardInterrupt
            Ctrl-C, which stops the run at its next accepted step.
        """
        run = _core.run_scene(self.text, self.source, self.overrides, _t_end(t_end), _main_thread())
        result = result_of_run(run)
        if not isinstance(result, Result):
            return result
        if result.status == "interrupted":
            _core.clear_interrupt()
            raise KeyboardInterrupt(result.summary.get("stop_reason", "interrupted"))
        if "tolerance_warning" in result.summary:  # atol coarser than rtol x the motion's size
            warnings.warn(result.summary["tolerance_warning"], ToleranceWarning, stacklevel=2)
        if "resolution_warning" in result.summary:  # a cylinder thinner than the links
            warnings.warn(result.summary["resolution_warning"], ResolutionWarning, stacklevel=2)
        if run.error:
            error = NumericalError(run.error)
            error.result = result  # type: ignore[attr-defined]
            raise error
        return result

    def __reduce__(self) -> Tuple[Any, ...]:
        return (Scene, (self.text, self.source, self.overrides))

    def __repr__(self) -> str:
        extra = f" with {', '.join(self.overrides)}" if self.overrides else ""
        return f"<Scene {self.source}{extra}>"

    def _repr_html_(self) -> str:
        import html

        rows = []
        for section, keys in self.effective.items():
            if isinstance(keys, dict):
                for k, v in keys.items():
                    rows.append(f"<tr><td>{html.escape(section)}</td><td>{html.escape(k)}</td>"
                                f"<td>{html.escape(json.dumps(v))}</td></tr>")
            else:
                rows.append(f"<tr><td>{html.escape(section)}</td><td></td><td>{html.escape(json.dumps(keys))}</td></tr>")
        overrides = (f"<p>overrides: {html.escape(', '.join(self.overrides))}</p>" if self.overrides else "")
        return (f"<div><strong>chainsim.Scene</strong> {html.escape(self.source)}{overrides}"
                f"<table><tr><th>section</th><th>key</th><th>value</th></tr>{''.join(rows)}</table></div>")


def _settings(**kwargs: Any) -> Dict[str, Any]:
    return {k: v for k, v in kwargs.items() if v is not None}


_COMMON_PARAMETERS = """f : float, optional
        The dissipation f of the front, in [0, 1].
    eta0, eps, force, length, density, gravity : float, optional
        The problem's settings, as the command's options of the same names (docs/reduced.md).
    t_max : float, optional
        The end of the run, in units of t0.
    method : str, optional
        The integrator's method.
    rtol, atol, max_step : float, optional
        The integrator's tolerances and largest step.
    max_steps : int, optional
        The integrator's most steps."""


def reduced(problem: str, *, f: Optional[float] = None, eta0: Optional[float] = None, eps: Optional[float] = None,
            force: Optional[float] = None, length: Optional[float] = None, density: Optional[float] = None,
            gravity: Optional[float] = None, t_max: Optional[float] = None, method: Optional[str] = None,
            rtol: Optional[float] = None, atol: Optional[float] = None, max_step: Optional[float] = None,
            max_steps: Optional[int] = None) -> ReducedResult:
    """The reduced ODE of a canonical problem, as ``chainsim reduced``.

    Parameters
    ----------
    problem : {"falling", "folded", "sliding"}
        The canonical problem.
    {common}

    Parameters left at None take the command's defaults.

    Returns
    -------
    ReducedResult

    Raises
    ------
    ChainsimInputError
        A value of the wrong type or out of range, naming the keyword.
    """
    series, summary = _core.reduced(problem, _settings(
        f=f, eta0=eta0, eps=eps, force=force, length=length, density=density, gravity=gravity, t_max=t_max,
        method=method, rtol=rtol, atol=atol, max_step=max_step, max_steps=max_steps))
    return ReducedResult(series, json.loads(summary))


def compare(problem: str, *, nodes: Optional[int] = None, f: Optional[float] = None, eta0: Optional[float] = None,
            eps: Optional[float] = None, force: Optional[float] = None, length: Optional[float] = None,
            density: Optional[float] = None, gravity: Optional[float] = None, t_max: Optional[float] = None,
            tilt_deg: Optional[float] = None, bend_deg: Optional[float] = None, x0: Optional[float] = None,
            u0: Optional[float] = None, R: Optional[float] = None, method: Optional[str] = None,
            rtol: Optional[float] = None, atol: Optional[float] = None, max_step: Optional[float] = None,
            max_steps: Optional[int] = None) -> Comparison:
    """A canonical problem on the string solver against its reduced ODE (falling, folded, sliding) or its exact
    solution (edge, peg, pulley), as ``chainsim compare PROBLEM``: the same run (one C++ implementation) for the
    same options, without the files.

    Parameters
    ----------
    problem : {"falling", "folded", "sliding", "edge", "peg", "pulley"}
        The canonical problem.
    nodes : int, optional
        The string's nodes.
    {common}
    tilt_deg, bend_deg : float, optional
        Release the chain tilted or curved (degrees; falling, folded, sliding).
    x0 : float, optional
        edge: the hanging fraction at release (0 < x0 < 1, default 0.2); peg: the longer side's fraction
        (0.5 < x0 < 1, default 0.6).
    u0, R : float, optional
        pulley: the offset at release and the pulley's radius (m; defaults 0.05 and 0.1).

    Parameters left at None take the command's defaults; those a problem has no use for are refused as the
    command refuses them (eta0, eps, force for edge and peg; f too for pulley; x0, u0, R for the others).

    Returns
    -------
    Comparison
        ``string_series`` and ``summary`` (string_series.csv and summary.json), and ``reduced_series``
        (falling, folded, sliding) or ``exact_series`` (edge, peg, pulley).

    Raises
    ------
    ChainsimInputError
        A keyword of the wrong type, out of range, or of no use to the problem, naming it.
    NumericalError
        The string run failed; its ``comparison`` holds what was done.

    Warns
    -----
    ResolutionWarning
        pulley: a pulley thinner than 4 links (the summary's ``resolution_warning``).
    """
    string_series, reduced_series, exact_series, summary, error = _core.compare(problem, _settings(
        nodes=nodes, f=f, eta0=eta0, eps=eps, force=force, length=length, density=density, gravity=gravity,
        t_max=t_max, tilt_deg=tilt_deg, bend_deg=bend_deg, x0=x0, u0=u0, R=R, method=method, rtol=rtol, atol=atol,
        max_step=max_step, max_steps=max_steps))
    comparison = Comparison(string_series, reduced_series, json.loads(summary), exact_series=exact_series)
    if "resolution_warning" in comparison.summary:  # a pulley thinner than the links
        warnings.warn(comparison.summary["resolution_warning"], ResolutionWarning, stacklevel=2)
    if error:
        e = NumericalError(f"the string solver failed: {error}")
        e.comparison = comparison  # type: ignore[attr-defined]
        raise e
    return comparison


if reduced.__doc__ and compare.__doc__:  # not under python -OO
    reduced.__doc__ = reduced.__doc__.replace("{common}", _COMMON_PARAMETERS)
    compare.__doc__ = compare.__doc__.replace("{common}", _COMMON_PARAMETERS)


# ------------------------------------------------------------------------------------------------------------------
# Sweeps

Row = Dict[str, Any]


def _scene_point(task: tuple) -> Row:
    """One point of a scene sweep (runs on a Dask worker too): the row as a dict."""
    text, source, overrides, t_end, point = task
    return json.loads(_core.run_sweep_point(text, source, overrides, t_end, point))


def _scene_point_full(task: tuple) -> Tuple[Row, Union[Result, ReducedResult, None]]:
    """One point of a scene sweep and its result (None for a refused point): the same row as `_scene_point`."""
    text, source, overrides, t_end, point = task
    row, run = _core.run_sweep_point_full(text, source, overrides, t_end, point)
    return json.loads(row), None if run is None else result_of_run(run)


def _reduced_point_full(task: tuple) -> Tuple[Row, Optional[ReducedResult]]:
    """One point of a reduced-model sweep: the summary flattened as a scene sweep's row, and the result."""
    problem, params = task
    start = time.perf_counter()
    result = None
    try:
        result = reduced(problem, **params)
        row = json.loads(_core.flatten_summary(json.dumps(result.summary)))
        row.update(status="completed", error="")
    except (ChainsimInputError, NumericalError) as e:
        row = {"status": "failed" if isinstance(e, NumericalError) else "error", "error": str(e)}
    row["wall_time_s"] = time.perf_counter() - start
    return row, result


def _reduced_point(task: tuple) -> Row:
    return _reduced_point_full(task)[0]


def _progress_bar(total: int, progress: Optional[bool]) -> Any:
    """A tqdm progress bar over `total` points on stderr: with progress=True, or by default (None) when stderr is
    a terminal and tqdm (python3-tqdm) is installed; None otherwise."""
    if progress is False or (progress is None and not (hasattr(sys.stderr, "isatty") and sys.stderr.isatty())):
        return None
    try:
        from tqdm import tqdm
    except ImportError:
        if progress:
            raise ChainsimInputError("progress=True needs tqdm (the Debian package python3-tqdm)") from None
        return None
    return tqdm(total=total, desc="sweep", unit="point", file=sys.stderr, dynamic_ncols=True)


def _run_tasks(point: Callable[[tuple], Any], tasks: List[tuple], workers: int, client: Any, bar: Any) -> List[Any]:
    """`point` of every task, in order: on a Dask client (one task each) or on local threads."""
    if client is not None:
        futures = client.map(point, tasks, pure=False)
        if bar is not None:
            from dask.distributed import as_completed
            for _ in as_completed(futures):
                bar.update(1)
        return client.gather(futures)
    from concurrent.futures import ThreadPoolExecutor, as_completed as completed
    with ThreadPoolExecutor(max_workers=workers) as pool:
        futures = [pool.submit(point, task) for task in tasks]
        if bar is not None:
            for _ in completed(futures):
                bar.update(1)
        return [f.result() for f in futures]


def sweep(target: Union["Scene", str], grid: Mapping[str, Sequence[Any]], *, t_end: Optional[float] = None,
          workers: Optional[int] = None, client: Any = None, results: bool = False,
          progress: Optional[bool] = None) -> DataFrame:
    """Runs `target` at every point of `grid`; one row per point.

    Parameters
    ----------
    target : Scene or {"falling", "folded", "sliding"}
        A Scene (grid keys: the dotted keys of ``chainsim run --set``, and ``f`` for the scene's only front), or
        the name of a canonical problem for the reduced model (grid keys: the keywords of `reduced`).
    grid : dict of str to list
        ``{key: [values]}``; the points are all combinations (the last key varies fastest).
    t_end : float, optional
        Replaces the scene's ``[stop] t_end`` (s) at every point.
    workers : int, optional
        Local threads (default: every core this process may use); the C++ runs release the GIL and share
        nothing.
    client : dask.distributed.Client, optional
        The points go to its workers instead (one task per point).
    results : bool, optional
        Also return every point's whole run: a column ``result`` holding its `Result` (`ReducedResult` for the
        reduced model; None for a refused point), arrays and all. Results pickle, so they come back from Dask
        workers too. Default False: only the summary rows (cheaper to send).
    progress : bool, optional
        A tqdm progress bar (python3-tqdm) on stderr as the points end; default None: on when stderr is a
        terminal, False: never.

    Returns
    -------
    pandas.DataFrame
        Columns: the grid keys, ``status`` (completed | stopped | failed | error | interrupted), ``error``,
        ``wall_time_s``, then the run's summary (stats.json flattened: nested keys as ``"a.b"``), and with
        `results` the column ``result``. A failed point is a row with its error.

    Raises
    ------
    ChainsimInputError
        Before any point runs: a grid that is not a dict of lists, an axis without values, and two keys that
        set one scene key (f and effects.heap[0].f, or stop.t_end with t_end): a row would show one value while
        the other ran.
    KeyboardInterrupt
        Ctrl-C during a local sweep.
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
    for name, flag in (("results", results), ("progress", progress)):
        if not (isinstance(flag, (bool, np.bool_)) or (name == "progress" and flag is None)):
            raise ChainsimInputError(f"{name} = {flag!r} must be True or False")
    # The grid's own checks (an axis without values), the same as `chainsim sweep`'s.
    points = _core.sweep_points([(k, ["0"] * len(vs)) for k, vs in zip(keys, values)])
    params = [dict(zip(keys, combo)) for combo in itertools.product(*values)]
    point: Callable[[tuple], Any]
    if isinstance(target, str):
        _core.check_problem(target)
        allowed = [p for p in inspect.signature(reduced).parameters if p != "problem"]
        for k in keys:
            if k not in allowed:
                raise ChainsimInputError(f"the grid key {k} is not a keyword of reduced(): allowed {', '.join(allowed)}")
        if t_end is not None:
            raise ChainsimInputError("t_end applies to Scene sweeps: a reduced sweep takes t_max (units of t0) as a "
                                     "grid key")
        tasks: List[tuple] = [(target, p) for p in params]
        point = _reduced_point_full if results else _reduced_point
    elif isinstance(target, Scene):
        points = _core.sweep_points([(k, [_toml_value(v, k) for v in vs]) for k, vs in zip(keys, values)])
        assert len(points) == len(params)
        # A scene key set twice (an alias and its full key, or stop.t_end with t_end) is refused before any runs.
        _core.check_sweep_points(target.text, target.source, target.overrides, t_end, points)
        tasks = [(target.text, target.source, target.overrides, t_end, p) for p in points]
        point = _scene_point_full if results else _scene_point
    else:
        raise ChainsimInputError(f"sweep() runs a Scene or a problem name (falling, folded, sliding), not {target!r}")

    workers = int(workers or len(os.sched_getaffinity(0)) or 1)
    bar = _progress_bar(len(tasks), progress)
    try:
        if client is None and point is _scene_point:  # the C++ sweep: its threads, its Ctrl-C
            assert isinstance(target, Scene)
            update = None if bar is None else (lambda done: bar.update(done - bar.n))
            rows = [json.loads(r) for r in _core.run_sweep(target.text, target.source, target.overrides, t_end,
                                                            [t[4] for t in tasks], workers, _main_thread(), update)]
        else:
            rows = _run_tasks(point, tasks, workers, client, bar)
    finally:
        if bar is not None:
            bar.close()
    found: List[Any] = []
    if results:
        rows, found = [r for r, _ in rows], [res for _, res in rows]
    if any(r.get("status") == "interrupted" for r in rows) and client is None:
        _core.clear_interrupt()
        raise KeyboardInterrupt("sweep interrupted by the user")
    table = pd.DataFrame([{**p, **r} for p, r in zip(params, rows)])
    first = keys + ["status", "error", "wall_time_s"]
    table = table[first + [c for c in table.columns if c not in first]]
    if results:
        table["result"] = pd.Series(found, index=table.index, dtype=object)
    return table


# ------------------------------------------------------------------------------------------------------------------
# Run directories and figures (the plotting tool, python/chainsim_plot)

def read_run(directory: PathLike) -> Union[Result, ReducedResult, Comparison]:
    """Reads a run directory back into the type the module returns for the same run.

    Parameters
    ----------
    directory : str or os.PathLike
        A directory written by ``chainsim run`` (or `Result.write`), ``chainsim reduced`` or ``chainsim compare``.

    Returns
    -------
    Result or ReducedResult or Comparison
        A `Result` for a run of a scene (its arrays in the shapes of `Scene.run()`'s, bit for bit the numbers
        of the files), a `ReducedResult` for ``chainsim reduced``, a `Comparison` for ``chainsim compare``; each
        with ``kind`` and ``path``.

    Raises
    ------
    chainsim_plot.readers.RunError
        The directory holds none of the files a chainsim command writes, or a file is malformed.
    """
    from ._results import read_directory
    return read_directory(directory)


def plot(directory: PathLike, times: Optional[Sequence[float]] = None, animate: bool = False, speed: float = 1.0,
         fps: int = 25, fmt: Optional[str] = None, html: bool = False) -> List[str]:
    """Draws a run directory into ``DIR/figures/`` as ``chainsim plot DIR`` does.

    Parameters
    ----------
    directory : str or os.PathLike
        A directory of ``chainsim run``, ``reduced``, ``compare`` or ``canonical``.
    times : list of float, optional
        Times (s) of the snapshots and tension profiles.
    animate : bool, optional
        Also an animation of the string (``--animate``).
    speed : float, optional
        The animation's speed in units of real time.
    fps : int, optional
        The animation's frames per second.
    fmt : {"mp4", "gif", "html"}, optional
        The animation's format (default mp4 with ffmpeg, else gif).
    html : bool, optional
        The animation as one self-contained HTML page with play and scrub controls (``--animate --html``).

    Returns
    -------
    list of str
        The paths written.
    """
    from chainsim_plot.cli import plot_run
    return plot_run(os.fspath(directory), times=times, animate=animate, speed=speed, fps=fps,
                    fmt="html" if html else fmt)


# ------------------------------------------------------------------------------------------------------------------
# Fits to measured series (python/chainsim/fitting.py, docs/fit.md)

from .fitting import Data, FitResult, fit  # noqa: E402

__all__ += ["Data", "FitResult", "fit"]
