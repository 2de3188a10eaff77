#!/usr/bin/python3
"""Figures of docs/scenes.md: one PNG per example scene, from `chainsim run` outputs.

Usage: /usr/bin/python3 docs/figures/make_scene_figures.py RESULTS_DIR
where RESULTS_DIR/<scene>/ holds the outputs of
    build/chainsim run cases/scenes/<scene>.toml --out RESULTS_DIR/<scene>
for shaken_chain, travelling_loop, whip_crack, pendulum_release, folded_chain_ends_apart, swinging_u,
pendulum_whip and thrown_chain (string scenes; the last three with slack = "allow"), spinning_loop_dropped
(3D, closed, slack = "allow"), chain_off_table_edge and
chain_over_peg and chain_over_two_pegs (edges), atwood_pulley, chain_lifting_off_pulley, atwood_rough_pulley and chain_over_round_peg (cylinders), chain_landing_at_angle and chain_landing_on_table (a surface),
chain_off_real_table (a table bounded by its edge), chain_into_heap_on_table (a heap on a contact surface), streaming_corner (a kink) and
falling_chain, folded_chain, sliding_chain, swinging_sliding_chain, tilted_falling_chain and
curved_falling_chain (scenes with fronts), and RESULTS_DIR/<scene>_reduced/ the same canonical scenes run with
model = "reduced". docs/figures/run_scene_figures.sh RESULTS_DIR does all of it (and `chainsim plot` on each
run). Writes docs/figures/scene_<scene>.png: the string at several times and the energy ledger, drawn by
`chainsim plot`'s package (python/chainsim_plot), with the quantity that scene is about in between.
"""
import math
import os
import sys

import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, os.path.join(HERE, "..", "..", "python"))

import matplotlib  # noqa: E402

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

from chainsim_plot.figures import choose_times, decorate, draw_ledger, draw_snapshots, ledger_columns  # noqa: E402
from chainsim_plot.readers import load_run  # noqa: E402


def snapshots(ax, run, times, title):
    notes = draw_snapshots([ax], run, choose_times(run.nodes.times, times)).notes()
    ax.set_title(title + ("\n(" + "; ".join(notes) + ")" if notes else ""), fontsize=9)


def ledger(ax, run):
    table, works, residual, _ = ledger_columns(run)
    draw_ledger(ax, run, table, works)
    worst = float(np.max(np.abs(table[residual])))
    ax.set_title(f"energy ledger (max |{residual}| = {worst:.1e} J)", fontsize=10)


def tip_speed(run, node=-1):
    frames = run.nodes
    return frames.times, np.array([np.linalg.norm(frames.velocities(k)[node]) for k in range(len(frames))])


def speed_panel(ax, ts, speed, reference, reference_label, title):
    """The tip speed against a reference speed, its maximum marked."""
    ax.plot(ts, speed, label="tip speed")
    ax.plot(ts, reference, "--", label=reference_label)
    k = int(np.argmax(speed))
    ax.annotate(f"{speed[k]:.1f} m/s at t = {ts[k]:.3g} s", (ts[k], speed[k]), fontsize=7,
                xytext=(-90, -10), textcoords="offset points")
    decorate(ax, "t (s)", "m/s", title)


def shaken_chain(run, ax):
    snapshots(ax[0], run, [0, 1.1, 2.2, 3.2, 4.2], "shaken top: x0 + A(1 - cos wt), A = 2 cm, w = 3 rad/s")
    f = run.nodes
    ax[1].plot(f.times, [f.positions(k)[0, 0] for k in range(len(f))], label="top (driven)")
    ax[1].plot(f.times, [f.positions(k)[-1, 0] for k in range(len(f))], label="free end")
    decorate(ax[1], "t (s)", "x (m)", "driven top and free end: forcing at 3 rad/s beats with mode 1 (3.77 rad/s)")


def travelling_loop(run, ax):
    snapshots(ax[0], run, [0, 0.4, 0.8, 1.2], "loop at 2 m/s: the shape stays, node 0 (dot) travels")
    tab = run.tension
    for want in [0, 2.5, 5]:
        t = tab["t"][np.argmin(np.abs(tab["t"] - want))]
        rows = tab["t"] == t
        ax[1].plot(tab["s_mid"][rows], tab["T"][rows], ".", ms=3, label=f"t = {t:g} s")
    ax[1].axhline(0.1 * 2.0 ** 2, color="k", lw=0.8, ls=":", label="lambda v^2 = 0.4 N")
    ax[1].set_ylim(0.39, 0.41)
    decorate(ax[1], "s (m)", "T (N)", "tension along the loop")


