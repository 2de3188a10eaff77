#!/usr/bin/python3
"""chainsim against PyElastica on the hanging chain's first mode, at equal accuracy (docs/work-precision.md,
"Against PyElastica"). Not a test.

The problem: a chain of length 1 m hanging from a fixed point, started at rest on its first mode shape
J0(j01 sqrt(sigma/l)) with a 1 mm amplitude, run for three periods; the error is that of omega1, measured from
the zero crossings of the modal projection (the study's measurement, work_precision.HangingModeCase) against
omega1 = (j01/2) sqrt(g/l). PyElastica 0.3.3 at N = 200 reached 7.4e-6 there in 1.64 M Position-Verlet steps.

  --write-scene PATH   writes the scene (the mode shape as a polyline, [string] elements = "quadratic", the
                       method, tolerance and outputs given by --nodes, --method, --rtol; atol = rtol times the
                       amplitude relative to the length) and stops;
  otherwise            runs the scene once with --json (steps, the solver's time, omega1's error from its nodes.csv),
                       then times `chainsim run SCENE --out DIR --quiet` under /usr/bin/time --repeats times in this
                       session (the whole process: start-up, parsing, integration, writing nodes.csv; elapsed time
                       also with a microsecond clock around it, CPU time from the kernel's rusage, since %e prints
                       10 ms steps), and prints the medians and the ratio to
                       PyElastica's time: measured in the same session by tests/bench/pyelastica_step_cost.py when
                       --pyelastica PATH is given (its per-step median times 1.64e6 steps), else the published
                       108 s (PyElastica 0.3.3 measured earlier on this machine, docs/work-precision.md).
Extra `--set KEY=VALUE` pass through to `chainsim run` (to try other settings on the same scene).

  /usr/bin/python3 tests/bench/hanging_best.py --chainsim build/chainsim --scene cases/scenes/hanging_chain_best.toml
"""
import argparse
import json
import math
import os
import resource
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

HERE = Path(__file__).resolve().parent
ROOT = HERE.parents[1]
sys.path.insert(0, str(HERE))
from work_precision import HangingModeCase  # noqa: E402  (the study's measurement of omega1)

PUBLISHED_PYELASTICA_S = 108.0
PYELASTICA_STEPS = 1.64e6
TARGET = 7.4e-6  # PyElastica's omega1 error at N = 200
AMPLITUDE = 1e-3  # relative to the length: 1 mm on 1 m
PERIODS = 3.0


def write_scene(path, nodes, method, rtol, points):
    case = HangingModeCase(ROOT / "cases" / "scenes" / "hanging_chain.toml", amplitude=AMPLITUDE, periods=PERIODS)
    s = np.linspace(0.0, case.ell, points)
    x = case.amplitude * case.ell * case.phi(case.ell - s)
    pts = ",\n          ".join(f"[{xi:.17g}, {-si:.17g}]" for xi, si in zip(x, s))
    atol = rtol * AMPLITUDE
    path.write_text(f"""# The hanging chain's first mode at the documented best settings for omega1 within {TARGET:g}
# (docs/work-precision.md, "Against PyElastica"): a chain of length 1 m (0.1 kg/m) hanging from a fixed point,
# started at rest on its first mode shape J0(j01 sqrt(sigma/l)) (sigma from the free end) with a 1 mm amplitude,
# run for three periods; omega1 = (j01/2) sqrt(g/l) = {case.omega:.9f} rad/s. Fourth-order quadratic elements on
# {nodes} nodes, {method} at rtol {rtol:g}, atol = rtol times the amplitude (atol is relative to the length).
# Written by tests/bench/hanging_best.py --write-scene (the shape through {points} points of the mode: the chords
# depart from it by about 2e-10 m, far below atol).
#   chainsim run cases/scenes/hanging_chain_best.toml --out results/hanging_chain_best --quiet
[string]
length = 1.0          # m
density = 0.1         # kg/m
nodes = {nodes}
elements = "quadratic"

[shape]
kind = "polyline"
points = [{pts}]

[ends]
start = "fixed"

[effects.gravity]
g = [0.0, -9.81]

[solver]
method = "{method}"
rtol = {rtol:g}
atol = {atol:g}         # rtol x amplitude / length

[output]
interval = 0.02       # s: frames for the zero crossings of the modal projection
fields = ["nodes", "stats"]  # stats.json: the run's summary and counters
formats = ["csv"]

[stop]
t_end = {PERIODS * 2 * math.pi / case.omega:.15g}   # s, three periods of the first mode
""")


