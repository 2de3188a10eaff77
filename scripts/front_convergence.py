#!/usr/bin/env python3
"""Mesh convergence of front tracking in general geometry (docs/shocks.md, "Second order at a moving front").

Runs the solver on a scene at N = 20·2^k + 1 nodes (`chainsim run SCENE --set string.nodes=N`), and measures
under refinement, each against a Richardson extrapolation whose observed order is computed from the runs:
  - the stop time t_stop,
  - the front path s0(t) on a grid of times (cubic Hermite in the per-step samples of s0 and ds0/dt,
    series.csv), its largest deviation over the grid,
  - the energy ledger's residual (exact value 0: its largest |K + V − K0 − V0 − W_...| over the run,
    relative to the energy scale, as the solver reports it).
Writes <out>/<scene>/convergence.json and, for all scenes, <out>/front_convergence.png (log-log, errors
against the links per metre) and prints a table.

    /usr/bin/python3 scripts/front_convergence.py --binary build/chainsim --out results/front_convergence \
        --nodes 41,81,161,321,641 \
        --scene cases/scenes/curved_falling_chain.toml \
        --scene "cases/scenes/swinging_sliding_chain_moving.toml:stop.front[0].front=heap_start;stop.front[0].s0=0.3@swinging chain, turning start" \
        --scene "cases/scenes/swinging_sliding_chain_moving.toml:stop.front[0].front=heap_start;stop.front[0].s0=0.3@swinging chain, sliding start" \
        --turn "swinging chain, turning start"
"""
import argparse
import json
import math
import os
import subprocess
import sys

import tomllib

import numpy as np


def compatible_turn(scene, nodes, out):
    """A copy of `scene` (a polyline: heap, hole, hanging part; [velocity] tangential at speed w) whose
    hanging part also turns about the hole at ω = g·n / w at t = 0, so that the material passing the hole
    turns with the tangent (w ω) exactly as gravity's sideways pull g·n demands of a straight string.
    Written as node velocities into out/scene.toml; returns its path."""
    with open(scene, "rb") as f:
        spec = tomllib.load(f)
    p = np.array(spec["shape"]["points"], dtype=float)
    t = (p[2] - p[1]) / np.linalg.norm(p[2] - p[1])
    n = np.array([-t[1], t[0]])
    w = float(spec["velocity"]["speed"])
    s0 = float(spec["effects"]["heap"][0]["s0"])
    omega = float(np.dot(spec["effects"]["gravity"]["g"], n)) / w
    h = float(spec["string"]["length"]) / (nodes - 1)
    values = []
    for i in range(nodes):
        r = i * h - s0
        v = w * t + omega * r * n if r > 1e-12 else np.zeros(2)
        values.append(f"[{v[0]:.17g}, {v[1]:.17g}]")
    lines, skip = [], False
    with open(scene) as f:
        for line in f:
            if line.startswith("["):
                skip = line.strip() == "[velocity]"
            if not skip:
                lines.append(line)
    lines.append('\n[velocity]\nkind = "nodes"\nvalues = [' + ", ".join(values) + "]\n")
    os.makedirs(out, exist_ok=True)
    path = os.path.join(out, "scene.toml")
    with open(path, "w") as f:
        f.writelines(lines)
    return path


def run(binary, scene, nodes, rtol, out, extra, turn):
    if turn:
        scene = compatible_turn(scene, nodes, out)
    cmd = [binary, "run", scene, "--out", out, "--json", "--quiet", "--set", f"string.nodes={nodes}",
           "--set", f"solver.rtol={rtol}", "--set", f"solver.atol={rtol * 1e-2}", "--set", "output.interval=10"]
    cmd += [a for s in extra for a in ("--set", s)]
    proc = subprocess.run(cmd, capture_output=True, text=True)
    if proc.returncode != 0:
        sys.exit(f"{' '.join(cmd[:12])} ... failed ({proc.returncode}): {proc.stderr.strip()} {proc.stdout[-2000:]}")
    summary = json.loads(proc.stdout)
    data = np.genfromtxt(os.path.join(out, "series.csv"), delimiter=",", names=True)
    return summary, data


def hermite(t, s, sd, times):
    """s(times) by cubic Hermite interpolation in the samples (t, s, ds/dt)."""
    out = np.empty_like(times)
    for q, tq in enumerate(times):
        k = min(max(np.searchsorted(t, tq) - 1, 0), len(t) - 2)
        dt = t[k + 1] - t[k]
        u = (tq - t[k]) / dt
        h00, h10, h01, h11 = 2 * u**3 - 3 * u**2 + 1, u**3 - 2 * u**2 + u, -2 * u**3 + 3 * u**2, u**3 - u**2
        out[q] = h00 * s[k] + h10 * dt * sd[k] + h01 * s[k + 1] + h11 * dt * sd[k + 1]
    return out


def richardson(values):
    """Observed orders of successive triples, and the extrapolation from the finest three."""
    v = [np.asarray(x, dtype=float) for x in values]
    orders = []
    for a, b, c in zip(v, v[1:], v[2:]):
        orders.append(float(math.log2(np.max(np.abs(a - b)) / np.max(np.abs(b - c)))))
    p = orders[-1]
    limit = v[-1] + (v[-1] - v[-2]) / (2**p - 1)
    return orders, limit


