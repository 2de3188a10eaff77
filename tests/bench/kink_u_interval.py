"""The swinging U's kink between two crossings, frame by frame (docs/model.md §9, "The crossing breaks the jump
conditions").

Runs cases/scenes/swinging_u.toml with [solver] kinks = "insert" on one mesh to --to with frames every --interval
and prints, for every frame in [--from, --to], with a the split link's first node (from the front's s0 in
series.csv) and b = a + 1:
  l-/h, the front's speed s0_dot (series.csv) and tau- = lambda s0_dot^2 against the tension of the arm's link
  (a-2, a-1) (tension.csv); the front's own turn (between the links (a-1, a) and (b, b+1)); the turns of the arm
  at a-2 and a-1 and at b+1 (deg); the rotation rates of the links (a-2, a-1), (a-1, a), (b, b+1) and of the
  split link's chord (a, b) (rad/s; a smooth arm rotates as a whole, at the rate of the links farther away,
  printed as "arm").

    /usr/bin/python3 tests/bench/kink_u_interval.py --binary build/chainsim --nodes 201 --from 0.6436 --to 0.6486
"""
import argparse
import os
import subprocess

import numpy as np


def turn_deg(t1, t2):
    return np.degrees(np.arctan2(t1[0] * t2[1] - t1[1] * t2[0], t1 @ t2))


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--binary", default="build/chainsim")
    parser.add_argument("--scene", default="cases/scenes/swinging_u.toml")
    parser.add_argument("--nodes", type=int, default=201)
    parser.add_argument("--density", type=float, default=0.1, help="the scene's string.density (kg/m)")
    parser.add_argument("--from", dest="t0", type=float, default=0.6436)
    parser.add_argument("--to", dest="t1", type=float, default=0.6486)
    parser.add_argument("--interval", type=float, default=0.0002)
    parser.add_argument("--out", default="/tmp/kink_u_interval")
    args = parser.parse_args()
    out = os.path.join(args.out, f"n{args.nodes}")
    subprocess.run([args.binary, "run", args.scene, "--set", f"string.nodes={args.nodes}", "--set",
                    'solver.kinks="insert"', "--set", f"stop.t_end={args.t1}", "--set",
                    f"output.interval={args.interval}", "--out", out], check=True, stdout=subprocess.DEVNULL)
    nodes = np.loadtxt(os.path.join(out, "nodes.csv"), delimiter=",", skiprows=1)
    tension = np.loadtxt(os.path.join(out, "tension.csv"), delimiter=",", skiprows=1)
    with open(os.path.join(out, "series.csv")) as f:
        head = f.readline().strip().split(",")
    series = np.loadtxt(os.path.join(out, "series.csv"), delimiter=",", skiprows=1)
    c_s0, c_sd = head.index("s0_0"), head.index("s0dot_0")
    print("t | a | l-/h | s0_dot | tau- | arm T | front turn | turn a-2, a-1 | turn b+1 | "
          "rate (a-2,a-1), (a-1,a), chord (a,b), (b,b+1), arm (a-8,a-7)")
    for row in series:
        t = row[0]
        if not (args.t0 - 1e-12 <= t <= args.t1 + 1e-12) or not np.isfinite(row[c_s0]):
            continue
        f = nodes[np.abs(nodes[:, 0] - t) < 1e-9]
        if len(f) < 2:
            continue
        s, x, v = f[:, 2], f[:, 3:5], f[:, 5:7]
        h = s[1] - s[0]
        a = int(np.floor(row[c_s0] / h + 1e-9))
        b = a + 1
        if a < 9 or b + 2 >= len(s):
            continue
        link = np.diff(x, axis=0)
        length = np.linalg.norm(link, axis=1)
        tang = link / length[:, None]
        normal = np.stack([-tang[:, 1], tang[:, 0]], axis=1)
        rate = np.einsum("ij,ij->i", np.diff(v, axis=0), normal) / length
        T = tension[np.abs(tension[:, 0] - t) < 1e-9]
        arm_T = T[T[:, 1] == a - 2, 3]
        sd = row[c_sd]
        print(f"{t:.4f} | {a} | {(row[c_s0] - s[a]) / h:.3f} | {sd:.3f} | {args.density * sd ** 2:.4f} | "
              f"{arm_T[0] if len(arm_T) else float('nan'):.4f} | {abs(turn_deg(tang[a - 1], tang[b])):.2f} | "
              f"{turn_deg(tang[a - 3], tang[a - 2]):.2f}, {turn_deg(tang[a - 2], tang[a - 1]):.2f} | "
              f"{turn_deg(tang[b], tang[b + 1]):.2f} | {rate[a - 2]:.1f}, {rate[a - 1]:.1f}, {rate[a]:.1f}, "
              f"{rate[b]:.1f}, {rate[a - 8]:.1f}")


if __name__ == "__main__":
    main()
