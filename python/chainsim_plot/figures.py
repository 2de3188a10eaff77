"""The figures of a run: each function draws onto matplotlib axes or writes one PNG and returns its path.

    snapshots.png  the string at several times (x-y; x-y and x-z in 3D), heaps, the plane, the edges (their tables) and the fronts
    energy.png     the energy ledger: K, V, each work term, and the residual of the balance
    tension.png    the tension along s at the same times, the fronts' s0 dotted (and T(s, t) when the links
                   do not change)
    fronts.png     each front's s0 and speed ds0/dt over time
    compare.png    chainsim compare: the string solver against the reduced ODE
    reduced.png    a reduced run: eta(t) and P/P0
"""
import os
import textwrap

import numpy as np

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

from .readers import RunError  # noqa: E402

DPI = 110
HEAP_COLOR = "tab:brown"
FRONT_COLOR = "tab:red"
# An edge whose two arms leave its point within 20 degrees of each other (the string turns back on itself, by
# 180 degrees over a peg) is drawn as a peg, a disc inside the bend: a wedge between the arms would be a sliver.
PEG_COS = np.cos(np.radians(20.0))


# --- helpers --------------------------------------------------------------------------------------

def save(fig, out_dir, name, dpi=DPI):
    """Writes fig to out_dir/name (creating out_dir), closes it and returns the path; with out_dir None
    (chainsim.Result.plot()), writes nothing and returns the figure, open."""
    if out_dir is None:
        return fig
    os.makedirs(out_dir, exist_ok=True)
    path = os.path.join(out_dir, name)
    fig.savefig(path, dpi=dpi)
    plt.close(fig)
    return path


def decorate(ax, xlabel, ylabel, title=None, legend=True):
    ax.set_xlabel(xlabel)
    ax.set_ylabel(ylabel)
    if title:
        ax.set_title(title, fontsize=10)
    if legend and ax.get_legend_handles_labels()[0]:
        ax.legend(fontsize=7, loc="best")
    ax.grid(alpha=0.3, which="both")


def semilogy_abs(ax, t, r, **kw):
    """|r| on a log axis; exact zeros (e.g. the first sample) are drawn at the bottom of the axis."""
    a = np.abs(np.asarray(r, dtype=float))
    positive = a[a > 0]
    floor = max(positive.min(), positive.max() * 1e-12) / 2 if positive.size else 1e-300
    ax.semilogy(t, np.maximum(a, floor), **kw)
    return float(a.max()) if a.size else 0.0


def plain_axis(ax, *series):
    """No offset notation on the y-axis ("1e-13 - 1" for round-off on a constant), and a curve that is
    constant to round-off (spread below 1e-9 of its size) drawn flat in a window of +-5% around it (+-1 at
    zero), not zoomed into its round-off."""
    ax.ticklabel_format(axis="y", useOffset=False)
    values = np.concatenate([np.asarray(s, dtype=float).ravel() for s in series]) if series else np.array([])
    values = values[np.isfinite(values)]
    if values.size == 0:
        return
    lo, hi = values.min(), values.max()
    size = max(abs(lo), abs(hi))
    if hi - lo <= 1e-9 * size or size == 0:
        mid = 0.5 * (lo + hi)
        half = 0.05 * abs(mid) if mid != 0 else 1.0
        ax.set_ylim(mid - half, mid + half)


def choose_times(times, wanted=None, count=6):
    """Indices of the frames to draw: the nearest to each wanted time, or `count` frames spread evenly
    from the first to the last."""
    times = np.asarray(times)
    if wanted:
        lo, hi = times[0], times[-1]
        for t in wanted:
            if t < lo - 1e-12 * max(1.0, abs(lo)) or t > hi + 1e-12 * max(1.0, abs(hi)):
                raise RunError(f"--times: t = {t:g} s is outside the run: allowed {lo:g} <= t <= {hi:g} s")
        return sorted({int(np.argmin(np.abs(times - t))) for t in wanted})
    n = min(count, len(times))
    return sorted({int(np.argmin(np.abs(times - t))) for t in np.linspace(times[0], times[-1], n)})


def time_colors(n):
    """n colours from dark blue (first) to green (last): viridis without its yellow end, which is hardly
    visible on white."""
    cmap = plt.get_cmap("viridis")
    return [cmap(0.8 * k / max(1, n - 1)) for k in range(n)]


PROJECTIONS = {2: [(0, 1)], 3: [(0, 1), (0, 2)]}
AXIS_NAMES = "xyz"


# --- the string's geometry: layout shared by the snapshots and the animation ----------------------