def pyelastica_seconds(path):
    if not path:
        return PUBLISHED_PYELASTICA_S, "published (PyElastica 0.3.3, measured earlier on this machine)"
    p = subprocess.run([sys.executable, str(HERE / "pyelastica_step_cost.py"), path, "--json"],
                       capture_output=True, text=True)
    if p.returncode != 0:
        sys.exit(p.stderr.strip() or f"pyelastica_step_cost.py failed ({p.returncode})")
    r = json.loads(p.stdout)
    return r["extrapolated_s"], f"measured now: {r['per_step_s'] * 1e6:.2f} us per step x {PYELASTICA_STEPS:.3g}"


HAVE_TIME = os.path.exists("/usr/bin/time")


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--chainsim", default=str(ROOT / "build" / "chainsim"))
    ap.add_argument("--scene", default=str(ROOT / "cases" / "scenes" / "hanging_chain_best.toml"))
    ap.add_argument("--repeats", type=int, default=7)
    ap.add_argument("--pyelastica", default=os.environ.get("PYELASTICA_PATH", ""),
                    help="a PyElastica checkout to time in this session (else the published 108 s)")
    ap.add_argument("--set", action="append", default=[], help="KEY=VALUE passed to chainsim run")
    ap.add_argument("--write-scene", type=Path, help="write the scene to this path and stop")
    ap.add_argument("--nodes", type=int, default=7)
    ap.add_argument("--method", default="erk4")
    ap.add_argument("--rtol", type=float, default=1e-4)
    ap.add_argument("--points", type=int, default=1001)
    opts = ap.parse_args()
    if opts.write_scene:
        write_scene(opts.write_scene, opts.nodes, opts.method, opts.rtol, opts.points)
        return
    if opts.repeats < 1:
        sys.exit("--repeats must be >= 1")

    case = HangingModeCase(Path(opts.scene), amplitude=AMPLITUDE, periods=PERIODS)
    sets = [a for s in opts.set for a in ("--set", s)]
    timed, elapsed, cpu, solver = [], [], [], []
    with tempfile.TemporaryDirectory() as tmp:
        first = Path(tmp) / "run0"
        # Once untimed with --json: the solver's own figures (steps, its wall time) and the outputs to measure.
        cmd = [opts.chainsim, "run", opts.scene, "--out", str(first), "--quiet", "--json"] + sets
        p = subprocess.run(cmd, capture_output=True, text=True, cwd=ROOT)
        if p.returncode != 0:
            sys.exit(f"{' '.join(cmd)} failed ({p.returncode}): {p.stderr.strip()}")
        summary = json.loads(p.stdout.splitlines()[0])
        error, _ = case.measure(first, {})
        for k in range(opts.repeats):
            out = Path(tmp) / f"run{k + 1}"
            # /usr/bin/time (Debian's package time) is optional: a fresh machine may not have it.
            cmd = (["/usr/bin/time", "-f", "%e %U %S"] if HAVE_TIME else []) + [
                opts.chainsim, "run", opts.scene, "--out", str(out), "--quiet"] + sets
            before = resource.getrusage(resource.RUSAGE_CHILDREN)
            start = time.perf_counter()
            p = subprocess.run(cmd, capture_output=True, text=True, cwd=ROOT)
            timed.append(time.perf_counter() - start)
            after = resource.getrusage(resource.RUSAGE_CHILDREN)
            if p.returncode != 0:
                sys.exit(f"{' '.join(cmd)} failed ({p.returncode}): {p.stderr.strip()}")
            if HAVE_TIME:
                elapsed.append(float(p.stderr.strip().splitlines()[-1].split()[0]))
            cpu.append(after.ru_utime + after.ru_stime - before.ru_utime - before.ru_stime)
    wall = statistics.median(timed)
    py_s, py_how = pyelastica_seconds(opts.pyelastica)
    print(f"scene {os.path.relpath(opts.scene, ROOT)} {' '.join(opts.set)}; load average {os.getloadavg()[0]:.1f}")
    print(f"omega1 relative error {error:.3e} (target {TARGET:g}: {'met' if error <= TARGET else 'NOT met'}); "
          f"{summary.get('steps')} steps, {summary.get('rhs_evals')} right-hand sides, solver {summary['wall_s']:.4f} s")
    print(f"chainsim run, whole process, {opts.repeats} runs: elapsed median {wall:.4f} s "
          f"({', '.join(f'{e:.4f}' for e in timed)}); "
          + (f"/usr/bin/time %e median {statistics.median(elapsed):.2f} s; " if elapsed else "") +
          f"CPU (user + system) median {statistics.median(cpu):.4f} s")
    print(f"PyElastica: {py_s:.1f} s ({py_how})")
    print(f"ratio PyElastica / chainsim: {py_s / wall:,.0f}x (elapsed, whole process), "
          f"{py_s / statistics.median(cpu):,.0f}x (CPU)")


if __name__ == "__main__":
    main()