def whip_crack(run, ax):
    snapshots(ax[0], run, [0, 0.2, 0.4, 0.5, 0.6, 0.68, 0.76], "whip: handle swung once, A = 0.25 m, w = 8 rad/s")
    ts, speed = tip_speed(run)
    speed_panel(ax[1], ts, speed, 0.25 * 8 * np.abs(np.sin(8 * ts)), "hand speed A w |sin wt|",
                "the crack: the tip outruns the hand about ninefold")


def pendulum_release(run, ax):
    snapshots(ax[0], run, [0, 0.15, 0.25, 0.35, 0.42, 0.455, 0.49], "chain released horizontally, top fixed")
    ts, speed = tip_speed(run)
    f = run.nodes
    drop = np.array([max(0.0, -f.positions(k)[-1, 1]) for k in range(len(f))])
    vertical = np.abs([f.velocities(k)[-1, 1] for k in range(len(f))])
    speed_panel(ax[1], ts, speed, np.sqrt(2 * 9.81 * drop), "free fall from the same height, sqrt(2 g |y_tip|)",
                "the tip falls freely until it whips through the bottom: the extra speed is horizontal")
    ax[1].plot(ts, vertical, ":", label="vertical speed of the tip")
    ax[1].legend(fontsize=7)


def front_position(ax, run, reduced_dir, to_s0, title):
    ax.plot(run.series["t"], run.fronts[0].s0, lw=2, alpha=0.7, label=f"{run.fronts[0].name} front s0 (string solver)")
    if os.path.exists(os.path.join(reduced_dir, "series.csv")):
        red = load_run(reduced_dir).reduced
        ax.plot(red["t"], to_s0(red["y"]), "k:", lw=2, label="reduced ODE")
    decorate(ax, "t (s)", "s0 (m)", title)


def falling_chain(run, ax):
    snapshots(ax[0], run, [0, 0.15, 0.25, 0.32, 0.36], "falling chain onto a table, f = 0.5")
    front_position(ax[1], run, run.path + "_reduced", lambda y: y,
                   "material above the table = s0: the reduced ODE is exact")


def folded_chain(run, ax):
    snapshots(ax[0], run, [0, 0.2, 0.35, 0.45, 0.52], "folded chain, f = 0.5")
    front_position(ax[1], run, run.path + "_reduced", lambda y: y, "resting arm = s0 of the fold")


def sliding_chain(run, ax):
    snapshots(ax[0], run, [0, 0.25, 0.4, 0.5], "sliding chain through a hole, f = 0.5")
    front_position(ax[1], run, run.path + "_reduced", lambda y: 1.0 - y, "heap = s0: the hanging part is 1 - s0")


def swinging_sliding_chain(run, ax):
    snapshots(ax[0], run, [0, 0.15, 0.3, 0.4, 0.47, 0.52], "sliding chain released 30 deg off the vertical")
    f = run.nodes
    angle = [math.degrees(math.atan2(f.positions(k)[-1, 0], -f.positions(k)[-1, 1])) for k in range(len(f))]
    ax[1].plot(run.series["t"], 1.0 - run.fronts[0].s0, label="hanging length 1 - s0 (m)")
    ax[1].plot(f.times, np.array(angle) / 100, label="free end's angle from the vertical / 100 (deg)")
    decorate(ax[1], "t (s)", "", "it swings while it slides out of the heap")


def chain_onto_table(run, ax, title, subtitle):
    snapshots(ax[0], run, [0, 0.15, 0.25, 0.31, 0.345, 0.35], title)
    ax[1].plot(run.series["t"], run.fronts[0].s0, label="material above the table s0 (m)")
    ax[1].plot(run.series["t"], run.series["front_0_x"], label="contact position x (m)")
    decorate(ax[1], "t (s)", "m", subtitle)


def tilted_falling_chain(run, ax):
    chain_onto_table(run, ax, "chain falling tilted 25 deg onto a table, f = 0.5",
                     "the contact slides along the table as the chain comes down")