class Layout:
    """How a run's string is drawn: the projections, the partial links to the heaps' fronts, and two
    optional offsets for motions that would hide themselves. `stagger`: a motion along one vertical line
    (the canonical chains) draws each later snapshot further right; `aside`: the arm beyond a fold is
    drawn shifted sideways (the two arms of a fold lie on one line)."""

    def __init__(self, run, stagger_ok=True):
        self.run = run
        frames = run.nodes
        self.dim = frames.dim
        self.projections = PROJECTIONS[min(self.dim, 3)]
        lo, hi = frames.bounds()
        for f in run.fronts:
            p = f.positions()
            if p is not None:
                lo, hi = np.minimum(lo, p.min(axis=0)), np.maximum(hi, p.max(axis=0))
            if f.point is not None:
                lo, hi = np.minimum(lo, f.point), np.maximum(hi, f.point)
        self.lo, self.hi = lo, hi
        self.size = float(max(np.max(hi - lo), 1e-12))
        flat = self.dim == 2 and (hi[0] - lo[0]) < 0.05 * (hi[1] - lo[1])
        self.stagger = 0.15 * (hi[1] - lo[1]) if (flat and stagger_ok) else 0.0
        self.fold = next((f for f in run.fronts if f.kind == "fold"), None)
        self.aside = 0.03 * (hi[1] - lo[1]) if (flat and self.fold is not None) else 0.0

    def notes(self):
        out = []
        if self.stagger:
            out.append(f"each later snapshot drawn {self.stagger:.2g} m further right")
        if self.aside:
            out.append(f"the arm past the fold drawn {self.aside:.2g} m aside")
        return out

    def curve(self, k, t=None):
        """Frame k as an (m x dim) array of points to draw (NaN rows break the line), with the partial
        links to the heaps' fronts, the folds' positions between their arms (the arm past the first fold
        shifted aside, joined to the other by a bar at the fold), a closed string closed."""
        frames, run = self.run.nodes, self.run
        t = frames.times[k] if t is None else t
        x = frames.positions(k).copy()
        nodes = frames.nodes(k)
        s = frames.s(k)
        if self.aside:
            x[(s if s is not None else nodes.astype(float)) > self.fold.s0_at(t), 0] += self.aside
        breaks = np.flatnonzero(np.diff(nodes) != 1) + 1  # gaps: a heap inside the listing
        pieces = np.split(x, breaks)
        if run.closed and len(pieces) == 1:
            pieces = [np.vstack([x, x[:1]])]
        if s is not None:  # a fold or a kink is a corner of the string at s0, between two nodes
            for f in run.fronts:
                p = f.position_at(t)
                if f.kind not in ("fold", "kink") or p is None:
                    continue
                corner = [p]
                if f is self.fold and self.aside:  # the arms drawn apart: a short bar across at the fold
                    corner.append(p + np.eye(len(p))[0] * self.aside)
                s0 = f.s0_at(t)
                for q, sq in enumerate(np.split(s, breaks)):
                    j = int(np.searchsorted(sq, s0, side="right"))
                    if 0 < j < len(sq):
                        pieces[q] = np.insert(pieces[q], j, corner, axis=0)
        for f in run.fronts:
            if f.kind != "heap":
                continue
            p = f.position_at(t)
            if p is None:
                continue
            if f.side == "end":
                pieces[-1] = np.vstack([pieces[-1], p])
            else:
                pieces[0] = np.vstack([p, pieces[0]])
        out = []
        for q, piece in enumerate(pieces):
            if q:
                out.append(np.full((1, x.shape[1]), np.nan))
            out.append(piece)
        return np.vstack(out)

    def front_point(self, f, t):
        """Where front f is marked at time t: its position from the series (the first fold halfway between
        its arms when the arm past it is drawn aside), or None if the series has no position."""
        p = f.position_at(t)
        if p is not None and f is self.fold and self.aside:
            p = p.copy()
            p[0] += 0.5 * self.aside
        return p

    def front_markers(self, t):
        """[(front, position)] of the fronts at time t (positions from the series)."""
        return [(f, p) for f in self.run.fronts for p in [self.front_point(f, t)] if p is not None]

    def draw_planes(self, ax, proj, extra=0.0, label=True):
        """The obstacles (draw_obstacles): the old name, kept."""
        self.draw_obstacles(ax, proj, extra, label)

    def draw_obstacles(self, ax, proj, extra=0.0, label=True, shifts=None):
        """The obstacles, drawn once and the same in the snapshots and the animation: the plane (table)
        under each heap on a plane, as its trace on the projection `proj` (only where the projection sees
        it edge-on), and each edge (edge_geometry): a grey wedge at its point between the two arms' initial
        directions (the obstacle lies inside the bend; a peg, where the arms turn back on each other, a grey
        disc inside the bend touching the point) and, with `table = "before"|"after"`, the table's
        face as a thick grey line from the point along that side's initial direction (in 3D only on a
        projection that sees the table edge-on). `extra`: how much
        further right they must reach (staggered snapshots); `shifts`: the staggered snapshots' offsets to the
        right, each drawn over its own copy of the edges (a chain over a peg)."""
        self._draw_contact_obstacles(ax, proj, extra, label)
        for f in self.run.fronts:
            if f.kind == "edge":
                for q, shift in enumerate(shifts if shifts else [0.0]):
                    self._draw_edge(ax, f, proj, extra, label and q == 0, shift)
                continue
            if f.kind != "heap" or not f.on_plane or f.plane_normal is None or f.point is None:
                continue
            self._plane_trace(ax, f.point, f.plane_normal, proj, extra, "plane (table)" if label else None)

    def _plane_trace(self, ax, point, normal, proj, extra, label, edge=None):
        """A plane through `point` with `normal`, as its trace on the projection `proj` (only where the
        projection sees it edge-on); False where it does not. A table that ends at an edge (`edge`: its
        point and the direction from it into the table) is drawn from the edge into the table only."""
        a, b = proj
        n = np.asarray(normal, dtype=float)
        if self.dim == 3 and abs(n[3 - a - b]) > 1e-9 * np.linalg.norm(n):
            return False
        d = np.array([-n[b], n[a]])
        d = d / np.linalg.norm(d)
        if d[0] < 0:
            d = -d
        p = np.asarray(point, dtype=float)[[a, b]]
        if edge is not None:
            e = np.asarray(edge[0], dtype=float)[[a, b]]
            inward = np.asarray(edge[1], dtype=float)[[a, b]]
            if np.linalg.norm(inward) > 0:
                self._face(ax, np.array([e, e + (1.2 * self.size + extra) * inward / np.linalg.norm(inward)]), label)
                return True
        centre = p + np.dot(0.5 * (self.lo[[a, b]] + self.hi[[a, b]]) - p, d) * d
        half = 0.6 * self.size
        self._face(ax, np.array([centre - half * d, centre + (half + extra) * d]), label)
        return True

    def _draw_contact_obstacles(self, ax, proj, extra, label):
        """The obstacles of [[effects.surface]] and [[effects.cylinder]] (the summary's `obstacles`): a
        plane as its trace (where the projection sees it edge-on), a cylinder as a grey disc (2D, or a 3D
        cylinder whose axis is normal to the projection), or else as its silhouette, the band of half-width R
        about its axis's projection, across the picture."""
        from matplotlib.patches import Circle, Polygon
        a, b = proj
        first = {"surface": True, "cylinder": True}
        count = {"surface": 0, "cylinder": 0}
        for o in self.run.summary.get("obstacles", []):
            kind = o.get("kind")
            if kind not in count:
                continue
            gid = f"obstacle {kind}{count[kind]}"  # surface0, cylinder0, ... in the scene's order
            count[kind] += 1
            lab = kind if label and first[kind] else None
            if kind == "surface":
                edge = (o["edge_point"], o["inward"]) if "inward" in o else None
                if not self._plane_trace(ax, o["point"], o["normal"], proj, extra, lab, edge):
                    continue
                ax.lines[-1].set_gid(gid)
            else:
                c = np.asarray(o["center"], dtype=float)[[a, b]]
                style = dict(facecolor="0.75", edgecolor="0.45", lw=1.0, zorder=0, label=lab, gid=gid)
                axis = np.asarray(o.get("axis", [0, 0, 1]), dtype=float) if self.dim == 3 else None
                if axis is not None and abs(axis[a]) + abs(axis[b]) > 1e-9 * np.linalg.norm(axis):
                    u = axis[[a, b]] / np.linalg.norm(axis[[a, b]])
                    n = np.array([-u[1], u[0]]) * o["radius"]
                    mid = c + np.dot(0.5 * (self.lo[[a, b]] + self.hi[[a, b]]) - c, u) * u
                    half = 0.6 * self.size + extra
                    ax.add_patch(Polygon([mid - half * u + n, mid + half * u + n, mid + half * u - n,
                                          mid - half * u - n], closed=True, **style))
                else:
                    ax.add_patch(Circle(c, o["radius"], **style))
            first[kind] = False

    @staticmethod
    def _face(ax, ends, label):
        """A rigid surface seen edge-on: a thick grey line between `ends`."""
        ax.plot(ends[:, 0], ends[:, 1], "k-", lw=2.5, alpha=0.45, label=label)

    def edge_geometry(self, f):
        """(point, before, after) of the edge front f: its point and the unit directions, from it, of the
        string's two sides in the first frame (before: s < s0, after: s > s0; None where that side has no
        node away from the point). Each side's direction is the one to its node nearest the point."""
        frames = self.run.nodes
        x = frames.positions(0)
        s = frames.s(0)
        p = f.point
        s0 = f.s0_at(frames.times[0]) if f.series is not None and f"s0_{f.k}" in f.series else f.info.get("s0")
        if s is None or s0 is None:
            return p, None, None
        dist = np.linalg.norm(x - p, axis=1)
        away = dist > 1e-9 * self.size

        def side(mask):
            q = np.flatnonzero(mask & away)
            if len(q) == 0:
                return None
            j = q[np.argmin(dist[q])]
            return (x[j] - p) / dist[j]
        return p, side(s < s0), side(s > s0)

    def _draw_edge(self, ax, f, proj, extra, label, shift=0.0):
        """Edge f on the projection `proj`, `shift` to the right (a staggered snapshot's copy: without its
        table, which the unshifted copy draws)."""
        if f.point is None:
            return
        a, b = proj
        p, before, after = self.edge_geometry(f)
        p2 = p[[a, b]] + np.array([shift, 0.0])
        r = 0.07 * self.size
        arms = [d[[a, b]] for d in (before, after) if d is not None and np.linalg.norm(d[[a, b]]) > 1e-9]
        units = [d / np.linalg.norm(d) for d in arms]
        if len(arms) == 2 and np.dot(units[0], units[1]) > PEG_COS:
            # A peg: the string turns back on itself (by 180 degrees, or as the projection sees it), so the
            # wedge between its arms would have no area. A grey disc inside the bend, touching the point.
            from matplotlib.patches import Circle
            inside = (units[0] + units[1]) / np.linalg.norm(units[0] + units[1])
            ax.add_patch(Circle(p2 + 0.5 * r * inside, 0.5 * r, facecolor="0.45", alpha=0.6, lw=0, zorder=0,
                                gid=f"obstacle {f.name}", label=f"peg ({f.name})" if label else None))
        elif len(arms) == 2:
            wedge = np.array([p2, p2 + r * arms[0], p2 + r * arms[1]])
            ax.fill(wedge[:, 0], wedge[:, 1], color="0.45", alpha=0.6, lw=0, gid=f"obstacle {f.name}",
                    label=f"edge ({f.name})" if label else None)
        else:
            ax.plot([p2[0]], [p2[1]], "^", ms=9, color="0.45", alpha=0.6, mew=0, gid=f"obstacle {f.name}",
                    label=f"edge ({f.name})" if label else None)
        side = {"before": before, "after": after}.get(f.info.get("table"))
        if side is None or shift:
            return
        if self.dim == 3 and "direction" in f.info:  # the table's plane holds the edge and that side
            n = np.cross(side, np.asarray(f.info["direction"], dtype=float))
            if abs(n[3 - a - b]) > 1e-9 * np.linalg.norm(n):
                return  # drawn only where the projection sees it edge-on, as a heap's plane
        d = side[[a, b]]
        if np.linalg.norm(d) < 1e-9:
            return
        d = d / np.linalg.norm(d)
        corners = np.array([[u, v] for u in (self.lo[a], self.hi[a] + extra) for v in (self.lo[b], self.hi[b])])
        length = max(float(np.max((corners - p2) @ d)), 0.0) + 0.08 * self.size
        self._face(ax, np.array([p2, p2 + length * d]), "table" if label else None)
        ax.lines[-1].set_gid(f"table {f.name}")

    def heaps(self, t):
        """[(front, position, marker size)] of the heaps at time t: a heap on a plane sits at the moving
        contact, a pinned heap at its point; the marker's area grows with the mass in the heaps."""
        series = self.run.series
        frac = 0.5
        if series is not None and "heap_mass" in series and "moving_mass" in series:
            h = np.interp(t, series["t"], series["heap_mass"])
            m = np.interp(t, series["t"], series["moving_mass"])
            frac = h / (h + m) if h + m > 0 else 0.0
        out = []
        for f in self.run.fronts:
            if f.kind != "heap":
                continue
            p = f.position_at(t) if f.on_plane else f.point
            if p is None:
                p = f.point
            if p is not None:
                out.append((f, p, 3.0 + 13.0 * np.sqrt(max(frac, 0.0))))
        return out

    def limits(self, ax, proj, shift=0.0):
        a, b = proj
        pad = 0.08 * self.size
        ax.set_xlim(self.lo[a] - pad - (self.aside if self.aside else 0), self.hi[a] + pad + shift + self.aside)
        ax.set_ylim(self.lo[b] - pad, self.hi[b] + pad)


