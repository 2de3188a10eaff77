"""Reading the outputs of chainsim runs, by column name.

A run directory is recognised by the files in it (see `load_run`):

    kind        written by                                       files
    string      chainsim run (a scene without fronts)            nodes.csv, tension.csv, energy.csv, stats.json
    fronts      chainsim run (a scene with heaps or a fold)      nodes.csv, series.csv, stats.json
    reduced     chainsim reduced, chainsim run (model="reduced")  series.csv, summary.json or stats.json
    compare     chainsim compare falling|folded|sliding          string_series.csv, reduced_series.csv, summary.json
                chainsim compare edge|peg|pulley                 string_series.csv, exact_series.csv, summary.json
    canonical   chainsim canonical                               summary.csv, figure_data/, falling/ folded/ sliding/

Every table is read by its header and every column is optional: a string run with fronts may carry
energy.csv and tension.csv as well, nodes.csv may or may not have the columns s and vx, vy[, vz].
"""
import contextlib
import csv
import fcntl
import json
import os

import numpy as np


class RunError(Exception):
    """A run directory or file that cannot be drawn: the message says which and why (exit code 2)."""


class Table:
    """A CSV table as named numpy columns."""

    def __init__(self, path, columns, data):
        self.path = path
        self.columns = columns
        self._data = data

    def __contains__(self, name):
        return name in self._data

    def __getitem__(self, name):
        return self._data[name]

    def get(self, name, default=None):
        return self._data.get(name, default)

    def __len__(self):
        return len(self._data[self.columns[0]]) if self.columns else 0

    def matching(self, prefix):
        """The columns whose name starts with `prefix`, in file order."""
        return [c for c in self.columns if c.startswith(prefix)]


def read_table(path):
    """Reads a CSV file with a header of column names and numeric rows (chainsim's CsvTable). A first
    column that is not numeric (e.g. `problem` in summary.csv) is kept as strings. Returns None if the
    file does not exist; raises RunError if it cannot be read or parsed."""
    if not os.path.exists(path):
        return None
    try:
        with open(path, newline="") as fh:
            header = next(csv.reader([fh.readline()]), None)
            if not header:
                raise RunError(f"{path}: the file is empty (no header line)")
            columns = [c.strip() for c in header]
            try:  # the fast path: every field a number
                values = np.loadtxt(fh, delimiter=",", ndmin=2)
            except ValueError:
                values = None
    except OSError as e:
        raise RunError(f"{path}: cannot read it: {e.strerror}") from e
    if values is not None and values.size == 0:
        values = np.zeros((0, len(columns)))
    if values is not None and values.shape[1] == len(columns):
        return Table(path, columns, {name: values[:, j] for j, name in enumerate(columns)})
    return _read_table_slowly(path, columns)


def _read_table_slowly(path, columns):
    """The table read field by field: a text first column, or the line at fault named."""
    with open(path, newline="") as fh:
        rows = list(csv.reader(fh))[1:]
    data = {}
    for i, row in enumerate(rows):
        if len(row) != len(columns):
            raise RunError(f"{path}:{i + 2}: {len(row)} fields, but the header has {len(columns)} "
                           f"(a truncated or foreign file)")
    for j, name in enumerate(columns):
        values = [row[j] for row in rows]
        try:
            data[name] = np.array(values, dtype=float)
        except ValueError:
            if j == 0:
                data[name] = np.array(values, dtype=object)
                continue
            bad = next(i for i, v in enumerate(values) if not _is_number(v))
            raise RunError(f"{path}:{bad + 2}: column '{name}' = '{values[bad]}' is not a number") from None
    return Table(path, columns, data)


def _is_number(text):
    try:
        float(text)
        return True
    except ValueError:
        return False


def read_json(path):
    if not os.path.exists(path):
        return None
    try:
        with open(path) as fh:
            return json.load(fh)
    except OSError as e:
        raise RunError(f"{path}: cannot read it: {e.strerror}") from e
    except json.JSONDecodeError as e:
        raise RunError(f"{path}:{e.lineno}:{e.colno}: not valid JSON ({e.msg}): an interrupted write?") from e


