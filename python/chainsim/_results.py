"""The results of chainsim runs as ordinary Python objects (docs/python.md): `Result` (a run of a scene on the
string solver, from `Scene.run()`, `read_run()` or a sweep with ``results=True``), `ReducedResult` and
`Comparison` (from `chainsim.compare()`, or `read_run()` of a directory of `chainsim compare`). They hold numpy
arrays and dicts only, so they pickle (Dask sends them between processes), and they export to pandas, xarray and
netCDF. A `Result` made by `Scene.run()` also keeps the C++ run, for `write()`: that part is left behind when it
is pickled.
"""
from __future__ import annotations

import html
import json
import os
from typing import TYPE_CHECKING, Any, Dict, List, Optional, Sequence, Union

import numpy as np

from . import _core
from ._core import ChainsimInputError

if TYPE_CHECKING:  # pragma: no cover
    from matplotlib.figure import Figure
    from pandas import DataFrame
    from xarray import Dataset
else:  # imported where used (pandas and xarray take longer to import than chainsim): these names label the hints
    DataFrame = Dataset = Figure = Any

Arrays = Dict[str, np.ndarray]
PathLike = Union[str, "os.PathLike[str]"]

#: Units of the arrays by name (SI): the attrs of `Result.to_xarray()`.
UNITS = {"t": "s", "s": "m", "s_mid": "m", "x": "m", "y": "m", "z": "m", "vx": "m/s", "vy": "m/s", "vz": "m/s",
         "T": "N", "K": "J", "V": "J", "W_applied": "J", "W_shocks": "J", "W_heaps": "J", "W_remesh": "J",
         "drift": "J", "energy_residual": "J", "s0": "m", "s0_dot": "m/s", "position": "m", "reaction": "N",
         "momentum_residual": "N s"}


def _unit(name: str) -> Optional[str]:
    """The unit of a column by its name (series and forces columns by their prefixes), None if unknown."""
    if name in UNITS:
        return UNITS[name]
    for prefix, unit in (("s0dot_", "m/s"), ("s0_", "m"), ("front_", "m"), ("R_", "N"), ("T_", "N"),
                         ("support_", "N"), ("F_", "N")):
        if name.startswith(prefix):
            return unit
    return None


def _html_table(rows: Sequence[tuple]) -> str:
    cells = "".join(f"<tr><th style='text-align:left'>{html.escape(str(k))}</th>"
                    f"<td style='text-align:left'>{html.escape(str(v))}</td></tr>" for k, v in rows)
    return f"<table>{cells}</table>"