def space_axes(ax, proj, adjustable="datalim"):
    """Labels and equal scales for a panel of the string in space; `adjustable="box"` keeps limits that
    were set (the animation)."""
    a, b = proj
    ax.set_xlabel(f"{AXIS_NAMES[a]} (m)")
    ax.set_ylabel(f"{AXIS_NAMES[b]} (m)")
    ax.set_aspect("equal", adjustable=adjustable)
    ax.grid(alpha=0.3)


# --- snapshots ------------------------------------------------------------------------------------

def draw_snapshots(axes, run, picks, layout=None):
    """The string at the frames `picks` on each projection's axes; heaps, the plane, fronts marked.
    Returns the layout (its notes() say what was shifted)."""
    layout = layout or Layout(run)
    frames = run.nodes
    colors = time_colors(len(picks))
    shifts = [q * layout.stagger for q in range(len(picks))]
    for ax, proj in zip(axes, layout.projections):
        a, b = proj
        layout.draw_obstacles(ax, proj, extra=shifts[-1], shifts=shifts if layout.stagger else None)
        for q, k in enumerate(picks):
            pts = layout.curve(k)
            ax.plot(pts[:, a] + shifts[q], pts[:, b], "-", lw=1.3, color=colors[q],
                    label=f"t = {frames.times[k]:.4g} s")
            ax.plot(pts[0, a] + shifts[q], pts[0, b], "o", ms=4, color=colors[q])
        labelled = set()
        for q, k in enumerate(picks):
            t = frames.times[k]
            for f, p, size in layout.heaps(t):
                ax.plot(p[a] + shifts[q], p[b], "o", ms=size, color=HEAP_COLOR, alpha=0.6, mew=0,
                        label=f"heap ({f.name})" if "heap " + f.name not in labelled else None)
                labelled.add("heap " + f.name)
            for f, p in layout.front_markers(t):
                marker = "D" if f.kind == "fold" else "o"
                ax.plot(p[a] + shifts[q], p[b], marker, ms=5, mfc="none", color=FRONT_COLOR,
                        label=f"front {f.name}" if f.name not in labelled else None)
                labelled.add(f.name)
        space_axes(ax, proj)
        ax.legend(fontsize=6, loc="best")
    return layout


