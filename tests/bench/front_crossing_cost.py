#!/usr/bin/env python3
"""The cost of fronts on fine meshes (docs/work-precision.md, "Fronts on fine meshes"; docs/shocks.md,
"The cost of a crossing"): `chainsim compare PROBLEM --nodes N` of the three canonical problems on a
list of meshes, one run each, in one session. Prints, per run, the process's wall time, the string
solver's own time (wall_s), the process's CPU time (user + system: the steadier figure on a shared
machine, where wall time is mostly waiting for a core), the crossings, steps and right-hand sides, the
right-hand sides and the CPU time per crossing, the CPU time per right-hand side and node, and the
errors against the reduced ODE; then, per problem, the ratio of the CPU time on the finest mesh to the
coarsest.

    /usr/bin/python3 tests/bench/front_crossing_cost.py [--binary build/chainsim] [--nodes 200,800,3200]
        [--problems falling,folded,sliding] [--method erk5] [--repeat 3]

With --repeat N each run is made N times and the times printed are the medians (the counts are the same
every time: the runs are deterministic).

Not a test: it checks no timing (the counted bound is tests/convergence/test_front_crossing_cost.cpp).
"""
import argparse
import json
import resource
import statistics
import subprocess
import sys
import tempfile
import time


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--binary", default="build/chainsim")
    parser.add_argument("--nodes", default="200,800,3200")
    parser.add_argument("--problems", default="falling,folded,sliding")
    parser.add_argument("--method", default=None, help="the compare's --method (default: its own)")
    parser.add_argument("--repeat", type=int, default=1, help="runs of each case; the times are the medians")
    args = parser.parse_args()
    meshes = [int(n) for n in args.nodes.split(",")]
    print(f"{'problem':8s} {'nodes':>5s} {'process':>8s} {'solver':>8s} {'cpu':>8s} {'cross':>5s} {'steps':>6s} {'rhs':>7s} "
          f"{'rhs/cr':>6s} {'cpu ms/cr':>9s} {'ns/rhs/node':>11s} {'rel_err_t_stop':>14s} {'err_eta':>9s} {'rel_err_P':>9s}")
    with tempfile.TemporaryDirectory() as out:
        for problem in args.problems.split(","):
            solver = {}
            for n in meshes:
                command = [args.binary, "compare", problem, "--nodes", str(n), "--json", "--out", f"{out}/{problem}{n}"]
                if args.method:
                    command += ["--method", args.method]
                times = []
                for _ in range(max(args.repeat, 1)):
                    before = resource.getrusage(resource.RUSAGE_CHILDREN)
                    start = time.perf_counter()
                    run = subprocess.run(command, capture_output=True, text=True)
                    process = time.perf_counter() - start
                    after = resource.getrusage(resource.RUSAGE_CHILDREN)
                    if run.returncode != 0:
                        break
                    s = json.loads(run.stdout)
                    times.append((process, s["wall_s"], (after.ru_utime - before.ru_utime) + (after.ru_stime - before.ru_stime)))
                if run.returncode != 0:
                    print(f"{problem} {n}: exit {run.returncode}: {run.stdout[-400:]} {run.stderr[-400:]}")
                    continue
                process, wall, cpu = (statistics.median(column) for column in zip(*times))
                s["wall_s"] = wall
                cross = max(s["transfers"], 1)
                solver[n] = cpu
                print(f"{problem:8s} {n:5d} {process:8.2f} {s['wall_s']:8.3f} {cpu:8.2f} {s['transfers']:5d} "
                      f"{s['steps']:6d} {s['rhs_evals']:7d} {s['rhs_evals'] / cross:6.1f} {1e3 * cpu / cross:9.3f} "
                      f"{1e9 * cpu / s['rhs_evals'] / n:11.1f} {s['rel_err_t_stop']:14.3e} "
                      f"{s['max_abs_err_eta']:9.2e} {s['max_rel_err_P']:9.2e}", flush=True)
            if len(solver) == len(meshes) and len(meshes) > 1:
                print(f"{problem}: CPU time at {meshes[-1]} nodes / at {meshes[0]} nodes = "
                      f"{solver[meshes[-1]] / solver[meshes[0]]:.1f} (nodes x{meshes[-1] / meshes[0]:g})")
    return 0


if __name__ == "__main__":
    sys.exit(main())