class Result:
    """A run of a scene on the string solver: what `chainsim run` records, as numpy arrays.

    Made by `Scene.run()`, read from a run directory by `chainsim.read_run()`, or returned for each point of
    ``chainsim.sweep(..., results=True)``. The arrays are named as the columns of the CSV files of
    `chainsim run` (docs/string_solver.md), with the frame index first.

    Parameters
    ----------
    run : chainsim._core.Run, optional
        The C++ run (`Scene.run()` passes it); the arrays and the summary are copied from it.
    summary : dict, optional
        stats.json as a dict (when `run` is not given).
    nodes, tension, energy, forces, fronts, series : dict of numpy.ndarray, optional
        The arrays (when `run` is not given): see Attributes.
    kind : {"string", "fronts"}, optional
        A run without or with fronts (default: from `fronts`).
    path : str, optional
        The run directory it was read from, if any.
    _arrays : dict, optional
        ``run.arrays()`` when the caller has them already (internal: the frames are copied once).

    Attributes
    ----------
    nodes : dict of numpy.ndarray
        ``t`` (F,), ``node``, ``s`` (N,), ``x``, ``y`` [, ``z``], ``vx``, ``vy`` [, ``vz``] (F, N), ``moving``
        (F, N): nodes.csv, NaN where a node is in a heap (not moving).
    tension : dict of numpy.ndarray
        ``t`` (F,), ``link``, ``s_mid`` (L,), ``T`` (F, L): tension.csv, NaN for a link in no arc.
    energy : dict of numpy.ndarray
        ``t``, ``K``, ``V``, ``W_applied``, ``drift`` [, ``W_shocks``, ``W_heaps``, ``W_remesh``] (F,): energy.csv.
    forces : dict of numpy.ndarray
        ``t`` and the measured forces (F,): forces.csv.
    series : dict of numpy.ndarray
        One entry per accepted step (runs with fronts): series.csv.
    fronts : dict of numpy.ndarray
        ``t`` (F,), ``s0``, ``s0_dot`` (F, fronts), ``position``, ``reaction`` (F, fronts, dim): the fronts at the
        frames (empty for a run read from a directory: its series has them at every step).
    summary : dict
        stats.json (also `stats`).
    kind : str
        ``"string"`` or ``"fronts"`` (a run with heaps or a fold).
    path : str or None
        The directory it was read from (`read_run`), else None.
    """

    def __init__(self, run: Optional[_core.Run] = None, *, summary: Optional[Dict[str, Any]] = None,
                 nodes: Optional[Arrays] = None, tension: Optional[Arrays] = None, energy: Optional[Arrays] = None,
                 forces: Optional[Arrays] = None, fronts: Optional[Arrays] = None, series: Optional[Arrays] = None,
                 kind: Optional[str] = None, path: Optional[str] = None,
                 _arrays: Optional[Dict[str, Arrays]] = None) -> None:
        self._run = run
        if run is not None:
            summary = json.loads(run.summary())
            arrays = run.arrays() if _arrays is None else _arrays  # result_of_run has them already
            nodes, tension, energy = arrays.get("nodes"), arrays.get("tension"), arrays.get("energy")
            forces, fronts, series = arrays.get("forces"), arrays.get("fronts"), arrays.get("series")
        self.summary: Dict[str, Any] = summary or {}
        self.nodes: Arrays = dict(nodes or {})
        self.tension: Arrays = dict(tension or {})
        self.energy: Arrays = dict(energy or {})
        self.forces: Arrays = dict(forces or {})
        self.fronts: Arrays = dict(fronts or {})
        self.series: Arrays = dict(series or {})
        self.path = path
        if kind is None:
            s0 = self.fronts.get("s0")
            kind = "fronts" if (s0 is not None and s0.ndim == 2 and s0.shape[1] > 0) or "s0_0" in self.series \
                else "string"
        self.kind: str = kind

    # --- pickling: the arrays and the summary; the C++ run stays behind ---------------------------------------
    def __getstate__(self) -> Dict[str, Any]:
        state = dict(self.__dict__)
        state["_run"] = None
        return state

    def __setstate__(self, state: Dict[str, Any]) -> None:
        self.__dict__.update(state)

    # --- shortcuts --------------------------------------------------------------------------------------------
    @property
    def stats(self) -> Dict[str, Any]:
        """stats.json as a dict (the same object as `summary`)."""
        return self.summary

    @property
    def status(self) -> str:
        """``summary["status"]``: completed, stopped, failed or interrupted."""
        return str(self.summary.get("status", "completed"))

    @property
    def name(self) -> str:
        """The run directory's name (`read_run`), else ``"result"``: the title of its figures."""
        return os.path.basename(os.path.normpath(self.path)) if self.path else "result"

    @property
    def t(self) -> np.ndarray:
        """The frame times (s), shape (F,)."""
        return self.nodes["t"] if "t" in self.nodes else self.series["t"]

    def _stack(self, prefix: str) -> np.ndarray:
        axes = [a for a in ("x", "y", "z") if a in self.nodes]
        return np.stack([self.nodes[prefix + a] for a in axes], axis=-1)

    @property
    def positions(self) -> np.ndarray:
        """Node positions (m), shape (F, N, dim); NaN for a node in a heap."""
        return self._stack("")

    @property
    def velocities(self) -> np.ndarray:
        """Node velocities (m/s), shape (F, N, dim); NaN for a node in a heap."""
        return self._stack("v")

    # --- files ------------------------------------------------------------------------------------------------
    def write(self, directory: PathLike) -> PathLike:
        """Writes the run directory exactly as ``chainsim run --out DIR`` does (the same C++ writer).

        Parameters
        ----------
        directory : str or os.PathLike
            The run directory; locked while it is written, and cleared first of what any chainsim command
            wrote there (never of other files).

        Returns
        -------
        str or os.PathLike
            `directory`.

        Raises
        ------
        ChainsimInputError
            The directory is held by another chainsim process, or this Result holds no C++ run (it was read
            from a directory, or unpickled: its arrays export with `to_netcdf`).
        """
        if self._run is None:
            origin = f"read from {self.path}" if self.path else "unpickled (or made from arrays)"
            raise ChainsimInputError(f"write(): this Result was {origin}: only the Result of Scene.run() (or of a "
                                     f"local sweep with results=True) writes a run directory; save its arrays with "
                                     f"to_netcdf(path)")
        self._run.write(os.fspath(directory))
        return directory

    def plot(self, directory: Optional[PathLike] = None, *, times: Optional[List[float]] = None,
             save: Optional[PathLike] = None, **options: Any) -> Any:
        """The figures of ``chainsim plot`` (snapshots, energy, tension, fronts), as matplotlib figures.

        Parameters
        ----------
        directory : str or os.PathLike, optional
            The older form, kept: writes the run directory there (`write`) and draws it into
            ``directory/figures/`` as ``chainsim plot DIR`` does, with `options` (``animate``, ``speed``,
            ``fps``, ``fmt``, ``html``) as for `chainsim.plot`; returns the paths written.
        times : list of float, optional
            Times (s) of the snapshots and tension profiles (default: 6 spread over the run).
        save : str or os.PathLike, optional
            Also write the figures as PNG files into this directory (nothing is written without it).
        **options
            With `directory` only: the options of `chainsim.plot`.

        Returns
        -------
        dict of str to matplotlib.figure.Figure
            The figures by name (``"snapshots"``, ``"energy"``, ``"tension"``, ``"fronts"``), closed to pyplot
            (display one in a notebook by making it a cell's value). With `directory`: the list of paths written.
        """
        from chainsim_plot.cli import draw

        if directory is not None:
            from . import plot
            self.write(directory)
            return plot(directory, times=times, **options)
        if options:
            raise ChainsimInputError(f"plot(): {', '.join(sorted(options))} apply to plot(directory, ...), which "
                                     f"writes the run directory and its figures")
        figures: Dict[str, Figure] = draw(self.reader_run(), None, times)
        if save is not None:
            os.makedirs(os.fspath(save), exist_ok=True)
            for name, fig in figures.items():
                fig.savefig(os.path.join(os.fspath(save), name + ".png"), dpi=110)
        return figures

    def reader_run(self) -> Any:
        """This run as the plotting tool's reader holds a run directory (chainsim_plot.readers.Run), in memory:
        the rows of nodes.csv and tension.csv, energy.csv and series.csv, with which its figures are drawn."""
        from chainsim_plot.readers import Frames, Run, Table, _fronts

        def table(name: str, columns: Arrays) -> Any:
            return Table(f"{self.name}/{name}", list(columns), columns)

        nodes = tension = None
        if "x" in self.nodes:
            moving = self.nodes["moving"]
            k, i = np.nonzero(moving)
            cols: Arrays = {"t": self.nodes["t"][k], "node": i.astype(float), "s": self.nodes["s"][i]}
            for a in ("x", "y", "z", "vx", "vy", "vz"):
                if a in self.nodes:
                    cols[a] = self.nodes[a][k, i]
            nodes = Frames(table("nodes.csv", cols))
        if "T" in self.tension:
            k, j = np.nonzero(np.isfinite(self.tension["T"]))
            tension = table("tension.csv", {"t": self.tension["t"][k], "link": j.astype(float),
                                            "s_mid": self.tension["s_mid"][j], "T": self.tension["T"][k, j]})
        energy = table("energy.csv", self.energy) if self.energy else None
        series = table("series.csv", self.series) if self.series else None
        fronts = _fronts(series, self.summary.get("fronts"))
        return Run(self.path or self.name, "fronts" if fronts else "string", [], self.summary, nodes=nodes,
                   energy=energy, series=series, tension=tension, fronts=fronts)

    @classmethod
    def from_reader_run(cls, run: Any) -> "Result":
        """A Result from a run directory read by the plotting tool's reader (`read_run` uses it).

        Parameters
        ----------
        run : chainsim_plot.readers.Run
            A run of `chainsim run` (kind ``"string"`` or ``"fronts"``).

        Returns
        -------
        Result
            Its arrays in the shapes of `Scene.run()`'s (a node absent from a frame of nodes.csv is NaN there).
        """
        from chainsim_plot.readers import read_table

        def columns(t: Any) -> Arrays:
            return {c: t[c] for c in t.columns} if t is not None else {}

        summary = dict(run.summary)
        nodes: Arrays = {}
        if run.nodes is not None:
            table = run.nodes.table
            t = run.nodes.times
            k = np.searchsorted(t, table["t"])
            i = table["node"].astype(int)
            n = max(int(summary.get("nodes", 0)), int(i.max()) + 1 if len(i) else 0)
            nodes["t"] = t
            nodes["node"] = np.arange(n)
            s = np.full(n, np.nan)
            if "s" in table:
                s[i] = table["s"]
            nodes["s"] = s
            for a in ("x", "y", "z", "vx", "vy", "vz"):
                if a in table:
                    nodes[a] = np.full((len(t), n), np.nan)
                    nodes[a][k, i] = table[a]
            moving = np.zeros((len(t), n), dtype=bool)
            moving[k, i] = True
            nodes["moving"] = moving
        tension: Arrays = {}
        if run.tension is not None:
            table = run.tension
            t = np.unique(table["t"]) if run.nodes is None else run.nodes.times
            k = np.searchsorted(t, table["t"])
            j = table["link"].astype(int)
            L = max(int(summary.get("links", 0)), int(j.max()) + 1 if len(j) else 0)
            tension = {"t": t, "link": np.arange(L), "s_mid": np.full(L, np.nan), "T": np.full((len(t), L), np.nan)}
            tension["s_mid"][j] = table["s_mid"]
            tension["T"][k, j] = table["T"]
        forces = read_table(os.path.join(run.path, "forces.csv"))
        return cls(summary=summary, nodes=nodes, tension=tension, energy=columns(run.energy),
                   forces=columns(forces), series=columns(run.series), kind=run.kind, path=run.path)

    # --- exports ----------------------------------------------------------------------------------------------
    def to_dataframe(self, table: str = "nodes") -> DataFrame:
        """One table of the run as a pandas DataFrame, in the layout of its CSV file.

        Parameters
        ----------
        table : {"nodes", "tension", "energy", "forces", "series", "fronts"}
            ``nodes``: one row per (t, node) with s, x, y[, z], vx, vy[, vz], moving (every node, NaN where not
            moving); ``tension``: one row per (t, link) with s_mid, T; ``fronts``: one row per (t, front) with s0,
            s0_dot, position_x, ..., reaction_x, ...; the others: one row per frame (per step for ``series``).

        Returns
        -------
        pandas.DataFrame
            Indexed by t (and node, link or front).
        """
        import pandas as pd

        if table == "nodes":
            f, n = self.nodes["moving"].shape
            index = pd.MultiIndex.from_product([self.nodes["t"], self.nodes["node"]], names=["t", "node"])
            data = {"s": np.tile(self.nodes["s"], f)}
            for name, value in self.nodes.items():
                if getattr(value, "ndim", 0) == 2:
                    data[name] = value.reshape(f * n)
            return pd.DataFrame(data, index=index)
        if table == "tension":
            f, n = self.tension["T"].shape
            index = pd.MultiIndex.from_product([self.tension["t"], self.tension["link"]], names=["t", "link"])
            return pd.DataFrame({"s_mid": np.tile(self.tension["s_mid"], f), "T": self.tension["T"].reshape(f * n)},
                                index=index)
        if table == "fronts":
            t = self.fronts.get("t", np.zeros(0))
            s0 = self.fronts.get("s0", np.zeros((len(t), 0)))
            f, q = s0.shape
            index = pd.MultiIndex.from_product([t, np.arange(q)], names=["t", "front"])
            data = {"s0": s0.reshape(f * q), "s0_dot": self.fronts["s0_dot"].reshape(f * q)} if q else {}
            for name in ("position", "reaction"):
                for d, a in enumerate("xyz"[:self.fronts[name].shape[2]] if q else ""):
                    data[f"{name}_{a}"] = self.fronts[name][:, :, d].reshape(f * q)
            return pd.DataFrame(data, index=index)
        columns = {"energy": self.energy, "forces": self.forces, "series": self.series}.get(table)
        if columns is None:
            raise ChainsimInputError(f"to_dataframe(): table = {table!r} is not a table of a run: allowed nodes, "
                                     f"tension, energy, forces, series, fronts")
        if not columns:
            return pd.DataFrame()
        return pd.DataFrame({k: v for k, v in columns.items() if k != "t"}, index=pd.Index(columns["t"], name="t"))

    def to_xarray(self) -> Dataset:
        """The run as an xarray Dataset (python3-xarray), with units in the attrs.

        Dimensions ``time`` (the frames), ``node``, ``link``, ``front``, ``axis`` (x, y[, z]) and ``step``
        (the accepted steps of `series`). Variables: the node arrays (time, node), ``T`` (time, link), the
        energy ledger and the forces (time), the fronts (time, front[, axis]), the series (step); coordinates
        ``time``, ``s`` (node), ``s_mid`` (link), ``t_step`` (step). Every variable with a known unit has
        ``attrs["units"]``; the summary is ``attrs["summary"]`` (JSON text, so that netCDF can hold it).

        Returns
        -------
        xarray.Dataset
        """
        import xarray as xr

        def attrs(name: str, description: str = "") -> Dict[str, str]:
            out = {}
            unit = _unit(name)
            if unit:
                out["units"] = unit
            if description:
                out["long_name"] = description
            return out

        data: Dict[str, Any] = {}
        coords: Dict[str, Any] = {}
        t = self.t if (self.nodes or self.series) else np.zeros(0)
        coords["time"] = ("time", np.asarray(self.nodes.get("t", self.energy.get("t", t))), attrs("t", "time"))
        if self.nodes:
            coords["node"] = ("node", self.nodes["node"].astype(np.int32))
            coords["s"] = ("node", self.nodes["s"], attrs("s", "material coordinate of the node"))
            for name, value in self.nodes.items():
                if getattr(value, "ndim", 0) == 2:
                    data[name] = (("time", "node"), value, attrs(name))
        if self.tension:
            coords["link"] = ("link", self.tension["link"].astype(np.int32))
            coords["s_mid"] = ("link", self.tension["s_mid"], attrs("s_mid", "material coordinate of the link's "
                                                                              "midpoint"))
            data["T"] = (("time", "link"), self.tension["T"], attrs("T", "tension"))
        for columns in (self.energy, self.forces):
            for name, value in columns.items():
                if name != "t":
                    data[name] = ("time", value, attrs(name))
        s0 = self.fronts.get("s0")
        if s0 is not None and s0.shape[1] > 0:
            data["s0"] = (("time", "front"), s0, attrs("s0", "material coordinate of the front"))
            data["s0_dot"] = (("time", "front"), self.fronts["s0_dot"], attrs("s0_dot"))
            dim = self.fronts["position"].shape[2]
            coords["axis"] = ("axis", ["x", "y", "z"][:dim])
            for name in ("position", "reaction"):
                data["front_" + name] = (("time", "front", "axis"), self.fronts[name], attrs(name))
        if self.series:
            coords["t_step"] = ("step", self.series["t"], attrs("t", "time of the accepted step"))
            for name, value in self.series.items():
                if name != "t":
                    data["series_" + name] = ("step", value, attrs(name))
        ds = xr.Dataset(data, coords=coords)
        ds.attrs["summary"] = json.dumps(self.summary)
        ds.attrs["kind"] = self.kind
        ds.attrs["status"] = self.status
        return ds

    def to_netcdf(self, path: PathLike, **options: Any) -> PathLike:
        """Writes `to_xarray()` to a netCDF file (xarray's writer: python3-netcdf4, else h5netcdf or SciPy).

        Parameters
        ----------
        path : str or os.PathLike
            The file.
        **options
            Passed to ``xarray.Dataset.to_netcdf`` (``engine``, ``format``, ...).

        Returns
        -------
        str or os.PathLike
            `path`.
        """
        self.to_xarray().to_netcdf(os.fspath(path), **options)
        return path

    # --- display ----------------------------------------------------------------------------------------------
    def _headline(self) -> List[tuple]:
        s = self.summary
        rows = [("status", s.get("status")), ("t_stop (s)", s.get("t_stop")), ("frames", s.get("frames")),
                ("nodes", s.get("nodes")), ("energy drift (J)", s.get("energy_drift")),
                ("max constraint violation", s.get("max_constraint_violation")), ("stop reason", s.get("stop_reason"))]
        if self.path:
            rows.append(("read from", self.path))
        return [(k, v) for k, v in rows if v is not None]

    def _repr_html_(self) -> str:
        arrays = ", ".join(f"{name} ({', '.join(k for k in table)})" for name, table in
                           (("nodes", self.nodes), ("tension", self.tension), ("energy", self.energy),
                            ("forces", self.forces), ("series", self.series), ("fronts", self.fronts)) if table)
        return (f"<div><strong>chainsim.Result</strong> ({html.escape(self.kind)} run)"
                f"{_html_table(self._headline())}<p style='font-size:smaller'>arrays: {html.escape(arrays)}</p></div>")

    def __repr__(self) -> str:
        s = self.summary
        return f"<Result {s.get('status')} t_stop={s.get('t_stop')} frames={s.get('frames')} nodes={s.get('nodes')}>"