def snapshots_figure(run, out_dir, wanted=None):
    frames = run.nodes
    picks = choose_times(frames.times, wanted)
    layout = Layout(run)
    n = len(layout.projections)
    fig, axes = plt.subplots(1, n, figsize=(6.5 * n, 5.5), squeeze=False, dpi=DPI)
    draw_snapshots(axes[0], run, picks, layout)
    notes = layout.notes()
    notes.append("small dot: the first node drawn" + (" (s = 0)" if not run.fronts else ""))
    if run.fronts:
        notes.append("open markers: the fronts")
    if any(f.kind == "heap" for f in run.fronts):
        notes.append("brown discs: the heaps (area grows with their mass)")
    if any(f.kind == "edge" for f in run.fronts):
        notes.append("grey wedge: the edge, inside the bend (a grey disc: a peg); thick grey line: the table")
    title = f"{run.name}: the string at {len(picks)} times\n" + textwrap.fill("; ".join(notes), 70 * n)
    fig.suptitle(title, fontsize=9)
    fig.tight_layout()
    return save(fig, out_dir, "snapshots.png")


# --- energy ledger ---------------------------------------------------------------------------------

def ledger_columns(run):
    """(table, works, residual, note): the table with K and V, its cumulative work columns, its residual
    column and how the residual is defined."""
    if run.kind == "reduced":
        table = run.reduced
        works = [c for c in table.columns if c.startswith("E_")]
        return table, works, "ledger", "ledger = K + V - (K0 + V0) - sum of the works"
    if run.kind == "compare":
        table = run.series
    else:
        table = run.energy if run.energy is not None and "K" in run.energy else run.series
    if table is None or "K" not in table or "V" not in table:
        return None, [], None, ""
    works = [c for c in table.columns if c.startswith("W_")]
    residual = next((c for c in ("energy_residual", "drift", "ledger") if c in table), None)
    return table, works, residual, f"{residual} = K + V - (K0 + V0) - sum of the works"


