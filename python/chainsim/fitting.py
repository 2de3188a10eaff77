"""Fits of a scene's parameters to measured series: `chainsim.fit` and `chainsim fit` (docs/fit.md).

    data = chainsim.Data.from_csv("drop.csv")                       # columns t, y [, sigma]
    fit = chainsim.fit("falling", data, free={"f": 0.5, "t_offset": 0.0})
    fit.value["f"], fit.interval["f"], fit.profile_interval["f"]
    print(fit.table()); fit.write("results/fit")                     # fit.json, fit_table.txt, figures

The model is chainsim itself: the reduced ODE for a canonical problem ("falling", "folded", "sliding", or a scene
with model = "reduced"), the string solver for any other scene. The fit is weighted nonlinear least squares with
bounds (SciPy's least_squares, trust-region reflective), with central finite differences evaluated in parallel
(threads, or Dask tasks with client=). Uncertainty: the covariance from the Jacobian scaled by the residual
variance, and the profile likelihood of one parameter (f by default), both with 95% intervals.

Every problem with the input (a CSV row, a parameter, a bound, a fit that does not converge) raises
ChainsimInputError with the file, line, column and value where there is one, as the command-line tool's exit 2.
"""
import csv
import json
import math
import os
import re
import sys
import time

import numpy as np

from . import _core  # noqa: F401  (the compiled half: the package is complete)
from ._core import ChainsimInputError, NumericalError

__all__ = ["Data", "FitResult", "fit", "main", "CHI2_95"]

CHI2_95 = 3.841458820694124     # the 95% quantile of chi-square with 1 degree of freedom (1.959964²)
Z_95 = math.sqrt(CHI2_95)
PROBLEMS = ("falling", "folded", "sliding")
REDUCED_KEYS = ("f", "eta0", "eps", "force", "length", "density", "gravity")
REDUCED_SOLVER_KEYS = ("t_max", "method", "rtol", "atol", "max_step", "max_steps")  # fixed= only
# Default bounds of the parameters chainsim knows (the ranges the scene format and `chainsim reduced` allow).
KNOWN_BOUNDS = {"f": (0.0, 1.0), "eta0": (0.0, 1.0), "t_offset": (-np.inf, np.inf)}
# A pot (a start heap that pushes, docs/model.md) may have -1/2 <= f < 0: its loss (1/2 + f) lambda v^3 >= 0.
POT_MIN_F = -0.5
# Columns whose time derivative is another column of the same series: the model is interpolated between its
# steps by cubic Hermite polynomials there (error ~ h^4), linearly elsewhere.
TIME_DERIVATIVE = {"y": "ydot", "ydot": "yddot"}
UNITS = {"y": "m", "ydot": "m/s", "yddot": "m/s²", "P": "N", "t_stop": "s", "K": "J", "V": "J", "s0_0": "m",
         "s0dot_0": "m/s", "support_x": "N", "support_y": "N", "front_0_x": "m", "front_0_y": "m"}


def _error(message):
    return ChainsimInputError(message)


# ----------------------------------------------------------------------------------------------------------------
# Data

