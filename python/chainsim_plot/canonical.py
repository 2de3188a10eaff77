"""The main job's figures, from what `chainsim canonical --out DIR` writes (DIR/summary.csv, DIR/figure_data/).

`canonical_figures(DIR, OUT)` writes into OUT (default DIR/figures/) and returns the paths, in this order:

    fall_time_vs_f.png                    the paper's Figs. 3b, 4b, 5b: fall time against f, the quadrature
                                          (lines), the reduced ODE (circles) and the string solver (crosses)
    {falling,folded,sliding}_chain.png    the paper's profiles y/l(t/t0) and P/P0(t/t0): lines the reduced ODE
                                          (ARKODE), open circles the exact quadrature, crosses the string solver
                                          with front tracking
    {falling,folded,sliding}_snapshots.png  the string at seven times, placed by its front position, its shock
                                          marked
    agreement.png                         the three-way differences of the stop times and the string's energy
                                          ledger residual

With `scene=SCENE.toml` (a scene with a heap on a table, run by `chainsim run SCENE --out DIR/<scene file stem>`)
also OUT/<stem>.png: the string's nodes at several times, the contact's path along the table, and the length
above the table beside the reduced (vertical) falling chain at the same f. `chainsim plot DIR` and
scripts/plot_canonical.py both draw through this module.
"""
import math
import os

import numpy as np

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
from matplotlib.lines import Line2D  # noqa: E402

from .figures import choose_times, save, time_colors  # noqa: E402
from .readers import RunError, load_run, read_table  # noqa: E402

DPI = 130
PROBLEMS = ("falling", "folded", "sliding")
TITLES = {
    "falling": "Falling chain, $\\eta_0=1$, stop at $\\eta=\\varepsilon=0.01$",
    "folded": "Folded chain, $\\eta_0=0$, $F=0$, stop at $\\eta=1-\\varepsilon$",
    "sliding": "Sliding chain, $\\eta_0=0.25$, stop at $\\eta=1$",
}
SHOCK = dict(marker="o", ms=9, mfc="none", mec="tab:red", mew=1.6, ls="none")  # as in docs/model.md's sketch


def read(path, columns=()):
    """A table `chainsim canonical` writes; RunError naming the file if it is missing or lacks a column."""
    table = read_table(path)
    if table is None:
        raise RunError(f"{path}: missing (written by `chainsim canonical`)")
    lacking = [c for c in columns if c not in table]
    if lacking:
        raise RunError(f"{path}: lacks the column(s) {', '.join(lacking)} (has {', '.join(table.columns)})")
    if len(table) == 0:
        raise RunError(f"{path}: no rows")
    return table


def summary_rows(root):
    """DIR/summary.csv as one dict per problem and f."""
    table = read(os.path.join(root, "summary.csv"), ("problem", "f", "nodes"))
    return [{c: table[c][i] for c in table.columns} for i in range(len(table))]


CURVE = ("xi", "eta", "P_over_P0")


def curves(data_dir, problem, f):
    """The reduced ODE, the quadrature and the string run of one problem at one f."""
    stem = os.path.join(data_dir, f"{problem}_f{f:.2f}")
    return tuple(read(stem + suffix, CURVE) for suffix in ("_ode.csv", "_exact.csv", "_string.csv"))


def spread(xs, ys, count, phase):
    """Indices of about `count` points evenly spaced along the curve (xs, ys) (arc length in axis units
    normalized by each range), shifted by `phase` (0..1) of a spacing, so that two marker sets interleave."""
    xs, ys = np.asarray(xs, dtype=float), np.asarray(ys, dtype=float)
    sx = np.ptp(xs) or 1.0
    sy = np.ptp(ys) or 1.0
    arc = np.r_[0.0, np.cumsum(np.hypot(np.diff(xs) / sx, np.diff(ys) / sy))]
    targets = arc[-1] * np.minimum(1.0, (np.arange(count + 1) + phase) / count)
    return np.unique(np.searchsorted(arc, targets, side="right") - 1)


