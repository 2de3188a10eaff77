#!/usr/bin/python3
"""Figures of docs/scenes.md: one PNG per example scene, from `chainsim run` outputs.

Usage: /usr/bin/python3 docs/figures/make_scene_figures.py RESULTS_DIR
where RESULTS_DIR/<scene>/ holds the outputs of
    build/chainsim run cases/scenes/<scene>.toml --out RESULTS_DIR/<scene>
for shaken_chain, travelling_loop, whip_crack and pendulum_release. Writes docs/figures/scene_<scene>.png:
the string at several times, the quantity that scene is about, and its energy ledger.
"""
import csv
import math
import os
import sys
from collections import defaultdict

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

HERE = os.path.dirname(os.path.abspath(__file__))


def read_rows(path):
    with open(path, newline="") as fh:
        return list(csv.DictReader(fh))


def frames(root):
    """{t: [(node, x, y, vx, vy), ...]} sorted by time and node."""
    by_t = defaultdict(list)
    for r in read_rows(os.path.join(root, "nodes.csv")):
        by_t[float(r["t"])].append((int(r["node"]), float(r["x"]), float(r["y"]), float(r["vx"]), float(r["vy"])))
    return {t: sorted(v) for t, v in sorted(by_t.items())}


def shapes(ax, data, times, closed=False, mark=None, title="", equal=True):
    cmap = plt.get_cmap("viridis")
    keys = list(data)
    for k, want in enumerate(times):
        t = min(keys, key=lambda s: abs(s - want))
        pts = data[t]
        xs = [p[1] for p in pts] + ([pts[0][1]] if closed else [])
        ys = [p[2] for p in pts] + ([pts[0][2]] if closed else [])
        color = cmap(k / max(1, len(times) - 1))
        ax.plot(xs, ys, "-", lw=1.2, color=color, label=f"t = {t:.3g} s")
        if mark is not None:
            ax.plot(pts[mark][1], pts[mark][2], "o", ms=4, color=color)
    if equal:
        ax.set_aspect("equal")
    ax.set_xlabel("x (m)")
    ax.set_ylabel("y (m)")
    ax.set_title(title, fontsize=10)
    ax.legend(fontsize=6, loc="best")
    ax.grid(alpha=0.3)


def decorate(ax, xlabel, ylabel, title, title_size=10):
    ax.set_xlabel(xlabel)
    ax.set_ylabel(ylabel)
    ax.set_title(title, fontsize=title_size)
    ax.legend(fontsize=7)
    ax.grid(alpha=0.3)


def ledger(ax, root):
    rows = read_rows(os.path.join(root, "energy.csv"))
    t = [float(r["t"]) for r in rows]
    ax.plot(t, [float(r["K"]) + float(r["V"]) - float(rows[0]["K"]) - float(rows[0]["V"]) for r in rows],
            label="K + V - (K0 + V0)")
    ax.plot(t, [float(r["W_applied"]) for r in rows], "--", label="W_applied")
    drift = max(abs(float(r["drift"])) for r in rows)
    decorate(ax, "t (s)", "J", f"energy ledger (max |drift| = {drift:.1e} J)")


def tip_speed(data, node):
    ts = list(data)
    return ts, [math.hypot(data[t][node][3], data[t][node][4]) for t in ts]


def speed_panel(ax, ts, speed, reference, reference_label, title):
    """The tip speed against a reference speed, its maximum marked."""
    ax.plot(ts, speed, label="tip speed")
    ax.plot(ts, reference, "--", label=reference_label)
    k = max(range(len(speed)), key=lambda i: speed[i])
    ax.annotate(f"{speed[k]:.1f} m/s at t = {ts[k]:.3g} s", (ts[k], speed[k]), fontsize=7,
                xytext=(-90, -10), textcoords="offset points")
    decorate(ax, "t (s)", "m/s", title)


def shaken_chain(root, ax):
    data = frames(root)
    shapes(ax[0], data, [0, 1.1, 2.2, 3.2, 4.2], title="shaken top: x0 + A(1 - cos wt), A = 2 cm, w = 3 rad/s "
           "(x stretched)", equal=False)
    ts = list(data)
    ax[1].plot(ts, [data[t][0][1] for t in ts], label="top (driven)")
    ax[1].plot(ts, [data[t][-1][1] for t in ts], label="free end")
    decorate(ax[1], "t (s)", "x (m)", "driven top and free end: forcing at 3 rad/s beats with mode 1 (3.77 rad/s)", 9)


def travelling_loop(root, ax):
    data = frames(root)
    shapes(ax[0], data, [0, 0.4, 0.8, 1.2], closed=True, mark=0,
           title="loop at 2 m/s: the shape stays, node 0 (dot) travels")
    rows = read_rows(os.path.join(root, "tension.csv"))
    by_t = defaultdict(list)
    for r in rows:
        by_t[float(r["t"])].append((float(r["s_mid"]), float(r["T"])))
    for want in [0, 2.5, 5]:
        t = min(by_t, key=lambda s: abs(s - want))
        s, T = zip(*sorted(by_t[t]))
        ax[1].plot(s, T, ".", ms=3, label=f"t = {t:g} s")
    ax[1].axhline(0.1 * 2.0 ** 2, color="k", lw=0.8, ls=":", label="lambda v^2 = 0.4 N")
    ax[1].set_ylim(0.39, 0.41)
    decorate(ax[1], "s (m)", "T (N)", "tension along the loop")


def whip_crack(root, ax):
    data = frames(root)
    shapes(ax[0], data, [0, 0.2, 0.4, 0.5, 0.6, 0.68, 0.76], title="whip: handle swung once, A = 0.25 m, w = 8 rad/s")
    ts, speed = tip_speed(data, -1)
    speed_panel(ax[1], ts, speed, [0.25 * 8 * abs(math.sin(8 * t)) for t in ts], "hand speed A w |sin wt|",
                "the crack: the tip outruns the hand about ninefold")


def pendulum_release(root, ax):
    data = frames(root)
    shapes(ax[0], data, [0, 0.15, 0.25, 0.35, 0.42, 0.455, 0.49], title="chain released horizontally, top fixed")
    ts, speed = tip_speed(data, -1)
    speed_panel(ax[1], ts, speed, [math.sqrt(2 * 9.81 * max(0.0, -data[t][-1][2])) for t in ts],
                "free fall from the same height, sqrt(2 g |y_tip|)", "the tip falls faster than a free particle")


def main():
    root = sys.argv[1]
    for scene, draw in [("shaken_chain", shaken_chain), ("travelling_loop", travelling_loop),
                        ("whip_crack", whip_crack), ("pendulum_release", pendulum_release)]:
        fig, ax = plt.subplots(1, 3, figsize=(15, 4.2), gridspec_kw={"width_ratios": [1.1, 1.2, 1.2]})
        draw(os.path.join(root, scene), ax)
        ledger(ax[2], os.path.join(root, scene))
        fig.suptitle(f"cases/scenes/{scene}.toml", fontsize=11)
        fig.tight_layout()
        out = os.path.join(HERE, f"scene_{scene}.png")
        fig.savefig(out, dpi=110)
        plt.close(fig)
        print("wrote", out)


if __name__ == "__main__":
    main()