WORK_LABELS = {"W_applied": "W_applied (forces, driven ends)", "W_shocks": "W_shocks (dissipated at the shocks)",
               "W_heaps": "W_heaps (external shocks at the heaps)", "W_remesh": "W_remesh (node transfers)",
               "E_shock": "work of the shock", "E_heap": "work of the heap", "E_force": "work of the end force"}


def draw_ledger(ax, run, table, works):
    """K, V, K + V - (K0 + V0) and each work term that is not zero, against t."""
    t, K, V = table["t"], table["K"], table["V"]
    ax.plot(t, K, label="K (kinetic)")
    ax.plot(t, V, label="V (potential)")
    ax.plot(t, K + V - K[0] - V[0], "k-", lw=1.8, label="K + V - (K0 + V0)")
    styles = ["--", ":", "-.", (0, (5, 1, 1, 1))]
    for q, c in enumerate(works):
        if np.max(np.abs(table[c])) > 0 or c == "W_applied":
            ax.plot(t, table[c], linestyle=styles[q % len(styles)], label=WORK_LABELS.get(c, c))
    if len(works) > 1:
        ax.plot(t, sum(table[c] for c in works), "--", color="0.4", lw=1, label="sum of the works")
    decorate(ax, "t (s)", "J", "energy ledger")