def model_legend(ax, fs, colors, nodes, **kwargs):
    """One entry per f (its colour) and one per model (its marker)."""
    handles = [Line2D([], [], color=c, lw=2, label=f"$f={f:g}$") for f, c in zip(fs, colors)]
    handles += [Line2D([], [], color="k", lw=1.3, label="reduced ODE"),
                Line2D([], [], color="k", marker="o", mfc="none", ls="none", label="quadrature"),
                Line2D([], [], color="k", marker="x", ls="none", label=f"string solver, {nodes:g} nodes")]
    ax.legend(handles=handles, fontsize=7, **kwargs)


FALL_TIME_PANELS = [
    ("(a) falling chain, $\\eta_0=1$", [("falling", "")], "falling"),
    ("(b) folded chain, $\\eta_0=0$", [("folded", "")], "folded"),
    ("(c) sliding chain", [("sliding0", "$\\eta_0=0$"), ("sliding25", "$\\eta_0=0.25$"),
                           ("sliding75", "$\\eta_0=0.75$")], "sliding0"),
]


def read_fall_times(data_dir):
    """figure_data/fall_time_vs_f.csv (reduced ODE and quadrature) and fall_time_string.csv (string solver)."""
    keys = [key for _, series, _ in FALL_TIME_PANELS for key, _ in series]
    reduced = ["f"] + [k + s for k in keys for s in ("_exact", "_ode")]
    string = ["f"] + [k + "_string" for _, _, k in FALL_TIME_PANELS]
    return (read(os.path.join(data_dir, "fall_time_vs_f.csv"), reduced),
            read(os.path.join(data_dir, "fall_time_string.csv"), string))


def fall_time_figure(fall_times, out_dir):
    d, s = fall_times
    fig, axes = plt.subplots(1, 3, figsize=(13, 3.8), dpi=DPI)
    for ax, (title, series, string_key) in zip(axes, FALL_TIME_PANELS):
        colors = []
        for key, label in series:
            line, = ax.plot(d["f"], d[key + "_exact"], "-", label=f"quadrature {label}")
            colors.append(line.get_color())
            ax.plot(d["f"], d[key + "_ode"], "o", ms=3.5, mfc="none", color=line.get_color(),
                    label=f"reduced ODE ($\\varepsilon=10^{{-6}}$) {label}")
            if key == string_key:
                ax.plot(s["f"], s[key + "_string"], "x", ms=7, mew=1.5, color="k",
                        label=f"string solver ($\\varepsilon=10^{{-4}}$) {label}")
        ax.set_xlabel("$f$")
        ax.set_ylabel("$t_f/t_0$")
        ax.set_title(title)
        ax.grid(alpha=0.3)
        if len(series) == 1:
            ax.legend(fontsize=7)
        else:  # one entry per eta0 (its colour), one per model (its marker): outside, so it hides no curve
            handles = [Line2D([], [], color=c, lw=2, label=label) for c, (_, label) in zip(colors, series)]
            handles += [Line2D([], [], color="k", lw=1.3, label="quadrature"),
                        Line2D([], [], color="k", marker="o", ms=3.5, mfc="none", ls="none",
                               label="reduced ODE ($\\varepsilon=10^{-6}$)"),
                        Line2D([], [], color="k", marker="x", ms=7, mew=1.5, ls="none",
                               label="string solver ($\\varepsilon=10^{-4}$), $\\eta_0=0$")]
            ax.legend(handles=handles, fontsize=7, loc="upper left", bbox_to_anchor=(1.02, 1.0), borderaxespad=0)
    fig.tight_layout()
    return save(fig, out_dir, "fall_time_vs_f.png", DPI)