class Frames:
    """The string at each recorded frame, from nodes.csv: `times`, and for frame k `nodes(k)` (node
    indices), `positions(k)` (n x dim), `s(k)` (material coordinates, if written) and `velocities(k)`
    (n x dim, if written). Only the nodes in motion are listed in runs with fronts."""

    def __init__(self, table):
        self.table = table
        self.axes = [a for a in ("x", "y", "z") if a in table]
        if "t" not in table or "node" not in table or len(self.axes) < 2:
            raise RunError(f"{table.path}: needs the columns t, node, x, y (has {', '.join(table.columns)})")
        t = table["t"]
        if len(t) == 0:
            raise RunError(f"{table.path}: no rows (the run wrote no frame)")
        starts = np.flatnonzero(np.r_[True, t[1:] != t[:-1]])
        self._bounds = np.r_[starts, len(t)]
        self.times = t[starts]
        self.dim = len(self.axes)
        self.has_s = "s" in table
        self.has_velocity = all(("v" + a) in table for a in self.axes)

    def __len__(self):
        return len(self.times)

    def _rows(self, k):
        return slice(self._bounds[k], self._bounds[k + 1])

    def nodes(self, k):
        return self.table["node"][self._rows(k)].astype(int)

    def positions(self, k):
        rows = self._rows(k)
        return np.column_stack([self.table[a][rows] for a in self.axes])

    def s(self, k):
        return self.table["s"][self._rows(k)] if self.has_s else None

    def velocities(self, k):
        if not self.has_velocity:
            return None
        rows = self._rows(k)
        return np.column_stack([self.table["v" + a][rows] for a in self.axes])

    def nearest(self, t):
        return int(np.argmin(np.abs(self.times - t)))

    def bounds(self):
        """(lo, hi) of the positions over all frames, per axis."""
        xyz = np.column_stack([self.table[a] for a in self.axes])
        return xyz.min(axis=0), xyz.max(axis=0)


class Front:
    """One front of a run with fronts: its description from stats.json (if any) and its columns in the
    series (s0_k, s0dot_k, front_k_x, ...)."""

    def __init__(self, k, info, series):
        self.k = k
        self.info = info or {}
        self.name = self.info.get("name", f"front {k}")
        self.kind = self.info.get("kind", "heap" if "heap" in self.name else ("fold" if "fold" in self.name else ""))
        self.side = self.info.get("side", "start" if self.name == "heap_start" else "end")
        self.point = np.array(self.info["point"], dtype=float) if "point" in self.info else None
        self.on_plane = bool(self.info.get("on_plane", False))
        self.plane_normal = np.array(self.info["plane_normal"], dtype=float) if "plane_normal" in self.info else None
        self.series = series

    @property
    def s0(self):
        return self.series[f"s0_{self.k}"]

    @property
    def s0dot(self):
        return self.series.get(f"s0dot_{self.k}")

    def position_columns(self):
        return [c for c in (f"front_{self.k}_{a}" for a in ("x", "y", "z")) if c in self.series]

    def positions(self):
        """(n_samples x dim) positions of the front, or None if the series does not have them."""
        cols = self.position_columns()
        return np.column_stack([self.series[c] for c in cols]) if len(cols) >= 2 else None

    def position_at(self, t):
        p = self.positions()
        if p is None:
            return None
        ts = self.series["t"]
        return np.array([np.interp(t, ts, p[:, d]) for d in range(p.shape[1])])

    def s0_at(self, t):
        return float(np.interp(t, self.series["t"], self.s0))


class Run:
    """Everything a run directory holds, read once."""

    def __init__(self, path, kind, files, summary=None, nodes=None, energy=None, series=None, tension=None,
                 reduced=None, fronts=None, exact=None):
        self.path = path
        self.kind = kind
        self.files = files
        self.summary = summary or {}
        self.nodes = nodes
        self.energy = energy
        self.series = series
        self.tension = tension
        self.reduced = reduced
        self.exact = exact  # exact_series.csv of `chainsim compare edge|peg|pulley`: the exact solution
        self.fronts = fronts or []

    @property
    def name(self):
        return os.path.basename(os.path.normpath(self.path))

    @property
    def closed(self):
        s = self.summary
        return "nodes" in s and "links" in s and s["nodes"] == s["links"] and not self.fronts


def _fronts(series, info):
    if series is None:
        return []
    ks = sorted(int(c[3:]) for c in series.columns if c.startswith("s0_") and c[3:].isdigit())
    info = info if isinstance(info, list) else []
    return [Front(k, info[k] if k < len(info) else None, series) for k in ks]


LOCK_NAME = ".chainsim.lock"


@contextlib.contextmanager
def holding(path):
    """Holds the run directory `path` as every chainsim command that writes one does (RunDirectory in
    solver/output.hpp): an exclusive flock on path/.chainsim.lock holding this process's pid, released
    (and the file removed) on leaving, or by the kernel if the process dies. A directory another chainsim
    process holds (a run still writing it) raises RunError naming its pid; meanwhile, a run into it is
    refused the same way."""
    check_directory(path)
    lock = os.path.join(path, LOCK_NAME)
    while True:
        try:
            fd = os.open(lock, os.O_RDWR | os.O_CREAT | os.O_CLOEXEC, 0o644)
        except OSError as e:
            raise RunError(f"RUN_DIR '{path}' is not writable: cannot create '{lock}': {e.strerror}") from e
        try:
            fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
        except OSError as e:
            holder = os.pread(fd, 32, 0).decode(errors="replace").strip()
            os.close(fd)
            raise RunError(f"RUN_DIR '{path}' is in use by another chainsim process (pid "
                           f"{holder or 'not yet recorded'}), which holds '{lock}': wait for that run to end") from e
        try:
            same = os.path.samestat(os.fstat(fd), os.stat(lock))
        except OSError:
            same = False
        if same:
            break
        os.close(fd)  # the holder before us removed the name meanwhile: lock the current one
    try:
        os.ftruncate(fd, 0)
        os.pwrite(fd, f"{os.getpid()}\n".encode(), 0)
        yield
    finally:
        try:
            os.unlink(lock)
        except OSError:
            pass
        os.close(fd)


