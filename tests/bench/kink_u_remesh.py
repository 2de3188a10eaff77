"""Where the swinging U's W_remesh goes with kinks = "insert", event by event, and how its state converges
(docs/model.md §9, "W_remesh event by event").

Runs cases/scenes/swinging_u.toml with [solver] kinks = "insert" on successive meshes (each twice the links of
the one before) with CHAINSIM_TRACE_FRONTS set (one stderr line per front event: the energy the re-layout of
the mass parcels and the projection after it change, and the velocity jumps along the front's stencil
a-1, a, b, b+1 before it) and prints
  1. W_remesh per event class: the insertion, the crossings in time windows (re-layout / projection), the
     absorption's re-layout (its impact is W_shocks);
  2. the arm-side velocity jump |v_a - v_(a-1)| at the crossings (median, in the windows): a smooth arm has
     h |dv/ds|, O(h);
  3. the arm's corner at the crossings: its turn at a-1 and a-2 before, at the new a-1 and a-2 after (the
     `arm_corner` lines), and the turn the kink constraint's reaction on a-1 would make against tau-; and the
     front itself before and after: its own turn, its speed, tau- = lambda s0_dot^2 against the arm's tension;
  4. the state at the --times: the largest and the RMS distance between the same material points on
     successive meshes (the coarser mesh's nodes, every other node of the finer), where the largest sits, and K.

    /usr/bin/python3 tests/bench/kink_u_remesh.py --binary build/chainsim --nodes 101 201 401 801 --out /tmp/kink_u
"""
import argparse
import csv
import os
import re
import subprocess
import sys

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from slack_u_error import load  # noqa: E402  (the frames of nodes.csv by time)

WINDOWS = [(0.0, 0.40), (0.40, 0.50), (0.50, 0.60), (0.60, 0.70), (0.70, 0.80), (0.80, 2.0)]