def curved_falling_chain(run, ax):
    chain_onto_table(run, ax, "chain falling curved onto a table, f = 0.5",
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


def folded_chain_ends_apart(run, ax):
    snapshots(ax[0], run, [0, 0.15, 0.25, 0.32, 0.37, 0.4, 0.42], "folded chain, ends 4 cm apart")
    f = run.nodes
    ts = f.times
    end = np.array([f.positions(k)[-1, 1] for k in range(len(f))])
    first = f.positions(0)
    length = float(np.sum(np.linalg.norm(np.diff(first, axis=0), axis=1)))  # the links are exact
    y0 = (length - end[0]) / 2  # the tight fold whose free end starts as high
    ax[1].plot(ts, end, "o", ms=3, label="string solver, resolved bight")
    for fd, style in [(0.0, "-"), (0.5, "--"), (1.0, ":")]:
        ax[1].plot(ts, tight_fold_end_height(fd, length, y0, ts), style, lw=1.2, label=f"tight fold, f = {fd:g}")
    decorate(ax[1], "t (s)", "free end height (m)", "it follows the energy-conserving fold (f = 0)")


def edge_slide(run, ax, title, subtitle):
    """The chain of 1 m sliding off a smooth table over its edge at the origin, 20 cm hanging at release, f = 0:
    the hanging length against x0 cosh(sqrt(g/l) t) and the lift-off length x*."""
    snapshots(ax[0], run, [0, 0.1, 0.22, 0.32, 0.42, 0.525], title)
    g, ell, x0 = 9.81, 1.0, 0.2
    ts = np.asarray(run.series["t"])
    ax[1].plot(ts, ell - np.asarray(run.fronts[0].s0), lw=2, alpha=0.7, label="hanging length 1 - s0 (string solver)")
    ax[1].plot(ts, x0 * np.cosh(math.sqrt(g / ell) * ts), "k:", lw=2, label="x0 cosh(sqrt(g/l) t), exact for f = 0")
    x_star = (ell + math.sqrt(ell * ell + 8 * x0 * x0)) / 4
    t_star = math.acosh(x_star / x0) / math.sqrt(g / ell)
    ax[1].axhline(x_star, color="r", lw=0.8, ls="--",
                  label=f"lift-off length x* = {x_star:.4f} m (t* = {t_star:.4f} s)")
    for e in run.summary.get("events", []):
        if e.get("kind") == "lift_off" and e.get("front") is not None:  # the edge's (not a contact lift-off)
            ax[1].plot([e["t"]], [ell - e["s0"]], "rx", ms=8, label=f"the run's lift-off event, t = {e['t']:.4f} s")
    decorate(ax[1], "t (s)", "m", subtitle)


def chain_off_table_edge(run, ax):
    edge_slide(run, ax, "chain sliding off a smooth table over its edge, f = 0",
               "the edge pushes while the table part's tension exceeds its momentum flux")


def chain_off_real_table(run, ax):
    edge_slide(run, ax, "the same chain on a real table: a surface bounded by its edge, f = 0",
               "the table's contact forces hold its part: the same x(t) and lift-off")


def chain_over_peg(run, ax):
    snapshots(ax[0], run, [0, 0.2, 0.3, 0.4, 0.45, 0.49], "chain over a sharp peg, f = 0.5, released at rest")
    g, ell, f, x0 = 9.81, 1.0, 0.5, 0.6
    frames = run.nodes
    ax[1].plot(frames.times, [-frames.positions(k)[-1, 1] for k in range(len(frames))], lw=2, alpha=0.7,
               label="longer side x (string solver)")
    # The reference: l x'' = g (2x - l) - 2 f x'^2 (docs/model.md §8), classical RK4 on a fine step.
    def acc(x, v):
        return (g * (2 * x - ell) - 2 * f * v * v) / ell
    dt, x, v, ts, xs = 1e-4, x0, 0.0, [0.0], [x0]
    while ts[-1] < frames.times[-1]:
        k1 = (v, acc(x, v))
        k2 = (v + dt / 2 * k1[1], acc(x + dt / 2 * k1[0], v + dt / 2 * k1[1]))
        k3 = (v + dt / 2 * k2[1], acc(x + dt / 2 * k2[0], v + dt / 2 * k2[1]))
        k4 = (v + dt * k3[1], acc(x + dt * k3[0], v + dt * k3[1]))
        x += dt / 6 * (k1[0] + 2 * k2[0] + 2 * k3[0] + k4[0])
        v += dt / 6 * (k1[1] + 2 * k2[1] + 2 * k3[1] + k4[1])
        ts.append(ts[-1] + dt)
        xs.append(x)
    ax[1].plot(ts, xs, "k:", lw=2, label="l x'' = g (2x - l) - 2 f x'^2 (RK4)")
    ax[1].axhline(0.91776, color="r", lw=0.8, ls="--", label="lift-off x* = 0.91776 m")
    decorate(ax[1], "t (s)", "m", "the peg pushes until its reaction falls to zero")


def chain_over_two_pegs(run, ax):
    snapshots(ax[0], run, [0, 0.3, 0.6, 0.754], "chain over two sharp pegs, f = 0.5, ends pulled by 2 N and 0.5 N")
    ts = np.asarray(run.series["t"])
    s0, s1 = np.asarray(run.fronts[0].s0), np.asarray(run.fronts[1].s0)
    # The closed form (docs/model.md §8): l x'' = F1 - F2 - 2 f x'^2, x = x0 + ln cosh(sqrt(AB) t)/B.
    ell, f, x0 = 1.2, 0.5, 0.4
    A, B = 1.5 / ell, 2 * f / ell
    exact = x0 + np.log(np.cosh(np.sqrt(A * B) * ts)) / B
    ax[1].plot(ts, s0, lw=2, alpha=0.7, label="first peg's s0 = x (string solver)")
    ax[1].plot(ts, s1 - 0.3, "--", lw=1.5, label="second peg's s0 - 0.3 m")
    ax[1].plot(ts, exact, "k:", lw=2, label="x0 + ln cosh(sqrt(AB) t)/B, exact")
    worst = float(np.max(np.abs(s0 - exact)))
    ax[1].axvline(0.754021410, color="r", lw=0.8, ls="--", label="lift-off off the second peg, t* = 0.75402 s")
    decorate(ax[1], "t (s)", "m", f"the material runs through both pegs (max |x - exact| = {worst:.1e} m)")


def streaming_corner(run, ax):
    snapshots(ax[0], run, [0, 0.1, 0.2, 0.28], "string streaming at 2 m/s through a fixed corner (a conservative kink);\ndots: its start, running to the corner; the shape does not change")
    ts = np.asarray(run.series["t"])
    s0 = np.asarray(run.fronts[0].s0)
    # The exact solution (docs/model.md §7.2, §2.5): the corner stays at the origin and runs through the material
    # at ds0/dt = -v = -2 m/s from s0 = 0.63 m.
    ax[1].plot(ts, s0, lw=2, alpha=0.7, label="kink s0 (string solver)")
    ax[1].plot(ts, 0.63 - 2.0 * ts, "k:", lw=2, label="exact s0 = 0.63 m - 2 m/s t")
    corner = np.hypot(np.asarray(run.series["front_0_x"]), np.asarray(run.series["front_0_y"]))
    ax[1].plot(ts, corner, label="|x0|: the kink's distance from the fixed corner (m)")
    decorate(ax[1], "t (s)", "m", "the kink runs through the material at -v and stays put in space")


def atwood_u_panel(ax, run, title):
    """u = x1 - l_free/2 = (x1 - x2)/2 of the heavy Atwood chain (the sides' lengths read off the end nodes'
    depths, while they hang) against u0 cosh(sqrt(2g/l) t), which holds up to the shorter side's lift-off."""
    g, ell, u0, t_lift = 9.81, 1.0, 0.05, 0.525026
    frames = run.nodes
    u = [(frames.positions(k)[0, 1] - frames.positions(k)[-1, 1]) / 2 for k in range(len(frames))]
    ax.plot(frames.times, u, lw=2, alpha=0.7, label="u = (x1 - x2)/2 (string solver)")
    ts = np.linspace(0, min(frames.times[-1], t_lift), 200)
    ax.plot(ts, u0 * np.cosh(math.sqrt(2 * g / ell) * ts), "k:", lw=2, label="u0 cosh(sqrt(2g/l) t), exact")
    ax.axhline(0.2583, color="r", lw=0.8, ls="--", label="lift-off u* = 0.2583 m (t* = 0.525 s)")
    if frames.times[-1] > t_lift:
        ax.axvline(t_lift, color="r", lw=0.8, ls=":")
    decorate(ax, "t (s)", "m", title)


def atwood_pulley(run, ax):
    snapshots(ax[0], run, [0, 0.2, 0.3, 0.4, 0.5], "heavy Atwood chain over a smooth pulley, R = 0.1 m")
    atwood_u_panel(ax[1], run, "the wrapped half circle moves with the chain")


def chain_lifting_off_pulley(run, ax):
    snapshots(ax[0], run, [0, 0.45, 0.55, 0.6, 0.65, 0.75], "the heavy Atwood chain lifting off its pulley")
    atwood_u_panel(ax[1], run, "the cosh up to the lift-off at t* = 0.525 s; then the chain leaves the pulley")


def atwood_rough_pulley(run, ax):
    snapshots(ax[0], run, [0, 0.2, 0.3, 0.4, 0.5], "heavy Atwood chain over a rough pulley, R = 0.1 m, mu = 0.1")
    g, ell, R, mu, x1 = 9.81, 1.0, 0.1, 0.1, 0.45
    x2 = ell - math.pi * R - x1
    E, c = math.exp(mu * math.pi), 2 * mu / (1 + mu * mu)
    frames = run.nodes
    u = [(frames.positions(k)[0, 1] - frames.positions(k)[-1, 1]) / 2 for k in range(len(frames))]
    X = np.asarray(u) - u[0]
    ax[1].plot(frames.times, X, lw=2, alpha=0.7, label="X = displacement towards x1 (string solver)")

    def acc(x, v, mu_, e_, c_):  # the capstan ODE of docs/model.md section 10 (sliding towards x1)
        a1, a2 = x1 + x, x2 - x
        if mu_ == 0:
            return g * (a1 - a2) / ell
        return (g * (a1 - e_ * a2 - R * c_ * (1 + e_)) + (e_ - 1) * v * v) / (a1 + e_ * a2 + R * (e_ - 1) / mu_)

    # On a smooth pulley the shorter side would lift off at 0.352 s (docs/model.md section 10): drawn to there.
    for mu_, e_, c_, t_end, style, label in [(mu, E, c, frames.times[-1], "k:", "capstan ODE (RK4)"),
                                             (0.0, 1.0, 0.0, 0.352, "g--", "smooth pulley, to its lift-off at 0.352 s")]:
        ts, xs, x, v, dt = [0.0], [0.0], 0.0, 0.0, t_end / 2000
        for _ in range(2000):
            k1 = (v, acc(x, v, mu_, e_, c_))
            k2 = (v + dt / 2 * k1[1], acc(x + dt / 2 * k1[0], v + dt / 2 * k1[1], mu_, e_, c_))
            k3 = (v + dt / 2 * k2[1], acc(x + dt / 2 * k2[0], v + dt / 2 * k2[1], mu_, e_, c_))
            k4 = (v + dt * k3[1], acc(x + dt * k3[0], v + dt * k3[1], mu_, e_, c_))
            x += dt / 6 * (k1[0] + 2 * k2[0] + 2 * k3[0] + k4[0])
            v += dt / 6 * (k1[1] + 2 * k2[1] + 2 * k3[1] + k4[1])
            ts.append(ts[-1] + dt)
            xs.append(x)
        ax[1].plot(ts, xs, style, lw=1.5, label=label)
    decorate(ax[1], "t (s)", "m", "beyond the capstan bound (x1 = 0.45 m > 0.4161 m) it slides")


def chain_over_round_peg(run, ax):
    snapshots(ax[0], run, [0, 0.1, 0.2, 0.3, 0.4], "a V swinging over a round peg, R = 1 cm")
    centre = np.array([0.0, -0.016666666666666666])
    frames = run.nodes
    for node, label in [(0, "shorter side's end (s = 0)"), (-1, "longer side's end")]:
        angle = []
        for k in range(len(frames)):
            r = frames.positions(k)[node] - centre
            angle.append(math.degrees(math.atan2(r[0], -r[1])))
        ax[1].plot(frames.times, np.unwrap(np.radians(angle)) * 180 / math.pi, lw=2, label=label)
    ax[1].axhline(0, color="k", lw=0.6)
    decorate(ax[1], "t (s)", "deg", "each end's angle about the peg from the downward vertical")


def free_fall_landing_loss(frames, ts, nodes=slice(None), g=9.81):
    """-sum of m g y0 over the chosen nodes (lumped masses: 1 kg/m over 1 m, half a link's mass at each end)
    that have landed on the table y = 0 by each time in ts, each falling freely from rest at its height y0:
    a node lands at sqrt(2 y0/g) and loses its normal kinetic energy m g y0."""
    y0 = frames.positions(0)[:, 1]
    n = len(y0)
    mass = np.full(n, 1.0 / (n - 1))
    mass[[0, -1]] /= 2
    y0, mass = y0[nodes], mass[nodes]
    return np.array([-np.sum(mass * g * y0 * (np.sqrt(2 * y0 / g) <= t)) for t in ts])


def chain_landing_at_angle(run, ax):
    snapshots(ax[0], run, [0, 0.1, 0.15, 0.2, 0.25, 0.3], 'chain landing at 20 deg on a smooth table, slack = "allow"')
    frames = run.nodes
    # Every node falls freely (no tension) and lands at sqrt(2 y0/g), losing its normal kinetic energy m g y0.
    ts = np.linspace(0, frames.times[-1], 400)
    ax[1].plot(run.energy["t"], run.energy["W_impacts"], lw=2, alpha=0.7, label="W_impacts (string solver)")
    ax[1].plot(ts, free_fall_landing_loss(frames, ts), "k:", lw=1.5,
               label="- sum of m g y0 over the nodes landed by t (free fall)")
    decorate(ax[1], "t (s)", "J", "each landing takes the node's normal kinetic energy")


def chain_landing_on_table(run, ax):
    snapshots(ax[0], run, [0, 0.04, 0.08, 0.1, 0.2, 0.3], "level chain dropped 5 cm onto a smooth table at 0.5 m/s")
    g, h, speed = 9.81, 0.05, 0.5
    frames = run.nodes
    mass = np.full(len(frames.positions(0)), 1.0 / (len(frames.positions(0)) - 1))  # 1 kg/m over 1 m, lumped
    mass[[0, -1]] /= 2
    total = float(np.sum(mass))
    v = np.array([mass @ frames.velocities(k) / total for k in range(len(frames))])
    # The closed form (the scene's header): free fall until every node lands at once, at sqrt(2 h/g); the
    # perfectly inelastic landing takes the normal kinetic energy M g h and keeps the speed along the table.
    t_land = math.sqrt(2 * h / g)
    ts = np.linspace(0, frames.times[-1], 400)
    e = run.energy
    ax[1].plot(e["t"], e["W_impacts"], "o-", ms=4, lw=2, alpha=0.7, label="W_impacts (J, string solver; each line at the frames)")
    ax[1].plot(ts, np.where(ts >= t_land, -total * g * h, 0.0), "k:", lw=1.5,
               label=f"- M g h = -{total * g * h:.4f} J from t = sqrt(2h/g) = {t_land:.5f} s")
    ax[1].plot(frames.times, v[:, 0], "s-", ms=3, lw=1.5, alpha=0.7, label="centre of mass v_x (m/s)")
    ax[1].plot(frames.times, v[:, 1], "^-", ms=3, lw=1.5, alpha=0.7, label="centre of mass v_y (m/s)")
    ax[1].plot(ts, np.full_like(ts, speed), "--", color="0.3", lw=1.2, label="0.5 m/s: kept along the table")
    ax[1].plot(ts, np.where(ts < t_land, -g * ts, 0.0), "-.", color="0.3", lw=1.2, label="- g t until the landing, then 0")
    worst = max(float(np.max(np.abs(np.asarray(e["W_impacts"])[np.asarray(e["t"]) > t_land] + total * g * h))),
                float(np.max(np.abs(v[:, 0] - speed))))
    decorate(ax[1], "t (s)", "J, m/s",
             f"the landing takes M g h and keeps the sliding speed (max error {worst:.1e})", legend=False)
    ax[1].set_ylim(-1.1, 1.75)  # room above the curves for the legend
    ax[1].legend(fontsize=7, loc="upper right")


def chain_into_heap_on_table(run, ax):
    snapshots(ax[0], run, [0, 0.1, 0.15, 0.2, 0.247], "a V of chain falling into its heap on a table, f = 1")
    g = 9.81
    frames = run.nodes
    ts = np.linspace(0, run.series["t"][-1], 400)
    # f = 1: no tension, every node falls freely. The heap takes the vertical arm at g t^2/2 a second (lambda =
    # 1 kg/m); the tilted arm (s < 0.5 m, nodes 0 ... 39 of 81) lands on the table node by node.
    ax[1].plot(run.series["t"], run.series["heap_mass"], lw=2, alpha=0.7, label="heap mass (kg, string solver)")
    ax[1].plot(ts, g * ts ** 2 / 2, "k:", lw=1.5, label="lambda g t^2/2 (free fall into the heap)")
    ax[1].plot(run.series["t"], -np.asarray(run.series["W_impacts"]), lw=2, alpha=0.7,
               label="-W_impacts (J, string solver): the tilted arm's landings")
    arm = slice(0, int(round(0.5 * (len(frames.positions(0)) - 1))))
    ax[1].plot(ts, -free_fall_landing_loss(frames, ts, arm), "--", color="0.3", lw=1.2,
               label="sum of m g y0 over the tilted arm's nodes landed by t")
    decorate(ax[1], "t (s)", "kg, J", "free fall: the heap's mass and the landings' loss")


def slack_panel(ax, run, title):
    """The energy the snaps dissipated (W_snap) against time."""
    e = run.energy
    ax.plot(e["t"], 1e3 * np.asarray(e["W_snap"]), label="W_snap (mJ): booked by the snaps")
    if "W_snap_supports" in e:
        ax.plot(e["t"], 1e3 * np.asarray(e["W_snap_supports"]), "--", label="W_snap_supports (mJ)")
    decorate(ax, "t (s)", "mJ", title)


def swinging_u(run, ax):
    snapshots(ax[0], run, [0, 0.4, 0.5, 0.6, 0.8, 1.0], 'swinging U, slack = "allow": links go slack and snap taut')
    slack_panel(ax[1], run, "energy lost at the snaps (perfectly inelastic)")


def pendulum_whip(run, ax):
    snapshots(ax[0], run, [0, 0.3, 0.45, 0.6, 0.8, 1.0], 'chain pendulum past its whip, slack = "allow"')
    slack_panel(ax[1], run, "energy lost at the snaps after the whip")


def thrown_chain(run, ax):
    snapshots(ax[0], run, [0, 0.3, 0.6, 0.9, 1.2, 1.5], "chain thrown up at 7 rad/s, goes slack and is caught")
    slack_panel(ax[1], run, "energy lost at the snaps when the chain is caught")


def snapshots_3d(ax, run, times, title):
    """A 3D run's snapshots in its two projections (x-y on ax[0], x-z on ax[1])."""
    notes = draw_snapshots([ax[0], ax[1]], run, choose_times(run.nodes.times, times)).notes()
    ax[0].set_title(title + ("\n(" + "; ".join(notes) + ")" if notes else ""), fontsize=9)
    ax[1].set_title("seen from above (x-z)", fontsize=9)


def spinning_loop_dropped(run, ax):
    snapshots_3d(ax, run, [0, 0.05, 0.1, 0.15, 0.2, 0.3],
                 'a loop spun and tumbling at 8 rad/s, dropped onto a table (3D, closed, slack = "allow")')


SCENES = [shaken_chain, travelling_loop, whip_crack, pendulum_release, falling_chain, folded_chain, sliding_chain,
          swinging_sliding_chain, tilted_falling_chain, curved_falling_chain, folded_chain_ends_apart,
          chain_off_table_edge, swinging_u, pendulum_whip, thrown_chain, chain_over_peg, chain_over_two_pegs,
          atwood_pulley, chain_lifting_off_pulley, atwood_rough_pulley, chain_over_round_peg, streaming_corner, chain_landing_at_angle, chain_landing_on_table,
          chain_off_real_table, chain_into_heap_on_table,
          spinning_loop_dropped]


def main():
    if len(sys.argv) != 2:
        sys.stderr.write("usage: make_scene_figures.py RESULTS_DIR   (see docs/figures/run_scene_figures.sh)\n")
        sys.exit(2)
    root = sys.argv[1]
    for draw in SCENES:
        scene = draw.__name__
        if not os.path.exists(os.path.join(root, scene)):
            print("skipped", scene, "(no results)")
            continue
        fig, ax = plt.subplots(1, 3, figsize=(16, 4.6), gridspec_kw={"width_ratios": [1.2, 1.2, 1.2]})
        run = load_run(os.path.join(root, scene))
        draw(run, ax)
        ledger(ax[2], run)
        fig.suptitle(f"cases/scenes/{scene}.toml", fontsize=11)
        fig.tight_layout()
        out = os.path.join(HERE, f"scene_{scene}.png")
        fig.savefig(out, dpi=110)
        plt.close(fig)
        print("wrote", out)


if __name__ == "__main__":
    main()
