#!/usr/bin/python3
"""The steady chain fountain (docs/model.md §4.5): its closed form, the scene that starts on it, and its figures.

    /usr/bin/python3 docs/figures/fountain.py steady            # print v, the rise, the catenary's a, the length
    /usr/bin/python3 docs/figures/fountain.py scene > cases/scenes/chain_fountain.toml
    /usr/bin/python3 docs/figures/fountain.py figures RESULTS   # docs/figures/fountain_*.png

`figures` reads RESULTS/chain_fountain (the scene as it is) and RESULTS/chain_fountain_off (the same pot and floor,
16 m in the pot, started 10 % slow on the steady shape of another pot, f = -0.1: a start off the steady state);
docs/figures/run_fountain_figures.sh runs both and draws docs/figures/fountain.png and the animation.

The steady state. A chain drawn from a pot at the origin (f_p < 0: T = (1 + f_p) λ v²) and running into a heap on
the floor at (d, -H) (f_f: T = (1 - f_f) λ v²) moves along a fixed curve at the speed v on which T' = T - λ v² obeys
the statics of a hanging chain: T' - λ g y is uniform. So
    v² = g H / (f_p + f_f),   T' = λ g (y - y_c),   y_c = -f_p v² / g,
and the curve is the inverted catenary y = y_c - a cosh((x - x_c) / a) through both heaps (a, x_c from
a cosh(x_c / a) = y_c and a cosh((d - x_c) / a) = y_c + H); the top of the fountain is at y_c - a.
"""
import argparse
import math
import os
import sys

import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))

# The scene's physics: a pot at the origin whose mouth points 70 degrees above the +x axis, the floor 0.5 m below,
# pot f = -0.2, floor f = 0.6.
G = 9.81
H, THETA_DEG = 0.5, 70.0
F_POT, F_FLOOR = -0.2, 0.6
POT_CONTENT = 3.0  # m of chain in the pot at t = 0: it runs empty at t = 3.0 / v = 0.86 s
NODES = 401
POLYLINE_POINTS = 801  # vertices of the catenary in the scene (chords 1.2 mm: < 1e-7 m from the curve)


def steady(H=H, theta_deg=THETA_DEG, f_pot=F_POT, f_floor=F_FLOOR, g=G):
    """The steady fountain in closed form: speed v, y_c, the catenary's a and x_c, the rise y_c - a, where it meets
    the floor (x_floor) and the length in the air."""
    theta = math.radians(theta_deg)
    v2 = g * H / (f_pot + f_floor)
    yc = -f_pot * v2 / g
    a = yc * math.cos(theta)  # a cosh(x_c / a) = y_c with sinh(x_c / a) = tan(theta)
    xc = a * math.asinh(math.tan(theta))
    x_floor = xc + a * math.acosh((yc + H) / a)
    length = a * math.tan(theta) + math.sqrt((yc + H) ** 2 - a * a)
    return dict(f_pot=f_pot, v=math.sqrt(v2), yc=yc, a=a, xc=xc, rise=yc - a, x_floor=x_floor, length=length)


def catenary_points(st, n):
    """n points of the catenary from the pot (0, 0) to the floor (x_floor, -H), at equal arc length."""
    a, xc, yc = st["a"], st["xc"], st["yc"]
    sigma = np.linspace(-a * math.sinh(xc / a), st["length"] - a * math.sinh(xc / a), n)  # arc length from the top
    x = xc + a * np.arcsinh(sigma / a)
    y = yc - np.sqrt(a * a + sigma * sigma)
    x[0], y[0], y[-1] = 0.0, 0.0, -H
    return np.column_stack([x, y])


def polyline(st, n=POLYLINE_POINTS, ell=None):
    """The whole string: the pot's content straight down below the pot (a heap is shapeless), then the catenary.
    With `ell`, the pot holds what makes the string that long."""
    cat = catenary_points(st, n)
    chords = float(np.linalg.norm(np.diff(cat, axis=0), axis=1).sum())
    content = POT_CONTENT if ell is None else ell - chords
    return np.vstack([[[0.0, -content]], cat]), content