class Data:
    """One measured series: times, the values of an observable that chainsim outputs, and their standard deviations.

    Parameters
    ----------
    t : array_like or None
        Times (s), strictly increasing (unused for ``observable="t_stop"``).
    values : array_like
        The measured values.
    observable : str
        A column of the model's series.csv (reduced: y, ydot, P, eta, ...; string runs with fronts: s0_0,
        front_0_y, support_y, ...) or forces.csv, ``"node[K].x"`` (a node's coordinate), or ``"t_stop"`` (a stop
        time: each value is one measured stop time).
    sigma : float or array_like, optional
        Standard deviations of the values (None: estimated from the residuals).
    settings : dict, optional
        Keys that hold for this series only (a drop from another height: ``{"eta0": 0.8}``, or scene keys
        ``{"string.length": 0.8}``); series with the same `run` label share one model run.
    run : str, optional
        Label of the run (drop) the series belongs to: per-run parameters (``per_run=``) are fitted once per
        label. Default: each series its own run.
    name : str, optional
        How tables and figures name the series (default: the observable).
    lines : list of int, optional
        The file's line of each value, for messages (`from_csv` sets them).
    columns : dict, optional
        The file's column names of t, the values and sigma, for messages (`from_csv` sets them).
    """

    def __init__(self, t, values, observable, sigma=None, settings=None, run=None, name=None, lines=None,
                 columns=None):
        self.observable = str(observable)
        self.name = name or self.observable
        self.values = np.asarray(values, dtype=float).reshape(-1)
        self.t = np.zeros_like(self.values) if t is None else np.asarray(t, dtype=float).reshape(-1)
        self.lines = list(lines) if lines is not None else [None] * len(self.values)
        self.columns = columns or {"t": "t", "value": self.observable, "sigma": "sigma"}
        self.settings = dict(settings or {})
        self.run = run
        self.header_line = None   # the line of a CSV file's header row
        self.sigma_given = sigma is not None
        if sigma is None:
            self.sigma = None
        else:
            s = np.asarray(sigma, dtype=float)
            self.sigma = np.full(len(self.values), float(s)) if s.ndim == 0 else s.reshape(-1)
        self._check()

    def _where(self, i, column):
        line = self.lines[i]
        return f"{self.name}:{line}: column {column}" if line is not None else f"{self.name}[{i}]: {column}"

    def _check(self):
        n = len(self.values)
        if len(self.t) != n or (self.sigma is not None and len(self.sigma) != n):
            raise _error(f"{self.name}: t, values and sigma have different lengths ({len(self.t)}, {n}, "
                         f"{len(self.sigma) if self.sigma is not None else '-'})")
        if n == 0:
            raise _error(f"{self.name}: no data points (allowed: at least 1 for t_stop, 2 for a series)")
        for label, array in (("t", self.t), ("value", self.values), ("sigma", self.sigma)):
            if array is None:
                continue
            bad = np.flatnonzero(~np.isfinite(array))
            if bad.size:
                i = int(bad[0])
                raise _error(f"{self._where(i, self.columns[label])} = {array[i]} is not a finite number "
                             f"(allowed: finite numbers; remove the row or fill it)")
        if self.sigma is not None:
            bad = np.flatnonzero(self.sigma <= 0)
            if bad.size:
                i = int(bad[0])
                raise _error(f"{self._where(i, self.columns['sigma'])} = {self.sigma[i]} is out of range: allowed "
                             f"sigma > 0")
        if self.observable != "t_stop":
            if n < 2:
                raise _error(f"{self.name}: {n} data point: too few (allowed: at least 2 points for a series; "
                             f"a single number is a t_stop)")
            bad = np.flatnonzero(np.diff(self.t) <= 0)
            if bad.size:
                i = int(bad[0]) + 1
                raise _error(f"{self._where(i, self.columns['t'])} = {self.t[i]!r} is not after the previous time "
                             f"{self.t[i - 1]!r}: allowed strictly increasing times (sort the rows, merge repeats)")

    @classmethod
    def from_csv(cls, path, observable=None, time="t", sigma=None, settings=None, run=None, column=None):
        """Reads a CSV file: a header row naming the columns, then one row per point (lines starting with # are
        comments).

        Parameters
        ----------
        path : str or os.PathLike
            The CSV file.
        observable : str, optional
            The model output the values are (see `Data`).
        time : str, optional
            The time column (s), default ``"t"``.
        sigma : str or float, optional
            A column of standard deviations, or a number (default: the column "sigma" if there is one, else
            estimated from the residuals).
        settings : dict, optional
            As for `Data`.
        run : str, optional
            As for `Data`.
        column : str, optional
            The column that holds the values (default: the observable's name; without either, the only column
            that is neither the time nor sigma).

        Returns
        -------
        Data

        Raises
        ------
        ChainsimInputError
            Unsorted times, NaN, a missing column: with the file, line, column and value.
        """
        path = os.fspath(path)
        try:
            with open(path, newline="") as handle:
                text = handle.read()
        except OSError as e:
            raise _error(f"{path}: cannot read the data file: {e.strerror}")
        rows = [(k + 1, line) for k, line in enumerate(text.splitlines())
                if line.strip() and not line.lstrip().startswith("#")]
        if not rows:
            raise _error(f"{path}: no header row (allowed: a CSV file whose first row names the columns, "
                         f"e.g. t,y)")
        header_line, header = rows[0]
        names = [c.strip() for c in next(csv.reader([header]))]
        sigma_column = sigma if isinstance(sigma, str) else ("sigma" if "sigma" in names and sigma is None else None)
        if column is None and observable is not None:
            column = observable
        if column is None and time not in names:
            raise _error(f"{path}:{header_line}: no column '{time}' in the header {names} (the time column is set by "
                         f"--time-column / time=)")
        if column is None:
            others = [c for c in names if c not in (time, sigma_column)]
            if len(others) != 1:
                raise _error(f"{path}:{header_line}: cannot tell the observable from the columns {names}: name it "
                             f"(--observable, observable=)")
            column = others[0]
        observable = observable or column
        value_column = column
        needed = [value_column] + ([time] if observable != "t_stop" else []) + ([sigma_column] if sigma_column else [])
        for column in needed:
            if column not in names:
                raise _error(f"{path}:{header_line}: no column '{column}' in the header {names} (the time column is "
                             f"set by --time-column / time=, the values by --column / column= or --observable / "
                             f"observable=)")
        index = {c: names.index(c) for c in needed}
        t, values, sig, lines = [], [], [], []
        for line, row_text in rows[1:]:
            row = [c.strip() for c in next(csv.reader([row_text]))]
            if len(row) != len(names):
                raise _error(f"{path}:{line}: {len(row)} columns, the header has {len(names)} ({names})")
            parsed = {}
            for column in needed:
                raw = row[index[column]]
                try:
                    parsed[column] = float(raw)
                except ValueError:
                    raise _error(f"{path}:{line}: column {column} = '{raw}' is not a number")
            lines.append(line)
            values.append(parsed[value_column])
            t.append(parsed[time] if observable != "t_stop" else 0.0)
            if sigma_column:
                sig.append(parsed[sigma_column])
        if sigma_column:
            sigma = sig
        elif isinstance(sigma, str):
            sigma = None
        data = cls(t, values, observable, sigma=sigma, settings=settings, run=run, name=path, lines=lines,
                   columns={"t": time, "value": value_column, "sigma": sigma_column or "sigma"})
        data.header_line = header_line
        return data

    def __repr__(self):
        return f"<Data {self.name}: {self.observable}, {len(self.values)} points>"


# ----------------------------------------------------------------------------------------------------------------
# The model: one run of chainsim per run label and parameter vector

def _scene_key(scene, key):
    """`f` -> the dotted key of the scene's only front's dissipation, as `chainsim sweep` resolves it (the same
    code: chainsim._core.sweep_key)."""
    if key != "f":
        return key
    return _core.sweep_key(scene.text, scene.source, scene.overrides, key)


def _allowed_range(target, name):
    """The range the scene format allows for a free parameter, or None where it states none.

    ``f`` and ``eta0`` of the reduced models are in [0, 1]. On a scene, a front's dissipation is in [0, 1],
    except a pot's (a start heap declared ``pot = true``), which may push: -1/2 <= f <= 1 (docs/scenes.md)."""
    if isinstance(target, str) or name not in KNOWN_BOUNDS and not name.endswith(".f"):
        return KNOWN_BOUNDS.get(name)
    if name == "t_offset":
        return KNOWN_BOUNDS[name]
    key = _scene_key(target, name)
    match = re.fullmatch(r"effects\.heap\[(\d+)\]\.f", key)
    if match:
        heaps = target.effective.get("effects", {}).get("heap", [])
        k = int(match.group(1))
        if k < len(heaps) and heaps[k].get("pot", False):
            return (POT_MIN_F, 1.0)
    return KNOWN_BOUNDS["f"] if key.endswith(".f") else KNOWN_BOUNDS.get(name)


def _run_model(target, settings):
    """Runs the model with `settings` (parameter and per-series values, t_offset removed)."""
    from . import Scene, reduced
    if isinstance(target, str):
        unknown = [k for k in settings if k not in REDUCED_KEYS + REDUCED_SOLVER_KEYS]
        if unknown:
            raise _error(f"'{unknown[0]}' is not a parameter of the reduced {target} chain: allowed "
                         f"{', '.join(REDUCED_KEYS + ('t_offset',) + REDUCED_SOLVER_KEYS)}")
        return reduced(target, **settings)
    scene = target
    if settings:
        scene = scene.set(**{_scene_key(target, k): v for k, v in settings.items()})
    assert isinstance(scene, Scene)
    return scene.run()


