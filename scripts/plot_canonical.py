#!/usr/bin/python3
"""Draws the main job's figures from the data written by `chainsim canonical --out DIR`.

Usage: /usr/bin/python3 scripts/plot_canonical.py DIR [--scene SCENE.toml]
Writes DIR/figures/*.png:
  fall_time_vs_f.png          the paper's Figs. 3b, 4b, 5b with the string solver's points
  {falling,folded,sliding}_chain.png    the paper's profiles y/l(t/t0), P/P0(t/t0): lines the reduced ODE
                              (ARKODE), open circles the exact quadrature, crosses the string solver
                              with front tracking
  {falling,folded,sliding}_snapshots.png   the string at several times, with its shock marked
  agreement.png               the three-way differences of the stop times and the string's energy ledger
With --scene (a scene run by `chainsim run SCENE --out DIR/<scene file stem>`): DIR/figures/<stem>.png,
the string's nodes at several times, the contact's path along the table, and the length above the table
beside the reduced (vertical) falling chain at the same f. Needs Debian's python3-matplotlib.
"""
import argparse
import csv
import math
import os
import tomllib

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

PROBLEMS = ("falling", "folded", "sliding")
TITLES = {
    "falling": "Falling chain, $\\eta_0=1$, stop at $\\eta=\\varepsilon=0.01$",
    "folded": "Folded chain, $\\eta_0=0$, $F=0$, stop at $\\eta=1-\\varepsilon$",
    "sliding": "Sliding chain, $\\eta_0=0.25$, stop at $\\eta=1$",
}
SHOCK = dict(marker="o", ms=9, mfc="none", mec="tab:red", mew=1.6, ls="none")  # as in docs/model.md's sketch


def read(path):
    """A CSV file as {column: list}; numbers as floats, other text kept."""
    with open(path, newline="") as fh:
        rows = list(csv.DictReader(fh))

    def value(text):
        try:
            return float(text)
        except ValueError:
            return text

    return {k: [value(r[k]) for r in rows] for k in rows[0]}


def summary_rows(root):
    table = read(os.path.join(root, "summary.csv"))
    n = len(table["problem"])
    return [{k: v[i] for k, v in table.items()} for i in range(n)]


def curves(data_dir, problem, f):
    stem = os.path.join(data_dir, f"{problem}_f{f:.2f}")
    return read(stem + "_ode.csv"), read(stem + "_exact.csv"), read(stem + "_string.csv")


