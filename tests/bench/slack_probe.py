"""Self-convergence and ledgers of a slack motion, as a user would measure them (docs/model.md §9, "Other slack
motions, measured").

Runs one scene on successive meshes (`--set string.nodes=N` for each N given), to t_end, with one frame there, and
reports per mesh how the run ended (exit code, stop reason, the summary's relative energy and momentum residuals,
W_snap and the other booked terms of energy.csv at t_end), then the largest and the RMS distance between the same
material points on successive meshes at t_end (the finer mesh interpolated linearly along s to the coarser's nodes;
a closed string wraps round) and the observed orders log2(d_k / d_{k+1}) (meshes each twice the links of the one
before).

    /usr/bin/python3 tests/bench/slack_probe.py --binary build/chainsim --scene cases/scenes/spinning_loop_3d.toml \
        --nodes 41 81 161 321 --t 0.5 [--set solver.snap_restitution=0.5 ...]
"""
import argparse
import csv
import json
import math
import os
import subprocess

import numpy as np


def last_frame(directory):
    rows = []
    with open(os.path.join(directory, "nodes.csv")) as f:
        reader = csv.DictReader(f)
        coords = [c for c in ("x", "y", "z") if c in reader.fieldnames]
        for row in reader:
            rows.append((float(row["t"]), int(row["node"]), float(row["s"]), [float(row[c]) for c in coords]))
    t_last = max(r[0] for r in rows)
    frame = sorted((r[1], r[2], r[3]) for r in rows if r[0] == t_last)
    return t_last, np.array([r[1] for r in frame]), np.array([r[2] for r in frame])


def ledger_terms(directory):
    with open(os.path.join(directory, "energy.csv")) as f:
        rows = list(csv.DictReader(f))
    last = rows[-1]
    return {k: float(v) for k, v in last.items() if k.startswith("W_") and k not in ("W_applied",)}


def fronts_at_end(directory, summary):
    """The fronts' s0 at the last row of series.csv (runs with fronts), as ' | name s0 = ... m'."""
    path = os.path.join(directory, "series.csv")
    if not os.path.exists(path):
        return ""
    with open(path) as f:
        rows = list(csv.DictReader(f))
    names = [f["name"] for f in summary.get("fronts", [])]
    out = ""
    for k, name in enumerate(names):
        if f"s0_{k}" in rows[-1]:
            out += f" | {name} s0 = {float(rows[-1][f's0_{k}']):.9f} m"
    return out + f" | snaps {rows[-1].get('snaps', '-')}"


def at(s_fine, x_fine, s, length, closed):
    """The finer mesh's positions at the material points s (linear along s; wrapped round for a closed loop)."""
    if closed:
        s_fine = np.append(s_fine, s_fine[0] + length)
        x_fine = np.vstack([x_fine, x_fine[:1]])
    return np.column_stack([np.interp(s, s_fine, x_fine[:, k]) for k in range(x_fine.shape[1])])


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--binary", default="build/chainsim")
    parser.add_argument("--scene", required=True)
    parser.add_argument("--nodes", type=int, nargs="+", required=True)
    parser.add_argument("--t", type=float, required=True, help="the time at which the states are compared (s)")
    parser.add_argument("--set", action="append", default=[], help="a further --set of every run")
    parser.add_argument("--out", default="results/slack_probe")
    args = parser.parse_args()
    states = []
    print(f"{args.scene} {' '.join(args.set)} at t = {args.t} s")
    print("nodes | exit | stop | t_stop (s) | energy residual | momentum residual | booked terms (J) | steps | wall (s)")
    for n in args.nodes:
        directory = os.path.join(args.out, f"n{n}")
        command = [args.binary, "run", args.scene, "--out", directory, "--json", "--set", f"string.nodes={n}",
                   "--set", f"stop.t_end={args.t}", "--set", f"output.interval={args.t}"]
        for s in args.set:
            command += ["--set", s]
        done = subprocess.run(command, capture_output=True, text=True)
        try:
            summary = json.loads(done.stdout)
        except json.JSONDecodeError:
            print(f"{n} | {done.returncode} | no summary: {done.stderr.strip()[:400]}")
            states.append(None)
            continue
        terms = ledger_terms(directory) if os.path.exists(os.path.join(directory, "energy.csv")) else {}
        print(f"{n} | {done.returncode} | {summary.get('stop_reason')} | {summary.get('t_stop')} | "
              f"{summary.get('energy_residual', float('nan')):.2e} | {summary.get('momentum_residual', float('nan')):.2e} | "
              + ", ".join(f"{k} {v:.3e}" for k, v in terms.items() if v != 0) + f" | {summary.get('steps')} | "
              f"{summary.get('wall_s', 0):.2f}"
              + fronts_at_end(directory, summary))
        if done.returncode != 0:
            print("   " + (summary.get("error") or done.stderr.strip())[:600])
            states.append(None)
            continue
        spec = summary["scene_effective"]["string"]
        states.append((spec["closed"], last_frame(directory)))
    previous = None
    for k in range(1, len(states)):
        if states[k - 1] is None or states[k] is None:
            continue
        closed, (t0, s0, x0) = states[k - 1]
        _, (t1, s1, x1) = states[k]
        length = (s0[1] - s0[0]) * len(s0) if closed else s0[-1]
        d = np.linalg.norm(x0 - at(s1, x1, s0, length, closed), axis=1)
        largest, rms = d.max(), math.sqrt(np.mean(d ** 2))
        order = f", orders {math.log2(previous[0] / largest):.2f} (max) {math.log2(previous[1] / rms):.2f} (RMS)" \
            if previous else ""
        print(f"  {len(s0)} -> {len(s1)} nodes: max {largest:.3e} m at s = {s0[int(np.argmax(d))]:.3f} m, "
              f"RMS {rms:.3e} m{order}")
        previous = (largest, rms)


if __name__ == "__main__":
    main()