def problem_figure(by_f, out_dir, problem, nodes):
    """by_f: {f: (reduced ODE, quadrature, string) tables} of one problem."""
    fs = list(by_f)
    fig, (ax1, ax2) = plt.subplots(1, 2, figsize=(11, 4.2), dpi=DPI)
    # The paper draws the folded chain's weight as ln(1 + P/P0) (its caption: P_f = 3 P0 <-> ln 4).
    log_p = problem == "folded"
    colors = [f"C{k}" for k in range(len(fs))]
    for f, color in zip(fs, colors):
        ode, ref, string = by_f[f]
        for ax, key in ((ax1, "eta"), (ax2, "P_over_P0")):
            tr = np.log1p if key == "P_over_P0" and log_p else (lambda v: v)
            ax.plot(ode["xi"], tr(ode[key]), "-", lw=1.3, color=color)
            for data, marker, phase in ((ref, "o", 0.0), (string, "x", 0.5)):
                ys = tr(data[key])
                # On the falling chain's log axis the markers are spread along log P.
                along = np.log10(np.maximum(ys, 1e-2)) if problem == "falling" and key != "eta" else ys
                picks = spread(data["xi"], along, 14, phase)
                ax.plot(data["xi"][picks], ys[picks], marker, ms=5, mew=1.2, mfc="none", color=color)
    ax1.set_ylabel("$y/\\ell$")
    ax2.set_ylabel("$\\ln(1+P/P_0)$" if log_p else "$P/P_0$")
    if problem == "falling":
        ax2.set_yscale("log")  # P diverges at the cutoff for 0 < f < 1 (51 P0 for f = 0.5)
        ax2.set_ylim(1e-2, None)
    for ax in (ax1, ax2):
        ax.set_xlabel("$t/t_0$")
        ax.grid(alpha=0.3, which="both")
    model_legend(ax1, fs, colors, nodes, loc="lower left" if problem == "falling" else "upper left")
    fig.suptitle(TITLES[problem] + ": reduced ODE, quadrature and string solver")
    fig.tight_layout()
    return save(fig, out_dir, f"{problem}_chain.png", DPI)


def heap(ax, x, y, mass):
    """A heap of `mass` (units of lambda l) as a half-disc of area proportional to it."""
    if mass <= 1e-9:
        return
    r = math.sqrt(2 * mass / math.pi) * 0.25
    angles = np.linspace(0, math.pi, 41)
    ax.fill(x + r * np.cos(angles), y + r * np.sin(angles), color="0.6", lw=0)