class ReducedResult:
    """A run of a reduced ODE (`chainsim.reduced`, a scene with ``model = "reduced"``, or `read_run` of a
    directory of `chainsim reduced`).

    Parameters
    ----------
    series : dict of numpy.ndarray
        The columns of series.csv (``t``, ``eta``, ``P``, ...).
    summary : dict
        summary.json (docs/reduced.md).
    path : str, optional
        The directory it was read from, if any.

    Attributes
    ----------
    series, summary, path
        As given; `kind` is ``"reduced"``.
    """

    kind = "reduced"

    def __init__(self, series: Arrays, summary: Dict[str, Any], path: Optional[str] = None) -> None:
        self.series = dict(series)
        self.summary = summary
        self.path = path

    def to_dataframe(self) -> DataFrame:
        """The series as a pandas DataFrame indexed by t.

        Returns
        -------
        pandas.DataFrame
        """
        import pandas as pd
        return pd.DataFrame({k: v for k, v in self.series.items() if k != "t"},
                            index=pd.Index(self.series["t"], name="t"))

    def to_xarray(self) -> Dataset:
        """The series as an xarray Dataset on the dimension ``time`` (t in s), the summary as JSON text in
        ``attrs["summary"]``.

        Returns
        -------
        xarray.Dataset
        """
        import xarray as xr
        ds = xr.Dataset({k: ("time", v) for k, v in self.series.items() if k != "t"},
                        coords={"time": ("time", self.series["t"], {"units": "s"})})
        ds.attrs["summary"] = json.dumps(self.summary)
        return ds

    def _repr_html_(self) -> str:
        s = self.summary
        rows = [(k, s.get(k)) for k in ("problem", "t_stop", "t_stop_over_t0", "t_stop_over_t0_exact") if k in s]
        return f"<div><strong>chainsim.ReducedResult</strong>{_html_table(rows)}</div>"

    def __repr__(self) -> str:
        s = self.summary
        return f"<ReducedResult {s.get('problem')} f={s.get('parameters', {}).get('f')} t_stop={s.get('t_stop')}>"