def run(binary, scene, n, interval, directory):
    trace = os.path.join(directory, "trace.txt")
    if not os.path.exists(os.path.join(directory, "stats.json")):
        os.makedirs(directory, exist_ok=True)
        with open(trace, "w") as err:
            subprocess.run([binary, "run", scene, "--set", f"string.nodes={n}", "--set", 'solver.kinks="insert"',
                            "--set", f"output.interval={interval}", "--out", directory], check=True,
                           stdout=subprocess.DEVNULL, stderr=err, env=dict(os.environ, CHAINSIM_TRACE_FRONTS="1"))
    events = []
    for line in open(trace):
        if line.startswith("front_event"):
            events.append({k: (v if k == "kind" else float(v)) for k, v in re.findall(r"(\w+)=(\S+)", line)})
        elif line.startswith("arm_corner"):  # the arm's corner at a - 1 before / after each crossing
            row = {k: (v if k == "when" else float(v)) for k, v in re.findall(r"(\w+)=(\S+)", line)}
            row["kind"] = "corner_" + row.pop("when")
            events.append(row)
    energy = list(csv.DictReader(open(os.path.join(directory, "energy.csv"))))
    return events, energy, load(directory)


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--binary", default="build/chainsim")
    parser.add_argument("--scene", default="cases/scenes/swinging_u.toml")
    parser.add_argument("--nodes", type=int, nargs="+", default=[101, 201, 401, 801])
    parser.add_argument("--interval", type=float, default=0.05)
    parser.add_argument("--times", type=float, nargs="+", default=[0.3, 0.5, 0.75, 0.9, 1.0])
    parser.add_argument("--out", default="results/kink_u_remesh")
    args = parser.parse_args()
    runs = [run(args.binary, args.scene, n, args.interval, os.path.join(args.out, f"n{n}")) for n in args.nodes]

    print("W_remesh per event (mJ): N | insert | crossings " +
          " | ".join(f"[{a:g}, {b:g})" for a, b in WINDOWS) + " (re-layout/projection) | absorb re-layout (in W_shocks) | total | "
          "energy.csv W_remesh at the end")
    for n, (events, energy, _) in zip(args.nodes, runs):
        ins = sum(e["relayout"] + e["projection"] for e in events if e["kind"] == "insert")
        cells = []
        for a, b in WINDOWS:
            c = [e for e in events if e["kind"] == "cross" and a <= e["t"] < b]
            cells.append(f"{1e3 * sum(e['relayout'] for e in c):.3f}/{1e3 * sum(e['projection'] for e in c):.3f} ({len(c)})")
        absorb = sum(e["relayout"] for e in events if e["kind"] == "absorb")
        total = sum(e["relayout"] + e["projection"] for e in events if e["kind"] in ("insert", "cross"))
        print(f"{n} | {1e3 * ins:.4f} | " + " | ".join(cells) + f" | {1e3 * absorb:.4f} | {1e3 * total:.3f} | "
              f"{1e3 * float(energy[-1]['W_remesh']):.3f}")

    print("\n|v_a - v_(a-1)| at the crossings, median (m/s): N | h (m) | " + " | ".join(f"[{a:g}, {b:g})" for a, b in WINDOWS))
    for n, (events, _, frames) in zip(args.nodes, runs):
        s = frames[min(frames)][0]
        cells = []
        for a, b in WINDOWS:
            dv = [e["jump_before"] for e in events if e["kind"] == "cross" and a <= e["t"] < b]
            cells.append(f"{np.median(dv):.3f}" if dv else "-")
        print(f"{n} | {s[1] - s[0]:.5f} | " + " | ".join(cells))

    print("\nafter each crossing: where the front is re-drawn, l-/h of its new split link (1 or 0: where it was), "
          "median; and the front's mean speed in the material from the crossings (links per s times h) against "
          "the jump conditions' |s0_dot|, median: N | " + " | ".join(f"[{a:g}, {b:g})" for a, b in WINDOWS))
    for n, (events, _, frames) in zip(args.nodes, runs):
        s = frames[min(frames)][0]
        h = s[1] - s[0]
        cells = []
        for a, b in WINDOWS:
            c = [e for e in events if e["kind"] == "cross" and a <= e["t"] < b]
            if len(c) < 2:
                cells.append("-")
                continue
            rate = h * (len(c) - 1) / (c[-1]["t"] - c[0]["t"])
            cells.append(f"{np.median([(e['s0'] / h) % 1 for e in c]):.2f}, {rate:.2f} / "
                         f"{np.median([abs(e['s0_dot']) for e in c]):.2f} m/s")
        print(f"{n} | " + " | ".join(cells))

    print("\nre-layout of the crossings in [0.4, 0.8) s (mJ): N | total | its kinetic part | the merge of the node next "
          "to the kink alone, -(lambda h / 6) sum |v_a - v_(a-1)|^2")
    for n, (events, _, frames) in zip(args.nodes, runs):
        s = frames[min(frames)][0]
        h = s[1] - s[0]
        c = [e for e in events if e["kind"] == "cross" and 0.4 <= e["t"] < 0.8]
        lam = 0.1
        print(f"{n} | {1e3 * sum(e['relayout'] for e in c):.3f} | {1e3 * sum(e['relayout_K'] for e in c):.3f} | "
              f"{-1e3 * sum(lam * h / 6 * e['jump_before'] ** 2 for e in c):.3f}")

    print("\nthe arm's corner at the crossings (deg, medians): the turn at a-1 and a-2 before the crossing, at the new "
          "a-1 and a-2 after it (projection done), and the largest turn the kink constraint's reaction on a-1 would make "
          "against tau: N | window: before a-1, a-2 | after a-1, a-2 | reaction")
    for n, (events, _, _) in zip(args.nodes, runs):
        cells = []
        for a, b in [(0.4, 0.6), (0.6, 0.7), (0.7, 0.8)]:
            bf = [e for e in events if e["kind"] == "corner_before" and a <= e["t"] < b]
            af = [e for e in events if e["kind"] == "corner_after" and a <= e["t"] < b]
            if not bf or not af:
                cells.append("-")
                continue
            med = lambda rows, k: np.median([r[k] for r in rows])  # noqa: E731
            cells.append(f"[{a:g}, {b:g}): {med(bf, 'turn_deg'):.2f}, {med(bf, 'turn_prev_deg'):.2f} | "
                         f"{med(af, 'turn_deg'):.2f}, {med(af, 'turn_prev_deg'):.2f} | "
                         f"{max(r['reaction_turn_deg'] for r in bf):.1e}")
        print(f"{n} | " + " || ".join(cells))

    print("\nthe front at the crossings (medians): its own turn (deg), its speed |s0_dot| (m/s), tau- = lambda s0_dot^2 "
          "and the tension of the arm's link (a-2, a-1) from the last solve (N), before the crossing | after it "
          "(projection done): N | window: turn, |s0_dot|, tau-, arm T | the same after")
    for n, (events, _, _) in zip(args.nodes, runs):
        cells = []
        for a, b in [(0.4, 0.6), (0.6, 0.7), (0.7, 0.8)]:
            bf = [e for e in events if e["kind"] == "corner_before" and a <= e["t"] < b and "front_turn_deg" in e]
            af = [e for e in events if e["kind"] == "corner_after" and a <= e["t"] < b and "front_turn_deg" in e]
            if not bf or not af:
                cells.append("-")
                continue
            med = lambda rows, k: np.median([abs(r[k]) for r in rows])  # noqa: E731
            cells.append(f"[{a:g}, {b:g}): " + " | ".join(
                f"{med(rows, 'front_turn_deg'):.1f}, {med(rows, 's0_dot'):.2f}, {med(rows, 'tau'):.3f}, "
                f"{med(rows, 'arm_tension'):.3f}" for rows in (bf, af)))
        print(f"{n} | " + " || ".join(cells))

    print("\nstate at t: t | meshes | max (m) at s (m) | RMS (m) | K coarse / fine (mJ)")
    for t in args.times:
        for k in range(len(runs) - 1):
            f1, f2 = runs[k][2], runs[k + 1][2]
            t1 = min(f1, key=lambda q: abs(q - t))
            s1, x1 = f1[t1]
            s2, x2 = f2[min(f2, key=lambda q: abs(q - t))]
            d = np.linalg.norm(x1 - x2[::2], axis=1)
            K = [float(min(e, key=lambda r: abs(float(r["t"]) - t))["K"]) for e in (runs[k][1], runs[k + 1][1])]
            print(f"{t1:g} | {len(s1)}->{len(s2)} | {d.max():.3e} at {s1[np.argmax(d)]:.3f} | "
                  f"{np.sqrt(np.mean(d ** 2)):.3e} | {1e3 * K[0]:.3f} / {1e3 * K[1]:.3f}")


if __name__ == "__main__":
    main()