def snapshot_figure(string, out_dir, problem, f, count=7, nodes=None, chain_nodes=None):
    """The string at `count` times from the start to the stop, side by side (one column per time).

    The string run's front position s0(t) (the height y = eta l of the moving part) places the string:
    in the paper's geometry it stays straight and vertical, so the moving material s lies at a height
    fixed by s and y (see the branches below). Dots are material points every 0.1 l, the red circle
    the shock (contact, fold or hole), the grey mound the heap with its mass (1 - eta) lambda l.
    """
    xi, eta = string["xi"], string["eta"]
    picks = [int(np.argmin(np.abs(xi - xi[-1] * j / (count - 1)))) for j in range(count)]
    frames = []  # with the run's node frames: the solver's own nodes at the frame times
    if nodes is not None:
        times = np.unique(nodes["t"])
        chosen = times[[int(round(j * (len(times) - 1) / (count - 1))) for j in range(count)]]
        picks = [int(np.argmin(np.abs(string["t"] - T))) for T in chosen]
        # the chain's length from its link length: s = node * l / (nodes - 1), and the last node may be in a heap
        first = nodes["node"] > 0
        length = float(np.median(nodes["s"][first] / nodes["node"][first])) * (chain_nodes - 1)
        for T in chosen:
            at = nodes["t"] == T
            frames.append((nodes["s"][at] / length, nodes["x"][at] / length, nodes["y"][at] / length))
    gap = 0.55  # horizontal distance between two snapshots (units of l)
    fig, ax = plt.subplots(figsize=(8.8, 5.6) if problem == "folded" else (11, 4.4), dpi=DPI)
    marks = np.linspace(0.0, 1.0, 11)
    for j, k in enumerate(picks):
        x0, y = gap * j, eta[k]
        node_s, node_x, node_y = frames[j] if frames else (None, None, None)
        if problem == "falling":  # moving part s in [0, y] above the contact, s at height y - s
            above = marks[marks < y]
            ax.plot([x0, x0], [0, y], "-", color="tab:blue", lw=2)
            if frames:
                ax.plot(x0 + node_x, node_y, ".", color="k", ms=3)
            else:
                ax.plot(np.full(len(above), x0), y - above, ".", color="k", ms=4)
            heap(ax, x0, 0.0, 1 - y)
            ax.plot([x0], [0], **SHOCK)
        elif problem == "folded":  # resting arm s in [0, y] down to the fold at depth y, moving arm s - 2y
            d = 0.04  # the arms lie on one line; drawn d apart
            resting, moving = marks[marks <= y], marks[marks > y]
            ax.plot([x0, x0], [0, -y], "-", color="tab:gray", lw=2)
            ax.plot([x0 + d, x0 + d], [-y, 1 - 2 * y], "-", color="tab:blue", lw=2)
            ax.plot([x0, x0 + d], [-y, -y], "-", color="tab:blue", lw=1)
            if frames:  # the arms share one line: the nodes past the fold drawn d aside
                past = node_s > y
                ax.plot(x0 + node_x[~past], node_y[~past], ".", color="k", ms=3)
                ax.plot(x0 + d + node_x[past], node_y[past], ".", color="k", ms=3)
            else:
                ax.plot(np.full(len(resting), x0), -resting, ".", color="k", ms=4)
                ax.plot(np.full(len(moving), x0 + d), moving - 2 * y, ".", color="k", ms=4)
            ax.plot([x0 - 0.05, x0 + 0.05], [0, 0], "-", color="k", lw=3)  # the fixed end
            ax.plot([x0 + d / 2], [-y], **SHOCK)
        else:  # sliding: hanging part s in [1 - y, 1] below the hole, s at depth s - (1 - y)
            hanging = marks[marks >= 1 - y]
            ax.plot([x0, x0], [0, -y], "-", color="tab:blue", lw=2)
            if frames:
                ax.plot(x0 + node_x, node_y, ".", color="k", ms=3)
            else:
                ax.plot(np.full(len(hanging), x0), -(hanging - (1 - y)), ".", color="k", ms=4)
            heap(ax, x0 - 0.2, 0.0, 1 - y)
            ax.plot([x0], [0], **SHOCK)
        ax.text(x0, 1.08 if problem != "sliding" else 0.32, f"$t/t_0$={xi[k]:.3f}\n$\\eta$={eta[k]:.3f}",
                ha="center", fontsize=7.5)
    if problem in ("falling", "sliding"):
        ax.axhline(0, color="k", lw=0.8)  # the table
    ax.set_aspect("equal")
    ax.set_xlim(-0.45, gap * (count - 1) + 0.3)
    ax.set_ylim({"falling": (-0.15, 1.3), "folded": (-1.1, 1.3), "sliding": (-1.1, 0.5)}[problem])
    ax.set_ylabel("height / $\\ell$")
    ax.set_xticks([])
    how = {"falling": "moving part blue, heap on the table grey, contact shock red",
           "folded": "moving arm blue, resting arm grey, fold red (arms on one line, drawn apart)",
           "sliding": "hanging part blue, heap on the table grey, shock at the hole red"}[problem]
    dots = ("dots: the solver's nodes at its frames" if frames else
            "placed by the run's front position $s_0(t)$ (the string stays straight); "
            "dots: material points every $0.1\\,\\ell$")
    ax.set_title(f"{problem.capitalize()} chain, $f={f:g}$, on the string solver with front tracking: {how}\n{dots}",
                 fontsize=8)
    fig.tight_layout()
    return save(fig, out_dir, f"{problem}_snapshots.png", DPI)


AGREEMENT = (("rel_diff_string_reduced", "string vs reduced ODE", "x"),
             ("rel_diff_reduced_quadrature", "reduced ODE vs quadrature", "o"),
             ("rel_diff_string_quadrature", "string vs quadrature", "+"),
             ("energy_residual_string", "string: energy ledger residual (relative)", "s"))
# The bounds tests/problems/test_canonical_job.cpp holds each quantity to, drawn on its own panel.
STOP_TIME_BOUND = 1e-9   # string vs ODE and string vs quadrature (reduced ODE vs quadrature: 1e-10)
LEDGER_BOUND = 1e-7      # the string run's energy ledger


