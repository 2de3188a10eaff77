"""How a node reaches a peg along a swinging side (docs/model.md §8, "Why a swinging side fails at the point").

Runs a chain laid as a V over a peg at the origin (sides at 37° from the vertical, released with a tangential
speed of 0.5 m/s under gravity, slack allowed: docs/data/v_over_peg.toml, the scene of the `[slack][edge]` test "a
tangential start over an edge or a peg") on each mesh, frames every --interval, and prints for the node that reaches the peg first, over
its last frames before it crosses: its distance r to the peg (in links), the turn between its last whole link
and its partial link (deg), and its velocity along and across the partial link (m/s) with r times the latter (its
angular momentum about the peg per unit mass, m²/s).

    /usr/bin/python3 tests/bench/edge_swing_approach.py --binary build/chainsim --nodes 12 24 48
"""
import argparse
import collections
import csv
import math
import os
import subprocess



def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--binary", default="build/chainsim")
    parser.add_argument("--scene", default="docs/data/v_over_peg.toml")
    parser.add_argument("--nodes", type=int, nargs="+", default=[12, 24, 48])
    parser.add_argument("--interval", type=float, default=0.0002)
    parser.add_argument("--frames", type=int, default=12, help="frames printed per mesh")
    parser.add_argument("--out", default="results/edge_swing_approach")
    args = parser.parse_args()
    for n in args.nodes:
        out = os.path.join(args.out, f"n{n}")
        os.makedirs(out, exist_ok=True)
        run = subprocess.run([args.binary, "run", args.scene, "--set", f"string.nodes={n}", "--set",
                              f"output.interval={args.interval}", "--set", "stop.t_end=0.2", "--out", out],
                             capture_output=True, text=True)
        frames = collections.defaultdict(dict)
        with open(os.path.join(out, "nodes.csv")) as f:
            for row in csv.DictReader(f):
                frames[float(row["t"])][int(row["node"])] = tuple(float(row[k]) for k in ("x", "y", "vx", "vy"))
        with open(os.path.join(out, "series.csv")) as f:
            series = [(float(row["t"]), float(row["s0_0"])) for row in csv.DictReader(f)]
        h = 1.0 / (n - 1)
        # The first node to reach the peg: the last one before it at the start (the material runs to the + side),
        # and the frames before the front passes it.
        a = int(series[0][1] / h)
        crossed = next((t for t, s0 in series if s0 <= a * h), series[-1][0])
        times = sorted(t for t in frames if t < crossed)
        print(f"{n} nodes: node {a} reaches the peg at t = {crossed:.4f} s; the run ends: "
              f"{(run.stderr.strip().splitlines() or ['completed'])[-1][:160]}")
        step = max(1, min(len(times), 40) // args.frames)
        for t in times[-min(len(times), 40)::step]:
            x, y, vx, vy = frames[t][a]
            r = math.hypot(x, y)
            ex, ey = -x / r, -y / r  # along the partial link, towards the peg
            px, py = frames[t][a - 1][:2]
            dx, dy = x - px, y - py
            dl = math.hypot(dx, dy)
            turn = math.degrees(math.atan2(dx * ey - dy * ex, dx * ex + dy * ey) if dl > 0 else 0.0)
            along, across = ex * vx + ey * vy, ex * vy - ey * vx
            print(f"  t = {t:.4f} s  r = {r / h:.2e} h  turn {turn:7.2f} deg  v along {along:.3f}  across {across:.3f} m/s"
                  f"  r v_across {r * across:.2e} m^2/s")


if __name__ == "__main__":
    main()
