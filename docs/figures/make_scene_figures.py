#!/usr/bin/python3
"""Figures of docs/scenes.md: one PNG per example scene, from `chainsim run` outputs.

Usage: /usr/bin/python3 docs/figures/make_scene_figures.py RESULTS_DIR
where RESULTS_DIR/<scene>/ holds the outputs of
    build/chainsim run cases/scenes/<scene>.toml --out RESULTS_DIR/<scene>
for shaken_chain, travelling_loop, whip_crack, pendulum_release and folded_chain_ends_apart (string scenes) and falling_chain,
folded_chain, sliding_chain, swinging_sliding_chain, tilted_falling_chain and curved_falling_chain (scenes
with fronts), and
RESULTS_DIR/<scene>_reduced/ the same canonical scenes run with model = "reduced".
docs/figures/run_scene_figures.sh RESULTS_DIR does all of it. Writes docs/figures/scene_<scene>.png: the
string at several times, the quantity that scene is about, and its energy ledger.
"""
import csv
import json
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
    space_axes(ax, title, 10, equal)


def space_axes(ax, title, title_size, equal=True):
    """An x-y panel of the string's shapes."""
    if equal:
        ax.set_aspect("equal")
    ax.set_xlabel("x (m)")
    ax.set_ylabel("y (m)")
    ax.set_title(title, fontsize=title_size)
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


# --- scenes with fronts: nodes.csv holds the moving nodes (t, node, s, x, y), series.csv the samples
# (t, s0_k, s0dot_k, front_k_x, front_k_y, K, V, W_*, ...), stats.json the fronts that were built.

def front_frames(root):
    """{t: [(node, s, x, y), ...]} of the moving nodes, sorted by time and node."""
    by_t = defaultdict(list)
    for r in read_rows(os.path.join(root, "nodes.csv")):
        by_t[float(r["t"])].append((int(r["node"]), float(r["s"]), float(r["x"]), float(r["y"])))
    return {t: sorted(v) for t, v in sorted(by_t.items())}


def series(root):
    rows = read_rows(os.path.join(root, "series.csv"))
    return {k: [float(r[k]) for r in rows] for k in rows[0]}


def nearest(ts, t):
    return min(range(len(ts)), key=lambda i: abs(ts[i] - t))


def front_shapes(ax, root, times, title, aside=0.0, stagger=0.0):
    """The moving string at several times, with its partial link to each heap's front (from the samples)
    and the heaps: a table for a heap on a plane, a hole for a pinned one. `aside`: the part beyond a
    fold is drawn shifted by this much in x (the two arms of a fold lie on one line). `stagger`: each
    later snapshot is drawn this much further right (motions along one vertical line)."""
    data, ser = front_frames(root), series(root)
    times = sorted({min(data, key=lambda s: abs(s - want)) for want in times} | {list(data)[-1]})
    with open(os.path.join(root, "stats.json")) as fh:
        fronts = json.load(fh)["fronts"]
    cmap = plt.get_cmap("viridis")
    keys = list(data)
    for k, want in enumerate(times):
        t = min(keys, key=lambda s: abs(s - want))
        pts = data[t]
        i = nearest(ser["t"], t)
        color = cmap(k / max(1, len(times) - 1))
        xs, ys = [], []
        for q, f in enumerate(fronts):
            if f["kind"] == "fold":
                s_fold = ser[f"s0_{q}"][i]
                xs = [p[2] + (aside if p[1] > s_fold else 0.0) for p in pts]
                ys = [p[3] for p in pts]
        if not xs:
            xs, ys = [p[2] for p in pts], [p[3] for p in pts]
        for q, f in enumerate(fronts):  # partial links to the heaps' fronts
            if f["kind"] == "heap":
                fx, fy = ser[f"front_{q}_x"][i], ser[f"front_{q}_y"][i]
                if f["side"] == "end":
                    xs, ys = xs + [fx], ys + [fy]
                else:
                    xs, ys = [fx] + xs, [fy] + ys
        xs = [x + k * stagger for x in xs]
        ax.plot(xs, ys, "-", lw=1.2, color=color, label=f"t = {t:.3g} s")
        if stagger:
            ax.plot(xs[0], ys[0], "o", ms=3, color=color)
    shift = (len(times) - 1) * stagger
    for q, f in enumerate(fronts):
        if f["kind"] != "heap":
            continue
        px, py = f["point"][0], f["point"][1]
        if f["on_plane"]:
            xs = ser[f"front_{q}_x"]
            lo, hi = min(xs + [px]) - 0.25, max(xs + [px]) + 0.25 + shift
            ax.plot([lo, hi], [py, py], "k-", lw=2.5, alpha=0.6)
            ax.plot([min(xs), max(xs)], [py, py], "-", color="tab:brown", lw=5, alpha=0.7,
                    label="heap laid on the table")
        else:
            ax.plot([px - 0.6, px - 0.03], [py, py], "k-", lw=2.5, alpha=0.6)
            ax.plot([px + 0.03, px + 0.3 + shift], [py, py], "k-", lw=2.5, alpha=0.6)
            ax.plot([px + k * stagger for k in range(len(times))], [py] * len(times), "v", color="tab:brown", ms=6,
                    label="hole (pinned front)")
    space_axes(ax, title, 9)