def _table(result, observable):
    """(t, values, dvalues/dt or None, smooth) of an observable of a run, or raises ChainsimInputError naming the
    columns; smooth: the run is the reduced ODE (no front crossings)."""
    from . import ReducedResult
    smooth = isinstance(result, ReducedResult)
    series = getattr(result, "series", {}) or {}
    forces = getattr(result, "forces", {}) or {}
    nodes = getattr(result, "nodes", {}) or {}
    name = observable
    tables = [series, forces]
    for prefix, table in (("series.", series), ("forces.", forces)):
        if observable.startswith(prefix):
            name, tables = observable[len(prefix):], [table]
    if observable.startswith("node[") and "]." in observable and nodes:
        k_text, _, axis = observable[5:].partition("].")
        try:
            k = int(k_text)
            values = np.asarray(nodes[axis], dtype=float)[:, k]
        except (ValueError, KeyError, IndexError):
            raise _error(f"observable '{observable}': no such node coordinate (allowed: node[K].x, node[K].y"
                         f"{', node[K].z' if 'z' in nodes else ''} with 0 <= K < {np.asarray(nodes['x']).shape[1]})")
        # A node in a heap lies where it landed (its coordinates are NaN in the frames): hold its last position.
        last = values[0]
        values = values.copy()
        for i, v in enumerate(values):
            last = v if np.isfinite(v) else last
            values[i] = last
        return np.asarray(nodes["t"], dtype=float), values, None, False
    for table in tables:
        if name in table and name != "t":
            d = TIME_DERIVATIVE.get(name)
            if d is None and name.startswith("s0_") and "s0dot_" + name[3:] in table:
                d = "s0dot_" + name[3:]
            return (np.asarray(table["t"], dtype=float), np.asarray(table[name], dtype=float),
                    np.asarray(table[d], dtype=float) if d and d in table else None, smooth)
    available = sorted({c for c in list(series) + list(forces) if c != "t"})
    if nodes:
        available.append("node[K].x|y")
    raise _error(f"observable '{observable}' is not an output of this model: allowed t_stop, "
                 f"{', '.join(available)}")


def _interpolate(t_model, y_model, dy_model, smooth, t):
    """The model at times t: cubic Hermite between steps where dy/dt is known; else a cubic spline through the steps
    of a smooth model (the reduced ODE), linear interpolation for the string solver (whose series may have kinks at
    front crossings); held constant before the first and after the last step (the chain at rest before its
    release and after its stop)."""
    keep = np.append(np.diff(t_model) > 0, True)  # a crossing may repeat a time: keep the state after it
    tm, ym = t_model[keep], y_model[keep]
    if dy_model is None and smooth and len(tm) >= 4:
        from scipy.interpolate import CubicSpline
        return CubicSpline(tm, ym)(np.clip(t, tm[0], tm[-1]))
    if dy_model is None:
        return np.interp(t, tm, ym)
    dm = dy_model[keep]
    tc = np.clip(t, tm[0], tm[-1])
    i = np.clip(np.searchsorted(tm, tc, side="right") - 1, 0, len(tm) - 2)
    h = tm[i + 1] - tm[i]
    s = (tc - tm[i]) / h
    h00, h10, h01, h11 = 2 * s**3 - 3 * s**2 + 1, s**3 - 2 * s**2 + s, -2 * s**3 + 3 * s**2, s**3 - s**2
    return h00 * ym[i] + h10 * h * dm[i] + h01 * ym[i + 1] + h11 * h * dm[i + 1]


def _predict(task, with_span=False):
    """One model run and its predictions at the data times (a module-level function: it runs on Dask workers).

    task = (target, settings, t_offset, [(observable, times), ...]) -> [predicted values, ...]
    with_span: also the last time of each observable's table on the data's clock (None for t_stop)."""
    target, settings, t_offset, wanted = task
    result = _run_model(target, settings)
    out, ends = [], []
    for observable, t in wanted:
        if observable == "t_stop":
            out.append(np.full(len(t), float(result.summary["t_stop"]) + t_offset))
            ends.append(None)
        else:
            table = _table(result, observable)
            out.append(_interpolate(*table, np.asarray(t) - t_offset))
            ends.append(float(table[0][-1]) + t_offset)
    return (out, ends) if with_span else out


# ----------------------------------------------------------------------------------------------------------------
# The fit

