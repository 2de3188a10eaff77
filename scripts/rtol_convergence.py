#!/usr/bin/env python3
"""The largest distance of a node between runs of one scene at successive rtols (atol = rtol/100), at given times.

An ODE solution's differences fall with rtol; a floor in them is a part of the motion set by the steps rather than
by the model (docs/model.md §9, "Convergence in rtol after releases").

Usage: /usr/bin/python3 scripts/rtol_convergence.py SCENE.toml [--chainsim build/chainsim] [--rtols 1e-6 1e-8 ...]
       [--times 0.5 1.0]
Prints, per pair of rtols, the largest |Δx| (m) over the nodes at each time (the times must be frame times of the
scene: multiples of its output interval), and the steps of each run.
"""
import argparse
import csv
import json
import math
import subprocess
import sys
import tempfile


def positions(path, times):
    out = {t: {} for t in times}
    with open(path) as f:
        for row in csv.DictReader(f):
            t = float(row["t"])
            for T in times:
                if abs(t - T) < 1e-9:
                    out[T][int(row["node"])] = [float(row[c]) for c in ("x", "y", "z") if c in row]
    return out


def main():
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("scene")
    p.add_argument("--chainsim", default="build/chainsim")
    p.add_argument("--rtols", type=float, nargs="+", default=[1e-6, 1e-8, 1e-10, 1e-12])
    p.add_argument("--times", type=float, nargs="+", default=[0.5, 1.0])
    a = p.parse_args()
    runs = []
    with tempfile.TemporaryDirectory() as tmp:
        for r in a.rtols:
            out = f"{tmp}/{r:g}"
            res = subprocess.run([a.chainsim, "run", a.scene, "--out", out, "--json", "--set", f"solver.rtol={r:g}",
                                  "--set", f"solver.atol={r * 1e-2:g}"], capture_output=True, text=True)
            try:
                summary = json.loads(res.stdout)
            except json.JSONDecodeError:
                sys.exit(f"rtol_convergence: the run at rtol {r:g} wrote no summary (exit {res.returncode}): "
                         f"{res.stderr.strip()}")
            if "steps" not in summary:
                sys.exit(f"rtol_convergence: the run at rtol {r:g} did not start (exit {res.returncode}): "
                         f"{summary.get('error') or res.stderr.strip()}")
            print(f"rtol {r:g}: {summary['status']}, {summary['steps']} steps")
            runs.append(positions(f"{out}/nodes.csv", a.times))
            missing = [t for t in a.times if not runs[-1][t]]
            if missing:
                sys.exit(f"rtol_convergence: no frame at t = {', '.join(f'{t:g}' for t in missing)} s in the run at rtol "
                         f"{r:g} (the times must be frame times of the scene, before its end)")
    for k in range(1, len(runs)):
        cells = []
        for t in a.times:
            x0, x1 = runs[k - 1][t], runs[k][t]
            d = max(math.dist(x0[i], x1[i]) for i in x0 if i in x1)
            cells.append(f"{d:.2e} m at {t:g} s")
        print(f"rtol {a.rtols[k - 1]:g} -> {a.rtols[k]:g}: " + ", ".join(cells))


if __name__ == "__main__":
    main()