def points_text(pts, per_line=4):
    items = [f"[{x:.15g}, {y:.15g}]" for x, y in pts]
    lines = [", ".join(items[k:k + per_line]) for k in range(0, len(items), per_line)]
    return "[\n  " + ",\n  ".join(lines) + ",\n]"


def scene_text(st, shape=None, speed_factor=1.0):
    """The scene on the steady state `st`; or, with `shape` (another steady state) and `speed_factor`, the same
    chain and heaps started on that shape at speed_factor v (the string as long: the pot holds the difference)."""
    pts, content = polyline(st)
    ell = float(np.linalg.norm(np.diff(pts, axis=0), axis=1).sum())
    speed = st["v"] * speed_factor
    if shape is not None:
        pts, content = polyline(shape, ell=ell)
        ell = float(np.linalg.norm(np.diff(pts, axis=0), axis=1).sum())
    off = "" if shape is None and speed_factor == 1 else (
        f"# OFF THE STEADY STATE: started at {speed_factor:g} v on the steady shape of a pot with f = {shape['f_pot'] if shape else F_POT}.\n")
    return off + f'''# The chain fountain (docs/model.md §4.5, docs/scenes.md): a chain is drawn out of a pot at the origin that
# pushes it (a pot: f = {F_POT}, so the tension there is (1 + f) λ v² < λ v²) and leaves it along the pot's mouth,
# {THETA_DEG:g}° above the +x axis (the direction the shape leaves the pot in); it falls onto a heap on the floor
# {H} m below (f = {F_FLOOR}: (1 - f) λ v² there; the contact slides along the floor). It starts on the steady state:
# the speed v = sqrt(g H / (f_pot + f_floor)) = {st["v"]:.12g} m/s along the inverted catenary on which T - λ v² is
# the tension of a hanging chain, y = y_c - a cosh((x - x_c)/a), y_c = -f_pot v²/g = {st["yc"]:.12g} m,
# a = y_c cos {THETA_DEG:g}° = {st["a"]:.12g} m, x_c = {st["xc"]:.12g} m: the fountain rises y_c - a = {st["rise"]:.12g} m
# above the pot, meets the floor at x = {st["x_floor"]:.12g} m, and {st["length"]:.12g} m of chain are in the air.
# It stays there until the pot runs empty (t = {content / speed:.3f} s).
# Written by docs/figures/fountain.py (the closed form; `fountain.py scene > this file`).
#   chainsim run cases/scenes/chain_fountain.toml --out results/chain_fountain
[string]
density = 1.0         # kg/m, λ (the length is the shape's, {ell:.12g} m)
nodes = {NODES}

[shape]
kind = "polyline"
# m: the pot's content ({content:.6g} m) straight down below the pot (a heap is shapeless: where is irrelevant),
# then {POLYLINE_POINTS} points of the catenary from the pot (0, 0) to the floor.
points = {points_text(pts)}

[velocity]
kind = "tangential"   # the whole string moves along itself
speed = {speed:.15g}  # m/s

[effects.gravity]
g = [0.0, -{G}]       # m/s²

[[effects.heap]]      # the pot
side = "start"        # it holds s < s0 and feeds the chain
pot = true            # a pot may push (-0.5 <= f <= 1); its mouth keeps the direction the shape leaves it in
s0 = {content:.15g}   # m: the chain in the pot
f = {F_POT}             # the pot pushes: Biggins & Warner's alpha = -f = {-F_POT:g}
point = [0.0, 0.0]    # m: the pot's mouth (pinned)

[[effects.heap]]      # the heap on the floor
side = "end"          # it holds s > s0: empty at t = 0
s0 = {ell:.15g}
f = {F_FLOOR}               # Biggins & Warner's beta = f = {F_FLOOR:g}
point = [{pts[-1][0]:.15g}, -{H}]  # m: where the chain meets the floor at t = 0
on_plane = true       # the contact slides along the floor

[effects.plane]       # the floor
point = [0.0, -{H}]
normal = [0.0, 1.0]

[solver]
method = "erk5"
rtol = 1e-9
atol = 1e-11

[output]
interval = 0.01       # s between node frames

[stop]
t_end = {max(2.0, math.ceil(1.5 * content / speed)):.1f}           # s, a safety stop: the pot runs empty first
'''