class _Problem:
    """The parameters, the runs and the weighted residuals of a fit."""

    def __init__(self, target, data, free, bounds, per_run, fixed, workers, client):
        self.target, self.data, self.client = target, data, client
        self.workers = workers or len(os.sched_getaffinity(0)) or 1
        self.fixed = dict(fixed or {})
        labels = []
        for k, d in enumerate(data):
            label = d.run if d.run is not None else f"#{k}"
            if label not in labels:
                labels.append(label)
        self.runs = labels
        self.run_of = [labels.index(d.run if d.run is not None else f"#{k}") for k, d in enumerate(data)]
        for r in range(len(labels)):
            members = [d for d, rr in zip(data, self.run_of) if rr == r]
            if any(m.settings != members[0].settings for m in members):
                raise _error(f"the series of run '{labels[r]}' have different settings ({members[0].settings} and "
                             f"others): series of one run share its settings")
        per_run = list(per_run or [])
        for name in per_run:
            if name not in free:
                raise _error(f"per_run names '{name}', which is not a free parameter (free: {', '.join(free)})")
        self.names, self.x0, self.lo, self.hi, self.owner, self.base = [], [], [], [], [], []
        bounds = dict(bounds or {})
        for name, spec in free.items():
            allowed = _allowed_range(target, name)
            if isinstance(spec, (tuple, list)):
                if len(spec) != 3:
                    raise _error(f"free parameter {name} = {spec!r}: allowed a start value or (start, lower, upper)")
                start, lo, hi = (float(v) for v in spec)
            else:
                start = float(spec)
                lo, hi = bounds.get(name, allowed or (-np.inf, np.inf))
            lo, hi = float(lo), float(hi)
            if name in bounds and isinstance(spec, (tuple, list)):
                raise _error(f"free parameter {name}: bounds given twice (in free= and in bounds=)")
            if allowed is not None:
                klo, khi = allowed
                if lo < klo or hi > khi:
                    raise _error(f"free parameter {name}: bounds [{lo}, {hi}] are out of range: allowed "
                                 f"{klo} <= {name} <= {khi}")
            if not (lo < hi) or math.isnan(start):
                raise _error(f"free parameter {name}: lower bound {lo} is not below the upper bound {hi}")
            if not (lo <= start <= hi):
                raise _error(f"free parameter {name} = {start} is out of range: allowed {lo} <= {name} <= {hi}")
            if name in self.fixed:
                raise _error(f"{name} is both free and fixed")
            owners = range(len(labels)) if name in per_run else [None]
            for r in owners:
                self.names.append(name if r is None else f"{name}[{labels[r]}]")
                self.base.append(name)
                self.owner.append(r)
                self.x0.append(start)
                self.lo.append(lo)
                self.hi.append(hi)
        self.x0, self.lo, self.hi = (np.array(a, dtype=float) for a in (self.x0, self.lo, self.hi))
        self.scale = [np.ones(len(d.values)) for d in data]   # the sigma used in the weights
        self.evaluations = 0
        self._last = (None, None)   # the last full evaluation: least_squares asks for the Jacobian where it was

    # values of one run: the fixed keys, its series' settings, the shared and its own parameters
    def settings(self, x, r):
        s = dict(self.fixed)
        s.update(next(d.settings for d, rr in zip(self.data, self.run_of) if rr == r))
        for value, name, owner in zip(x, self.base, self.owner):
            if owner is None or owner == r:
                s[name] = float(value)
        t_offset = s.pop("t_offset", 0.0)
        return s, t_offset

    def task(self, x, r):
        s, t_offset = self.settings(x, r)
        wanted = [(d.observable, d.t) for d, rr in zip(self.data, self.run_of) if rr == r]
        return (self.target, s, t_offset, wanted)

    def map(self, tasks):
        """Runs the tasks (model runs) in parallel: Dask tasks with a client, else local threads."""
        self.evaluations += len(tasks)
        if self.client is not None:
            return self.client.gather(self.client.map(_predict, tasks, pure=False))
        if len(tasks) == 1 or self.workers == 1:
            return [_predict(t) for t in tasks]
        from concurrent.futures import ThreadPoolExecutor
        with ThreadPoolExecutor(max_workers=min(self.workers, len(tasks))) as pool:
            return list(pool.map(_predict, tasks))

    def predictions(self, xs, runs=None):
        """For each parameter vector of xs, {run: [predictions of its series]} for the runs asked for."""
        if runs is None and len(xs) == 1 and self._last[0] == xs[0].tobytes():
            return [self._last[1]]
        cache = runs is None and len(xs) == 1
        runs = range(len(self.runs)) if runs is None else runs
        jobs = [(i, r) for i in range(len(xs)) for r in (runs[i] if isinstance(runs, list) else runs)]
        try:
            out = self.map([self.task(xs[i], r) for i, r in jobs])
        except NumericalError as e:
            raise NumericalError(f"the model failed at {self.describe(xs[0])}: {e}") from None
        result = [dict() for _ in xs]
        for (i, r), value in zip(jobs, out):
            result[i][r] = value
        if cache:
            self._last = (xs[0].tobytes(), result[0])
        return result

    def describe(self, x):
        return ", ".join(f"{n} = {v:.6g}" for n, v in zip(self.names, x))

    def residuals_from(self, pred):
        parts = []
        counters = {}
        for k, (d, r) in enumerate(zip(self.data, self.run_of)):
            j = counters.get(r, 0)
            counters[r] = j + 1
            parts.append((pred[r][j] - d.values) / self.scale[k])
        return np.concatenate(parts)

    def residuals(self, x):
        return self.residuals_from(self.predictions([x])[0])

    def raw_residuals(self, x):
        """Unweighted residuals (model - data) per series."""
        pred = self.predictions([x])[0]
        counters, out = {}, []
        for d, r in zip(self.data, self.run_of):
            j = counters.get(r, 0)
            counters[r] = j + 1
            out.append(pred[r][j] - d.values)
        return out

    def steps(self, x, diff_step):
        h = diff_step * np.maximum(np.abs(x), 1.0)
        h = np.where(np.isfinite(self.hi - self.lo), np.minimum(h, 0.25 * (self.hi - self.lo)), h)
        return h

    def jacobian(self, x, diff_step):
        """Central differences (one-sided at a bound), every run in parallel; only the runs a parameter acts on."""
        h = self.steps(x, diff_step)
        xs, runs, plan = [], [], []
        for j in range(len(x)):
            affected = list(range(len(self.runs))) if self.owner[j] is None else [self.owner[j]]
            up, down = min(x[j] + h[j], self.hi[j]), max(x[j] - h[j], self.lo[j])
            for value in (up, down):
                xv = x.copy()
                xv[j] = value
                xs.append(xv)
                runs.append(affected)
            plan.append((up, down, affected))
        base = self.predictions([x])[0]
        preds = self.predictions(xs, runs)
        columns = []
        for j, (up, down, affected) in enumerate(plan):
            pu, pd = dict(base), dict(base)
            pu.update(preds[2 * j])
            pd.update(preds[2 * j + 1])
            columns.append((self.residuals_from(pu) - self.residuals_from(pd)) / (up - down))
        return np.stack(columns, axis=1)


class FitResult:
    """The result of `chainsim.fit` (docs/fit.md).

    Parameters
    ----------
    **fields
        The attributes below (`fit` makes it).

    Attributes
    ----------
    value, sd, interval : dict
        {name: best value}, {name: standard deviation}, {name: (low, high)} (covariance, 95%).
    profile_interval : dict
        {name: (low, high)} from the profile likelihood (the profiled parameter).
    profile : dict
        {"parameter", "values", "delta_chi2"} (delta chi-square / s^2 along the profile).
    on_bound : dict
        {name: "lower" | "upper"} for a parameter that ends on its bound.
    covariance, names : numpy.ndarray, list
        The covariance matrix and the order of its rows.
    series : list of dict
        Per series: name, observable, n, rms, residual_norm, noise (estimated or given sigma).
    chi2, dof, s2 : float
        Weighted sum of squares, N - p, chi2 / dof (the residual variance).
    """

    def __init__(self, **fields):
        self.__dict__.update(fields)

    def to_dict(self):
        """The fit as plain JSON values (what fit.json holds).

        Returns
        -------
        dict
        """
        keys = ("target", "names", "value", "sd", "interval", "profile_interval", "profile_parameter", "on_bound",
                "covariance", "correlation", "chi2", "dof", "points", "s2", "absolute_sigma", "series", "profile",
                "optimizer", "evaluations", "wall_s", "warnings", "threshold")
        return {k: _jsonable(getattr(self, k)) for k in keys}

    def table(self):
        """The fit as a text table: parameters (value, sd, 95% intervals), then series (points, residuals, noise)."""
        plural = "s" if len(self.names) != 1 else ""
        lines = [f"fit of {self.target}: {self.points} points, {len(self.names)} parameter{plural}, chi2 = "
                 f"{self.chi2:.6g}, s^2 = chi2/(N-p) = {self.s2:.4g}" + (" (sigma taken as given)"
                                                                          if self.absolute_sigma else "")]
        w = max([18] + [len(n) for n in self.names])
        lines.append(f"{'parameter':<{w}} {'value':>13} {'sd':>11} {'95% (covariance)':>29} {'95% (profile)':>29}")
        for n in self.names:
            lo, hi = self.interval[n]
            p = self.profile_interval.get(n)
            ptext = f"[{p[0]:.6g}, {p[1]:.6g}]" if p else "-"
            bound = f"  on its {self.on_bound[n]} bound" if n in self.on_bound else ""
            lines.append(f"{n:<{w}} {self.value[n]:>13.7g} {self.sd[n]:>11.3g} {f'[{lo:.6g}, {hi:.6g}]':>29} "
                         f"{ptext:>29}{bound}")
        lines.append(f"{'series':<30} {'observable':<14} {'points':>6} {'residual norm':>14} {'rms':>11} "
                     f"{'noise':>11}")
        for s in self.series:
            lines.append(f"{os.path.basename(s['name']):<30} {s['observable']:<14} {s['n']:>6} "
                         f"{s['residual_norm']:>14.4g} {s['rms']:>11.4g} {s['noise']:>11.4g}"
                         + (" (given)" if s["sigma_given"] else " (estimated)"))
        lines += [f"warning: {w}" for w in self.warnings]
        return "\n".join(lines)

    def __repr__(self):
        parts = ", ".join(f"{n} = {self.value[n]:.6g} [{self.interval[n][0]:.4g}, {self.interval[n][1]:.4g}]"
                          for n in self.names)
        return f"<FitResult {parts}>"

    def write(self, directory, figures=True):
        """Writes the files of ``chainsim fit --out``.

        Parameters
        ----------
        directory : str or os.PathLike
            Where: fit.json (last: its presence means the set is complete), fit_table.txt, fit_series.csv (data,
            model and residuals).
        figures : bool, optional
            Also fit.png and profile.png (default True).

        Returns
        -------
        list of str
            The paths written.
        """
        os.makedirs(directory, exist_ok=True)
        written = []
        rows = ["series,observable,t,data,model,residual,sigma"]
        for s in self.series:
            for t, y, m, sig in zip(s["t"], s["data"], s["model"], s["sigma"]):
                rows.append(f"{json.dumps(s['name'])},{s['observable']},{t!r},{y!r},{m!r},{m - y!r},{sig!r}")
        written.append(_write_text(os.path.join(directory, "fit_series.csv"), "\n".join(rows) + "\n"))
        written.append(_write_text(os.path.join(directory, "fit_table.txt"), self.table() + "\n"))
        if figures:
            written += plot_fit(self, directory)
        written.append(_write_text(os.path.join(directory, "fit.json"), json.dumps(self.to_dict(), indent=1) + "\n"))
        return written