def agreement_figure(rows, out_dir):
    """Two panels on one row of labels: the three-way differences of the stop times against their test bound,
    and, apart (another quantity, another bound), the string run's energy-ledger residual."""
    fig, (ax1, ax2) = plt.subplots(2, 1, figsize=(8, 6.2), sharex=True, dpi=DPI,
                                   gridspec_kw={"height_ratios": [1.5, 1]})
    labels = [f"{r['problem']}\n$f$={r['f']:g}" for r in rows]
    xs = range(len(rows))
    tiny = 1e-17  # exact agreement drawn at the bottom of the log axis
    colors = plt.rcParams["axes.prop_cycle"].by_key()["color"]
    for (key, label, marker), color in zip(AGREEMENT, colors):
        ax = ax2 if key == "energy_residual_string" else ax1
        ax.semilogy(xs, [max(r[key], tiny) for r in rows], marker, ms=6, mfc="none", color=color, label=label)
    for ax, bound, text, bottom in ((ax1, STOP_TIME_BOUND, "test bound, string vs ODE and vs quadrature", 1e-16),
                                    (ax2, LEDGER_BOUND, "test bound, energy ledger", 1e-16)):
        ax.axhline(bound, color="tab:red", lw=0.8, ls="--")
        ax.text(len(rows) - 0.5, bound * 1.6, text, ha="right", va="bottom", fontsize=7, color="tab:red")
        ax.set_ylim(bottom, bound * 100)
        ax.grid(alpha=0.3, which="major")
        ax.legend(fontsize=7, loc="upper left")
    ax1.set_ylabel("relative difference of $t_{\\rm stop}$")
    ax2.set_ylabel("relative residual")
    ax2.set_xticks(list(xs))
    ax2.set_xticklabels(labels, fontsize=7)
    ax1.set_title(f"Stop times $t_{{\\rm stop}}$ three ways, and the string run's energy ledger "
                  f"(string solver: {rows[0]['nodes']:g} nodes)", fontsize=10)
    fig.tight_layout()
    return save(fig, out_dir, "agreement.png", DPI)


def scene_parameters(scene_path):
    """(f, length, g) of a scene with a heap under vertical gravity, from its TOML file."""
    import tomllib
    try:
        with open(scene_path, "rb") as fh:
            scene = tomllib.load(fh)
    except OSError as e:
        raise RunError(f"--scene '{scene_path}': cannot read it: {e.strerror}") from e
    except tomllib.TOMLDecodeError as e:
        raise RunError(f"--scene '{scene_path}': not a valid TOML file ({e})") from e
    try:
        f = scene["effects"]["heap"][0]["f"]
        length = scene["string"]["length"]
        g = -scene["effects"]["gravity"]["g"][1]
    except (KeyError, IndexError, TypeError) as e:
        raise RunError(f"--scene '{scene_path}': needs [string] length, [effects.gravity] g and an "
                       f"[[effects.heap]] with f (missing {e})") from None
    if not (length > 0 and g > 0):
        raise RunError(f"--scene '{scene_path}': needs length > 0 and gravity pointing down (-y): length = "
                       f"{length}, g = {-g}")
    return float(f), float(length), float(g)


def read_scene(root, scene_path):
    """The scene's parameters (f, length, g), its run DIR/<scene file stem> and the reduced falling chain at
    the same f (figure_data/falling_f<f>_ode.csv, None if `chainsim canonical` did not run that f)."""
    f, ell, g = scene_parameters(scene_path)
    run_dir = os.path.join(root, os.path.splitext(os.path.basename(scene_path))[0])
    how = f"(run the scene with `chainsim run {scene_path} --out {run_dir}`)"
    if not os.path.isdir(run_dir):
        raise RunError(f"--scene: {run_dir} does not exist {how}")
    run = load_run(run_dir)
    if run.nodes is None or not run.fronts or run.fronts[0].positions() is None:
        raise RunError(f"{run_dir}: the scene figure needs nodes.csv and a front's position in series.csv {how}")
    ode = read_table(os.path.join(root, "figure_data", f"falling_f{f:.2f}_ode.csv"))
    return (f, ell, g), run, ode