class Comparison:
    """`chainsim compare`: a canonical problem on the string solver against its reduced ODE (falling, folded,
    sliding) or its exact solution (edge, peg, pulley).

    Parameters
    ----------
    string_series : dict of numpy.ndarray
        string_series.csv (the string solver's samples, one per accepted step).
    reduced_series : dict of numpy.ndarray
        reduced_series.csv (falling, folded, sliding; empty for edge, peg, pulley).
    summary : dict
        summary.json: ``t_stop_over_t0``, ``t_stop_over_t0_reduced``, ``rel_err_t_stop``, ...; for edge, peg and
        pulley ``t_lift_off``, ``t_lift_off_exact``, ``abs_err_t_lift_off``, ``max_abs_err_x``, ... (docs/cli.md).
    path : str, optional
        The directory it was read from, if any.
    exact_series : dict of numpy.ndarray, optional
        exact_series.csv (edge, peg, pulley: the exact solution at the string's step times; empty for the
        others).

    Attributes
    ----------
    string_series, reduced_series, exact_series, summary, path
        As given; `kind` is ``"compare"``.
    problem : str
        ``summary["problem"]``: falling, folded, sliding, edge, peg or pulley.
    reference : dict of numpy.ndarray
        What the string is compared with: `exact_series` for edge, peg and pulley, else `reduced_series`.
    """

    kind = "compare"

    def __init__(self, string_series: Arrays, reduced_series: Arrays, summary: Dict[str, Any],
                 path: Optional[str] = None, exact_series: Optional[Arrays] = None) -> None:
        self.string_series = dict(string_series)
        self.reduced_series = dict(reduced_series)
        self.exact_series: Arrays = dict(exact_series or {})
        self.summary = summary
        self.path = path

    def __setstate__(self, state: Dict[str, Any]) -> None:
        state.setdefault("exact_series", {})  # pickled before compare() took edge, peg and pulley
        self.__dict__.update(state)

    @property
    def problem(self) -> str:
        """The problem's name (``summary["problem"]``)."""
        return str(self.summary.get("problem", ""))

    @property
    def reference(self) -> Arrays:
        """The series the string is compared with: `exact_series` (edge, peg, pulley) or `reduced_series`."""
        return self.exact_series if self.exact_series else self.reduced_series

    def __repr__(self) -> str:
        if self.exact_series:
            return (f"<Comparison {self.problem} t_lift_off={self.summary.get('t_lift_off')} "
                    f"abs_err_t_lift_off={self.summary.get('abs_err_t_lift_off')}>")
        return f"<Comparison {self.problem} rel_err_t_stop={self.summary.get('rel_err_t_stop')}>"


def columns_of(table: Any) -> Arrays:
    """A reader's Table (or None) as a dict of its columns."""
    return {c: table[c] for c in table.columns} if table is not None else {}


def result_of_run(run: _core.Run) -> Union[Result, ReducedResult]:
    """The Result (ReducedResult for model = "reduced") of a C++ run."""
    arrays = run.arrays()
    if "nodes" not in arrays:
        return ReducedResult(arrays["series"], json.loads(run.summary()))
    return Result(run, _arrays=arrays)  # one copy of the frames into numpy, not two


def read_directory(directory: PathLike) -> Union[Result, ReducedResult, Comparison]:
    """See chainsim.read_run."""
    from chainsim_plot.readers import load_run

    path = os.fspath(directory)
    run = load_run(path)
    if run.kind == "reduced":
        return ReducedResult(columns_of(run.reduced), run.summary, path=path)
    if run.kind == "compare":
        return Comparison(columns_of(run.series), columns_of(run.reduced), run.summary, path=path,
                          exact_series=columns_of(run.exact))
    return Result.from_reader_run(run)