def study(binary, scene, meshes, rtol, out, grid_fraction, extra, label, turn, differences=()):
    name, folder = label, label.replace(" ", "_")
    runs = []
    for nodes in meshes:
        summary, data = run(binary, scene, nodes, rtol, os.path.join(out, folder, f"n{nodes}"), extra, turn)
        runs.append((nodes, summary, data))
        print(f"  {name} N = {nodes}: t_stop = {summary['t_stop']:.12f} s, energy ledger "
              f"{summary['energy_residual']:.3e}, wall {summary.get('wall_s', float('nan')):.2f} s", flush=True)
    t_stop = [r[1]["t_stop"] for r in runs]
    t_min = min(t_stop)
    grid = np.linspace(0.02 * t_min, grid_fraction * t_min, 60)
    paths = [hermite(r[2]["t"], r[2]["s0_0"], r[2]["s0dot_0"], grid) for r in runs]
    energy = [r[1]["energy_residual"] for r in runs]
    orders_t, t_ref = richardson(t_stop)
    orders_s, s_ref = richardson(paths)
    err_t = [abs(t - t_ref) / t_ref for t in t_stop]
    err_s = [float(np.max(np.abs(p - s_ref))) for p in paths]
    orders_e = [math.log2(a / b) for a, b in zip(energy, energy[1:])]
    if differences:
        times = np.array(differences)
        at = [hermite(r[2]["t"], r[2]["s0_0"], r[2]["s0dot_0"], times) for r in runs]
        print(f"  {name}: (s0(N) - s0(2N)) / h at t = " + ", ".join(f"{t:g}" for t in times) + " s")
        for k in range(len(runs) - 1):
            with open(scene, "rb") as f:
                h = float(tomllib.load(f)["string"]["length"]) / (runs[k][0] - 1)
            print(f"    N = {runs[k][0]:5d} / {runs[k + 1][0]:5d}: " + " ".join(f"{d:9.2e}" for d in (at[k] - at[k + 1]) / h))
    result = {"scene": scene, "rtol": rtol, "nodes": meshes, "wall_s": [r[1].get("wall_s") for r in runs],
              "t_stop": t_stop, "t_stop_extrapolated": float(t_ref), "t_stop_rel_err": err_t,
              "t_stop_observed_orders": orders_t, "front_path_err": err_s, "front_path_observed_orders": orders_s,
              "energy_ledger": energy, "energy_ledger_orders": orders_e}
    with open(os.path.join(out, folder, "convergence.json"), "w") as f:
        json.dump(result, f, indent=1)
    return name, result


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--binary", default="build/chainsim")
    ap.add_argument("--out", default="results/front_convergence")
    ap.add_argument("--scene", action="append", required=True,
                    help="SCENE[:KEY=VALUE[;KEY=VALUE...]][@LABEL]: a scene, its --set overrides and a label")
    ap.add_argument("--turn", action="append", default=[],
                    help="LABEL of a study whose hanging part starts turning about its hole (compatible start)")
    ap.add_argument("--nodes", default="21,41,81,161,321")
    ap.add_argument("--rtol", type=float, default=1e-11)
    ap.add_argument("--grid-fraction", type=float, default=0.95, help="front path up to this fraction of t_stop")
    ap.add_argument("--differences", default="",
                    help="T1,T2,...: also print (s0(N) - s0(2N)) / h at these times for each pair of successive meshes "
                         "(h the coarser link): when a mesh's error is made")
    args = ap.parse_args()
    meshes = [int(n) for n in args.nodes.split(",")]
    results = []
    for item in args.scene:
        item, _, label = item.partition("@")
        scene, _, sets = item.partition(":")
        label = label or os.path.splitext(os.path.basename(scene))[0]
        results.append(study(args.binary, scene, meshes, args.rtol, args.out, args.grid_fraction,
                             [s for s in sets.split(";") if s], label, label in args.turn,
                             [float(t) for t in args.differences.split(",") if t.strip()]))
    for name, r in results:
        print(f"\n{name} (rtol {r['rtol']:g}); t_stop extrapolated {r['t_stop_extrapolated']:.12f} s")
        print("  N      t_stop rel err  order   front path err  order   energy ledger  order")
        for k, n in enumerate(r["nodes"]):
            o_t = f"{r['t_stop_observed_orders'][k - 2]:.2f}" if k >= 2 else "    "
            o_s = f"{r['front_path_observed_orders'][k - 2]:.2f}" if k >= 2 else "    "
            o_e = f"{r['energy_ledger_orders'][k - 1]:.2f}" if k >= 1 else "    "
            print(f"  {n:5d}  {r['t_stop_rel_err'][k]:.3e}       {o_t}    {r['front_path_err'][k]:.3e}       {o_s}"
                  f"    {r['energy_ledger'][k]:.3e}      {o_e}")
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    fig, axes = plt.subplots(1, len(results), figsize=(5.2 * len(results), 4.4), squeeze=False)
    for ax, (name, r) in zip(axes[0], results):
        links = np.array(r["nodes"], dtype=float) - 1
        ax.loglog(links, r["t_stop_rel_err"], "o-", label="stop time (relative)")
        ax.loglog(links, r["front_path_err"], "s-", label="front path max|s0 - s0*| (m)")
        ax.loglog(links, r["energy_ledger"], "^-", label="energy ledger (relative)")
        ref = r["t_stop_rel_err"][0] * (links / links[0]) ** -2
        ax.loglog(links, ref, "k--", lw=0.8, label="slope -2")
        ax.set_xlabel("links")
        ax.set_title(name.replace("_", " "), fontsize=10)
        ax.grid(True, which="both", lw=0.3)
        ax.legend(fontsize=8)
    axes[0][0].set_ylabel("error against the Richardson extrapolation\n(energy ledger: its residual, exact 0)")
    fig.tight_layout()
    png = os.path.join(args.out, "front_convergence.png")
    fig.savefig(png, dpi=120)
    print(f"\nfigure: {png}")


if __name__ == "__main__":
    main()
