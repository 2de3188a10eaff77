"""Swinging sides at a sharp peg: the measurements of docs/model.md §8, "Two options tried (measured, not adopted)".

Runs three families on refined meshes and prints one line per run: the status, the stop time and reason, the
crossings, the energy and momentum residuals (of the energy scale), W_remesh (its total and its largest jump at one
crossing, J) and the largest |R_y| of the first peg (N).

  v        docs/data/v_over_peg.toml to t = 0.2 s (the V over a peg: sides at 37°, 0.5 m/s, gravity)
  counter  the same V with its sides 2° off the vertical, sliding at 2 m/s: it must lift off near the vertical V's
           0.07457 s (the review's counter-example)
  pegs     cases/scenes/chain_over_two_pegs.toml with gravity (its sagging span reaches the pegs)

main's binary stops every swinging run at its first crossing (the crossing guard). The scheme variants are those of
docs/data/edge_swing_relay_experiment.patch, chosen by environment variables (see its header):

    git apply docs/data/edge_swing_relay_experiment.patch && cmake --build build -j2 --target chainsim
    CHAINSIM_NEAR=0.1 /usr/bin/python3 tests/bench/edge_swing_relay.py --binary build/chainsim --family v counter pegs
"""
import argparse
import csv
import json
import math
import os
import subprocess

FAMILIES = {
    "v": ("docs/data/v_over_peg.toml", [12, 24, 48, 96, 192], ["stop.t_end=0.2"]),
    "counter": ("docs/data/v_over_peg.toml", [21, 41, 81, 161, 321],
                ["velocity.speed=2.0", "stop.t_end=0.2",
                 "shape.points=[[{0}, {1}], [0.0, 0.0], [{2}, {1}]]".format(
                     repr(-0.5 * math.sin(math.radians(2))), repr(-0.5 * math.cos(math.radians(2))),
                     repr(0.5 * math.sin(math.radians(2))))]),
    "pegs": ("cases/scenes/chain_over_two_pegs.toml", [38, 74, 146, 290], ["effects.gravity.g=[0.0, -9.81]"]),
}


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--binary", default="build/chainsim")
    parser.add_argument("--family", nargs="+", default=list(FAMILIES), choices=list(FAMILIES))
    parser.add_argument("--nodes", type=int, nargs="*", help="replaces the family's meshes")
    parser.add_argument("--out", default="results/edge_swing_relay")
    args = parser.parse_args()
    for family in args.family:
        scene, meshes, sets = FAMILIES[family]
        for n in args.nodes or meshes:
            out = os.path.join(args.out, f"{family}{n}")
            command = [args.binary, "run", scene, "--json", "--out", out, "--set", f"string.nodes={n}"]
            for s in sets:
                command += ["--set", s]
            run = subprocess.run(command, capture_output=True, text=True)
            d = json.loads(run.stdout.splitlines()[0])
            reason = (d.get("stop_reason") or d.get("error") or "")[:90]
            w, r_max = [0.0], 0.0
            if os.path.exists(os.path.join(out, "series.csv")):
                with open(os.path.join(out, "series.csv")) as f:
                    rows = list(csv.DictReader(f))
                w = [float(r["W_remesh"]) for r in rows]
                r_max = max(abs(float(r["R_front0_y"])) for r in rows)
            jump = max([abs(b - a) for a, b in zip(w, w[1:])] or [0.0])
            print(f"{family} {n:4d} nodes: {d['status']:9s} t = {d.get('t_stop', float('nan')):.5f} s, "
                  f"{d.get('transfers', 0):3d} crossings, energy {d.get('energy_residual', 0):.2e}, "
                  f"momentum {d.get('momentum_residual', 0):.2e}, W_remesh {w[-1]:.2e} J (largest jump {jump:.2e}), "
                  f"|R_y| <= {r_max:.1f} N; {reason}")


if __name__ == "__main__":
    main()