def energy_figure(run, out_dir):
    table, works, residual, note = ledger_columns(run)
    if table is None:
        return None
    fig, (ax1, ax2) = plt.subplots(1, 2, figsize=(13, 4.5), dpi=DPI)
    draw_ledger(ax1, run, table, works)
    if residual is not None:
        worst = semilogy_abs(ax2, table["t"], table[residual], lw=1)
        scale = run.summary.get("energy_scale") if isinstance(run.summary, dict) else None
        title = f"|{residual}|: max {worst:.2e} J"
        if scale:
            title += f" ({worst / scale:.1e} of the energy scale {scale:.3g} J)"
        decorate(ax2, "t (s)", "J", title + f"\n{note}", legend=False)
    else:
        ax2.axis("off")
    fig.suptitle(f"{run.name}: energy", fontsize=10)
    fig.tight_layout()
    return save(fig, out_dir, "energy.png")


# --- tension ---------------------------------------------------------------------------------------

SLACK_TOLERANCE = 1e-8  # as the solver's slack check (docs/scenes.md, slack_tolerance): T < -1e-8 max|T| is slack


def tension_map(ax, s, times, grid):
    """T(s, t) as a colour map; returns (mesh, has slack, top clipped). Each sign gets the whole of its half of
    the colour scale (a diverging map centred on 0 with its own range on each side), so a little slack does not
    squeeze the positive tension into the pale middle; the top of the scale is the 99.5th percentile of the
    positive tension, so a short spike (the whip at the tip) does not wash out the rest (it shows as
    the colour bar's arrow)."""
    grid = np.asarray(grid, dtype=float)
    finite = grid[np.isfinite(grid)]
    top = float(np.max(np.abs(finite))) if finite.size else 0.0
    if top == 0.0:
        return ax.pcolormesh(s, times, grid, shading="nearest", cmap="viridis"), False, False
    positive = finite[finite > 0]
    vmax = float(np.percentile(positive, 99.5)) if positive.size else top
    clipped = positive.size > 0 and vmax < positive.max()
    low = float(finite.min())
    neg = low < -SLACK_TOLERANCE * top
    if not neg:
        return (ax.pcolormesh(s, times, grid, shading="nearest", cmap="viridis", vmin=max(low, 0.0), vmax=vmax),
                False, clipped)
    norm = matplotlib.colors.TwoSlopeNorm(vmin=low, vcenter=0.0, vmax=max(vmax, 1e-300))
    return ax.pcolormesh(s, times, grid, shading="nearest", cmap="RdBu_r", norm=norm), True, clipped


def tension_figure(run, out_dir, wanted=None):
    tab = run.tension
    if tab is None or len(tab) == 0 or "T" not in tab or "s_mid" not in tab:
        return None
    t = tab["t"]
    starts = np.flatnonzero(np.r_[True, t[1:] != t[:-1]])
    bounds = np.r_[starts, len(t)]
    times = t[starts]
    picks = choose_times(times, wanted)
    same = len(set(np.diff(bounds))) == 1 and np.allclose(
        tab["s_mid"][: bounds[1]], tab["s_mid"][bounds[-2]:bounds[-1]])
    fig, axes = plt.subplots(1, 2 if same else 1, figsize=(13 if same else 7, 4.5), squeeze=False, dpi=DPI)
    ax = axes[0][0]
    for color, k in zip(time_colors(len(picks)), picks):
        rows = slice(bounds[k], bounds[k + 1])
        ax.plot(tab["s_mid"][rows], tab["T"][rows], ".-", ms=2, lw=1, color=color, label=f"t = {times[k]:.4g} s")
        for f in run.fronts:  # where the tension jumps: each front's s0 at that time, from the series
            ax.axvline(f.s0_at(times[k]), color=color, ls=":", lw=1)
    if run.fronts:
        ax.plot([], [], "k:", lw=1, label="fronts: s0(t), dotted")
    ax.axhline(0, color="k", lw=0.6)
    decorate(ax, "s (m), link midpoints", "T (N)", "tension along the string")
    if same:
        n = bounds[1]
        grid = tab["T"].reshape(len(times), n)
        s = tab["s_mid"][:n]
        m, neg, clipped = tension_map(axes[0][1], s, times, grid)
        fig.colorbar(m, ax=axes[0][1], label="T (N)", extend="max" if clipped else "neither")
        decorate(axes[0][1], "s (m)", "t (s)", "T(s, t)" + (" (blue: slack, T < 0)" if neg else ""), legend=False)
    fig.suptitle(f"{run.name}: tension", fontsize=10)
    fig.tight_layout()
    return save(fig, out_dir, "tension.png")


# --- fronts ----------------------------------------------------------------------------------------

def fronts_figure(run, out_dir):
    if not run.fronts:
        return None
    t = run.series["t"]
    fig, (ax1, ax2) = plt.subplots(1, 2, figsize=(13, 4.5), dpi=DPI)
    for f in run.fronts:
        ax1.plot(t, f.s0, label=f"{f.name}" + (f" ({f.kind})" if f.kind and f.kind not in f.name else ""))
        if f.s0dot is not None:
            ax2.plot(t, f.s0dot, label=f.name)
    decorate(ax1, "t (s)", "s0 (m)", "front positions in the material, s0(t)")
    decorate(ax2, "t (s)", "ds0/dt (m/s)", "front speeds in the material")
    plain_axis(ax1, *[f.s0 for f in run.fronts])
    plain_axis(ax2, *[f.s0dot for f in run.fronts if f.s0dot is not None])
    fig.suptitle(f"{run.name}: fronts", fontsize=10)
    fig.tight_layout()
    return save(fig, out_dir, "fronts.png")


