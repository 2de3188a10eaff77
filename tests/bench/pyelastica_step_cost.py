#!/usr/bin/env python3
"""Per-step cost of PyElastica's Position Verlet on the hanging chain's rod (docs/work-precision.md, "Against
PyElastica"). Not a test; PyElastica is not a dependency of chainsim and nothing here is part of it.

The comparison in docs/work-precision.md times PyElastica on the hanging chain's first mode (ℓ = 1 m, three
periods, 1 mm amplitude): PyElastica 0.3.3 at N = 200 elements needed 1.64 M Position-Verlet steps there. This
script measures, on this machine and in the same session as chainsim's timing, what one such step costs, and
extrapolates the whole run: time = 1.64e6 × (median cost of a step).

It builds a 200-element Cosserat rod of length 1 m hanging from a fixed end under gravity (λ = 0.1 kg/m, a
soft, thin rod: the per-step cost does not depend on the material constants or on dt), finalizes the
simulator (numba compiles its kernels there, outside the timing), takes --warmup steps, then --repeats
batches of --steps steps, and prints the median cost of a step and the extrapolated time.

    /usr/bin/python3 tests/bench/pyelastica_step_cost.py /path/to/PyElastica [--steps 2000] [--repeats 7]
    PYELASTICA_PATH=/path/to/PyElastica /usr/bin/python3 tests/bench/pyelastica_step_cost.py

The path is a checkout of github.com/GazzolaLab/PyElastica (its `elastica` package at the top) or empty to use
an installed `elastica`. PyElastica needs numba; without it (or without PyElastica) the script says so and
exits with status 2. --json prints one JSON object instead of the text lines.
"""
import argparse
import inspect
import json
import os
import statistics
import sys
import time

PUBLISHED_STEPS = 1.64e6  # Position-Verlet steps of PyElastica 0.3.3 at N = 200 on this problem
N_ELEMENTS = 200
LENGTH = 1.0       # m
LINE_DENSITY = 0.1  # kg/m
RADIUS = 0.005     # m
GRAVITY = 9.81     # m/s^2
PERIODS = 3.0


def fail(message):
    print(f"pyelastica_step_cost: {message}", file=sys.stderr)
    sys.exit(2)


def import_elastica(path):
    if path:
        if not os.path.isdir(os.path.join(path, "elastica")):
            fail(f"{path} has no 'elastica' package: give the top of a PyElastica checkout "
                 "(argument or PYELASTICA_PATH)")
        sys.path.insert(0, os.path.abspath(path))
    try:
        import numba  # noqa: F401  (PyElastica compiles its kernels with numba)
    except ImportError as e:
        fail(f"PyElastica needs numba, which is not importable here ({e}); on Debian: apt-get install "
             "python3-numba (PyElastica states the numba versions it supports in its pyproject.toml)")
    try:
        import elastica
    except Exception as e:  # an ImportError, or a version conflict raised while importing
        fail(f"PyElastica is not importable{' from ' + path if path else ''}: {type(e).__name__}: {e}")
    return elastica


def straight_rod(ea, np):
    """The hanging rod, passing each constructor argument by the name this PyElastica version uses."""
    area = np.pi * RADIUS ** 2
    density = LINE_DENSITY / area
    youngs = 1e6
    params = inspect.signature(ea.CosseratRod.straight_rod).parameters
    kwargs = {"youngs_modulus": youngs}
    # nu (internal damping) was a required argument in early 0.3 releases and is refused (ValueError) when given in
    # later ones, where it defaults to None: pass it only where it is required.
    if "nu" in params and params["nu"].default is inspect.Parameter.empty:
        kwargs["nu"] = 0.0
    if "shear_modulus" in params or any(p.kind == p.VAR_KEYWORD for p in params.values()):
        kwargs["shear_modulus"] = youngs / 3.0
    start = np.zeros(3)
    direction = np.array([0.0, -1.0, 0.0])
    normal = np.array([0.0, 0.0, 1.0])
    return ea.CosseratRod.straight_rod(N_ELEMENTS, start, direction, normal, LENGTH, RADIUS, density, **kwargs)


def build(ea, np):
    mixins = [ea.BaseSystemCollection, ea.Constraints, ea.Forcing]

    class Simulator(*mixins):
        pass

    sim = Simulator()
    rod = straight_rod(ea, np)
    sim.append(rod)
    sim.constrain(rod).using(ea.OneEndFixedBC, constrained_position_idx=(0,), constrained_director_idx=(0,))
    sim.add_forcing_to(rod).using(ea.GravityForces, acc_gravity=np.array([0.0, -GRAVITY, 0.0]))
    sim.finalize()
    stepper = ea.PositionVerlet()
    if hasattr(stepper, "step"):  # newer PyElastica: stepper.step(system, time, dt)
        return lambda t, dt: stepper.step(sim, t, dt)
    do_step, stages = ea.extend_stepper_interface(stepper, sim)  # 0.3.x
    return lambda t, dt: do_step(stepper, stages, sim, t, dt)


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("path", nargs="?", default=os.environ.get("PYELASTICA_PATH", ""),
                    help="top of a PyElastica checkout (default: $PYELASTICA_PATH, else an installed elastica)")
    ap.add_argument("--steps", type=int, default=2000, help="steps per timed batch")
    ap.add_argument("--repeats", type=int, default=7, help="timed batches; the median is kept")
    ap.add_argument("--warmup", type=int, default=200, help="untimed steps first")
    ap.add_argument("--total-steps", type=float, default=PUBLISHED_STEPS,
                    help="steps of the whole run to extrapolate to (default: the published 1.64e6)")
    ap.add_argument("--json", action="store_true")
    opts = ap.parse_args()
    if opts.steps < 1 or opts.repeats < 1 or opts.warmup < 0 or opts.total_steps <= 0:
        fail("--steps and --repeats must be >= 1, --warmup >= 0, --total-steps > 0")

    ea = import_elastica(opts.path)
    import numpy as np

    omega1 = 0.5 * 2.404825557695773 * (GRAVITY / LENGTH) ** 0.5
    dt = PERIODS * 2 * np.pi / omega1 / opts.total_steps  # the run's step (the cost does not depend on it)
    step = build(ea, np)
    t = 0.0
    for _ in range(opts.warmup):
        t = step(t, dt)
    costs = []
    for _ in range(opts.repeats):
        start = time.perf_counter()
        for _ in range(opts.steps):
            t = step(t, dt)
        costs.append((time.perf_counter() - start) / opts.steps)
    per_step = statistics.median(costs)
    result = {"pyelastica_version": getattr(ea, "__version__", "unknown"), "n_elements": N_ELEMENTS,
              "steps_per_batch": opts.steps, "batches": opts.repeats, "per_step_s": per_step,
              "per_step_all_s": costs, "total_steps": opts.total_steps,
              "extrapolated_s": per_step * opts.total_steps}
    if opts.json:
        print(json.dumps(result))
    else:
        print(f"PyElastica {result['pyelastica_version']}, {N_ELEMENTS} elements, Position Verlet: "
              f"median {per_step * 1e6:.2f} us per step ({opts.repeats} batches of {opts.steps})")
        print(f"extrapolated to {opts.total_steps:.3g} steps: {result['extrapolated_s']:.1f} s")


if __name__ == "__main__":
    main()