def _jsonable(value):
    if isinstance(value, dict):
        return {str(k): _jsonable(v) for k, v in value.items()}
    if isinstance(value, (list, tuple)):
        return [_jsonable(v) for v in value]
    if isinstance(value, np.ndarray):
        return _jsonable(value.tolist())
    if isinstance(value, (np.floating, float)):
        return float(value) if math.isfinite(value) else None
    if isinstance(value, np.integer):
        return int(value)
    return value


def _write_text(path, text):
    """Writes a file atomically: a hidden temporary file beside it, renamed over it when complete."""
    folder, name = os.path.split(path)
    tmp = os.path.join(folder, f".{name}.tmp")
    with open(tmp, "w") as handle:
        handle.write(text)
    os.replace(tmp, path)
    return path


def _least_squares(problem, x0, diff_step, max_nfev, free_mask=None):
    """Bounded least squares on the free entries of x (free_mask: the others stay at x0)."""
    from scipy.optimize import least_squares
    mask = np.ones(len(x0), bool) if free_mask is None else free_mask

    def full(z):
        x = x0.copy()
        x[mask] = z
        return x

    result = least_squares(lambda z: problem.residuals(full(z)), x0[mask],
                           jac=lambda z: problem.jacobian(full(z), diff_step)[:, mask],
                           bounds=(problem.lo[mask], problem.hi[mask]), method="trf", x_scale="jac",
                           xtol=1e-8, ftol=1e-10, gtol=1e-8, max_nfev=max_nfev)
    return result, full(result.x)


def _profile_chi2(problem, x_best, j, value, diff_step, max_nfev):
    """chi2 with parameter j held at value and the others refitted (warm start at the best fit)."""
    x = x_best.copy()
    x[j] = value
    if len(x) == 1:
        r = problem.residuals(x)
        return float(r @ r), x
    mask = np.ones(len(x), bool)
    mask[j] = False
    result, x = _least_squares(problem, x, diff_step, max_nfev, mask)
    return float(2 * result.cost), x


def _profile_bound(problem, x_best, j, chi2_min, s2, sd, direction, diff_step, max_nfev):
    """Where the profile's delta chi2 / s2 crosses CHI2_95 on one side, or the bound if it does not."""
    from scipy.optimize import brentq
    f0 = x_best[j]
    limit = problem.hi[j] if direction > 0 else problem.lo[j]

    def g(v):
        with np.errstate(over="ignore"):   # data without noise: s2 is the smallest double
            return (_profile_chi2(problem, x_best, j, v, diff_step, max_nfev)[0] - chi2_min) / s2 - CHI2_95

    step = 2.0 * sd if sd > 0 and math.isfinite(sd) else 0.1 * max(abs(f0), 1.0)
    inner, outer = f0, f0 + direction * step
    for _ in range(40):
        if (outer - limit) * direction >= 0:
            outer = limit
            if g(outer) < 0:
                return float(limit), True
            break
        if g(outer) > 0:
            break
        inner, outer = outer, f0 + direction * (abs(outer - f0) * 2)
    else:
        raise _error(f"the profile of {problem.names[j]} does not reach the 95% level within "
                     f"{abs(outer - f0):.3g} of the best value: the data do not determine it")
    a, b = sorted((inner, outer))
    return float(brentq(g, a, b, xtol=1e-3 * max(sd, 1e-12), rtol=1e-10)), False