def every(values, count):
    """About `count` evenly spaced entries of a list, always with the last one."""
    step = max(1, len(values) // count)
    return values[::step] + ([values[-1]] if (len(values) - 1) % step else [])


def spread(xs, ys, count, phase):
    """Indices of about `count` points evenly spaced along the curve (xs, ys) (arc length in axis units
    normalized by each range), shifted by `phase` (0..1) of a spacing, so that two marker sets interleave."""
    sx = (max(xs) - min(xs)) or 1.0
    sy = (max(ys) - min(ys)) or 1.0
    arc = [0.0]
    for k in range(1, len(xs)):
        arc.append(arc[-1] + math.hypot((xs[k] - xs[k - 1]) / sx, (ys[k] - ys[k - 1]) / sy))
    picks, j = [], 0
    for m in range(count + 1):
        target = arc[-1] * min(1.0, (m + phase) / count)
        while j + 1 < len(arc) and arc[j + 1] <= target:
            j += 1
        if not picks or picks[-1] != j:
            picks.append(j)
    return picks


def model_legend(ax, fs, colors, nodes, **kwargs):
    """One entry per f (its colour) and one per model (its marker)."""
    from matplotlib.lines import Line2D
    handles = [Line2D([], [], color=c, lw=2, label=f"$f={f:g}$") for f, c in zip(fs, colors)]
    handles += [Line2D([], [], color="k", lw=1.3, label="reduced ODE"),
                Line2D([], [], color="k", marker="o", mfc="none", ls="none", label="quadrature"),
                Line2D([], [], color="k", marker="x", ls="none", label=f"string solver, {nodes:g} nodes")]
    ax.legend(handles=handles, fontsize=7, **kwargs)


def fall_time_figure(data_dir, out_dir):
    d = read(os.path.join(data_dir, "fall_time_vs_f.csv"))
    s = read(os.path.join(data_dir, "fall_time_string.csv"))
    fig, axes = plt.subplots(1, 3, figsize=(13, 3.8))
    panels = [
        ("(a) falling chain, $\\eta_0=1$", [("falling", "")], "falling"),
        ("(b) folded chain, $\\eta_0=0$", [("folded", "")], "folded"),
        ("(c) sliding chain", [("sliding0", "$\\eta_0=0$"), ("sliding25", "$\\eta_0=0.25$"),
                               ("sliding75", "$\\eta_0=0.75$")], "sliding0"),
    ]
    for ax, (title, series, string_key) in zip(axes, panels):
        for key, label in series:
            line, = ax.plot(d["f"], d[key + "_exact"], "-", label=f"quadrature {label}")
            ax.plot(d["f"], d[key + "_ode"], "o", ms=3.5, mfc="none", color=line.get_color(),
                    label=f"reduced ODE ($\\varepsilon=10^{{-6}}$) {label}")
            if key == string_key:
                ax.plot(s["f"], s[key + "_string"], "x", ms=7, mew=1.5, color="k",
                        label=f"string solver ($\\varepsilon=10^{{-4}}$) {label}")
        ax.set_xlabel("$f$")
        ax.set_ylabel("$t_f/t_0$")
        ax.set_title(title)
        ax.grid(alpha=0.3)
        ax.legend(fontsize=7)
    fig.tight_layout()
    fig.savefig(os.path.join(out_dir, "fall_time_vs_f.png"), dpi=130)
    plt.close(fig)


def problem_figure(data_dir, out_dir, problem, fs, nodes):
    fig, (ax1, ax2) = plt.subplots(1, 2, figsize=(11, 4.2))
    # The paper draws the folded chain's weight as ln(1 + P/P0) (its caption: P_f = 3 P0 <-> ln 4).
    log_p = problem == "folded"
    colors = [f"C{k}" for k in range(len(fs))]
    for f, color in zip(fs, colors):
        ode, ref, string = curves(data_dir, problem, f)
        for ax, key in ((ax1, "eta"), (ax2, "P_over_P0")):
            tr = (lambda v: math.log1p(v)) if key == "P_over_P0" and log_p else (lambda v: v)
            ax.plot(ode["xi"], [tr(v) for v in ode[key]], "-", lw=1.3, color=color)
            for data, marker, phase in ((ref, "o", 0.0), (string, "x", 0.5)):
                ys = [tr(v) for v in data[key]]
                # On the falling chain's log axis the markers are spread along log P.
                along = [math.log10(max(v, 1e-2)) for v in ys] if problem == "falling" and key != "eta" else ys
                picks = spread(data["xi"], along, 14, phase)
                ax.plot([data["xi"][k] for k in picks], [ys[k] for k in picks], marker, ms=5, mew=1.2,
                        mfc="none", color=color)
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
    fig.savefig(os.path.join(out_dir, f"{problem}_chain.png"), dpi=130)
    plt.close(fig)


def snapshot_figure(data_dir, out_dir, problem, f, count=7):
    """The string at `count` times from the start to the stop, side by side (one column per time).

    The string run's front position s0(t) (the height y = eta l of the moving part) places the string:
    in the paper's geometry it stays straight and vertical, so the moving material s lies at a height
    fixed by s and y (see the branches below). Dots are material points every 0.1 l, the red circle
    the shock (contact, fold or hole), the grey mound the heap with its mass (1 - eta) lambda l.
    """
    string = read(os.path.join(data_dir, f"{problem}_f{f:.2f}_string.csv"))
    xi, eta = string["xi"], string["eta"]
    picks = [min(range(len(xi)), key=lambda k: abs(xi[k] - xi[-1] * j / (count - 1))) for j in range(count)]
    gap = 0.55  # horizontal distance between two snapshots (units of l)
    fig, ax = plt.subplots(figsize=(8.8, 5.6) if problem == "folded" else (11, 4.4))
    marks = [0.1 * k for k in range(11)]
    for j, k in enumerate(picks):
        x0, y = gap * j, eta[k]
        if problem == "falling":  # moving part s in [0, y] above the contact, s at height y - s
            ax.plot([x0, x0], [0, y], "-", color="tab:blue", lw=2)
            ax.plot([x0] * len([s for s in marks if s < y]), [y - s for s in marks if s < y], ".", color="k", ms=4)
            heap(ax, x0, 0.0, 1 - y)
            ax.plot([x0], [0], **SHOCK)
        elif problem == "folded":  # resting arm s in [0, y] down to the fold at depth y, moving arm s - 2y
            d = 0.04  # the arms lie on one line; drawn d apart
            ax.plot([x0, x0], [0, -y], "-", color="tab:gray", lw=2)
            ax.plot([x0 + d, x0 + d], [-y, 1 - 2 * y], "-", color="tab:blue", lw=2)
            ax.plot([x0, x0 + d], [-y, -y], "-", color="tab:blue", lw=1)
            ax.plot([x0] * len([s for s in marks if s <= y]), [-s for s in marks if s <= y], ".", color="k", ms=4)
            moving = [s for s in marks if s > y]
            ax.plot([x0 + d] * len(moving), [s - 2 * y for s in moving], ".", color="k", ms=4)
            ax.plot([x0 - 0.05, x0 + 0.05], [0, 0], "-", color="k", lw=3)  # the fixed end
            ax.plot([x0 + d / 2], [-y], **SHOCK)
        else:  # sliding: hanging part s in [1 - y, 1] below the hole, s at depth s - (1 - y)
            ax.plot([x0, x0], [0, -y], "-", color="tab:blue", lw=2)
            hanging = [s for s in marks if s >= 1 - y]
            ax.plot([x0] * len(hanging), [-(s - (1 - y)) for s in hanging], ".", color="k", ms=4)
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
    ax.set_title(f"{problem.capitalize()} chain, $f={f:g}$, on the string solver with front tracking: {how}\n"
                 "placed by the run's front position $s_0(t)$ (the string stays straight); "
                 "dots: material points every $0.1\\,\\ell$", fontsize=8)
    fig.tight_layout()
    fig.savefig(os.path.join(out_dir, f"{problem}_snapshots.png"), dpi=130)
    plt.close(fig)


def heap(ax, x, y, mass):
    """A heap of `mass` (units of lambda l) as a half-disc of area proportional to it."""
    if mass <= 1e-9:
        return
    r = math.sqrt(2 * mass / math.pi) * 0.25
    angles = [math.pi * k / 40 for k in range(41)]
    ax.fill([x + r * math.cos(a) for a in angles], [y + r * math.sin(a) for a in angles], color="0.6", lw=0)


def agreement_figure(rows, out_dir):
    fig, ax = plt.subplots(figsize=(8, 4))
    labels = [f"{r['problem']}\n$f$={r['f']:g}" for r in rows]
    xs = range(len(rows))
    tiny = 1e-17  # exact agreement drawn at the bottom of the log axis
    for key, label, marker in (("rel_diff_string_reduced", "string vs reduced ODE", "x"),
                               ("rel_diff_reduced_quadrature", "reduced ODE vs quadrature", "o"),
                               ("rel_diff_string_quadrature", "string vs quadrature", "+"),
                               ("energy_residual_string", "string: energy ledger residual (relative)", "s")):
        ax.semilogy(xs, [max(r[key], tiny) for r in rows], marker, ms=6, mfc="none", label=label)
    ax.axhline(1e-9, color="tab:red", lw=0.8, ls="--")
    ax.text(len(rows) - 0.5, 1.3e-9, "test bound string vs ODE", ha="right", fontsize=7, color="tab:red")
    ax.set_xticks(list(xs))
    ax.set_xticklabels(labels, fontsize=7)
    ax.set_ylabel("relative difference or residual")
    ax.set_ylim(1e-16, 1e-6)
    ax.grid(alpha=0.3, which="major")
    ax.legend(fontsize=7, loc="upper left")
    ax.set_title(f"Stop times $t_{{\\rm stop}}$ three ways (string solver: {rows[0]['nodes']:g} nodes)", fontsize=10)
    fig.tight_layout()
    fig.savefig(os.path.join(out_dir, "agreement.png"), dpi=130)
    plt.close(fig)


def scene_figure(root, out_dir, scene_path):
    """A general scene with a heap on a table: nodes at several times, contact path, length above the table."""
    stem = os.path.splitext(os.path.basename(scene_path))[0]
    run_dir = os.path.join(root, stem)
    with open(scene_path, "rb") as fh:
        scene = tomllib.load(fh)
    nodes = read(os.path.join(run_dir, "nodes.csv"))
    series = read(os.path.join(run_dir, "series.csv"))
    f = scene["effects"]["heap"][0]["f"]
    ell = scene["string"]["length"]
    g = -scene["effects"]["gravity"]["g"][1]
    t0 = math.sqrt(2 * ell / g)
    times = sorted(set(nodes["t"]))
    picks = every(times, 6)
    fig, (ax1, ax2) = plt.subplots(1, 2, figsize=(12, 4.6), gridspec_kw={"width_ratios": [1.25, 1]})
    cmap = plt.get_cmap("viridis")
    for j, t in enumerate(picks):
        xs = [x for x, tt in zip(nodes["x"], nodes["t"]) if tt == t]
        ys = [y for y, tt in zip(nodes["y"], nodes["t"]) if tt == t]
        color = cmap(j / max(1, len(picks) - 1))
        ax1.plot(xs, ys, ".-", color=color, ms=3, lw=1, label=f"$t/t_0$ = {t / t0:.3f}")
    ts = series["t"]
    ax1.plot([series["front_0_x"][k] for k in (0, -1)], [series["front_0_y"][k] for k in (0, -1)], **SHOCK)
    ax1.plot(series["front_0_x"], series["front_0_y"], "-", color="tab:red", lw=3, alpha=0.5,
             label="path of the contact (shock):\nthe landed chain lies there")
    ax1.axhline(0, color="k", lw=0.8)
    ax1.set_aspect("equal")
    ax1.set_xlim(-0.05, 1.05)
    ax1.set_xlabel("x (m)")
    ax1.set_ylabel("y (m)")
    ax1.legend(fontsize=7, loc="upper right")
    ax1.set_title("the string's nodes at several times", fontsize=9)
    ax2.plot([t / t0 for t in ts], [s / ell for s in series["s0_0"]], "-", label="length above the table, string")
    ax2.plot([t / t0 for t in ts], [x / ell for x in series["front_0_x"]], "-", label="contact position $x_0$ on the table")
    ode_path = os.path.join(root, "figure_data", f"falling_f{f:.2f}_ode.csv")
    if os.path.exists(ode_path):
        ode = read(ode_path)
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
    fig.savefig(os.path.join(out_dir, f"{stem}.png"), dpi=130)
    plt.close(fig)


def main():
    parser = argparse.ArgumentParser(description="Draws the figures of `chainsim canonical --out DIR`.")
    parser.add_argument("dir", help="DIR as given to chainsim canonical --out")
    parser.add_argument("--scene", help="a scene file also run with `chainsim run SCENE --out DIR/<stem>`")
    args = parser.parse_args()
    root = args.dir
    data_dir = os.path.join(root, "figure_data")
    out_dir = os.path.join(root, "figures")
    os.makedirs(out_dir, exist_ok=True)
    rows = summary_rows(root)
    fall_time_figure(data_dir, out_dir)
    for problem in PROBLEMS:
        fs = [r["f"] for r in rows if r["problem"] == problem]
        problem_figure(data_dir, out_dir, problem, fs, rows[0]["nodes"])
        snapshot_figure(data_dir, out_dir, problem, 0.83 if 0.83 in fs else fs[-1])
    agreement_figure(rows, out_dir)
    if args.scene:
        scene_figure(root, out_dir, args.scene)
    print(f"figures  {out_dir}: " + ", ".join(sorted(os.listdir(out_dir))))


if __name__ == "__main__":
    main()
