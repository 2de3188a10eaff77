#!/usr/bin/env python3
"""The real table after its edge in the material against the table before it (docs/model.md §10, "A table after
its edge in the material").

Runs cases/scenes/chain_off_real_table.toml (the table before the edge, s = 0 at the table's free end) and its
mirror (s = 0 at the free hanging end, the table after the edge, points [[0, -0.2], [0, 0], [0.8, 0]]) at the
same x0 = 0.2 m, f, mesh and tolerance, and prints per run pair: both lift-off times and their difference, the
largest difference of the hanging lengths (ℓ − s0 against s0) at the output frames (every 0.01 s), and both
energy ledgers (relative). With MU, a rough table (mu = MU on the surface) too.

    /usr/bin/python3 scripts/mirror_table.py build/chainsim [MU]
"""
import csv
import json
import os
import subprocess
import sys
import tempfile

BIN = sys.argv[1] if len(sys.argv) > 1 else "build/chainsim"
MUS = [None] + ([float(sys.argv[2])] if len(sys.argv) > 2 else [])
HERE = os.path.dirname(os.path.abspath(__file__))
BASE = open(os.path.join(HERE, "..", "cases", "scenes", "chain_off_real_table.toml")).read()
POINTS = {"before": "[[-0.8, 0.0], [0.0, 0.0], [0.0, -0.2]]", "after": "[[0.0, -0.2], [0.0, 0.0], [0.8, 0.0]]"}


def scene(side, nodes, f, rtol, mu):
    lines = []
    for line in BASE.splitlines():
        if line.startswith("points ="):
            line = "points = " + POINTS[side]
        elif line.startswith("nodes ="):
            line = f"nodes = {nodes}"
        elif line.startswith("f = "):
            line = f"f = {f}"
        elif line.startswith("rtol"):
            line = f"rtol = {rtol}"
        elif line.startswith("atol"):
            line = f"atol = {rtol * 1e-2}"
        elif line.startswith("interval"):
            line = "interval = 0.01"
        elif line.startswith("edge = 0") and mu is not None:
            line += f"\nmu = {mu}"
        lines.append(line)
    return "\n".join(lines) + "\n"


def run(text, work, name):
    path = os.path.join(work, name + ".toml")
    with open(path, "w") as out:
        out.write(text)
    out_dir = os.path.join(work, name)
    done = subprocess.run([BIN, "run", path, "--out", out_dir, "--json"], capture_output=True, text=True)
    summary = json.loads(done.stdout)
    frames = {}
    with open(os.path.join(out_dir, "series.csv")) as f:
        for row in csv.DictReader(f):
            t = float(row["t"])
            if abs(t * 100 - round(t * 100)) < 1e-9:  # the output frames, at the same times in both runs
                frames[round(t, 9)] = float(row["s0_0"])
    return summary, frames


with tempfile.TemporaryDirectory() as work:
    for mu in MUS:
        for rtol in (1e-9, 1e-11):
            for f in (0.0, 0.5):
                for nodes in (21, 40, 52, 81, 100, 101):
                    a, xa = run(scene("before", nodes, f, rtol, mu), work, "before")
                    c, xc = run(scene("after", nodes, f, rtol, mu), work, "after")
                    common = sorted(set(xa) & set(xc))
                    dx = max(abs((1 - xa[t]) - xc[t]) for t in common)
                    print(f"mu={mu} rtol={rtol:g} f={f} nodes={nodes:3d}: {a['status']}/{c['status']} "
                          f"t_before={a['t_stop']:.12f} t_after={c['t_stop']:.12f} dt={c['t_stop'] - a['t_stop']:+.2e} "
                          f"max|dx|={dx:.1e} ({len(common)} frames) energy before={a['energy_residual']:.1e} "
                          f"after={c['energy_residual']:.1e} {c.get('error', '')}")