def fit(target, data, free=None, *, bounds=None, per_run=(), fixed=None, profile="f", profile_points=21,
        absolute_sigma=False, workers=None, client=None, diff_step=1e-4, max_nfev=200):
    """Fits parameters of a chainsim model to measured series (weighted nonlinear least squares, docs/fit.md).

    Parameters
    ----------
    target : str, Scene or os.PathLike
        A canonical problem ("falling", "folded", "sliding": the reduced ODE), a Scene, or a scene file's path (a
        scene with model = "reduced" runs the reduced ODE, any other the string solver).
    data : Data, str, os.PathLike or list of them
        A Data, a CSV file's path, or a list of them (joint fit: the shared parameters are fitted to all).
    free : dict, optional
        {name: start} or {name: (start, lower, upper)}: f, the reduced model's keywords (eta0, eps, force, length,
        density, gravity) or the scene's dotted keys, and t_offset (the release time on the data's clock).
        Default {"f": 0.5}. f is bounded to [0, 1] (a pot's f to [-1/2, 1]), eta0 to [0, 1].
    bounds : dict, optional
        {name: (lower, upper)} for parameters given by their start value only.
    per_run : sequence of str, optional
        Names of free parameters fitted once per run label (e.g. t_offset of each drop).
    fixed : dict, optional
        {name: value} set for every run (reduced keywords or scene keys).
    profile : str or None, optional
        The parameter whose profile likelihood is computed (None: none); default f when it is free.
    profile_points : int, optional
        Points of the profile drawn in the figure (0: only the interval's ends are found).
    absolute_sigma : bool, optional
        True: the given sigmas are the data's true standard deviations (no scaling by chi2/(N-p)).
    workers : int, optional
        Local threads for the model runs of the finite differences.
    client : dask.distributed.Client, optional
        Runs the model runs as Dask tasks instead.
    diff_step : float, optional
        Relative step of the central differences.
    max_nfev : int, optional
        Most iterations of the optimizer: a fit that needs more raises ChainsimInputError.

    Returns
    -------
    FitResult
    """
    from . import Scene
    start = time.perf_counter()
    if isinstance(target, (str, os.PathLike)) and os.fspath(target) not in PROBLEMS:
        target = Scene.from_file(target)
    if not isinstance(target, (str, Scene)):
        raise _error(f"fit() fits a Scene, a scene file or a problem ({', '.join(PROBLEMS)}), not {target!r}")
    data = [data] if isinstance(data, (Data, str, os.PathLike)) else list(data)
    data = [Data.from_csv(d) if isinstance(d, (str, os.PathLike)) else d for d in data]
    if not all(isinstance(d, Data) for d in data):
        raise _error(f"fit() fits chainsim.Data series or CSV files' paths, not {data!r}")
    if not data:
        raise _error("fit() needs at least one data series")
    free = {"f": 0.5} if free is None else dict(free)
    if not free:
        raise _error("fit() needs at least one free parameter")
    problem = _Problem(target, data, free, bounds, per_run, fixed, workers, client)
    n_points, n_par = sum(len(d.values) for d in data), len(problem.names)
    if n_points <= n_par:
        raise _error(f"{n_points} data points for {n_par} free parameters ({', '.join(problem.names)}): too few "
                     f"(allowed: more points than parameters)")
    # The observables are checked at the start values, before the fit; a message names the file that asks.
    try:
        problem.predictions([problem.x0])
    except ChainsimInputError as e:
        asking = [d for d in data if str(e).startswith(f"observable '{d.observable}'")]
        if not asking:
            raise
        d = asking[0]
        where = f"{d.name}:{d.header_line}" if d.header_line is not None else d.name
        raise _error(f"{where}: column {d.columns['value']}: {e}") from None
    warnings = []
    # Weights: the given sigmas; series without them are first weighted by their spread, then by the noise
    # estimated from that fit's residuals (so that series in different units count by their noise).
    for k, d in enumerate(data):
        problem.scale[k] = d.sigma if d.sigma is not None else np.full(len(d.values), max(np.std(d.values), 1e-300))
    result, x = _least_squares(problem, problem.x0, diff_step, max_nfev)
    if result.status == 0:
        raise _error(f"the fit did not converge in {max_nfev} evaluations (last: {problem.describe(x)}): check the "
                     f"start values, the bounds and the observable, or raise max_nfev (--max-nfev)")
    estimated = [k for k, d in enumerate(data) if d.sigma is None]
    raw = problem.raw_residuals(x)
    if estimated:
        for k in estimated:
            share = n_par * len(data[k].values) / n_points
            noise = math.sqrt(float(raw[k] @ raw[k]) / max(len(data[k].values) - share, 1.0))
            # data without noise (the model's own values): a floor at the round-off of the values
            floor = 1e-15 * max(float(np.abs(data[k].values).max()), 1e-300)
            problem.scale[k] = np.full(len(data[k].values), max(noise, floor))
        if len(data) > 1:
            result, x = _least_squares(problem, x, diff_step, max_nfev)
            raw = problem.raw_residuals(x)
    r = problem.residuals(x)
    chi2 = float(r @ r)
    dof = n_points - n_par
    s2 = 1.0 if absolute_sigma else max(chi2 / dof, np.finfo(float).tiny)   # > 0 for data without noise
    J = problem.jacobian(x, diff_step)
    on_bound = {}
    span = problem.hi - problem.lo
    for j, n in enumerate(problem.names):
        tol = 1e-6 * (span[j] if math.isfinite(span[j]) else max(abs(x[j]), 1.0))
        if x[j] - problem.lo[j] <= tol:
            on_bound[n] = "lower"
        elif problem.hi[j] - x[j] <= tol:
            on_bound[n] = "upper"
    if on_bound:
        warnings.append(", ".join(f"{n} is on its {b} bound ({x[problem.names.index(n)]:.6g})"
                                  for n, b in on_bound.items())
                        + ": the covariance interval there is not a confidence interval; the profile's is one-sided")
    JtJ = J.T @ J
    try:
        cov = np.linalg.inv(JtJ) * s2
    except np.linalg.LinAlgError:
        cov = np.linalg.pinv(JtJ) * s2
        warnings.append("the Jacobian is singular: some parameters are not determined by the data")
    sd = np.sqrt(np.maximum(np.diag(cov), 0.0))
    with np.errstate(invalid="ignore", divide="ignore"):
        corr = cov / np.outer(sd, sd)
    interval = {n: (float(x[j] - Z_95 * sd[j]), float(x[j] + Z_95 * sd[j])) for j, n in enumerate(problem.names)}
    # The profile likelihood of one parameter.
    profile_interval, profile_curve = {}, None
    if profile is not None and profile in problem.names:
        j = problem.names.index(profile)
        lo, lo_hit = _profile_bound(problem, x, j, chi2, s2, sd[j], -1, diff_step, max_nfev)
        hi, hi_hit = _profile_bound(problem, x, j, chi2, s2, sd[j], +1, diff_step, max_nfev)
        profile_interval[profile] = (lo, hi)
        if lo_hit or hi_hit:
            warnings.append(f"the 95% profile interval of {profile} reaches its "
                            f"{'lower' if lo_hit else 'upper'} bound: it is one-sided there")
        if profile_points:
            width = max(hi - lo, 1e-12)
            values = np.linspace(max(lo - 0.4 * width, problem.lo[j]), min(hi + 0.4 * width, problem.hi[j]),
                                 profile_points)
            values = np.union1d(values, [x[j]])
            chis = _map_profile(problem, x, j, values, diff_step, max_nfev)
            with np.errstate(over="ignore"):
                delta = (np.array(chis) - chi2) / s2
            profile_curve = {"parameter": profile, "values": values, "delta_chi2": delta}
    elif profile is not None and profile != "f":
        raise _error(f"profile = '{profile}' is not a free parameter (free: {', '.join(problem.names)})")
    # The series at the best fit, and the points past the model's end (held at its final state there).
    pred = problem.predictions([x])[0]
    ends = {}
    for rr in range(len(problem.runs)):
        ends[rr] = iter(_predict(problem.task(x, rr), with_span=True)[1])
    for d, rr in zip(data, problem.run_of):
        end = next(ends[rr])
        late = int(np.sum(d.t > end)) if end is not None else 0
        if late:
            warnings.append(f"{d.name}: {late} points after the model's end at t = {end:.6g} s (its stop, on the "
                            f"data's clock): the model is held at its final state there; cut the data at the stop "
                            f"(the landing) unless the observable stays put")
    series, counters = [], {}
    for k, (d, rr) in enumerate(zip(data, problem.run_of)):
        j = counters.get(rr, 0)
        counters[rr] = j + 1
        res = pred[rr][j] - d.values
        n = len(d.values)
        share = n_par * n / n_points
        series.append({"name": d.name, "observable": d.observable, "run": problem.runs[rr], "n": n,
                       "residual_norm": float(np.linalg.norm(res)), "rms": float(np.sqrt(np.mean(res**2))),
                       "noise": float(np.sqrt(res @ res / max(n - share, 1.0))) if d.sigma is None
                       else float(np.sqrt(np.mean(d.sigma**2))),
                       "sigma_given": d.sigma is not None, "settings": d.settings,
                       "t": d.t, "data": d.values, "model": pred[rr][j], "sigma": problem.scale[k]})
    return FitResult(
        target=target if isinstance(target, str) else target.source, names=list(problem.names),
        value={n: float(v) for n, v in zip(problem.names, x)}, sd={n: float(v) for n, v in zip(problem.names, sd)},
        interval=interval, profile_interval=profile_interval, profile_parameter=profile if profile_interval else None,
        profile=profile_curve, on_bound=on_bound, covariance=cov, correlation=corr, chi2=chi2, dof=dof,
        points=n_points, s2=s2, absolute_sigma=absolute_sigma, series=series, threshold=CHI2_95,
        optimizer={"method": "scipy.optimize.least_squares (trf)", "status": int(result.status),
                   "message": result.message, "nfev": int(result.nfev), "njev": int(result.njev or 0)},
        evaluations=problem.evaluations, wall_s=time.perf_counter() - start, warnings=warnings,
        _problem=problem, x=x)


