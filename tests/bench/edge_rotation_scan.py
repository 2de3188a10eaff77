#!/usr/bin/python3
"""Edges in 3D along general lines: each 2D edge problem rotated in space, run, and compared with its 2D run.

The chain off a table (the table before or after the edge) and the chain over a peg (f = 0) on several meshes,
each rotated by random rotations (seeded); the edge's line is the rotated out-of-plane axis, so the string meets
it at right angles and the 3D run is the 2D one turned. Each rotated run is classed as
  same      a lift-off within 1e-6 s of the 2D run's,
  wrong     a lift-off at another time (a wrong motion that ran on),
  located   a stop or failure with a diagnostic before any lift-off (status "failed", or the along-line check),
and the counts are printed (docs/model.md §8, "Round-off at a crossing").

  /usr/bin/python3 tests/bench/edge_rotation_scan.py --binary build/chainsim [--rotations 6]
"""
import argparse
import json
import math
import os
import subprocess
import tempfile
from collections import Counter

import numpy as np

PROBLEMS = {  # kind: (points in the plane, table)
    "edge": ([(-0.8, 0.0), (0.0, 0.0), (0.0, -0.2)], "before"),
    "edge_after": ([(0.0, -0.2), (0.0, 0.0), (-0.8, 0.0)], "after"),
    "peg": ([(0.0, -0.4), (0.0, 0.0), (0.0, -0.6)], "none"),
}
NODES = [11, 21, 33, 41, 101, 160]


def rotation(rng):
    axis = rng.normal(size=3)
    axis /= np.linalg.norm(axis)
    angle = rng.uniform(0.2, 2.5)
    k = np.array([[0, -axis[2], axis[1]], [axis[2], 0, -axis[0]], [-axis[1], axis[0], 0]])
    return np.eye(3) + math.sin(angle) * k + (1 - math.cos(angle)) * k @ k


def text(points, table, nodes, rot):
    def vec(v):
        w = v if rot is None else rot @ np.array([v[0], v[1], 0.0])
        return "[" + ", ".join(f"{c:.17g}" for c in w) + "]"

    lines = ['model = "string"', "[string]", "length = 1.0", "density = 1.0", f"nodes = {nodes}"]
    if rot is not None:
        lines.append("dimension = 3")
    lines += ["[shape]", 'kind = "polyline"', "points = [" + ", ".join(vec(p) for p in points) + "]",
              "[effects.gravity]", f"g = {vec((0.0, -9.81))}", "[[effects.edge]]", f"point = {vec((0.0, 0.0))}"]
    if rot is not None:
        lines.append("direction = [" + ", ".join(f"{c:.17g}" for c in rot[:, 2]) + "]")
    lines += ["f = 0.0", f'table = "{table}"', "[solver]", 'method = "erk5"', "rtol = 1e-9", "atol = 1e-11",
              "[output]", "interval = 1.0", "[stop]", "t_end = 2.0"]
    return "\n".join(lines) + "\n"


def run(binary, scene, work):
    path = os.path.join(work, "scene.toml")
    with open(path, "w") as f:
        f.write(scene)
    p = subprocess.run([binary, "run", path, "--out", os.path.join(work, "out"), "--json", "--quiet"],
                       capture_output=True, text=True)
    d = json.loads(p.stdout)
    lift = [e["t"] for e in d.get("events", []) if e.get("kind") == "lift_off" and e.get("front") is not None]
    return (lift[0] if lift else None), d.get("status"), (d.get("stop_reason") or d.get("error") or "")


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--binary", default="build/chainsim")
    ap.add_argument("--rotations", type=int, default=6)
    args = ap.parse_args()
    counts, per_nodes = Counter(), Counter()
    with tempfile.TemporaryDirectory() as work:
        for kind, (points, table) in PROBLEMS.items():
            for nodes in NODES:
                t2, status2, why2 = run(args.binary, text(points, table, nodes, None), work)
                if t2 is None:
                    print(f"{kind} {nodes} nodes: the 2D run has no lift-off ({status2}: {why2[:100]})")
                    continue
                for seed in range(args.rotations):
                    t3, status3, why3 = run(args.binary, text(points, table, nodes, rotation(np.random.default_rng(seed))), work)
                    c = "same" if t3 is not None and abs(t3 - t2) < 1e-6 else "wrong" if t3 is not None else "located"
                    counts[c] += 1
                    if c != "same":
                        per_nodes[nodes] += 1
                        print(f"{kind:10s} {nodes:4d} nodes, rotation {seed}: {c}: 2D lift-off {t2:.9g} s; 3D "
                              f"{'%.9g s' % t3 if t3 is not None else status3}: {why3[:110]}")
    print(f"{sum(counts.values())} rotated runs: {dict(counts)}; not the same, by mesh: {dict(sorted(per_nodes.items()))}")


if __name__ == "__main__":
    main()