def scene_figure(scene, out_dir):
    """A general scene with a heap on a table (read_scene): nodes at several times, contact path, length
    above the table."""
    (f, ell, g), run, ode = scene
    stem = run.name
    frames, front = run.nodes, run.fronts[0]
    t0 = math.sqrt(2 * ell / g)
    picks = choose_times(frames.times, count=6)  # evenly spaced in time: no two snapshots nearly the same
    fig, (ax1, ax2) = plt.subplots(1, 2, figsize=(12, 4.6), gridspec_kw={"width_ratios": [1, 1]}, dpi=DPI)
    for color, k in zip(time_colors(len(picks)), picks):
        x = frames.positions(k)
        ax1.plot(x[:, 0], x[:, 1], ".-", color=color, ms=3, lw=1, label=f"$t/t_0$ = {frames.times[k] / t0:.3f}")
    ts, contact = run.series["t"], front.positions()
    ax1.plot(contact[[0, -1], 0], contact[[0, -1], 1], **SHOCK)
    ax1.plot(contact[:, 0], contact[:, 1], "-", color="tab:red", lw=3, alpha=0.5,
             label="path of the contact (shock):\nthe landed chain lies there")
    ax1.axhline(0, color="k", lw=0.8)
    ax1.set_aspect("equal")
    xs = np.concatenate([frames.positions(k)[:, 0] for k in picks] + [contact[:, 0]])
    pad = 0.05 * ell
    ax1.set_xlim(xs.min() - pad, xs.max() + pad)  # the chain's extent, not the length: no empty half
    ax1.set_xlabel("x (m)")
    ax1.set_ylabel("y (m)")
    ax1.legend(fontsize=7, loc="upper left", bbox_to_anchor=(1.02, 1.0), borderaxespad=0)  # beside: hides nothing
    ax1.set_title("the string's nodes at several times", fontsize=9)
    ax2.plot(ts / t0, front.s0 / ell, "-", label="length above the table, string")
    ax2.plot(ts / t0, contact[:, 0] / ell, "-", label="contact position $x_0$ on the table")
    if ode is not None:
        ax2.plot(ode["xi"], ode["eta"], "--", color="k", lw=1,
                 label="reduced model (vertical chain, same $f$): $y/\\ell$; $x_0 \\equiv 0$")
    ax2.set_xlabel("$t/t_0$")
    ax2.set_ylabel("length / $\\ell$")
    ax2.grid(alpha=0.3)
    ax2.legend(fontsize=7)
    fig.suptitle(f"A general scene, {stem.replace('_', ' ')} ($f={f:g}$), on the string solver with front tracking:\n"
                 "the chain is curved and its contact slides along the table, which the reduced model cannot describe",
                 fontsize=10)
    fig.tight_layout()
    return save(fig, out_dir, f"{stem}.png", DPI)


def canonical_figures(root, out_dir=None, scene=None):
    """Every figure of `chainsim canonical --out root` (see the module's list); returns the paths written.
    Everything is read before anything is drawn: a missing or malformed file raises RunError and nothing
    is written."""
    data_dir = os.path.join(root, "figure_data")
    out_dir = out_dir or os.path.join(root, "figures")
    rows = summary_rows(root)
    fall_times = read_fall_times(data_dir)
    data = {}
    for problem in PROBLEMS:
        fs = [r["f"] for r in rows if r["problem"] == problem]
        if not fs:
            raise RunError(f"{os.path.join(root, 'summary.csv')}: no row for the {problem} chain")
        data[problem] = {f: curves(data_dir, problem, f) for f in fs}
    lacking = [key for key, _, _ in AGREEMENT if key not in rows[0]]
    if lacking:
        raise RunError(f"{os.path.join(root, 'summary.csv')}: lacks the column(s) {', '.join(lacking)}")
    scene_data = read_scene(root, scene) if scene else None
    node_frames = {}  # the string's nodes of the snapshot runs (written by chainsim canonical since it records them)
    for problem in PROBLEMS:
        f = 0.83 if 0.83 in data[problem] else list(data[problem])[-1]
        path = os.path.join(data_dir, f"{problem}_f{f:.2f}_string_nodes.csv")
        node_frames[problem] = read(path, ("t", "node", "s", "x", "y")) if os.path.exists(path) else None

    written = [fall_time_figure(fall_times, out_dir)]
    written += [problem_figure(data[p], out_dir, p, rows[0]["nodes"]) for p in PROBLEMS]
    for problem in PROBLEMS:
        f = 0.83 if 0.83 in data[problem] else list(data[problem])[-1]
        written.append(snapshot_figure(data[problem][f][2], out_dir, problem, f, nodes=node_frames[problem],
                                       chain_nodes=int(rows[0]["nodes"])))
    written.append(agreement_figure(rows, out_dir))
    if scene_data:
        written.append(scene_figure(scene_data, out_dir))
    return written
