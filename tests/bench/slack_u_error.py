"""Where the swinging U's mesh error sits after its kink forms (docs/model.md §9, "Where the U's error sits").

Runs cases/scenes/swinging_u.toml on successive meshes (each twice the links of the one before) and compares the
same material points (every node of the coarser mesh, every other node of the finer) at the output times: the
largest distance and where along the material it sits, the mass-weighted RMS distance, where the kink is (the
largest turn of the tangent over 2 cm of material on the finer mesh), the largest distance more than 5 cm of
material from the kink, and the share of the material whose distance exceeds half the largest.

    /usr/bin/python3 tests/bench/slack_u_error.py --binary build/chainsim --nodes 101 201 401 801 --out /tmp/u_error
"""
import argparse
import collections
import csv
import os
import subprocess

import numpy as np


def load(directory):
    frames = collections.defaultdict(list)
    with open(os.path.join(directory, "nodes.csv")) as f:
        for row in csv.DictReader(f):
            frames[round(float(row["t"]), 6)].append((int(row["node"]), float(row["s"]), float(row["x"]), float(row["y"])))
    out = {}
    for t, rows in frames.items():
        a = np.array(sorted(rows))
        out[t] = (a[:, 1], a[:, 2:4])
    return out


def kink(s, x, window=0.01):
    h = s[1] - s[0]
    w = max(1, int(round(window / h)))
    theta = np.unwrap(np.arctan2(np.diff(x[:, 1]), np.diff(x[:, 0])))
    turn = np.abs(theta[2 * w:] - theta[:-2 * w])
    k = int(np.argmax(turn))
    return s[k + w], np.degrees(turn[k])


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--binary", default="build/chainsim")
    parser.add_argument("--scene", default="cases/scenes/swinging_u.toml")
    parser.add_argument("--nodes", type=int, nargs="+", default=[101, 201, 401, 801])
    parser.add_argument("--interval", type=float, default=0.25)
    parser.add_argument("--out", default="results/slack_u_error")
    parser.add_argument("--t-end", type=float, help="replaces the scene's [stop] t_end (s)")
    args = parser.parse_args()
    runs = []
    for n in args.nodes:
        directory = os.path.join(args.out, f"n{n}")
        if not os.path.exists(os.path.join(directory, "stats.json")):
            t_end = ["--t-end", str(args.t_end)] if args.t_end else []
            subprocess.run([args.binary, "run", args.scene, "--set", f"string.nodes={n}", "--set",
                            f"output.interval={args.interval}", "--out", directory] + t_end, check=True,
                           stdout=subprocess.DEVNULL)
        runs.append(load(directory))
    print("t (s) | meshes | max (m) | at s (m) | RMS (m) | kink at s (m), turn | max > 5 cm from the kink (m) | share > max/2")
    for t in sorted(runs[0]):
        if t == 0:
            continue
        for k in range(len(runs) - 1):
            s1, x1 = runs[k][t]
            s2, x2 = runs[k + 1][t]
            d = np.linalg.norm(x1 - x2[::2], axis=1)
            sk, turn = kink(s2, x2)
            far = np.abs(s1 - sk) > 0.05
            print(f"{t:g} | {len(s1)}->{len(s2)} | {d.max():.2e} | {s1[np.argmax(d)]:.3f} | {np.sqrt(np.mean(d ** 2)):.2e} | "
                  f"{sk:.3f}, {turn:.0f} deg | {d[far].max():.2e} | {np.mean(d > d.max() / 2):.2f}")


if __name__ == "__main__":
    main()