def front_ledger(ax, root):
    ser = series(root)
    e0 = ser["K"][0] + ser["V"][0]
    ax.plot(ser["t"], [k + v - e0 for k, v in zip(ser["K"], ser["V"])], label="K + V - (K0 + V0)")
    ax.plot(ser["t"], ser["W_shocks"], "--", label="W_shocks (dissipated at the shock)")
    if max(abs(w) for w in ser["W_heaps"]) > 0:
        ax.plot(ser["t"], ser["W_heaps"], ":", label="W_heaps (external shock at the heap)")
    if max(abs(w) for w in ser["W_remesh"]) > 1e-9:
        ax.plot(ser["t"], ser["W_remesh"], "-.", label="W_remesh")
    ax.plot(ser["t"], [a + b + c + d for a, b, c, d in zip(ser["W_applied"], ser["W_shocks"], ser["W_heaps"], ser["W_remesh"])],
            "k--", lw=0.8, label="sum of the works")
    resid = max(abs(r) for r in ser["energy_residual"])
    decorate(ax, "t (s)", "J", f"energy ledger (max |residual| = {resid:.1e} J)")


def reduced_overlay(ax, root, to_s0, label="reduced ODE"):
    path = root + "_reduced"
    if not os.path.exists(os.path.join(path, "series.csv")):
        return
    rows = read_rows(os.path.join(path, "series.csv"))
    ax.plot([float(r["t"]) for r in rows], [to_s0(float(r["y"])) for r in rows], "k:", lw=2, label=label)


def front_position(ax, root, name, to_s0, title):
    ser = series(root)
    ax.plot(ser["t"], ser["s0_0"], lw=2, alpha=0.7, label=f"{name} front s0 (string solver)")
    reduced_overlay(ax, root, to_s0)
    decorate(ax, "t (s)", "s0 (m)", title)


def falling_chain(root, ax):
    front_shapes(ax[0], root, [0, 0.15, 0.25, 0.32, 0.36], "falling chain onto a table, f = 0.5 (time runs right)",
                 stagger=0.15)
    front_position(ax[1], root, "heap_end", lambda y: y,
                   "material above the table = s0: the reduced ODE is exact")


def folded_chain(root, ax):
    front_shapes(ax[0], root, [0, 0.2, 0.35, 0.45, 0.52], "folded chain, f = 0.5 (falling arm 3 cm aside; time runs right)",
                 aside=0.03, stagger=0.15)
    front_position(ax[1], root, "fold", lambda y: y, "resting arm = s0 of the fold")


def sliding_chain(root, ax):
    front_shapes(ax[0], root, [0, 0.25, 0.4, 0.5], "sliding chain through a hole, f = 0.5 (time runs right)",
                 stagger=0.15)
    front_position(ax[1], root, "heap_start", lambda y: 1.0 - y, "heap = s0: the hanging part is 1 - s0")


def swinging_sliding_chain(root, ax):
    front_shapes(ax[0], root, [0, 0.15, 0.3, 0.4, 0.47, 0.52], "sliding chain released 30 deg off the vertical")
    data, ser = front_frames(root), series(root)
    ts = list(data)
    angle = [math.degrees(math.atan2(data[t][-1][2], -data[t][-1][3])) for t in ts]
    ax[1].plot(ser["t"], [1.0 - s for s in ser["s0_0"]], label="hanging length 1 - s0 (m)")
    ax[1].plot(ts, [a / 100 for a in angle], label="free end's angle from the vertical / 100 (deg)")
    decorate(ax[1], "t (s)", "", "it swings while it slides out of the heap")