def _map_profile(problem, x_best, j, values, diff_step, max_nfev):
    """The profile at several values (each an independent refit; on threads when there is one parameter only, the
    model runs of each refit being parallel already otherwise)."""
    if len(x_best) == 1:
        xs = []
        for v in values:
            x = x_best.copy()
            x[j] = v
            xs.append(x)
        preds = problem.predictions(xs)
        return [float(problem.residuals_from(p) @ problem.residuals_from(p)) for p in preds]
    return [_profile_chi2(problem, x_best, j, v, diff_step, max_nfev)[0] for v in values]


# ----------------------------------------------------------------------------------------------------------------
# Figures

def plot_fit(fit_result, directory):
    """fit.png (each series: data and fitted model over time, residuals below) and profile.png (the profile of the
    profiled parameter with both 95% intervals); returns the paths."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    paths = []
    series = fit_result.series
    problem = fit_result._problem
    cols = len(series)
    fig, axes = plt.subplots(2, cols, figsize=(5.2 * cols, 5.6), sharex="col", squeeze=False,
                             gridspec_kw={"height_ratios": [2.2, 1]})
    counters = {}
    for k, s in enumerate(series):
        r = problem.run_of[k]
        ax, axr = axes[0, k], axes[1, k]
        t = np.asarray(s["t"])
        if s["observable"] == "t_stop":
            idx = np.arange(len(t))
            ax.errorbar(idx, s["data"], yerr=s["sigma"], fmt="o", ms=3, label="data")
            ax.axhline(s["model"][0], color="k", label="fitted model")
            axr.plot(idx, np.asarray(s["data"]) - s["model"], "o", ms=3)
            axr.set_xlabel("measurement")
        else:
            dense = np.linspace(t[0], t[-1], 600)
            settings, t_offset = problem.settings(fit_result.x, r)
            model = _predict((problem.target, settings, t_offset, [(s["observable"], dense)]))[0]
            ax.plot(t, s["data"], "o", ms=2.5, mfc="none", color="tab:blue", label="data")
            ax.plot(dense, model, "-", color="k", lw=1.2, label="fitted model")
            axr.plot(t, np.asarray(s["data"]) - s["model"], "o", ms=2.5, color="tab:blue")
            noise = float(np.mean(s["sigma"]))
            for sign in (-1, 1):
                axr.axhline(sign * noise, color="tab:gray", lw=0.8, ls="--", label="noise" if sign > 0 else None)
            axr.set_xlabel("t (s)")
            if "t_offset" in problem.base and t[0] <= t_offset <= t[-1]:
                ax.axvline(t_offset, color="tab:gray", lw=0.8, ls=":", label=f"release, t = {t_offset:.4g} s")
        counters[r] = counters.get(r, 0) + 1
        unit = "m" if s["observable"].startswith("node[") else UNITS.get(s["observable"], "")
        unit = f" ({unit})" if unit else ""
        ax.set_ylabel(s["observable"] + unit)
        axr.set_ylabel("data - model" + unit)
        axr.axhline(0, color="k", lw=0.8)
        ax.set_title(f"{os.path.basename(s['name'])}: {s['n']} points", fontsize=9)
        ax.legend(fontsize=8)
        for a in (ax, axr):
            a.grid(alpha=0.3)
    text = ", ".join(f"{n} = {fit_result.value[n]:.4g} ± {Z_95 * fit_result.sd[n]:.2g}" for n in fit_result.names)
    fig.suptitle(f"fit: {text} (95%)", fontsize=10)
    fig.tight_layout()
    paths.append(_save(fig, directory, "fit.png"))
    if fit_result.profile:
        p = fit_result.profile
        name = p["parameter"]
        fig, ax = plt.subplots(figsize=(5.5, 4))
        ax.plot(p["values"], p["delta_chi2"], "o-", ms=3, color="k", label=r"profile $\Delta\chi^2/s^2$")
        ax.axhline(CHI2_95, color="tab:red", lw=1, ls="--", label="95% level (3.84)")
        v, (lo, hi), (clo, chi) = fit_result.value[name], fit_result.profile_interval[name], fit_result.interval[name]
        ax.axvspan(lo, hi, color="tab:red", alpha=0.12, label=f"profile 95%: [{lo:.5g}, {hi:.5g}]")
        values = np.asarray(p["values"])
        ax.plot(values, ((values - v) / fit_result.sd[name]) ** 2, color="tab:blue", lw=1, ls=":",
                label=f"covariance (quadratic): [{clo:.5g}, {chi:.5g}]")
        ax.axvline(v, color="k", lw=0.8)
        ax.set_ylim(0, max(2 * CHI2_95, float(np.max(p["delta_chi2"])) * 1.05))
        ax.set_xlabel(name)
        ax.set_ylabel(r"$\Delta\chi^2 / s^2$")
        ax.set_title(f"profile of {name}: {v:.5g}", fontsize=10)
        ax.legend(fontsize=8)
        ax.grid(alpha=0.3)
        fig.tight_layout()
        paths.append(_save(fig, directory, "profile.png"))
    return paths


def _save(fig, directory, name):
    import matplotlib.pyplot as plt
    path = os.path.join(directory, name)
    tmp = os.path.join(directory, f".{name}.tmp.png")
    fig.savefig(tmp, dpi=110)
    plt.close(fig)
    os.replace(tmp, path)
    return path


# ----------------------------------------------------------------------------------------------------------------
# The command line: `chainsim fit` runs `python3 -m chainsim fit` (chainsim/__main__.py), which calls main()

def _parse_value(text):
    try:
        return json.loads(text)
    except ValueError:
        return text


def _parser():
    import argparse

    class Parser(argparse.ArgumentParser):
        def error(self, message):
            sys.stderr.write(f"chainsim: error: fit: {message} (see 'chainsim fit --help')\n")
            if "--json" in sys.argv[1:]:
                print(json.dumps({"status": "failed", "error": message, "exit_code": 2, "command": "fit"}))
            sys.exit(2)

    p = Parser(prog="chainsim fit", description="Fit f (and other scene keys) to measured series given as CSV: "
               "weighted least squares with bounds, 95% intervals from the covariance and the profile of f; "
               "docs/fit.md.")
    p.add_argument("target", help="falling | folded | sliding (the reduced ODE) or a scene file (.toml)")
    p.add_argument("data", nargs="+", help="CSV files: a header row, a time column and an observable column "
                   "[, sigma]; FILE@KEY=VALUE@... sets keys for that file's run (a drop from another height: "
                   "drop2.csv@eta0=0.8); FILE@run=NAME puts files of one drop in one run")
    p.add_argument("--observable", help="the column of values and the model output it is (default: the only column "
                   "that is not the time or sigma)")
    p.add_argument("--column", help="the CSV column of the values (default: the observable's name)")
    p.add_argument("--time-column", default="t", help="the time column (s) (default t)")
    p.add_argument("--sigma", help="the data's standard deviation (a number), or the name of a column of them "
                   "(default: the column sigma if present, else estimated from the residuals)")
    p.add_argument("--free", action="append", default=[], metavar="NAME=START[:LOWER:UPPER]",
                   help="a free parameter and its start value (default f=0.5); bounds default to the allowed range "
                   "(f, eta0 in [0, 1]; a pot's f in [-0.5, 1]), else unbounded")
    p.add_argument("--per-run", action="append", default=[], metavar="NAME",
                   help="fit this free parameter once per data file (e.g. t_offset of each drop)")
    p.add_argument("--set", action="append", default=[], metavar="KEY=VALUE", help="a fixed key for every run")
    p.add_argument("--profile", default="f", help="the parameter to profile (default f; 'none' for none)")
    p.add_argument("--absolute-sigma", action="store_true", help="the given sigmas are the true standard deviations")
    p.add_argument("--jobs", type=int, default=0, help="threads for the model runs (default: every core)")
    p.add_argument("--max-nfev", type=int, default=200, help="most iterations of the optimizer (default 200)")
    p.add_argument("--out", default="results/fit", help="output directory (default results/fit)")
    p.add_argument("--no-figures", action="store_true", help="write no figures")
    p.add_argument("--json", action="store_true", help="print the result as one JSON object")
    return p


def _parse_free(texts):
    free = {}
    for text in texts or ["f=0.5"]:
        name, eq, rest = text.partition("=")
        parts = rest.split(":")
        try:
            if not eq or not name or len(parts) not in (1, 3):
                raise ValueError
            values = tuple(float(v) for v in parts)
        except ValueError:
            raise _error(f"--free {text}: allowed NAME=START or NAME=START:LOWER:UPPER (numbers)")
        free[name.strip()] = values[0] if len(values) == 1 else values
    return free


def main(argv=None):
    args = _parser().parse_args(argv)
    try:
        fixed = {}
        for text in args.set:
            key, eq, value = text.partition("=")
            if not eq:
                raise _error(f"--set {text}: allowed KEY=VALUE")
            fixed[key.strip()] = _parse_value(value.strip())
        if args.jobs < 0:
            raise _error(f"--jobs = {args.jobs} is out of range: allowed jobs >= 0 (0: every core)")
        if args.max_nfev < 1:
            raise _error(f"--max-nfev = {args.max_nfev} is out of range: allowed max-nfev >= 1")
        sigma = None
        if args.sigma is not None:
            try:
                sigma = float(args.sigma)
            except ValueError:
                sigma = args.sigma
            if isinstance(sigma, float) and not (sigma > 0 and math.isfinite(sigma)):
                raise _error(f"--sigma = {args.sigma} is out of range: allowed sigma > 0, or a column name")
        data = []
        for k, item in enumerate(args.data):
            path, *keys = item.split("@")
            settings, run = {}, None
            for kv in keys:
                key, eq, value = kv.partition("=")
                if not eq:
                    raise _error(f"{item}: '{kv}' is not KEY=VALUE (allowed FILE@KEY=VALUE@...)")
                if key == "run":
                    run = value
                else:
                    settings[key] = _parse_value(value)
            data.append(Data.from_csv(path, observable=args.observable, time=args.time_column, sigma=sigma,
                                      settings=settings, run=run, column=args.column))
        result = fit(args.target, data, _parse_free(args.free), per_run=args.per_run, fixed=fixed,
                     profile=None if args.profile == "none" else args.profile, absolute_sigma=args.absolute_sigma,
                     workers=args.jobs or None, max_nfev=args.max_nfev)
        paths = result.write(args.out, figures=not args.no_figures)
    except ImportError as e:
        sys.stderr.write(f"chainsim: error: fit needs SciPy and matplotlib ({e}): install the Debian packages "
                         f"python3-scipy python3-matplotlib, or run with /usr/bin/python3\n")
        return 1
    except (ChainsimInputError, NumericalError) as e:
        code = 3 if isinstance(e, NumericalError) else 2
        if args.json:   # as every chainsim command prints a failure with --json
            print(json.dumps({"status": "failed", "error": str(e), "exit_code": code, "command": "fit"}))
        sys.stderr.write(f"chainsim: {'numerical failure' if code == 3 else 'error'}: {e}\n")
        return code
    if args.json:
        print(json.dumps(result.to_dict()))
    else:
        print(result.table())
        print("outputs    " + " ".join(paths))
    return 0