# --- the reduced model and the comparison ----------------------------------------------------------

def hermite(t, q, dq, at):
    """Cubic Hermite interpolation of q (with derivative dq) given at increasing times t, at `at`."""
    i = np.clip(np.searchsorted(t, at) - 1, 0, len(t) - 2)
    h = t[i + 1] - t[i]
    u = (at - t[i]) / h
    h00, h10 = 2 * u**3 - 3 * u**2 + 1, u**3 - 2 * u**2 + u
    h01, h11 = -2 * u**3 + 3 * u**2, u**3 - u**2
    return h00 * q[i] + h10 * h * dq[i] + h01 * q[i + 1] + h11 * h * dq[i + 1]


def reduced_figure(run, out_dir):
    r = run.reduced
    s = run.summary or {}
    xi = r["xi"] if "xi" in r else r["t"]
    fig, (ax1, ax2) = plt.subplots(1, 2, figsize=(13, 4.5), dpi=DPI)
    ax1.plot(xi, r["eta"], label="reduced ODE (ARKODE)")
    ax2.plot(xi, r["P_over_P0"] if "P_over_P0" in r else r["P"], label="reduced ODE (ARKODE)")
    t_exact, P_exact = s.get("t_stop_over_t0_exact"), s.get("P_stop_over_P0_exact")
    if isinstance(t_exact, (int, float)):
        ax1.plot([t_exact], [s.get("eta_stop", r["eta"][-1])], "k*", ms=9, label="stop time, exact quadrature")
        if isinstance(P_exact, (int, float)):
            ax2.plot([t_exact], [P_exact], "k*", ms=9, label="P at the stop, exact quadrature")
    problem = s.get("problem", "")
    p = s.get("parameters", {})
    what = {"falling": "height of the falling part", "folded": "length of the resting arm",
            "sliding": "hanging length"}.get(problem, "y")
    decorate(ax1, "t / t0", "eta = y / l", f"eta(t): {what}")
    decorate(ax2, "t / t0", "P / P0", "dynamic weight P / P0 (force on the support)")
    params = ", ".join(f"{k} = {p[k]:g}" for k in ("f", "eta0", "eps", "force") if isinstance(p.get(k), (int, float)))
    fig.suptitle(f"{run.name}: the {problem} chain, reduced model" + (f" ({params})" if params else "") +
                 (f"; stop: {s['stop_reason']}" if "stop_reason" in s else ""), fontsize=10)
    fig.tight_layout()
    return save(fig, out_dir, "reduced.png")


def compare_figure(run, out_dir):
    s, red = run.series, run.reduced
    summary = run.summary or {}
    problem = summary.get("problem", "")
    nz = np.flatnonzero(red["eta"] != 0)
    if not len(nz) or not run.fronts:
        raise RunError(f"{run.path}: the compare series lack eta or a front (s0_0)")
    ell = red["y"][nz[-1]] / red["eta"][nz[-1]]
    s0 = run.fronts[0].s0
    eta = 1.0 - s0 / ell if problem == "sliding" else s0 / ell
    t = s["t"]
    fig, axes = plt.subplots(1, 3, figsize=(17, 4.5), dpi=DPI)
    axes[0].plot(red["t"], red["eta"], "k-", lw=2.5, alpha=0.4, label="reduced ODE")
    axes[0].plot(t, eta, "-", lw=1, label="string solver (front tracking)")
    decorate(axes[0], "t (s)", "eta = y / l", "eta(t)")
    if "support_y" in s:
        axes[1].plot(red["t"], red["P"], "k-", lw=2.5, alpha=0.4, label="reduced ODE")
        axes[1].plot(t, s["support_y"], "-", lw=1, label="string solver: force on the support")
        title = "P (N)"
        if "max_rel_err_P" in summary:
            title += f": max rel. difference {summary['max_rel_err_P']:.2e} ({summary.get('P_compared_at', '')})"
        decorate(axes[1], "t (s)", "P (N)", title)
    inside = (t >= red["t"][0]) & (t <= red["t"][-1])
    ref = hermite(red["t"], red["y"] / ell, red["ydot"] / ell, t[inside])
    worst = semilogy_abs(axes[2], t[inside], eta[inside] - ref, lw=1)
    title = f"|eta_string - eta_reduced| at equal t: max {worst:.2e}"
    decorate(axes[2], "t (s)", "", title + "\n(reduced ODE by cubic Hermite interpolation)", legend=False)
    nodes = summary.get("nodes")
    fig.suptitle(f"{run.name}: the {problem} chain, string solver" + (f" ({nodes} nodes)" if nodes else "") +
                 " against the reduced ODE", fontsize=10)
    fig.tight_layout()
    return save(fig, out_dir, "compare.png")