def figures(results):
    sys.path.insert(0, os.path.join(HERE, "..", "..", "python"))
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    from chainsim_plot.readers import load_run

    st = steady()
    runs = {k: load_run(os.path.join(results, k)) for k in ("chain_fountain", "chain_fountain_off")}
    names = {"chain_fountain": ("C0", "on the steady state"), "chain_fountain_off": ("C3", "started off it")}
    fig, axes = plt.subplots(1, 3, figsize=(15, 4.8))
    # (a) the shape at the start and at the end of each run against the closed form's catenary.
    ax = axes[0]
    cat = catenary_points(st, 2001)
    ax.plot(cat[:, 0], cat[:, 1], "k-", lw=4, alpha=0.25, label="steady catenary (closed form)")
    for key, (color, name) in names.items():
        frames = runs[key].nodes
        for k, style in ((0, "--"), (len(frames) - 1, "o")):
            pos = frames.positions(k)
            ax.plot(pos[:, 0], pos[:, 1], style, color=color, ms=2.2, lw=0.9,
                    label=f"{name}, t = {frames.times[k]:.2f} s")
    ax.plot([0], [0], "ks", ms=6)
    ax.axhline(-H, color="k", lw=0.8)
    ax.set_aspect("equal")
    ax.set_xlabel("x (m)")
    ax.set_ylabel("y (m)")
    ax.set_title("shape: the nodes in the air", fontsize=10)
    ax.legend(fontsize=7, loc="lower left")
    # (b) speed and (c) rise against time.
    for key, (color, name) in names.items():
        frames = runs[key].nodes
        speed = [np.mean(np.linalg.norm(frames.velocities(k), axis=1)) for k in range(len(frames))]
        rise = [frames.positions(k)[:, 1].max() for k in range(len(frames))]
        axes[1].plot(frames.times, speed, "-", color=color, label=name)
        axes[2].plot(frames.times, rise, "-", color=color, label=name)
    axes[1].axhline(st["v"], color="k", lw=4, alpha=0.25, label=f"closed form, v = {st['v']:.4f} m/s")
    axes[2].axhline(st["rise"], color="k", lw=4, alpha=0.25, label=f"closed form, y_c - a = {st['rise']:.4f} m")
    axes[1].set_title("speed (mean over the nodes in the air)", fontsize=10)
    axes[2].set_title("rise above the pot (the highest node)", fontsize=10)
    for ax, unit in ((axes[1], "m/s"), (axes[2], "m")):
        ax.set_xlabel("t (s)")
        ax.set_ylabel(unit)
        ax.legend(fontsize=8)
    fig.tight_layout()
    out = os.path.join(HERE, "fountain.png")
    fig.savefig(out, dpi=100)
    print("wrote", out)


def main():
    global POT_CONTENT, NODES
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    sub = p.add_subparsers(dest="command", required=True)
    sub.add_parser("steady")
    ps = sub.add_parser("scene")
    ps.add_argument("--shape-pot-f", type=float, help="start on the steady shape of a pot with this f instead")
    ps.add_argument("--speed-factor", type=float, default=1.0, help="start at this multiple of the steady speed")
    ps.add_argument("--pot-content", type=float, default=POT_CONTENT, help="m of chain in the pot (on the steady state)")
    ps.add_argument("--nodes", type=int, default=NODES)
    pf = sub.add_parser("figures")
    pf.add_argument("results")
    args = p.parse_args()
    if args.command == "steady":
        for k, v in steady().items():
            print(f"{k} = {v:.12g}")
    elif args.command == "scene":
        POT_CONTENT, NODES = args.pot_content, args.nodes
        shape = None if args.shape_pot_f is None else steady(f_pot=args.shape_pot_f)
        sys.stdout.write(scene_text(steady(), shape, args.speed_factor))
    else:
        figures(args.results)


if __name__ == "__main__":
    main()
