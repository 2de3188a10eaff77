#!/usr/bin/python3
"""Figures of docs/string_solver.md from `chainsim run` outputs.

Usage: /usr/bin/python3 docs/figures/make_string_figures.py RESULTS_DIR
where RESULTS_DIR/<scene>/ holds the outputs of `chainsim run cases/scenes/<scene>.toml --out RESULTS_DIR/<scene>`
for hanging_chain, shaken_chain, damped_catenary and travelling_loop. Writes docs/figures/string_scenes.png.
"""
import os
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..", "python"))
from chainsim_plot.figures import time_colors  # noqa: E402
from chainsim_plot.readers import Frames, read_table  # noqa: E402


def frames(path):
    """{t: [(node, x, y), ...]} from nodes.csv."""
    f = Frames(read_table(path))
    return {t: [(int(i), x, y) for i, (x, y) in zip(f.nodes(k), f.positions(k))] for k, t in enumerate(f.times)}


def energy(path):
    table = read_table(path)
    return table["t"], table["drift"]


def draw(ax, data, picks, closed=False, title="", equal=True):
    times = list(data)
    colors = time_colors(len(picks))
    for k, i in enumerate(picks):
        t = times[min(i, len(times) - 1)]
        pts = data[t]
        xs = [p[1] for p in pts] + ([pts[0][1]] if closed else [])
        ys = [p[2] for p in pts] + ([pts[0][2]] if closed else [])
        ax.plot(xs, ys, "-o", ms=1.5, lw=1, color=colors[k], label=f"t = {t:g} s")
    if equal:
        ax.set_aspect("equal")
    ax.set_title(title, fontsize=10)
    ax.legend(fontsize=6, loc="best")
    ax.grid(alpha=0.3)


def main():
    if len(sys.argv) != 2:
        sys.stderr.write("usage: make_string_figures.py RESULTS_DIR   (RESULTS_DIR/<scene>/ from chainsim run, "
                         "for hanging_chain, shaken_chain, damped_catenary, travelling_loop)\n")
        sys.exit(2)
    root = sys.argv[1]
    out = os.path.join(os.path.dirname(os.path.abspath(__file__)), "string_scenes.png")
    fig, axes = plt.subplots(1, 5, figsize=(18, 4.2), gridspec_kw={"width_ratios": [0.7, 0.7, 1.3, 1.1, 1.3]})
    draw(axes[0], frames(os.path.join(root, "hanging_chain", "nodes.csv")), [0, 8, 16, 24, 32],
         title="hanging chain, mode 1", equal=False)
    draw(axes[1], frames(os.path.join(root, "shaken_chain", "nodes.csv")), [0, 40, 80, 120, 160, 200],
         title="shaken top, 3 rad/s", equal=False)
    draw(axes[2], frames(os.path.join(root, "damped_catenary", "nodes.csv")), [0, 5, 10, 20, 160],
         title="damped string -> catenary")
    draw(axes[3], frames(os.path.join(root, "travelling_loop", "nodes.csv")), [0, 100, 250], closed=True,
         title="loop travelling along itself")
    for scene in ["hanging_chain", "shaken_chain", "damped_catenary", "travelling_loop"]:
        t, d = energy(os.path.join(root, scene, "energy.csv"))
        axes[4].semilogy(t, [abs(x) + 1e-18 for x in d], label=scene)
    axes[4].set_title("ledger |K+V-(K0+V0)-W_applied| (J)", fontsize=10)
    axes[4].set_xlabel("t (s)")
    axes[4].legend(fontsize=6)
    axes[4].grid(alpha=0.3, which="both")
    fig.tight_layout()
    fig.savefig(out, dpi=120)
    print("wrote", out)


if __name__ == "__main__":
    main()