EXACT_TENSIONS = {  # exact_series.csv's tensions and reactions (docs/cli.md, chainsim compare edge|peg|pulley)
    "tension_edge": "tension before the edge", "tension_minus": "tension of the rising side at the peg",
    "tension_plus": "tension after it", "tension_short": "shorter side at the pulley",
    "tension_long": "longer side at the pulley"}


def exact_compare_figure(run, out_dir):
    """`chainsim compare edge|peg|pulley`: x(t) of the string solver on the exact one (with the lift-off), the
    exact tensions and the edge's reaction F0 against the string's, and |x - x_exact| at equal times."""
    s, ex = run.series, run.exact
    summary = run.summary or {}
    problem = summary.get("problem", "")
    fig, axes = plt.subplots(1, 3, figsize=(17, 4.5), dpi=DPI)
    axes[0].plot(ex["t"], ex["x"], "k-", lw=2.5, alpha=0.4, label="exact solution")
    x = None
    if run.fronts and len(s["t"]):  # edge, peg: the edge front at s0 = l - x (l from the first row)
        x = (ex["x"][0] + run.fronts[0].s0[0]) - run.fronts[0].s0
        axes[0].plot(s["t"], x, "-", lw=1, label="string solver: l - s0 of the edge front")
    for key, style, label in (("", "o", "string solver"), ("_exact", "kx", "exact")):
        t_l, x_l = summary.get("t_lift_off" + key), summary.get("x_lift_off" + key)
        if t_l is not None and x_l is not None:
            axes[0].plot([t_l], [x_l], style, mfc="none", ms=9, label=f"lift-off, {label}: t = {t_l:.6g} s")
    what = {"pulley": "x = x1, the longer side (m)"}.get(problem, "x, the longer or hanging side (m)")
    decorate(axes[0], "t (s)", what, f"x(t) to the lift-off ({problem})")
    for name, label in EXACT_TENSIONS.items():
        if name in ex:
            axes[1].plot(ex["t"], ex[name], "-", lw=1.5, label=f"{name}: {label} (exact)")
    for axis in ("x", "y"):
        if f"reaction_{axis}" in ex and f"R_front0_{axis}" in s:
            axes[1].plot(ex["t"], ex[f"reaction_{axis}"], "k-", lw=2.5, alpha=0.3, label=f"reaction F0_{axis} (exact)")
            axes[1].plot(s["t"], s[f"R_front0_{axis}"], "--", lw=1, label=f"R_front0_{axis} (string solver)")
    title = "tensions and reaction (N)" if "reaction_x" in ex else "tensions (N)"
    if "max_abs_err_tension" in summary:
        title += f": max |T error| {summary['max_abs_err_tension']:.2e} N"
    elif "max_abs_err_tension_short" in summary:
        title += (f": max |T error| {summary['max_abs_err_tension_short']:.2e} N (short), "
                  f"{summary.get('max_abs_err_tension_long', float('nan')):.2e} N (long)")
    decorate(axes[1], "t (s)", "N", title)
    if x is not None:
        inside = (s["t"] >= ex["t"][0]) & (s["t"] <= ex["t"][-1])
        ref = hermite(ex["t"], ex["x"], ex["x_dot"], s["t"][inside]) if "x_dot" in ex else \
            np.interp(s["t"][inside], ex["t"], ex["x"])
        worst = semilogy_abs(axes[2], s["t"][inside], x[inside] - ref, lw=1)
        decorate(axes[2], "t (s)", "m", f"|x_string - x_exact| at equal t: max {worst:.2e} m", legend=False)
    elif "lift_off_margin" in ex:  # the pulley: the string series has no x, its errors are in the summary
        axes[2].plot(ex["t"], ex["lift_off_margin"], "k-", lw=1.5, label="(tau2 - lambda xdot^2)/R (exact)")
        axes[2].axhline(0, color="0.5", lw=0.8)
        if summary.get("t_lift_off") is not None:
            axes[2].axvline(summary["t_lift_off"], color="C1", ls="--", lw=1,
                            label=f"the string's lift-off, t = {summary['t_lift_off']:.6g} s")
        title = "lift-off margin (N/m), zero at t*"
        if "max_abs_err_x" in summary:
            title += f"\nmax |x error| {summary['max_abs_err_x']:.2e} m (summary.json)"
        decorate(axes[2], "t (s)", "N/m", title)
    else:
        axes[2].set_visible(False)
    nodes = summary.get("nodes")
    fig.suptitle(f"{run.name}: the {problem} problem, string solver" + (f" ({nodes} nodes)" if nodes else "") +
                 " against the exact solution", fontsize=10)
    fig.tight_layout()
    return save(fig, out_dir, "compare.png")