def chain_onto_table(root, ax, title, subtitle):
    front_shapes(ax[0], root, [0, 0.15, 0.25, 0.31, 0.345, 0.36], title)
    ser = series(root)
    ax[1].plot(ser["t"], ser["s0_0"], label="material above the table s0 (m)")
    ax[1].plot(ser["t"], ser["front_0_x"], label="contact position x (m)")
    decorate(ax[1], "t (s)", "m", subtitle)


def tilted_falling_chain(root, ax):
    chain_onto_table(root, ax, "chain falling tilted 25 deg onto a table, f = 0.5",
                     "the contact slides along the table as the chain comes down")


def curved_falling_chain(root, ax):
    chain_onto_table(root, ax, "chain falling curved onto a table, f = 0.5",
                     "the contact slides along the table as the arc comes down")


def tight_fold_end_height(f, length, y0, times, g=9.81):
    """The free end's height l - 2 y(t) in the paper's folded chain (tight fold, F = 0), integrated here
    by RK4 from y'' = g/2 + (1 - f) y'^2 / (2 (l - y)) (an independent check of the scene, for the plot)."""
    def acc(y, v):
        return 0.5 * g + (1 - f) * v * v / (2 * (length - y))
    out, y, v, t, dt = [], y0, 0.0, 0.0, 1e-5
    for want in times:
        while t < want - 1e-12:
            step = min(dt, want - t)
            k1 = (v, acc(y, v))
            k2 = (v + 0.5 * step * k1[1], acc(y + 0.5 * step * k1[0], v + 0.5 * step * k1[1]))
            k3 = (v + 0.5 * step * k2[1], acc(y + 0.5 * step * k2[0], v + 0.5 * step * k2[1]))
            k4 = (v + step * k3[1], acc(y + step * k3[0], v + step * k3[1]))
            y += step * (k1[0] + 2 * k2[0] + 2 * k3[0] + k4[0]) / 6
            v += step * (k1[1] + 2 * k2[1] + 2 * k3[1] + k4[1]) / 6
            t += step
        out.append(length - 2 * y)
    return out


def folded_chain_ends_apart(root, ax):
    data = frames(root)
    shapes(ax[0], data, [0, 0.15, 0.25, 0.32, 0.37, 0.4, 0.42], mark=-1,
           title="folded chain, ends 4 cm apart (x stretched)", equal=False)
    ts = list(data)
    end = [data[t][-1][2] for t in ts]
    first = data[ts[0]]
    length = sum(math.hypot(b[1] - a[1], b[2] - a[2]) for a, b in zip(first, first[1:]))  # links are exact
    top = end[0]
    y0 = (length - top) / 2  # the tight fold whose free end starts as high
    ax[1].plot(ts, end, "o", ms=3, label="string solver, resolved bight")
    for f, style in [(0.0, "-"), (0.5, "--"), (1.0, ":")]:
        ax[1].plot(ts, tight_fold_end_height(f, length, y0, ts), style, lw=1.2, label=f"tight fold, f = {f:g}")
    decorate(ax[1], "t (s)", "free end height (m)", "it follows the energy-conserving fold (f = 0)")


def main():
    root = sys.argv[1]
    for scene, draw, fronts in [("shaken_chain", shaken_chain, False), ("travelling_loop", travelling_loop, False),
                                ("whip_crack", whip_crack, False), ("pendulum_release", pendulum_release, False),
                                ("falling_chain", falling_chain, True), ("folded_chain", folded_chain, True),
                                ("sliding_chain", sliding_chain, True),
                                ("swinging_sliding_chain", swinging_sliding_chain, True),
                                ("tilted_falling_chain", tilted_falling_chain, True),
                                ("curved_falling_chain", curved_falling_chain, True),
                                ("folded_chain_ends_apart", folded_chain_ends_apart, False)]:
        if not os.path.exists(os.path.join(root, scene)):
            print("skipped", scene, "(no results)")
            continue
        fig, ax = plt.subplots(1, 3, figsize=(15, 4.2), gridspec_kw={"width_ratios": [1.1, 1.2, 1.2]})
        draw(os.path.join(root, scene), ax)
        (front_ledger if fronts else ledger)(ax[2], os.path.join(root, scene))
        fig.suptitle(f"cases/scenes/{scene}.toml", fontsize=11)
        fig.tight_layout()
        out = os.path.join(HERE, f"scene_{scene}.png")
        fig.savefig(out, dpi=110)
        plt.close(fig)
        print("wrote", out)


if __name__ == "__main__":
    main()
