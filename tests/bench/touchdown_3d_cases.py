#!/usr/bin/env python3
"""The numbers of docs/model.md §10, "A touchdown front in 3D", *A lying part that curves in the plane*: the drawn
string with f = 0 whose lying part turns in the plane of the table before the front, so that the direction e of its
last link turns while the string runs (the front's 3D terms in e), against the exact solution.

Usage:
    /usr/bin/python3 tests/bench/touchdown_3d_cases.py [path/to/chainsim]     (default build/chainsim)

The table is z = 0. The lying part (s < 0.5 m) is a straight piece of 0.32 m and then a circular arc of radius
R = 0.3 m and length 0.18 m that ends at the origin along +x; the arc (s > 0.5 m) is 0.5 m straight from the origin at
the elevation 60° and the azimuth 30° from the plane of x and z. All of it moves along itself at U = 1 m/s towards the
lying end, the arc's end is driven along the arc at U, the lying end is loaded with λ U² = 1 N along its tangent,
λ = 1 kg/m, no gravity, f = 0. With f = 0 and τ = λ U² everywhere a string moving along itself keeps any shape, and
the jump conditions hold at any angle: the exact solution keeps the shape fixed in space, the corner at the origin,
s0 = 0.5 m + U t, the tension λ U² = 1 N, the table's reaction at the front zero, and the lying end runs back along
its straight piece. The runs go to 0.2 s (erk5, rtol 1e-10, atol 1e-13) on 20, 40, 80, 160, 320 nodes; printed: the
status, the largest errors over the run of s0, of x0 and of the arc's tension at its driven end, the front's reaction
(the table's normal force N: its least and largest), W_remesh at the end, the lying end's error and the lying nodes'
largest distance from the exact shape at the end, and the observed orders between successive meshes.
"""
import csv
import json
import math
import os
import subprocess
import sys
import tempfile

R, LC, BETA, PHI, U = 0.3, 0.18, math.radians(60), math.radians(30), 1.0
T_ARC = (math.cos(BETA) * math.cos(PHI), -math.cos(BETA) * math.sin(PHI), math.sin(BETA))
P0 = (-R * math.sin(LC / R), R - R * math.cos(LC / R), 0.0)  # where the circular arc begins
D0 = (math.cos(LC / R), -math.sin(LC / R), 0.0)  # the straight piece's direction (towards larger s)


def lying(sigma):
    """The exact lying shape at the distance sigma back from the origin along it: (point, unit tangent to larger s)."""
    if sigma <= LC:
        return (-R * math.sin(sigma / R), R - R * math.cos(sigma / R), 0.0), (math.cos(sigma / R), -math.sin(sigma / R), 0.0)
    return tuple(p - (sigma - LC) * d for p, d in zip(P0, D0)), D0


def vec(v):
    return "[" + ", ".join("%.17g" % x for x in v) + "]"


def scene(nodes, t_end=0.2, samples=400):
    h = 1.0 / (nodes - 1)
    points = [lying(0.5)[0]] + [lying(LC * (1 - k / samples))[0] for k in range(samples + 1)]
    points.append(tuple(0.5 * x for x in T_ARC))
    values = [tuple(-U * x for x in (lying(0.5 - i * h)[1] if i * h < 0.5 else T_ARC)) for i in range(nodes)]
    return f"""model = "string"
[string]
dimension = 3
density = 1.0
nodes = {nodes}
[shape]
kind = "polyline"
points = [{", ".join(vec(p) for p in points)}]
[velocity]
kind = "nodes"
values = [{", ".join(vec(v) for v in values)}]
[ends]
start = {{ kind = "loaded", force = {vec(tuple(-U * U * x for x in D0))} }}
end = {{ kind = "driven", path = "linear", velocity = {vec(tuple(-U * x for x in T_ARC))} }}
[[effects.surface]]
point = [0.0, 0.0, 0.0]
normal = [0.0, 0.0, 1.0]
f = 0.0
[solver]
method = "erk5"
rtol = 1e-10
atol = 1e-13
[output]
interval = 0.05
[stop]
t_end = {t_end}
"""


def norm(v):
    return math.sqrt(sum(x * x for x in v))


def measure(chainsim, nodes, tmp):
    path = os.path.join(tmp, "curved_%d.toml" % nodes)
    out = os.path.join(tmp, "curved_%d" % nodes)
    with open(path, "w") as f:
        f.write(scene(nodes))
    p = subprocess.run([chainsim, "run", path, "--out", out, "--json", "--quiet"], capture_output=True, text=True)
    j = json.loads(p.stdout)
    series = list(csv.DictReader(open(os.path.join(out, "series.csv"))))
    tau = "T_node%d" % (nodes - 1)
    m = {"status": j["status"], "t_stop": j["t_stop"], "reason": j.get("stop_reason", ""),
         "energy": j["relative_energy_drift"], "crossings": j["transfers"]}
    m["s0"] = max(abs(float(r["s0_0"]) - 0.5 - U * float(r["t"])) for r in series)
    m["x0"] = max(norm([float(r["front_0_" + c]) for c in "xyz"]) for r in series)
    m["tau"] = max(abs(float(r[tau]) - U * U) for r in series)
    normal = [float(r["R_front0_z"]) for r in series]
    m["N_min"], m["N_max"] = min(normal), max(normal)
    m["W_remesh"] = float(series[-1]["W_remesh"])
    rows = list(csv.DictReader(open(os.path.join(out, "nodes.csv"))))
    t = max(float(r["t"]) for r in rows)
    last = [r for r in rows if float(r["t"]) == t]
    end = [float(last[0][c]) for c in "xyz"]
    exact_end = lying(0.5 + U * t)[0]
    m["end"] = norm([a - b for a, b in zip(end, exact_end)])
    curve = [lying((0.5 + U * t) * k / 20000)[0] for k in range(20001)]
    held = [[float(r[c]) for c in "xyz"] for r in last if abs(float(r["z"])) < 1e-12]
    m["shape"] = max(min(norm([a - b for a, b in zip(x, c)]) for c in curve) for x in held)
    return m


def main():
    chainsim = sys.argv[1] if len(sys.argv) > 1 else os.path.join("build", "chainsim")
    meshes = [20, 40, 80, 160, 320]
    with tempfile.TemporaryDirectory() as tmp:
        ms = [measure(chainsim, n, tmp) for n in meshes]
    keys = ["s0", "x0", "tau", "end", "shape"]
    print("nodes | status (t_stop) | crossings | max err s0, x0, tau+ (m, m, N) | N min, max (N) | W_remesh (J) | "
          "lying end, shape at the end (m) | energy (relative) | orders of s0, x0, tau+, end, shape")
    for k, (n, m) in enumerate(zip(meshes, ms)):
        orders = "" if k == 0 else " ".join(
            "%.2f" % math.log2(ms[k - 1][q] / m[q]) if m[q] > 0 and ms[k - 1]["status"] == "completed" and
            m["status"] == "completed" else "-" for q in keys)
        print("%4d | %s (%.6g s) | %d | %.2e %.2e %.2e | %.2e %.2e | %.2e | %.2e %.2e | %.1e | %s" % (
            n, m["status"], m["t_stop"], m["crossings"], m["s0"], m["x0"], m["tau"], m["N_min"], m["N_max"],
            m["W_remesh"], m["end"], m["shape"], m["energy"], orders))
        if m["status"] != "completed":
            print("      " + m["reason"][:220])


if __name__ == "__main__":
    main()
