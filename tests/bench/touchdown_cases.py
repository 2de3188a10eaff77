#!/usr/bin/env python3
"""The numbers of docs/model.md §10, "A touchdown front", "What is not reached" (2) and (3), from the drawn string
of tests/convergence/test_touchdown.cpp (0.5 m on the plane y = 0 along x, 0.5 m of arc at 60°, λ = 1 kg/m, the
arc's end driven along the arc at U, the lying end loaded by τ⁻ = λ U² (1 − f cos θ)).

Usage:
    /usr/bin/python3 tests/bench/touchdown_cases.py [path/to/chainsim]     (default build/chainsim)

(2) f = 1, U = 1 m/s, to 0.3 s, 20/40/80/160 nodes: the lying end's x (node 0) with the touchdown front and with
    node contact (the same text without f, slack = "allow"); the exact value is −0.8 m.
(3) gravity: U = 3 m/s, the lying end's load 4.5 N, g = 9.81 m/s² down, f = 1, slack = "allow", to 0.12 s: the
    energy ledger's drift (J) with the touchdown front on 20/40/80/160 nodes, at rtol 1e-10 (atol 1e-13) and at
    rtol 1e-12 (atol 1e-15); then the state's self-convergence (frames every 0.01 s): the lying end's x and K at
    0.03, 0.06, 0.09, 0.12 s, the differences of successive meshes and their observed orders, and W_remesh.
"""
import csv
import json
import math
import os
import subprocess
import sys
import tempfile


def drawn(nodes, f, speed, load, gravity=None, t_end=0.3, slack=False, theta_deg=60.0):
    th = math.radians(theta_deg)
    c, s, h = math.cos(th), math.sin(th), 1.0 / (nodes - 1)
    values = ", ".join(
        "[%.17g, %.17g]" % ((-speed, 0.0) if i * h < 0.5 else (-speed * c, -speed * s)) for i in range(nodes))
    text = f"""model = "string"
[string]
density = 1.0
nodes = {nodes}
[shape]
kind = "polyline"
points = [[-0.5, 0.0], [0.0, 0.0], [{0.5 * c:.17g}, {0.5 * s:.17g}]]
[velocity]
kind = "nodes"
values = [{values}]
[ends]
start = {{ kind = "loaded", force = [{-load:.17g}, 0.0] }}
end = {{ kind = "driven", path = "linear", velocity = [{-speed * c:.17g}, {-speed * s:.17g}] }}
[[effects.surface]]
point = [0.0, 0.0]
normal = [0.0, 1.0]
"""
    if f is not None:
        text += f"f = {f}\n"
    if gravity is not None:
        text += f"[effects.gravity]\ng = [0.0, {-gravity}]\n"
    text += f"""[solver]
method = "erk5"
rtol = 1e-10
atol = 1e-13
{'slack = "allow"' if slack else ''}
[stop]
t_end = {t_end}
"""
    return text


def frames(out):
    """{t: (x of node 0, K, W_remesh)} at the frames: nodes.csv and series.csv (the step rows at the frame times)."""
    xs = {round(float(r["t"]), 9): float(r["x"]) for r in csv.DictReader(open(os.path.join(out, "nodes.csv")))
          if r["node"] == "0"}
    series = [(float(r["t"]), float(r["K"]), float(r["W_remesh"]))
              for r in csv.DictReader(open(os.path.join(out, "series.csv")))]
    result = {}
    for t, x in xs.items():
        row = min(series, key=lambda q: abs(q[0] - t))
        result[t] = (x, row[1], row[2])
    return result


def run(chainsim, text, tmp, name):
    path = os.path.join(tmp, name + ".toml")
    with open(path, "w") as fh:
        fh.write(text)
    out = os.path.join(tmp, name)
    proc = subprocess.run([chainsim, "run", path, "--out", out, "--quiet", "--json"], capture_output=True, text=True)
    summary = json.loads(proc.stdout) if proc.stdout.strip() else {"status": "failed", "error": proc.stderr.strip()}
    return summary, out


def last_x0(out):
    """x of node 0 in the last frame of nodes.csv."""
    rows = [r for r in csv.DictReader(open(os.path.join(out, "nodes.csv"))) if r["node"] == "0"]
    return float(rows[-1]["t"]), float(rows[-1]["x"])


def main():
    chainsim = sys.argv[1] if len(sys.argv) > 1 else "build/chainsim"
    with tempfile.TemporaryDirectory() as tmp:
        print("(2) f = 1, U = 1 m/s: the lying end's x at the last frame (exact -0.8 m at 0.3 s)")
        for nodes in (20, 40, 80, 160):
            for label, f, slack in (("front", 1.0, False), ("node contact", None, True)):
                summary, out = run(chainsim, drawn(nodes, f, 1.0, 0.5, slack=slack), tmp, f"c2_{nodes}_{f}")
                where = "%.3f s: x = %.5f m" % last_x0(out) if os.path.exists(os.path.join(out, "nodes.csv")) else ""
                print(f"  {nodes:4d} nodes, {label:12s}: {summary.get('status')} {summary.get('stop_reason', '')[:60]} {where}")
        print("(3) gravity 9.81 m/s^2, U = 3 m/s, load 4.5 N, f = 1, slack allowed, to 0.12 s: energy drift (J)")
        sizes = (20, 40, 80, 160)
        for nodes in sizes:
            text = drawn(nodes, 1.0, 3.0, 4.5, gravity=9.81, t_end=0.12, slack=True)
            summary, _ = run(chainsim, text, tmp, f"c3_{nodes}")
            tight = text.replace("rtol = 1e-10", "rtol = 1e-12").replace("atol = 1e-13", "atol = 1e-15")
            tight_summary, _ = run(chainsim, tight, tmp, f"c3t_{nodes}")
            print(f"  {nodes:4d} nodes: {summary.get('status')} drift {summary.get('energy_drift'):.3e} (rtol 1e-10), "
                  f"{tight_summary.get('energy_drift'):.3e} (rtol 1e-12); energy scale {summary.get('energy_scale'):.4g} J")
        print("(3) the state's self-convergence (frames every 0.01 s): value on 20/40/80/160 nodes | differences | orders")
        state = {}
        for nodes in sizes:
            text = drawn(nodes, 1.0, 3.0, 4.5, gravity=9.81, t_end=0.12, slack=True) + "[output]\ninterval = 0.01\n"
            _, out = run(chainsim, text, tmp, f"c3f_{nodes}")
            state[nodes] = frames(out)
        for label, q in (("x of the lying end (m)", 0), ("K (J)", 1), ("W_remesh (J)", 2)):
            print(f"  {label}")
            for t in (0.03, 0.06, 0.09, 0.12):
                values = [state[n][round(t, 9)][q] for n in sizes]
                diffs = [values[i] - values[i + 1] for i in range(len(values) - 1)]
                orders = [math.log2(abs(diffs[i] / diffs[i + 1])) if diffs[i] and diffs[i + 1] else float("nan")
                          for i in range(len(diffs) - 1)]
                print(f"    t = {t:.2f} s: " + " ".join(f"{v:.6f}" for v in values) + " | " +
                      " ".join(f"{d:.2e}" for d in diffs) + " | " + " ".join(f"{o:.2f}" for o in orders))


if __name__ == "__main__":
    main()