def check_directory(path):
    """Raises RunError unless `path` is a readable directory."""
    if not os.path.exists(path):
        raise RunError(f"RUN_DIR '{path}' does not exist")
    if not os.path.isdir(path):
        raise RunError(f"RUN_DIR '{path}' is not a directory")
    try:
        os.listdir(path)
    except OSError as e:
        raise RunError(f"RUN_DIR '{path}' cannot be read: {e.strerror}") from e
    if not os.access(path, os.R_OK | os.X_OK):
        raise RunError(f"RUN_DIR '{path}' cannot be read: permission denied")


def is_canonical(path):
    return os.path.exists(os.path.join(path, "summary.csv")) and os.path.isdir(os.path.join(path, "figure_data"))


def load_run(path):
    """Reads the run in `path` (see the module's table). Raises RunError when the directory holds none of
    the files a chainsim command writes, or a file is malformed."""
    check_directory(path)
    j = lambda name: os.path.join(path, name)  # noqa: E731
    files = sorted(os.listdir(path))
    # Every chainsim command clears what the others wrote before writing; a directory holding both
    # `chainsim run`'s summary and another command's was mixed by an older chainsim, or by hand.
    others = [f for f in ("summary.json", "string_series.csv", "reduced_series.csv", "exact_series.csv") if f in files]
    if "stats.json" in files and others:
        raise RunError(f"RUN_DIR '{path}' mixes the outputs of two commands: stats.json of `chainsim run` beside "
                       f"{', '.join(others)} of `chainsim compare` or `chainsim reduced`; run the command again "
                       f"(it removes the other's files first)")
    summary = read_json(j("stats.json"))
    if summary is None:
        summary = read_json(j("summary.json"))
    if os.path.exists(j("exact_series.csv")) and not os.path.exists(j("reduced_series.csv")):
        # chainsim compare edge|peg|pulley: the string solver against the exact solution.
        string, exact = read_table(j("string_series.csv")), read_table(j("exact_series.csv"))
        if string is None:
            raise RunError(f"{path}: a compare run of edge, peg or pulley needs string_series.csv beside "
                           f"exact_series.csv, and it is missing (run `chainsim compare` again)")
        if "t" not in exact or "x" not in exact:
            raise RunError(f"{path}/exact_series.csv: no column t or x (the exact solution's time and x)")
        return Run(path, "compare", files, summary, series=string, exact=exact, fronts=_fronts(string, None))
    if os.path.exists(j("string_series.csv")) or os.path.exists(j("reduced_series.csv")):
        string, reduced = read_table(j("string_series.csv")), read_table(j("reduced_series.csv"))
        if string is None or reduced is None:
            raise RunError(f"{path}: a compare run needs string_series.csv with either reduced_series.csv "
                           f"(compare falling|folded|sliding: eta and P against the reduced ODE) or "
                           f"exact_series.csv (compare edge|peg|pulley: x and the tensions against the exact "
                           f"solution); it has only {'reduced_series.csv' if string is None else 'string_series.csv'}")
        return Run(path, "compare", files, summary, series=string, reduced=reduced, fronts=_fronts(string, None))
    series = read_table(j("series.csv"))
    if series is not None and "eta" in series and "P" in series:  # the reduced model's series
        return Run(path, "reduced", files, summary, reduced=series)
    nodes = read_table(j("nodes.csv"))
    energy = read_table(j("energy.csv"))
    tension = read_table(j("tension.csv"))
    if nodes is None and energy is None and series is None and tension is None:
        raise RunError(f"RUN_DIR '{path}' holds none of the files chainsim writes (nodes.csv, energy.csv, "
                       f"series.csv, tension.csv, string_series.csv; or summary.csv and figure_data/ of "
                       f"`chainsim canonical`)")
    frames = Frames(nodes) if nodes is not None else None
    fronts = _fronts(series, (summary or {}).get("fronts"))
    return Run(path, "fronts" if fronts else "string", files, summary, nodes=frames, energy=energy, series=series,
               tension=tension, fronts=fronts)
